import numpy as np
import pytest

from models.errors import ModelError
from models.network.latency import EmpiricalLatency, load_delay_csv


def _write(tmp_path, text, name="delays.csv"):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def test_a_single_column_without_header_is_read_in_order(tmp_path):
    path = _write(tmp_path, "5.0\n7.25\n\n6\n")
    assert load_delay_csv(path).tolist() == [5.0, 7.25, 6.0]


def test_a_header_names_the_delay_ms_column_among_others(tmp_path):
    path = _write(tmp_path, "t_s,delay_ms,host\n0.0,4.5,a\n\n0.1, 5.5 ,b\n")
    assert load_delay_csv(path).tolist() == [4.5, 5.5]


def test_a_single_column_may_have_any_header(tmp_path):
    path = _write(tmp_path, "\ufefflatency\n1\n2\n")
    assert load_delay_csv(path).tolist() == [1.0, 2.0]


def test_an_empirical_latency_is_built_from_a_csv(tmp_path):
    model = EmpiricalLatency.from_csv(_write(tmp_path, "delay_ms\n1.5\n2.5\n"))
    assert model.samples_ms.tolist() == [1.5, 2.5]
    assert set(model.sample(np.random.default_rng(0), 50).tolist()) == {1_500_000, 2_500_000}


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("", "at least one delay"),
        ("\n\n  \n", "at least one delay"),
        ("delay_ms\n", "below the header"),
        ("delay_ms\n1.0\nabc\n", "line 3"),
        ("delay_ms\n1.0\n\n-2.0\n", "line 4"),
        ("1.0\nnan\n", "line 2"),
        ("1.0\ninf\n", "line 2"),
        ("t_s,host\n0.0,a\n", "column named delay_ms on line 1"),
        ("1.0,2.0\n", "one delay per row"),
        ("t_s,delay_ms\n0.0\n", "line 2"),
    ],
)
def test_a_malformed_delay_file_is_refused_naming_the_problem(tmp_path, text, expected):
    path = _write(tmp_path, text)
    with pytest.raises(ModelError, match=expected) as error:
        load_delay_csv(path)
    assert error.value.key == "network.latency_csv"
    assert error.value.value == str(path)


def test_a_missing_delay_file_is_refused(tmp_path):
    with pytest.raises(ModelError, match="readable CSV") as error:
        load_delay_csv(tmp_path / "nowhere.csv")
    assert error.value.key == "network.latency_csv"
