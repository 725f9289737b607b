"""A run's DDS domain, claimed before it starts (so its stand-ins get the same one).

``physical.dds_domain = "auto"`` becomes the domain the run holds
(:func:`adapters.ros2dds.domain.claim_domain`): the scenario the run and its stand-ins are
given names it.
"""

from __future__ import annotations

import dataclasses

from adapters.physical.settings import PhysicalConfig
from adapters.ros2dds.domain import DomainClaim, claim_domain, uses_dds
from cosim.scenario.model import Scenario


@dataclasses.dataclass
class RunDomain:
    """A run's claimed domain and the scenario that names it (``dds_domain`` resolved).

    Attributes:
        claim: the claim (release it when the run ends: :meth:`close`).
        scenario: the scenario with ``physical.dds_domain`` set to the claimed domain, to
            be given to the stand-ins and the run alike.
    """

    claim: DomainClaim
    scenario: Scenario

    def close(self) -> None:
        """Release the domain."""
        self.claim.release()

    def __enter__(self) -> RunDomain:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def claim_run_domain(scenario: Scenario) -> RunDomain | None:
    """Claim the DDS domain of a run of ``scenario``; None for a run that uses no DDS.

    The command line calls it before starting stand-ins, prints
    ``claim.describe()`` and runs ``RunDomain.scenario``.

    Raises:
        BridgeError: as :func:`~adapters.ros2dds.domain.claim_domain`.
    """
    if not uses_dds(scenario.sections):
        return None
    cfg = scenario.section(PhysicalConfig)
    claim = claim_domain(cfg, scenario.source)
    resolved = dataclasses.replace(cfg, dds_domain=claim.domain)
    return RunDomain(claim, scenario.with_section("physical", resolved))
