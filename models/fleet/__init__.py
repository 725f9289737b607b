"""The fleet's physics: differential-drive kinematics, drifting odometry, contacts."""
