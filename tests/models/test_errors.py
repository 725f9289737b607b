"""A model refusing its parameters says which, the value, and what was expected."""

import pytest

from models.errors import ModelError


def test_a_model_error_names_the_key_the_value_and_what_was_expected():
    error = ModelError("lidar.beams", -3, "at least 0")
    assert str(error) == "lidar.beams = -3: expected at least 0"
    assert (error.key, error.value, error.expected) == ("lidar.beams", -3, "at least 0")


def test_the_value_is_shown_as_python_writes_it():
    assert str(ModelError("world.name", "hall", "a known world")) == (
        "world.name = 'hall': expected a known world"
    )
    assert "(1.0, 2.0)" in str(ModelError("start_cell", (1.0, 2.0), "inside the grid"))


def test_a_model_error_is_a_value_error_so_callers_of_plain_functions_can_catch_it():
    with pytest.raises(ValueError, match="expected"):
        raise ModelError("k", 1, "2")
