"""ROS 2 bags as input: reading rosbag2 folders and bare MCAP files with rosbags."""
