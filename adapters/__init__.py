"""Adapters: SimPy-side wrappers that give the pure models time, rates and a place on the bus.

Each adapter is registered by name in the ``cosim.adapters`` entry-point group.
"""
