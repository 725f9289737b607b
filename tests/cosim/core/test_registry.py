import pytest

from cosim.core.errors import RegistryError
from cosim.core.registry import AdapterRegistry


class _Adapter:
    """Starts and finishes (the contract's methods)."""

    def start(self, run):
        pass

    def finish(self, run):
        return {}


class _A(_Adapter):
    name = "a"
    requires: tuple[str, ...] = ()


class _B(_Adapter):
    name = "b"
    requires = ("a",)


class _C(_Adapter):
    name = "c"
    requires = ("b", "a")


class _Loop1(_Adapter):
    name = "loop1"
    requires = ("loop2",)


class _Loop2(_Adapter):
    name = "loop2"
    requires = ("loop1",)


REG = AdapterRegistry({"a": _A, "b": _B, "c": _C, "loop1": _Loop1, "loop2": _Loop2})  # type: ignore[dict-item]


def test_an_unknown_adapter_name_suggests_the_nearest_names():
    registry = AdapterRegistry.from_entry_points()
    with pytest.raises(RegistryError, match=r"unknown adapter 'lidr'; did you mean 'lidar'"):
        registry.get("lidr")


def test_requirements_are_ordered_before_the_adapters_that_need_them():
    assert REG.resolve(["c"]) == ["a", "b", "c"]
    assert REG.resolve(["b", "a", "c"]) == ["a", "b", "c"]


def test_a_requirement_cycle_is_an_error_naming_the_cycle():
    with pytest.raises(RegistryError, match="loop1 -> loop2 -> loop1"):
        REG.resolve(["loop1"])


class _Orphan(_Adapter):
    name = "orphan"
    requires = ("missing",)


def test_a_requirement_that_is_not_registered_names_the_adapter_that_requires_it():
    registry = REG.with_adapter(_Orphan)
    with pytest.raises(
        RegistryError, match=r"adapter 'orphan' \(.*_Orphan\) requires unknown adapter 'missing'"
    ):
        registry.resolve(["a", "orphan"])


def test_an_unknown_adapter_given_to_cosim_run_names_the_argument(small_scenario):
    import cosim

    with pytest.raises(
        RegistryError,
        match=r"cosim\.run\(adapters=\[\.\.\., 'nosuch', \.\.\.\]\): unknown adapter 'nosuch'",
    ):
        cosim.run(small_scenario, duration_s=0.1, adapters=["nosuch"])


def test_the_installed_registry_lists_cosims_own_adapters_first_then_plugins_by_package():
    registry = AdapterRegistry.from_entry_points()
    names = registry.names()
    packages = [registry.package(name) for name in names]
    ours = [n for n, p in zip(names, packages, strict=True) if p == "cosim"]
    assert "fleet" in ours
    assert names[: len(ours)] == ours
    theirs = packages[len(ours) :]
    assert theirs == sorted(theirs)


def test_an_entry_given_in_code_is_registered_while_inside_and_named_as_given():
    from adapters.navigation.contract import CONTROLLERS
    from cosim.core.plugins import plugin_of
    from cosim.core.registry import registered

    class Steady:
        """Drives straight on."""

        name = "steady"

        def commands(self, inputs):
            return inputs

    with registered("cosim.controllers", "steady", Steady):
        assert CONTROLLERS.installed().get("steady") is Steady
        info = plugin_of(Steady)
        assert info is not None and (info.package, info.name) == ("", "steady")
    assert "steady" not in CONTROLLERS.installed()


def test_an_entry_given_in_code_cannot_take_a_registered_name():
    from cosim.core.errors import RegistryError
    from cosim.core.registry import registered

    taken = r"'dwa' is registered in cosim\.controllers already"
    with pytest.raises(RegistryError, match=taken), registered("cosim.controllers", "dwa", 1):
        pass


GREEDY = {"cosim.protocols": {"greedy": "clashkit.greedy:Greedy"}}


def test_a_group_with_a_name_registered_twice_refuses_to_load_but_lists_the_rest(tmp_path):
    from adapters.assignment.contract import PROTOCOLS
    from tests.packages import on_path, write_package

    write_package(tmp_path, "clashkit", "0.1.0", GREEDY)
    with on_path(tmp_path):
        with pytest.raises(RegistryError, match=r"^cosim\.protocols: 'greedy' is registered by"):
            PROTOCOLS.installed()
        assert "greedy" not in PROTOCOLS.listed() and "hungarian" in PROTOCOLS.listed()
        assert [c.name for c in PROTOCOLS.clashes()] == ["greedy"]
    assert "greedy" in PROTOCOLS.installed()  # uninstalled: cosim's greedy is back


def test_a_registry_two_packages_register_is_refused_by_name(tmp_path):
    from cosim.core.registry import group_named
    from tests.conftest import cosim_main
    from tests.packages import on_path, write_package

    registries = {"cosim.registries": {"cosim.planners": "clashkit.contract:PLANNERS"}}
    write_package(tmp_path, "clashkit", "0.1.0", registries)
    group_named.cache_clear()
    try:
        with on_path(tmp_path):
            with pytest.raises(RegistryError, match=r"'cosim\.planners' is registered by cosim"):
                group_named("cosim.planners")
            assert group_named("cosim.controllers").words == "local controller"
            done = cosim_main("plugins", "planner")  # named, then refused in one line
            assert done.returncode == 2 and done.stderr.count("\n") == 1
            assert "'cosim.planners' is registered by cosim" in done.stderr
            listing = cosim_main("plugins")  # every other registry, and the clash
            assert listing.returncode == 2
            assert "registries (cosim.registries): 1 clashing\n  cosim.planners" in listing.stdout
            assert "local controllers (cosim.controllers): 4" in listing.stdout
    finally:
        group_named.cache_clear()


def test_an_entry_says_its_package_version_and_target_without_importing_it(tmp_path):
    from adapters.assignment.contract import PROTOCOLS
    from tests.packages import on_path, write_package

    write_package(tmp_path, "lazykit", "0.3.0", {"cosim.protocols": {"lazy": "lazykit.x:Lazy"}})
    with on_path(tmp_path):
        info = PROTOCOLS.installed().plugin("lazy")  # lazykit.x does not exist: not imported
    assert (info.package, info.version, info.target) == ("lazykit", "0.3.0", "lazykit.x:Lazy")
    assert (info.group, info.name) == ("cosim.protocols", "lazy")
    builtin = PROTOCOLS.installed().plugin("hungarian")
    assert builtin.builtin and builtin.version
