from types import SimpleNamespace
from typing import Any, ClassVar

import pytest

from adapters.mapping.contract import MAP_SHARING, MapSharing
from adapters.mapping.settings import MappingConfig
from adapters.mapping.sharing import MapUpdateSharing, NoSharing, ScanSharing
from cosim.core.errors import RegistryError
from cosim.core.registry import Registry

BUILT_IN = {"none": NoSharing, "scans": ScanSharing, "maps": MapUpdateSharing}


def test_the_built_in_sharing_modes_are_registered_and_keep_the_contract():
    assert MAP_SHARING.installed().load_all() == BUILT_IN
    for name, mode in BUILT_IN.items():
        assert mode.name == name


def test_only_map_updates_need_the_maps_to_keep_their_own_changes():
    assert {name: mode.tracks_changes for name, mode in BUILT_IN.items()} == {
        "none": False,
        "scans": False,
        "maps": True,
    }


def test_the_default_section_chooses_a_registered_mode():
    assert MappingConfig().share in MAP_SHARING.installed()


class _Good:
    name: ClassVar[str] = "good"
    tracks_changes: ClassVar[bool] = False

    def __init__(self, context: Any) -> None:
        pass

    def start(self, run: Any) -> None:
        pass

    def mapped(self, run: Any, robot: int, pose: Any, scan: Any) -> None:
        pass


def _broken(**changes: Any) -> type:
    return type("Broken", (_Good,), {"name": "broken", **changes})


def test_a_mode_that_keeps_the_contract_is_accepted():
    mode: type[MapSharing] = Registry(MAP_SHARING, {"good": _Good}).get("good")
    assert mode is _Good


@pytest.mark.parametrize(
    ("entry", "problem"),
    [
        (SimpleNamespace(name="broken"), "is not a class (built with a SharingContext)"),
        (_broken(tracks_changes="yes"), "tracks_changes is not True or False"),
        (_broken(tracks_changes=None), "tracks_changes is not True or False"),
        (
            _broken(mapped=None),
            "has no mapped() method (see adapters.mapping.contract.MapSharing)",
        ),
        (_broken(start=0), "has no start() method (see adapters.mapping.contract.MapSharing)"),
    ],
)
def test_a_mode_breaking_the_contract_is_refused_naming_itself_and_what_is_wrong(entry, problem):
    with pytest.raises(RegistryError) as refused:
        Registry(MAP_SHARING, {"broken": entry}).get("broken")
    message = str(refused.value)
    assert message.startswith("map sharing mode 'broken' (")
    assert message.endswith(f": {problem}")


def test_a_broken_mode_is_left_out_of_the_loaded_ones_but_named_when_asked_for():
    registry = Registry(MAP_SHARING, {**BUILT_IN, "broken": _broken(tracks_changes=1)})
    assert registry.load_all() == BUILT_IN
    [broken] = [p for p in registry.describe() if p.name == "broken"]
    assert broken.error is not None and "tracks_changes is not True or False" in broken.error
