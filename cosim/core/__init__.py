"""The core every adapter relies on: the kernel, the bus, hosts, time, randomness, errors.

It holds the event kernel (:mod:`~cosim.core.kernel`), the topic bus and its links
(:mod:`~cosim.core.bus`, :mod:`~cosim.core.link`), hosts, per-component random streams,
integer-nanosecond time, the error hierarchy, the adapter contract and registry, the
recorder of tables, the message types and the reading of ROS 2 bags. It imports nothing
from the rest of :mod:`cosim`, nor from ``models`` or ``adapters``.
"""
