"""What happened to one message towards one destination host: its delivery status."""

from __future__ import annotations

from enum import StrEnum


class DeliveryStatus(StrEnum):
    """DeliveryStatus of one transmission towards one destination.

    The values are the strings recorded in the messages table.
    """

    DELIVERED = "delivered"
    LOST = "lost"
    QUEUE_FULL = "queue_full"
    OUT_OF_RANGE = "out_of_range"
    PARTITIONED = "partitioned"
