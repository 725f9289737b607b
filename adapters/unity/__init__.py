"""Unity scenes attached to a run: a ROS-TCP-Endpoint (Connector 0.7, ROS 2) served by cosim.

- ``framing``: the wire format (length-prefixed destination and payload, JSON commands);
- ``inbound``: what a scene may publish into the run (goal poses, velocity commands,
  tracked poses) and how it is checked;
- ``commands``: what a connection does with each frame;
- ``connection``: one scene's connection, its reader and writer threads;
- ``server``: the endpoint (:class:`~adapters.unity.server.UnitySink`): listening,
  connections, the kernel taking what scenes sent into the run;
- ``poses``: ``mocap.source = "unity"``, poses of the tracked robots from scenes;
- ``topics``: the bus topics of what scenes publish.
"""
