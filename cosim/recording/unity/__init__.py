"""Unity scenes attached to a run: a ROS-TCP-Endpoint (Connector 0.7, ROS 2) served by cosim.

- ``frames``: the wire format (length-prefixed destination and payload, JSON commands);
- ``inbound``: what a scene may publish into the run (goal poses) and how it is checked;
- ``commands``: a connection's handling of each frame;
- ``server``: the sink (:class:`UnitySink`): listening, sessions, pacing by the kernel.
"""

from cosim.recording.unity.server import UnityOptions, UnitySink

__all__ = ["UnityOptions", "UnitySink"]
