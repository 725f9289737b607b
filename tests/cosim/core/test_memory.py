"""The memory a run may take (cosim.core.memory): read from the system, said in one line."""

import subprocess
import sys
from pathlib import Path

import pytest

from cosim.core.memory import Room, available, size_text, smallest_fitting
from tests.conftest import REPO


def test_the_memory_left_is_read_from_this_linux_system():
    room = available()
    assert room is not None and room.bytes > 0
    meminfo = Path("/proc/meminfo").read_text().splitlines()
    total_kib = int(next(line for line in meminfo if line.startswith("MemTotal")).split()[1])
    assert room.bytes <= total_kib * 1024


def test_ulimit_v_bounds_the_memory_left_and_is_named():
    code = (
        "import resource\n"
        "resource.setrlimit(resource.RLIMIT_AS, (1 << 31, resource.RLIM_INFINITY))\n"
        "from cosim.core.memory import available\n"
        "room = available()\n"
        "print(room.source, room.bytes < (1 << 31))\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True, check=True
    )
    assert done.stdout.strip() == "ulimit -v True"


@pytest.mark.parametrize(
    ("count", "text"),
    [
        (640_000_000, "610 MiB"),
        (64_000_000, "61.0 MiB"),
        (9_600_000_000, "8.9 GiB"),
        (512, "512 bytes"),
        (2**40, "1.0 TiB"),
    ],
)
def test_sizes_are_said_as_people_read_them(count, text):
    assert size_text(count) == text


def test_the_smallest_fitting_cell_size_is_rounded_up_to_two_digits_and_fits():
    def need(resolution_m: float) -> int:
        return int(100 / resolution_m**2)  # 100 bytes a square metre at 1 m

    fits = smallest_fitting(need, 0.001, 1.0, room=1_000_000)
    assert fits == 0.01  # 1e6 bytes: exactly 1 cm
    fits = smallest_fitting(need, 0.001, 1.0, room=700_000)
    assert fits == 0.012 and need(fits) <= 700_000 and need(0.011) > 700_000


def test_no_cell_size_fits_when_even_the_largest_does_not():
    assert smallest_fitting(lambda r: 10**12, 0.001, 1.0, room=10**6) is None


def test_a_room_says_its_size_and_what_limits_it():
    room = Room(3 << 30, "ulimit -v")
    assert (size_text(room.bytes), room.source) == ("3.0 GiB", "ulimit -v")
