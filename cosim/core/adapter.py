"""The adapter contract and the context every adapter runs in.

An adapter gives a model time, a rate and a place on the bus. It is a class registered
under a name in the ``cosim.adapters`` entry-point group, constructed with the run's
:class:`RunContext` (where it may offer services to later adapters), started once all
adapters exist, and asked for its summary metrics at the end.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any, ClassVar, Protocol, TypeVar, runtime_checkable

from cosim.core.bus import Bus
from cosim.core.errors import RegistryError
from cosim.core.hosts import Host, HostId, HostKind
from cosim.core.kernel import Kernel
from cosim.core.recorder import Recorder
from cosim.core.registry import Group
from cosim.core.rng import RngStreams
from cosim.core.workers import Workers

T = TypeVar("T")


class ScenarioView(Protocol):
    """What an adapter sees of the validated scenario.

    Settings are read by section type (``run.settings(LidarConfig)``), so that the core
    needs to know no section: each capability declares its own.
    """

    @property
    def source(self) -> str:
        """The file or preset the scenario was loaded from (for messages)."""
        ...

    @property
    def seed(self) -> int:
        """The scenario seed."""
        ...

    @property
    def name(self) -> str:
        """The scenario name."""
        ...

    def section(self, kind: type[T]) -> T:
        """The scenario's section of type ``kind`` (a settings dataclass)."""
        ...

    @property
    def sections(self) -> Mapping[str, Any]:
        """Every section by name, for hooks a capability declares and others implement."""
        ...


@dataclass
class RunContext:
    """Everything a run's adapters share.

    Attributes:
        scenario: the validated scenario.
        kernel: the event kernel (integer ns).
        bus: the topic bus.
        rng: the run's named random streams.
        recorder: the tables being recorded.
        hosts: the hosts of the run, by id, in creation order.
        workers: the run's threads for per-robot work within one instant (results come
            back in order: tables are the same for any number of threads).
    """

    scenario: ScenarioView
    kernel: Kernel
    bus: Bus
    rng: RngStreams
    recorder: Recorder
    hosts: dict[HostId, Host] = field(default_factory=dict)
    workers: Workers = field(default_factory=Workers)
    _services: dict[type[Any], Any] = field(default_factory=dict)
    _checks: list[Callable[[], None]] = field(default_factory=list)

    def settings(self, kind: type[T]) -> T:
        """The scenario's settings section of type ``kind`` (e.g. ``run.settings(LidarConfig)``)."""
        return self.scenario.section(kind)

    def check_when_assembled(self, check: Callable[[], None]) -> None:
        """Run ``check()`` once every adapter is constructed (e.g. to validate host names).

        Checks run in registration order, before any adapter starts, also for ``cosim
        check``; a check raises a :class:`~cosim.core.errors.CosimError` to refuse the scenario.
        """
        self._checks.append(check)

    def run_checks(self) -> None:
        """Run the checks registered with :meth:`check_when_assembled`."""
        for check in self._checks:
            check()

    def add_host(self, host_id: str, kind: HostKind) -> HostId:
        """Create a host; creating the same host twice with the same kind is allowed."""
        hid = HostId(host_id)
        existing = self.hosts.get(hid)
        if existing is not None and existing.kind is not kind:
            raise ValueError(f"host {host_id!r} exists already as a {existing.kind} host")
        self.hosts[hid] = Host(hid, kind)
        return hid

    def provide(self, service: object) -> None:
        """Offer ``service`` to later adapters, keyed by its type."""
        kind = type(service)
        if kind in self._services:
            raise ValueError(f"a {kind.__name__} service is provided already")
        self._services[kind] = service

    def service(self, kind: type[T]) -> T:
        """Return the service of type ``kind``.

        Raises:
            RegistryError: if no adapter provides it (an adapter forgot a requirement).
        """
        found = self._services.get(kind)
        if found is None:
            raise RegistryError(
                f"no adapter provides a {kind.__name__}; add the adapter that does to `requires`"
            )
        return found  # type: ignore[no-any-return]

    def has_service(self, kind: type[Any]) -> bool:
        """Whether a service of type ``kind`` is provided."""
        return kind in self._services


@runtime_checkable
class Adapter(Protocol):
    """A running adapter."""

    def start(self, run: RunContext) -> None:
        """Start processes and subscriptions; called once, at time 0, in dependency order."""
        ...

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        """Return summary metrics (flat, JSON-serializable) at the end of the run.

        Each key is declared, with its unit and meaning, in the class's ``summary_keys``
        (see :mod:`cosim.core.summary`), from which the summary reference is generated.
        """
        ...


class AdapterType(Protocol):
    """What the ``cosim.adapters`` entry points name: a class constructed with the run.

    Attributes:
        name: the registered name.
        requires: names of adapters that must be constructed (and started) before.

    A class declares the keys its ``finish`` returns in ``summary_keys`` (a mapping of
    key to :class:`~cosim.core.summary.SummaryKey`: unit and meaning), and the tables it
    writes in ``tables``; both go into the generated references.

    A class may also declare a static ``check_scenario(scenario)`` that raises
    :class:`~cosim.core.errors.ConfigError` for combinations of sections it cannot run
    (:func:`cosim.runner.assembly.check_scenario` calls it before anything is built).
    """

    name: ClassVar[str]
    requires: ClassVar[tuple[str, ...]]

    def __call__(self, run: RunContext) -> Adapter:
        """Construct the adapter; may :meth:`RunContext.provide` services."""
        ...


@dataclass(frozen=True)
class Driver:
    """Robot software: the adapters that make up a ``robots.driver``.

    Drivers are registered in the ``cosim.drivers`` entry-point group; the entry point
    names a ``Driver`` object.

    Attributes:
        adapters: the adapters to run (their requirements are added).
        summary: one line saying what the robots do.
        needs_lidar: the software avoids what the lidar sees (refused with no beams).
    """

    adapters: tuple[str, ...]
    summary: str
    needs_lidar: bool = True


def _driver_contract(name: str, loaded: Any) -> str | None:
    if not isinstance(loaded, Driver):
        return f"is a {type(loaded).__name__}; expected a cosim.core.adapter.Driver"
    return None


DRIVERS = Group(
    "cosim.drivers",
    "robot driver",
    "robot drivers",
    "a `cosim.core.adapter.Driver` (the adapters that make up the robot software)",
    "`robots.driver`",
    named=False,
    check=_driver_contract,
)
"""Robot drivers: the robot software a scenario runs (``robots.driver``)."""
