"""labkit: a lab's own cosim plugins, registered through entry points (see pyproject.toml).

- ``sequential_auction`` (an assignment protocol, :mod:`labkit.auction`);
- ``pure_pursuit`` (a local controller, :mod:`labkit.pursuit`);
- ``rangefinder`` (a sensor adapter, :mod:`labkit.rangefinder`).
"""
