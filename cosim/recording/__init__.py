"""Recording a run for ROS 2 tools: the bag (rosbags) and the live view (Foxglove).

- ``selection``: which advertised topics ``record.topics`` keeps;
- ``schemas``: message definitions, hashes and QoS as rosbag2 records them;
- ``tap``: bus monitors that serialize each publication once and feed the sinks;
- ``bag``: the rosbag2 writer sink; ``foxglove``: the Foxglove WebSocket sink;
- ``setup``: what a run records, set up and closed around the kernel.

Reading bags (ours, rosbag2's, a bare ``.mcap``) is :mod:`adapters.bags.reader`: adapters
replaying recordings rely on it too.
"""
