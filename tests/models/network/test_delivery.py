"""Delivery statuses are the plain strings the messages table records."""

from cosim.core.link import DELIVERED
from cosim.core.recorder import MESSAGES
from models.network.delivery import DeliveryStatus


def test_the_statuses_are_their_documented_strings():
    assert [s.value for s in DeliveryStatus] == [
        "delivered",
        "lost",
        "queue_full",
        "out_of_range",
        "partitioned",
    ]


def test_a_status_equals_and_formats_as_its_string():
    assert DeliveryStatus.LOST == "lost" and f"{DeliveryStatus.QUEUE_FULL}" == "queue_full"
    assert DeliveryStatus("partitioned") is DeliveryStatus.PARTITIONED
    assert hash(DeliveryStatus.LOST) == hash("lost")


def test_delivered_is_the_cores_word_and_every_drop_reason_is_documented_in_the_table():
    assert DeliveryStatus.DELIVERED == DELIVERED
    for status in DeliveryStatus:
        assert status.value in MESSAGES.columns["status"]
