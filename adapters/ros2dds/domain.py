"""Which DDS domain a run talks on: one per run on this machine, unless the scenario pins one.

Runs on one machine share loopback, and a physical robot's topics carry the same names in
every run (``/robot_1/pose``): two runs on one DDS domain hear each other's robots. So
``physical.dds_domain = "auto"`` (the default) claims, for each run, the lowest domain of
:data:`AUTO_DOMAINS` that no other cosim run holds and where no DDS participant of this
machine is found (the domain's RTPS discovery ports are free). A claim is a lock on a file
per domain (``flock``, in :data:`LOCK_DIR`), held by the run's process while it lasts and
dropped by the kernel however the process ends, so two runs starting at the same instant
cannot take the same domain. A domain the scenario names is claimed the same way and
refused, in one line, while another cosim run holds it; other DDS participants there (a
robot, RViz, ``ros2 topic echo``) are welcome.

The claimed domain is what the run's participant joins, what ``--standin`` passes to the
stand-ins (``--domain``) and what a robot is started with (``ROS_DOMAIN_ID``).
"""

from __future__ import annotations

import errno
import fcntl
import os
import socket
import tempfile
from collections.abc import Mapping
from pathlib import Path
from types import TracebackType
from typing import IO, Any, Literal, Protocol, runtime_checkable

from cosim.core.errors import BridgeError

LOCK_DIR = Path(tempfile.gettempdir()) / "cosim-dds-domains"
"""Where the per-domain lock files live (one machine's runs share it)."""
AUTO_DOMAINS = range(1, 102)
"""Domains ``"auto"`` chooses from: 1 to 101. Domain 0 is ROS 2's default, where a
machine's other ROS 2 nodes usually are; above 101 the RTPS ports of Linux reach its
ephemeral port range (ROS 2's documentation, "The ROS_DOMAIN_ID")."""
PORT_BASE, DOMAIN_GAIN, PARTICIPANT_GAIN = 7400, 250, 2
"""RTPS well-known ports (DDSI-RTPS 2.3, 9.6.1.1): PB, DG and PG."""
UNICAST_DISCOVERY_OFFSET = 10
"""d1: a participant's unicast discovery port is PB + DG x domain + d1 + PG x index."""
PROBED_INDICES = 10
"""Participant indices probed: Cyclone DDS on loopback takes 0-9 (``MaxAutoParticipantIndex``)."""


@runtime_checkable
class DomainSettings(Protocol):
    """Settings naming a run's DDS domain (the physical section's ``dds_domain``, ``interface``)."""

    @property
    def dds_domain(self) -> int | Literal["auto"]:
        """The domain (``ROS_DOMAIN_ID``), or ``"auto"``: one chosen per run."""
        ...

    @property
    def interface(self) -> str:
        """The network interface or address DDS uses; empty for loopback."""
        ...


def discovery_ports(domain: int) -> list[int]:
    """The UDP ports a DDS participant of ``domain`` on this machine binds.

    The multicast discovery port (Cyclone binds it with multicast allowed, as ROS 2 does
    by default) and the unicast discovery port of participant indices 0-9 (loopback-only
    participants, as cosim's, take one of those).
    """
    base = PORT_BASE + DOMAIN_GAIN * domain
    unicast = base + UNICAST_DISCOVERY_OFFSET
    return [base, *(unicast + PARTICIPANT_GAIN * i for i in range(PROBED_INDICES))]


def bound_port(domain: int) -> int | None:
    """A discovery port of ``domain`` some process of this machine holds, or None."""
    for port in discovery_ports(domain):
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
            try:
                probe.bind(("", port))
            except OSError as error:
                if error.errno == errno.EADDRINUSE:
                    return port
                raise BridgeError(
                    f"cannot probe UDP port {port} of DDS domain {domain} ({error.strerror})"
                ) from error
    return None


class DomainClaim:
    """A DDS domain held for one run; a context manager that releases it.

    Attributes:
        domain: the domain id (``ROS_DOMAIN_ID``).
        chosen: True when ``"auto"`` chose it, False when the scenario named it.
        interface: the network interface, or "" for loopback.
    """

    def __init__(
        self, domain: int, lock: IO[str] | None, *, chosen: bool, interface: str = ""
    ) -> None:
        self.domain = domain
        self.chosen = chosen
        self.interface = interface
        self._lock = lock

    def describe(self) -> str:
        """One line for the run's console: where its robots talk, and how a robot joins."""
        where = f"interface {self.interface!r}" if self.interface else "loopback"
        how = "chosen for this run" if self.chosen else "from the scenario"
        joins = f"a robot joins with ROS_DOMAIN_ID={self.domain}"
        return f"DDS domain {self.domain} on {where} ({how}; {joins})"

    def release(self) -> None:
        """Give the domain back (closing the lock file drops its lock)."""
        if self._lock is not None:
            self._lock.close()
            self._lock = None

    def __enter__(self) -> DomainClaim:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        self.release()


def _lock_dir() -> Path:
    try:
        LOCK_DIR.mkdir(mode=0o777, parents=True, exist_ok=True)
    except OSError as error:
        raise BridgeError(
            f"{LOCK_DIR}: cannot create the DDS domain locks ({error.strerror}); expected a "
            "writable folder"
        ) from error
    return LOCK_DIR


def _lock(domain: int) -> IO[str] | int:
    """The locked file of ``domain``, or the process id of the run holding it."""
    path = _lock_dir() / f"domain-{domain}.lock"
    try:
        handle = path.open("a+", encoding="utf-8")
    except OSError as error:
        raise BridgeError(
            f"{path}: cannot open the DDS domain lock ({error.strerror}); expected a writable file"
        ) from error
    try:
        fcntl.flock(handle.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        handle.seek(0)
        text = handle.read().strip()
        handle.close()
        return int(text) if text.isdigit() else -1
    handle.seek(0)
    handle.truncate()
    handle.write(f"{os.getpid()}\n")
    handle.flush()
    return handle


def claim_domain(cfg: DomainSettings, source: str) -> DomainClaim:
    """Claim ``cfg.dds_domain`` (or, for ``"auto"``, a free domain) for this process's run.

    A domain this process holds already (the command line claimed it before starting the
    stand-ins) is returned without a new lock.

    Args:
        cfg: the settings naming the domain (the ``[physical]`` section).
        source: the scenario file or preset, for messages.

    Raises:
        BridgeError: the named domain is held by another cosim run, or ``"auto"`` finds no
            free domain.
    """
    if cfg.dds_domain != "auto":
        domain = int(cfg.dds_domain)
        held = _lock(domain)
        if isinstance(held, int) and held != os.getpid():
            holder = f"pid {held}" if held > 0 else "another process"
            raise BridgeError(
                f"{source}: [physical] dds_domain = {domain}: DDS domain {domain} is in use by "
                f"another cosim run ({holder}); expected a domain no other run uses "
                '(dds_domain = "auto" picks a free one)'
            )
        lock = None if isinstance(held, int) else held
        return DomainClaim(domain, lock, chosen=False, interface=cfg.interface)
    for domain in AUTO_DOMAINS:
        held = _lock(domain)
        if isinstance(held, int):
            continue
        if bound_port(domain) is not None:
            held.close()
            continue
        return DomainClaim(domain, held, chosen=True, interface=cfg.interface)
    raise BridgeError(
        f"{source}: [physical] dds_domain = 'auto': no free DDS domain among "
        f"{AUTO_DOMAINS.start}-{AUTO_DOMAINS.stop - 1} (each held by another cosim run or "
        "used by a DDS participant of this machine); expected one free, or a domain id"
    )


def uses_dds(sections: Mapping[str, Any]) -> bool:
    """Whether a run joins a DDS domain: some section says so (``uses_dds()``).

    The physical robots' section does when it names robots, the mocap section when its
    source listens on DDS.
    """
    for section in sections.values():
        says = getattr(section, "uses_dds", None)
        if callable(says) and says():
            return True
    return False


def domain_settings(sections: Mapping[str, Any]) -> DomainSettings:
    """The section holding the DDS keys (``dds_domain``, ``interface``: the physical one).

    Raises:
        BridgeError: no section holds them (no package declaring them is installed).
    """
    for section in sections.values():
        if isinstance(section, DomainSettings):
            return section
    raise BridgeError(
        "no settings section holds dds_domain and interface; expected the [physical] section "
        "(adapters.physical.settings) to be registered"
    )
