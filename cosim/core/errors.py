"""The error hierarchy of cosim.

One root, :class:`CosimError`, and a few leaves. Every message names the offending
file, key or value and says what was expected, so the command line can print it on
one line and exit with status 2. Anything else escaping the run is a bug (status 1).
"""

from __future__ import annotations

from typing import Any


class CosimError(Exception):
    """Root of every error that cosim raises on purpose.

    Attributes:
        kept: what a run kept before this error ended it (its ``RunResult``: the tables and
            a summary of the simulated time reached), or None.
    """

    kept: Any = None

    def say_kept(self, where: str) -> None:
        """Add where the results of the run so far are to the one-line message."""
        self.args = (f"{self}; {where}",)


class ConfigError(CosimError):
    """A scenario or study file, or a ``--set`` override, is invalid."""


class ScenarioError(CosimError):
    """A scenario is well-formed but cannot be built (e.g. shelves that do not fit)."""


class RegistryError(CosimError):
    """An adapter name is unknown or an adapter plugin is broken."""


class ExportError(CosimError):
    """Results cannot be written (existing output folder, unwritable path, ...)."""


class BagError(CosimError):
    """A file or folder given as a ROS 2 bag is not one, or cannot be read."""


class WorkerError(CosimError):
    """A study's worker process died or its Dask cluster went away mid-study."""


class BridgeError(CosimError):
    """An external system (DDS, SUMO, motion capture) cannot be reached or misbehaves.

    Raised while the kernel runs, it ends the run keeping what ran (:attr:`kept`).
    """


class WireError(CosimError):
    """Bytes are not the message they are said to be (CDR too short, a bad string, ...).

    Also raised when a message type is declared wrongly (a field without a wire type).
    """
