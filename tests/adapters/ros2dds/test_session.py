"""The run's one DDS session: opened once on the claimed domain, closed once, said where."""

from __future__ import annotations

from typing import Any

import pytest

import adapters.ros2dds.session as session
import cosim
from adapters.ros2dds.domain import DomainClaim
from adapters.ros2dds.session import DdsSession, dds_participant, dds_session
from cosim.core.adapter import RunContext
from cosim.core.bus import Bus
from cosim.core.errors import BridgeError
from cosim.core.kernel import Kernel
from cosim.core.recorder import Recorder
from cosim.core.rng import RngStreams


class Participant:
    """Stands for a RosParticipant: its domain, its interface, and how often it was closed."""

    def __init__(self, domain: int = 0, *, interface: str | None = None) -> None:
        self.domain = domain
        self.interface = interface
        self.closed = 0

    def close(self) -> None:
        self.closed += 1


class Claim(DomainClaim):
    """A claim without a lock file, counting its releases."""

    def __init__(self, domain: int) -> None:
        super().__init__(domain, None, chosen=False)
        self.released = 0

    def release(self) -> None:
        self.released += 1


def _run(**overrides: Any) -> RunContext:
    scenario = cosim.load_scenario("lab-room", overrides)
    kernel = Kernel()
    return RunContext(scenario, kernel, Bus(kernel), RngStreams(1), Recorder())


@pytest.fixture
def claims(monkeypatch: pytest.MonkeyPatch) -> list[tuple[Any, str, Claim]]:
    """Claims are made here (no lock file), participants are stand-ins (no DDS)."""
    made: list[tuple[Any, str, Claim]] = []

    def claim_domain(cfg: Any, source: str) -> Claim:
        claim = Claim(cfg.dds_domain if cfg.dds_domain != "auto" else 42)
        made.append((cfg, source, claim))
        return claim

    monkeypatch.setattr(session, "claim_domain", claim_domain)
    monkeypatch.setattr(session, "RosParticipant", Participant)
    return made


def test_a_session_says_where_the_run_listens():
    assert DdsSession(Participant(3)).where() == "DDS domain 3 on loopback"  # type: ignore[arg-type]
    on_lan = DdsSession(Participant(7, interface="eth0"))  # type: ignore[arg-type]
    assert on_lan.where() == "DDS domain 7 on interface 'eth0'"
    assert on_lan.domain == 7


def test_closing_leaves_the_domain_and_gives_it_back_once_however_often_it_is_called():
    participant, claim = Participant(3), Claim(3)
    dds = DdsSession(participant, claim)  # type: ignore[arg-type]
    for _ in range(3):
        dds.close()
    assert (participant.closed, claim.released, dds.closed) == (1, 1, True)


def test_a_session_without_a_claim_closes_its_participant():
    participant = Participant(0)
    DdsSession(participant).close()  # type: ignore[arg-type]
    assert participant.closed == 1


def test_the_run_opens_one_session_on_the_domain_its_physical_section_claims(claims):
    run = _run(**{"physical.dds_domain": 17, "physical.interface": "eth1"})
    first = dds_session(run)
    assert dds_session(run) is first and dds_participant(run) is first.participant
    [(cfg, source, claim)] = claims  # claimed once
    assert (cfg.dds_domain, source) == (17, "preset lab-room")
    assert first.claim is claim and run.service(DdsSession) is first
    assert (first.domain, first.participant.interface) == (17, "eth1")


def test_an_auto_domain_is_the_one_claimed_and_loopback_has_no_interface(claims):
    dds = dds_session(_run())
    assert dds.domain == 42 and dds.participant.interface is None
    assert dds.where() == "DDS domain 42 on loopback"


def test_a_participant_that_cannot_be_opened_gives_the_claimed_domain_back(claims, monkeypatch):
    def broken(domain: int, *, interface: str | None = None) -> None:
        raise BridgeError(f"DDS domain {domain}: cannot create a participant")

    monkeypatch.setattr(session, "RosParticipant", broken)
    run = _run(**{"physical.dds_domain": 5})
    with pytest.raises(BridgeError, match="cannot create a participant"):
        dds_session(run)
    [(_, _, claim)] = claims
    assert claim.released == 1
    assert not run.has_service(DdsSession)
