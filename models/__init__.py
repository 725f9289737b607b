"""Pure models of cosim: geometry, physics, sensing, channels and algorithms.

Nothing here knows about time, SimPy, the bus or the command line: functions and small
classes over NumPy arrays and shapely geometry, testable on their own.
"""
