"""ROS 2's wire protocol through Cyclone DDS, so that a real ROS 2 robot talks to cosim.

A robot running Humble or Jazzy with ``rmw_cyclonedds`` needs nothing of cosim: cosim
speaks DDS with ROS 2's names (:mod:`cosim.ros2dds.naming`), QoS profiles
(:mod:`cosim.ros2dds.qos`) and message layouts (:mod:`cosim.ros2dds.types`), through a
participant that is loopback-only unless told an interface
(:mod:`cosim.ros2dds.participant`).
"""
