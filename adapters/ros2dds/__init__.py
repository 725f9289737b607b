"""ROS 2's wire protocol through Cyclone DDS, so that a real ROS 2 robot talks to cosim.

A robot running Humble or Jazzy with ``rmw_cyclonedds`` needs nothing of cosim: cosim
speaks DDS with ROS 2's names (:mod:`adapters.ros2dds.naming`), QoS profiles
(:mod:`adapters.ros2dds.qos`) and message layouts (:mod:`adapters.ros2dds.types`), through a
participant that is loopback-only unless told an interface
(:mod:`adapters.ros2dds.participant`).
"""
