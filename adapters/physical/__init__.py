"""Physical robots joining a run over ROS 2's wire protocol (DDS)."""
