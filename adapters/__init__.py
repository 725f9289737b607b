"""Adapters: SimPy-side wrappers that give the pure models time, rates and a place on the bus.

Each adapter is registered by name in the ``cosim.adapters`` entry-point group. They are
grouped by capability, mirroring ``models/``:

- ``world/``: the warehouse and the base station;
- ``fleet/``: kinematics, odometry and contacts of the robots;
- ``sensing/``: the lidar;
- ``network/``: the link model between hosts;
- ``navigation/``: planning, control and recovery (the Nav2 role), random goals;
- ``assignment/`` and ``tasks/``: dynamic task assignment and the task source;
- ``drivers/``: simple robot software (waypoints, wander);
- ``recording/``: ground-truth samples for the tables, the ROS interface for bags.
"""
