"""The robots' bodies: batched kinematics and odometry, ground-truth contacts."""
