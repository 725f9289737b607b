"""Hosts: the computers adapters live on, named as the messages table names them."""

import dataclasses

import pytest

from cosim.core.hosts import BASE_HOST, Host, HostId, HostKind, robot_host


def test_a_robots_host_is_named_as_the_robot():
    assert robot_host("robot_3") == "robot_3"
    assert robot_host("robot_3") == HostId("robot_3")


def test_the_base_station_is_the_host_base():
    assert BASE_HOST == "base"


def test_host_kinds_are_the_strings_the_tables_and_messages_use():
    assert [kind.value for kind in HostKind] == ["robot", "base", "mocap", "external"]
    assert HostKind("mocap") is HostKind.MOCAP
    assert f"a {HostKind.ROBOT} host" == "a robot host"


def test_a_host_is_immutable_and_equal_by_id_and_kind():
    host = Host(HostId("robot_1"), HostKind.ROBOT)
    assert host == Host(HostId("robot_1"), HostKind.ROBOT)
    assert host != Host(HostId("robot_1"), HostKind.EXTERNAL)
    with pytest.raises(dataclasses.FrozenInstanceError):
        host.kind = HostKind.BASE  # type: ignore[misc]
    assert {host, Host(HostId("robot_1"), HostKind.ROBOT)} == {host}
