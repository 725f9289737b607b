"""The link between hosts: the ideal one delivers every copy at once, statuses are words."""

import dataclasses

import pytest

from cosim.core.hosts import HostId
from cosim.core.link import DELIVERED, AllDelivered, IdealLink, Link, Transfer
from models.network.delivery import DeliveryStatus


def test_delivered_is_the_built_in_network_models_word_for_it():
    assert DELIVERED == DeliveryStatus.DELIVERED == "delivered"


@pytest.mark.parametrize("dsts", [[], [HostId("b")], [HostId("b"), HostId("c"), HostId("a")]])
def test_the_ideal_link_delivers_every_copy_when_sent(dsts):
    link: Link = IdealLink()
    outcome = link.transmit(1_234, HostId("a"), dsts, 10_000_000, "/robot_1/scan")
    assert outcome == AllDelivered(1_234)


def test_outcomes_are_immutable_values():
    transfer = Transfer(HostId("b"), DeliveryStatus.LOST, None)
    assert transfer == Transfer(HostId("b"), "lost", None)
    with pytest.raises(dataclasses.FrozenInstanceError):
        transfer.status = DELIVERED  # type: ignore[misc]
    with pytest.raises(dataclasses.FrozenInstanceError):
        AllDelivered(5).t_recv_ns = 6  # type: ignore[misc]
    assert not hasattr(transfer, "__dict__")
