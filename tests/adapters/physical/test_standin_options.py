"""The stand-in robot's options and command line (no DDS, no physics)."""

import argparse
import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from adapters.physical.standin_options import (
    FLOAT_OPTIONS,
    MAX_RATE_HZ,
    StandinOptions,
    add_arguments,
    options_from,
)
from cosim.core.errors import ConfigError


def _parsed(*argv: str) -> StandinOptions:
    parser = argparse.ArgumentParser()
    add_arguments(parser)
    return options_from(parser.parse_args(list(argv)))


def test_the_defaults_are_a_jackals_limits_on_domain_0_on_loopback():
    options = StandinOptions(name="robot_1")
    assert (options.domain, options.interface, options.seed) == (0, None, 1)
    assert (options.x_m, options.y_m, options.yaw_rad) == (0.0, 0.0, 0.0)
    assert (options.max_speed_mps, options.max_reverse_mps, options.max_yaw_rate_radps) == (
        1.0,
        0.3,
        2.0,
    )
    assert (options.rate_hz, options.cmd_timeout_s, options.duration_s) == (100.0, 0.5, None)


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"name": "robot-1"}, "name 'robot-1'"),
        ({"rate_hz": 0.0}, r"rate_hz = 0.0: expected a rate in \(0, 1000.0\]"),
        ({"latency_ms": -1.0}, "latency_ms = -1.0: expected a value >= 0"),
        ({"x_m": math.nan}, "x_m = nan: expected a finite number"),
        ({"duration_s": 0.0}, "duration_s = 0.0: expected a value > 0"),
        ({"cmd_timeout_s": 0.0}, "cmd_timeout_s = 0.0: expected a value > 0"),
    ],
)
def test_invalid_options_raise_a_config_error_naming_the_value(changes, message):
    with pytest.raises(ConfigError, match=message):
        StandinOptions(**{"name": "robot_1", **changes})


def test_the_command_line_gives_the_options_it_names_and_the_defaults_otherwise():
    options = _parsed(
        "--name", "robot_3", "--domain", "7", "--interface", "eth0",
        "--x-m", "1.5", "--y-m", "-2", "--yaw-rad", "3.1", "--rate-hz", "50",
        "--latency-ms", "20", "--noise-std-m", "0.01", "--max-speed-mps", "0.5",
        "--seed", "9", "--duration-s", "4",
    )  # fmt: skip
    assert options == StandinOptions(
        name="robot_3",
        domain=7,
        interface="eth0",
        x_m=1.5,
        y_m=-2.0,
        yaw_rad=3.1,
        rate_hz=50.0,
        latency_ms=20.0,
        noise_std_m=0.01,
        max_speed_mps=0.5,
        seed=9,
        duration_s=4.0,
    )
    assert _parsed("--name", "robot_1") == StandinOptions(name="robot_1")


def test_every_numeric_option_of_the_command_line_is_a_float_field_with_a_unit():
    fields = StandinOptions.__dataclass_fields__
    for key, text in FLOAT_OPTIONS.items():
        assert isinstance(getattr(StandinOptions, key), float), key
        assert key in fields
        assert "(" in text and ")" in text, key  # the unit, in the help


def test_the_help_shows_each_options_default():
    parser = argparse.ArgumentParser()
    add_arguments(parser)
    text = " ".join(parser.format_help().split())
    assert "(default 100)" in text and "(default 0.5)" in text
    assert "--max-yaw-rate-radps" in text and "--cmd-timeout-s" in text


def test_the_name_is_required_on_the_command_line(capsys):
    with pytest.raises(SystemExit):
        _parsed("--rate-hz", "10")
    assert "--name" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("rate", "ok"), [(MAX_RATE_HZ, True), (0.001, True), (MAX_RATE_HZ + 0.5, False), (-1.0, False)]
)
def test_the_rate_is_at_most_what_a_wall_clock_loop_can_hold(rate, ok):
    if ok:
        assert StandinOptions(name="robot_1", rate_hz=rate).rate_hz == rate
    else:
        with pytest.raises(ConfigError, match=rf"rate_hz = {rate!r}: expected a rate in"):
            StandinOptions(name="robot_1", rate_hz=rate)


@pytest.mark.parametrize(
    "changes",
    [
        {"max_speed_mps": 0.0},
        {"max_yaw_rate_radps": -1.0},
        {"max_accel_mps2": 0.0},
        {"max_yaw_accel_radps2": 0.0},
        {"max_reverse_mps": -0.1},
        {"noise_std_rad": -0.1},
        {"y_m": math.inf},
        {"name": "/robot_1"},
        {"name": ""},
    ],
)
def test_limits_that_cannot_drive_and_names_that_are_no_ros_name_are_refused(changes):
    with pytest.raises(ConfigError) as refused:
        StandinOptions(**{"name": "robot_1", **changes})
    key = next(iter(changes))
    assert str(refused.value).startswith(f"{key} ") and "expected" in str(refused.value)


@settings(max_examples=200, deadline=None)
@given(
    st.text(max_size=12),
    st.integers(-5, 300),
    st.floats(allow_nan=True, allow_infinity=True),
    st.floats(allow_nan=True, allow_infinity=True),
    st.floats(allow_nan=True, allow_infinity=True),
)
def test_any_standin_options_build_or_fail_with_a_config_error(name, domain, rate, speed, noise):
    import argparse

    from adapters.physical.standin_options import FLOAT_OPTIONS, options_from

    values = {key: 0.0 for key in FLOAT_OPTIONS}
    values.update(rate_hz=rate, max_speed_mps=speed, noise_std_m=noise)
    values.update(max_yaw_rate_radps=2.0, cmd_timeout_s=0.5)
    args = argparse.Namespace(
        name=name, domain=domain, interface=None, seed=1, duration_s=None, **values
    )
    try:
        options = options_from(args)
    except ConfigError as error:
        assert "\n" not in str(error)
        return
    assert options.rate_hz > 0 and options.max_speed_mps > 0 and options.noise_std_m >= 0
