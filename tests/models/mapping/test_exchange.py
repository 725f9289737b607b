import zlib

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from models.errors import ModelError
from models.mapping.exchange import SCALE, PackedUpdate, pack, unpack


def test_the_changed_rectangle_round_trips_within_a_quantization_step():
    changes = np.zeros((50, 80), dtype=np.float32)
    changes[10:13, 20:30] = 0.85
    changes[30, 5] = -0.08
    packed = pack(changes)
    assert packed is not None
    assert (packed.ix0, packed.iy0, packed.width, packed.height) == (5, 10, 25, 21)
    block = unpack(packed, changes.shape)
    restored = np.zeros_like(changes)
    restored[10:31, 5:30] = block
    assert np.abs(restored - changes).max() <= SCALE / 2 + 1e-7


def test_nothing_changed_packs_to_nothing():
    assert pack(np.zeros((10, 10), dtype=np.float32)) is None


@pytest.mark.parametrize(
    "update",
    [
        PackedUpdate(-1, 0, 2, 2, SCALE, zlib.compress(bytes(4))),
        PackedUpdate(0, 0, 200, 2, SCALE, zlib.compress(bytes(400))),
        PackedUpdate(0, 0, 2, 2, SCALE, b"not zlib"),
        PackedUpdate(0, 0, 2, 2, SCALE, zlib.compress(bytes(5))),
        PackedUpdate(0, 0, 2, 2, SCALE, zlib.compress(bytes(10**7))),  # a zip bomb
    ],
)
def test_foreign_or_damaged_updates_are_refused(update):
    with pytest.raises(ModelError):
        unpack(update, (10, 10))


@given(
    ix0=st.integers(-5, 20), iy0=st.integers(-5, 20), width=st.integers(-2, 20),
    height=st.integers(-2, 20), data=st.binary(max_size=200),
)  # fmt: skip
def test_any_update_unpacks_or_is_refused(ix0, iy0, width, height, data):
    try:
        block = unpack(PackedUpdate(ix0, iy0, width, height, SCALE, data), (12, 12))
    except ModelError:
        return
    assert block.shape == (height, width)
