"""The ``ns3`` network backend: every host on one 802.11 network simulated by ns-3."""
