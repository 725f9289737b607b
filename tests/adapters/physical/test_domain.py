"""A run's DDS domain claimed before it starts: the scenario names it, stand-ins get it."""

import cosim
from adapters.physical.domain import claim_run_domain


def test_a_run_domain_resolves_the_scenario_and_says_where_a_robot_joins():
    scenario = cosim.load_scenario("lab-real-in-virtual")
    assert scenario.physical.dds_domain == "auto"
    with claim_run_domain(scenario) as run_domain:
        domain = run_domain.claim.domain
        assert run_domain.scenario.physical.dds_domain == domain
        assert run_domain.claim.describe() == (
            f"DDS domain {domain} on loopback (chosen for this run; a robot joins with "
            f"ROS_DOMAIN_ID={domain})"
        )


def test_a_scenario_without_dds_claims_no_domain():
    assert claim_run_domain(cosim.load_scenario("lab-room")) is None
