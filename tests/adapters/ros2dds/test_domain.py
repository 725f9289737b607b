"""A run's DDS domain: one per run on this machine, claimed with a lock, refused when taken."""

import os
import socket
import subprocess
import sys

import pytest

import cosim
from adapters.physical.settings import PhysicalConfig
from adapters.ros2dds.domain import (
    AUTO_DOMAINS,
    LOCK_DIR,
    bound_port,
    claim_domain,
    discovery_ports,
)
from adapters.ros2dds.participant import RosParticipant
from cosim.core.errors import BridgeError, ConfigError

AUTO = PhysicalConfig(robots=("robot_1",))


def test_the_discovery_ports_are_the_rtps_well_known_ports_of_the_domain():
    # DDSI-RTPS 9.6.1.1: 7400 + 250 d (multicast), 7400 + 250 d + 10 + 2 i (unicast)
    assert discovery_ports(1)[:3] == [7650, 7660, 7662]
    assert len(discovery_ports(0)) == 11


def test_two_auto_claims_of_one_machine_never_share_a_domain_and_a_released_one_is_reused():
    with claim_domain(AUTO, "test") as first, claim_domain(AUTO, "test") as second:
        assert first.chosen and second.chosen
        assert first.domain != second.domain
        assert first.domain in AUTO_DOMAINS and second.domain in AUTO_DOMAINS
        taken = first.domain
    with claim_domain(AUTO, "test") as again:
        assert again.domain <= taken  # the lowest free one: what the first gave back


def test_auto_skips_a_domain_a_dds_participant_of_this_machine_is_on():
    with claim_domain(AUTO, "test") as probe:
        free = probe.domain
    with RosParticipant(free):
        assert bound_port(free) is not None
        with claim_domain(AUTO, "test") as claim:
            assert claim.domain != free
    assert bound_port(free) is None


def test_auto_skips_a_domain_whose_discovery_port_is_bound_by_anything():
    with claim_domain(AUTO, "test") as probe:
        free = probe.domain
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as squatter:
        squatter.bind(("", discovery_ports(free)[0]))
        assert bound_port(free) == discovery_ports(free)[0]
        with claim_domain(AUTO, "test") as claim:
            assert claim.domain != free


def test_a_named_domain_held_by_another_run_is_refused_in_one_line_naming_it_and_the_pid():
    with claim_domain(AUTO, "test") as probe:
        domain = probe.domain
    lock = LOCK_DIR / f"domain-{domain}.lock"
    # another process takes the lock as a run would (pid written, flock held)
    hold = (
        "import fcntl, os, sys, time\n"
        f"f = open({str(lock)!r}, 'a+')\n"
        "fcntl.flock(f, fcntl.LOCK_EX)\n"
        "f.seek(0); f.truncate(); f.write(str(os.getpid())); f.flush()\n"
        "print('held', flush=True)\n"
        "time.sleep(30)\n"
    )
    holder = subprocess.Popen([sys.executable, "-c", hold], stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout is not None and holder.stdout.readline() == "held\n"
        with pytest.raises(BridgeError) as caught:
            claim_domain(PhysicalConfig(dds_domain=domain), "lab.toml")
        assert str(caught.value) == (
            f"lab.toml: [physical] dds_domain = {domain}: DDS domain {domain} is in use by "
            f"another cosim run (pid {holder.pid}); expected a domain no other run uses "
            '(dds_domain = "auto" picks a free one)'
        )
    finally:
        holder.kill()
        holder.wait()
    # the holder gone, the kernel dropped its lock: the domain is free again
    claim_domain(PhysicalConfig(dds_domain=domain), "lab.toml").release()


def test_a_process_claiming_its_own_named_domain_again_shares_the_claim():
    with claim_domain(AUTO, "test") as claim:
        again = claim_domain(PhysicalConfig(dds_domain=claim.domain), "test")
        assert again.domain == claim.domain and not again.chosen
        again.release()  # holds no lock of its own: the first claim still holds
        text = (LOCK_DIR / f"domain-{claim.domain}.lock").read_text()
        assert text.strip() == str(os.getpid())


def test_auto_with_a_network_interface_is_refused_at_load_naming_both_keys():
    with pytest.raises(ConfigError) as caught:
        cosim.load_scenario("lab-mixed", {"physical.interface": "eth0"})
    assert str(caught.value) == (
        "preset lab-mixed: [physical] dds_domain = 'auto': expected the robots' ROS_DOMAIN_ID "
        "(0-232) with interface = 'eth0': a robot on a network keeps its own domain"
    )


@pytest.mark.parametrize(
    ("value", "expected"),
    [
        (233, "dds_domain = 233: expected an integer or one of 'auto' >= 0 and <= 232"),
        ("any", "dds_domain = 'any': expected an integer or one of 'auto'"),
    ],
)
def test_a_bad_domain_is_refused_at_load(value, expected):
    with pytest.raises(ConfigError, match=expected):
        cosim.load_scenario("lab-mixed", {"physical.dds_domain": value})


def test_a_pose_timeout_must_be_positive():
    with pytest.raises(ConfigError, match=r"pose_timeout_s = 0\.0: expected a number"):
        cosim.load_scenario("lab-mixed", {"physical.pose_timeout_s": 0.0})
