"""Motion capture outside the kernel: recorded pose tracks and live mocap systems."""
