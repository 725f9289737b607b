"""The network between hosts: the link model on the bus, built from ``[network]``."""
