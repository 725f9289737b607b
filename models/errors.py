"""Errors raised by the pure models.

They carry the parameter, the value and what was expected as fields, so that the layer
that knows the scenario file can name it in its message.
"""

from __future__ import annotations

from typing import Any


class ModelError(ValueError):
    """A model cannot be built from the given parameters.

    Attributes:
        key: the parameter at fault, as ``section.key`` of the scenario contract.
        value: the offending value.
        expected: what would have been acceptable, in words.
    """

    def __init__(self, key: str, value: Any, expected: str) -> None:
        super().__init__(f"{key} = {value!r}: expected {expected}")
        self.key = key
        self.value = value
        self.expected = expected
