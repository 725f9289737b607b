"""The run's one DDS participant.

Shared by the physical-robot bridge and a ``ros2`` mocap source, opened on first use
(when the run starts, so ``cosim check`` opens no socket).
"""

from __future__ import annotations

from adapters.physical.settings import PhysicalConfig
from adapters.ros2dds.participant import RosParticipant
from cosim.core.adapter import RunContext


class DdsSession:
    """Holds the participant; :meth:`close` may be called by every user, it closes once."""

    def __init__(self, participant: RosParticipant) -> None:
        self.participant = participant
        self.closed = False

    def close(self) -> None:
        """Leave the DDS domain."""
        if not self.closed:
            self.closed = True
            self.participant.close()


def dds_session(run: RunContext) -> DdsSession:
    """The run's DDS session on ``physical.dds_domain`` (loopback unless an interface is named)."""
    if not run.has_service(DdsSession):
        cfg = run.settings(PhysicalConfig)
        participant = RosParticipant(cfg.dds_domain, interface=cfg.interface or None)
        run.provide(DdsSession(participant))
    return run.service(DdsSession)


def dds_participant(run: RunContext) -> RosParticipant:
    """The run's DDS participant (see :func:`dds_session`)."""
    return dds_session(run).participant
