"""The array types the models share name their dtypes."""

from typing import get_args

import numpy as np
import pytest

from models.arrays import BoolArray, FloatArray, IntArray, UInt8Array
from models.geometry.se2 import compose
from models.world.obstacles import DynamicObstacles


@pytest.mark.parametrize(
    ("alias", "dtype"),
    [(FloatArray, np.float64), (IntArray, np.int64), (BoolArray, np.bool_), (UInt8Array, np.uint8)],
)
def test_each_array_type_is_an_ndarray_of_its_dtype(alias, dtype):
    _, held = get_args(alias)
    assert get_args(held) == (dtype,)
    assert np.zeros(2, dtype=dtype).dtype == np.dtype(get_args(held)[0])


def test_a_model_documented_as_float_array_hands_out_float64():
    obstacles = DynamicObstacles()
    obstacles.update("people", np.array([[1, 2, 3]], dtype=np.int32), ["p0"])
    assert obstacles.discs.dtype == np.float64
    assert all(isinstance(v, float) for v in compose((0, 0, 0), (1, 2, 0.5)))
