"""Whose code it is: built-ins, installed plugins, code given in a test; the plugin error."""

import pickle

from adapters.navigation.contract import CONTROLLERS
from adapters.navigation.stack import NavigationAdapter
from cosim.core.plugins import (
    PluginError,
    PluginInfo,
    installed_plugins,
    plugin_of,
    plugin_of_module,
    refuse,
)
from cosim.core.registry import AdapterRegistry


class GivenController:
    """A controller a test hands to a registry."""

    name = "given"


def test_a_builtin_is_cosims_own_with_its_group_name_and_target():
    info = plugin_of(NavigationAdapter)
    assert info is not None and info.builtin
    assert (info.group, info.name) == ("cosim.adapters", "navigation")
    assert info.target == "adapters.navigation.stack:NavigationAdapter"
    assert info.describe().startswith("adapter 'navigation' (adapters.navigation.stack:")


def test_an_instance_is_named_by_its_class_entry():
    dwa = CONTROLLERS.installed().get("dwa")
    info = plugin_of(dwa)
    assert info is not None
    assert (info.package, info.group, info.name) == ("cosim", "cosim.controllers", "dwa")
    assert info.kind == "local controller"


def test_any_module_of_cosims_packages_is_cosims_and_other_libraries_are_nobodys():
    for module in ("models.navigation.dwa", "cosim.core.bus", "adapters.fleet.motion"):
        info = plugin_of_module(module)
        assert info is not None and info.builtin and info.target.startswith(module)
    assert plugin_of_module("numpy.linalg") is None
    assert plugin_of_module("simpy.core") is None


def test_code_given_to_a_registry_is_a_plugin_given_in_code():
    CONTROLLERS.installed().with_entry("given", GivenController)
    info = plugin_of(GivenController())
    assert info is not None and not info.builtin
    assert (info.package, info.group, info.name) == ("", "cosim.controllers", "given")
    assert info.describe() == (
        f"local controller 'given' ({__name__}:GivenController, given in code)"
    )


def test_an_adapter_given_in_code_is_noted_too():
    class Probe:
        name = "probe"
        requires = ()

        def start(self, run):
            pass

        def finish(self, run):
            return {}

    AdapterRegistry({}).with_adapter(Probe)
    info = plugin_of(Probe)
    assert info is not None and (info.group, info.name) == ("cosim.adapters", "probe")
    module = plugin_of_module(__name__)  # two plugins given here: the module is said
    assert module is not None and module.package == "" and module.target == __name__


def test_a_plugin_error_is_one_line_naming_the_plugin_what_it_did_and_when():
    plugin = PluginInfo("labkit", "0.1.0", "cosim.controllers", "pursuit", "labkit.p:Pursuit")
    error = PluginError(plugin, "returned nan", doing="computing robot_2's command")
    assert str(error) == (
        "local controller 'pursuit' (labkit.p:Pursuit, labkit 0.1.0) returned nan "
        "while computing robot_2's command"
    )
    error.at(12_500_000_000)
    assert str(error).endswith("at t = 12.5 s simulated")
    error.at(1)  # the first time given stays
    assert "12.5 s" in str(error) and "\n" not in str(error)


def test_a_plugin_error_crosses_processes_whole():
    plugin = PluginInfo("labkit", "0.1.0", "cosim.adapters", "prox", "labkit.x:Prox")
    error = PluginError(plugin, "raised ValueError: no", doing="starting", t_ns=0, details="tb")
    back = pickle.loads(pickle.dumps(error))
    assert str(back) == str(error)
    assert (back.plugin, back.details, back.t_ns) == (plugin, "tb", 0)


def test_refuse_names_the_owner_of_the_value():
    error = refuse(GivenController(), "returned a command of shape (3,); expected (2,)")
    assert "'given'" in str(error) and "shape (3,)" in str(error)


def test_a_plugin_naming_cosims_code_does_not_make_it_the_plugins(tmp_path):
    from adapters.assignment.protocols import Greedy
    from tests.packages import on_path, write_package

    claims = {
        "cosim.protocols": {"greedy": "adapters.assignment.protocols:Greedy"},  # a clash
        "cosim.loss_models": {"mine": "models.network.loss:check_probability"},
    }
    write_package(tmp_path, "clashkit", "0.1.0", claims)
    with on_path(tmp_path):
        info = plugin_of(Greedy)
        assert info is not None and info.builtin and info.name == "greedy"
        module = plugin_of_module("models.network.loss")
        assert module is not None and module.builtin
        assert {i.package for i in installed_plugins() if i.name == "greedy"} == {
            "cosim",
            "clashkit",
        }


def test_each_of_two_packages_clashing_on_a_name_owns_its_own_code(tmp_path):
    from tests.packages import on_path, write_package

    code = '"""Steers."""\n\n\nclass Steer:\n    """Steers."""\n\n    name = "steer"\n'
    for kit in ("akit", "bkit"):
        write_package(
            tmp_path,
            kit,
            "1.0",
            {"cosim.controllers": {"steer": f"{kit}.steer:Steer"}},
            {f"{kit}/steer.py": code},
        )
    # a third package (listed first) naming akit's class: it stays akit's
    write_package(tmp_path, "aakit", "1.0", {"cosim.controllers": {"c": "akit.steer:Steer"}})
    with on_path(tmp_path):
        import akit.steer
        import bkit.steer

        first, second = plugin_of(akit.steer.Steer), plugin_of(bkit.steer.Steer)
        assert first is not None and (first.package, first.name) == ("akit", "steer")
        assert second is not None and (second.package, second.name) == ("bkit", "steer")
        module = plugin_of_module("akit.steer")
        assert module is not None and module.package == "akit"
