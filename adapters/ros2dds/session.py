"""The run's one DDS participant.

Shared by the physical-robot bridge and a ``ros2`` mocap source, opened on first use
(when the run starts, so ``cosim check`` opens no socket), on the domain the run claims
(:mod:`adapters.ros2dds.domain`: ``physical.dds_domain``, or one chosen for the run, from
the section that holds the DDS keys).
"""

from __future__ import annotations

from adapters.ros2dds.domain import DomainClaim, claim_domain, domain_settings
from adapters.ros2dds.participant import RosParticipant
from cosim.core.adapter import RunContext


class DdsSession:
    """Holds the participant; :meth:`close` may be called by every user, it closes once.

    Args:
        participant: the run's participant.
        claim: the domain it joined, released on close.
    """

    def __init__(self, participant: RosParticipant, claim: DomainClaim | None = None) -> None:
        self.participant = participant
        self.claim = claim
        self.closed = False

    @property
    def domain(self) -> int:
        """The DDS domain the participant joined."""
        return self.participant.domain

    def where(self) -> str:
        """``DDS domain 3 on loopback``: where the run listens, for messages."""
        interface = self.participant.interface
        return f"DDS domain {self.domain} on " + (
            f"interface {interface!r}" if interface else "loopback"
        )

    def close(self) -> None:
        """Leave the DDS domain and give it back."""
        if not self.closed:
            self.closed = True
            self.participant.close()
            if self.claim is not None:
                self.claim.release()


def dds_session(run: RunContext) -> DdsSession:
    """The run's DDS session on its claimed domain (loopback unless an interface is named).

    Raises:
        BridgeError: the domain is held by another run, no domain is free, or DDS fails.
    """
    if not run.has_service(DdsSession):
        cfg = domain_settings(run.scenario.sections)
        claim = claim_domain(cfg, run.scenario.source)
        try:
            participant = RosParticipant(claim.domain, interface=cfg.interface or None)
        except BaseException:
            claim.release()
            raise
        run.provide(DdsSession(participant, claim))
    return run.service(DdsSession)


def dds_participant(run: RunContext) -> RosParticipant:
    """The run's DDS participant (see :func:`dds_session`)."""
    return dds_session(run).participant
