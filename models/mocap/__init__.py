"""Motion capture: how a Vicon-like system measures poses, and the checks a robot applies."""
