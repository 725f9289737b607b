"""An independent reader of bags (the `mcap` packages, not rosbags) and the run it reads."""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

from tests.conftest import SMALL

TASKS = {**SMALL, "robots.driver": "tasks", "scenario.duration_s": 6.0, "tasks.dwell_s": 0.5}
"""3 robots serving tasks by distributed simplex for 6 s: every kind of topic."""


@dataclass
class DecodedBag:
    """Every message of an MCAP file, decoded by `mcap_ros2` with the schemas it embeds."""

    types: dict[str, str] = field(default_factory=dict)
    log_ns: dict[str, list[int]] = field(default_factory=lambda: defaultdict(list))
    messages: dict[str, list[Any]] = field(default_factory=lambda: defaultdict(list))
    channel_metadata: dict[str, dict[str, str]] = field(default_factory=dict)
    profile: str = ""


def read_mcap(path: Path) -> DecodedBag:
    """Decode every message of ``path`` (an MCAP file written by anyone) independently."""
    bag = DecodedBag()
    with path.open("rb") as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        bag.profile = reader.get_header().profile
        for schema, channel, message, decoded in reader.iter_decoded_messages(log_time_order=True):
            bag.types[channel.topic] = schema.name
            bag.channel_metadata[channel.topic] = dict(channel.metadata)
            bag.log_ns[channel.topic].append(message.log_time)
            bag.messages[channel.topic].append(decoded)
    return bag


def mcap_file(bag_dir: Path) -> Path:
    (path,) = sorted(bag_dir.glob("*.mcap"))
    return path
