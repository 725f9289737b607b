"""QoS profiles: the values of ROS 2's rmw_qos_profile_sensor_data and rmw_qos_profile_default."""

import pytest
from cyclonedds.qos import Policy

from adapters.ros2dds.qos import QosKind, default_qos, qos_for, sensor_data_qos


def test_sensor_data_is_best_effort_keep_last_5_volatile():
    qos = sensor_data_qos()
    assert qos[Policy.Reliability] == Policy.Reliability.BestEffort
    assert qos[Policy.History] == Policy.History.KeepLast(depth=5)
    assert qos[Policy.Durability] == Policy.Durability.Volatile


def test_default_is_reliable_keep_last_10_volatile():
    qos = default_qos()
    assert isinstance(qos[Policy.Reliability], Policy.Reliability.Reliable)
    assert qos[Policy.History] == Policy.History.KeepLast(depth=10)
    assert qos[Policy.Durability] == Policy.Durability.Volatile


@pytest.mark.parametrize("kind", list(QosKind))
def test_every_profile_speaks_plain_cdr_only(kind):
    representation = qos_for(kind)[Policy.DataRepresentation]
    assert representation.use_cdrv0_representation
    assert not representation.use_xcdrv2_representation


def test_each_kind_names_its_profile():
    assert qos_for(QosKind.SENSOR_DATA) == sensor_data_qos()
    assert qos_for(QosKind.DEFAULT) == default_qos()
