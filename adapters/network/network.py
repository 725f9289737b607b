"""The network adapter: every inter-host message crosses the backend ``network.backend`` names.

It builds the chosen backend (registered in ``cosim.network_backends``; the built-in one
is :class:`adapters.network.links.LinksBackend`), installs it as the bus's link, and offers
a :class:`~adapters.network.contract.NetworkView` (who can hear whom right now) to
protocols.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar

from adapters.network.contract import NETWORK_BACKENDS, NetworkBackend, NetworkContext, NetworkView
from adapters.network.settings import NetworkConfig
from cosim.core.adapter import RunContext
from models.fleet.kinematics import FleetState


class NetworkAdapter:
    """Builds the network backend and installs it on the bus."""

    name: ClassVar[str] = "network"
    requires: ClassVar[tuple[str, ...]] = ("world", "fleet")

    def __init__(self, run: RunContext) -> None:
        cfg = run.settings(NetworkConfig)
        context = NetworkContext(run, cfg, list(run.service(FleetState).names))
        self.backend: NetworkBackend = NETWORK_BACKENDS.installed().get(cfg.backend)(context)
        run.bus.link = self.backend
        run.provide(NetworkView(self.backend))

    def start(self, run: RunContext) -> None:
        """Start the backend (every host exists now)."""
        self.backend.start(run)

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        """The backend's summary."""
        return self.backend.finish(run)

    def close(self) -> None:
        """Let the backend release what it holds (a radio's process), if it holds any.

        Called however the run ended, before :meth:`finish` when it ended well.
        """
        close = getattr(self.backend, "close", None)
        if callable(close):
            close()
