"""Recording a run for ROS 2 tools: the bag (rosbags), the live view (Foxglove), bag reading.

- ``topics``: which advertised topics ``record.topics`` keeps;
- ``schemas``: message definitions, hashes and QoS as rosbag2 records them;
- ``tap``: bus monitors that serialize each publication once and feed the sinks;
- ``bag``: the rosbag2 writer sink; ``live``: the Foxglove WebSocket sink;
- ``session``: what a run records, set up and closed around the kernel;
- ``reading``: opening any ROS 2 bag (ours, rosbag2's, a bare ``.mcap``) and ``bag info``.
"""
