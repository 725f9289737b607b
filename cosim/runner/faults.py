"""Whose fault a failed run is: a plugin's code, or cosim's own.

A run calls code of several packages (:mod:`cosim.core.plugins`). When an exception escapes
it, or the watchdog finds it hung (:mod:`cosim.runner.watchdog`), :func:`fault_of` reads
the traceback from the innermost frame outwards: the first frame of a plugin's module
(an installed package's, or code given in a script or test) names the plugin, and the
error becomes a :class:`~cosim.core.plugins.PluginError` (exit status 3); with no plugin
frame, it is cosim's own bug, an :class:`InternalError` (exit status 1). Either way the
runner keeps what ran and writes the traceback into the run folder (:data:`FAILURE_FILE`).
"""

from __future__ import annotations

import contextlib
import traceback
from collections.abc import Iterator
from pathlib import Path
from types import FrameType, TracebackType

from cosim.core.errors import CosimError
from cosim.core.plugins import PluginError, PluginInfo, plugin_of, plugin_of_module

FAILURE_FILE = "failure.txt"
"""The file of a failed run's folder that holds its one-line error and traceback."""


class InternalError(CosimError):
    """cosim's own code failed while a run went on (a bug): what ran is kept.

    Attributes:
        problem: what went wrong (``raised KeyError: 'x' in Mapper.on_scan (mapper.py:80)``).
        doing: what the run was doing.
        t_ns: the simulated time (ns).
        details: the traceback.
    """

    def __init__(
        self, problem: str, *, doing: str = "", t_ns: int | None = None, details: str = ""
    ):
        self.problem = problem
        self.doing = doing
        self.t_ns = t_ns
        self.details = details
        line = f"cosim's own code {problem}"
        if doing:
            line += f" while {doing}"
        if t_ns is not None:
            line += f" at t = {t_ns / 1e9:.9g} s simulated"
        super().__init__(line)

    def __reduce__(self) -> tuple[object, ...]:  # pickled across a study's worker processes
        return (_internal, (self.problem, self.doing, self.t_ns, self.details))


def _internal(problem: str, doing: str, t_ns: int | None, details: str) -> InternalError:
    return InternalError(problem, doing=doing, t_ns=t_ns, details=details)


class Hung(BaseException):
    """Raised in the running thread by the watchdog: the code running did not return in time.

    A ``BaseException``, as ``KeyboardInterrupt`` is, so that a plugin's ``except Exception``
    cannot swallow it.

    Attributes:
        timeout_s: the deadline it missed (s of wall-clock time).
    """

    def __init__(self, timeout_s: float) -> None:
        self.timeout_s = timeout_s
        super().__init__(timeout_s)  # args that build it again, as SimPy does

    def __str__(self) -> str:
        return f"did not return within {self.timeout_s:g} s"


def fault_of(
    error: BaseException, *, doing: str, t_ns: int | None
) -> PluginError | InternalError | CosimError:
    """The error that says whose fault ``error`` was, with its traceback as ``details``.

    Args:
        error: what escaped the run (with its traceback).
        doing: what the run was doing (``starting adapter 'proximity'``).
        t_ns: the simulated time (ns), or None before the run started.

    Returns:
        A :class:`PluginError` when a plugin's frame is in the traceback (or the error is
        one already, raised at the boundary); an :class:`InternalError` for any other
        exception; any other :class:`CosimError` as it is (bad input met mid-run, an
        external system gone), its traceback kept. A new error's ``__cause__`` is
        ``error``, whose traceback still holds the frames it came through.
    """
    fault = _fault_of(error, doing=doing, t_ns=t_ns)
    if fault is not error:  # the exception that escaped stays reachable, with its frames
        fault.__cause__ = error
    return fault


def _fault_of(
    error: BaseException, *, doing: str, t_ns: int | None
) -> PluginError | InternalError | CosimError:
    details = "".join(traceback.format_exception(error))
    plugin, where = blame(error.__traceback__)
    if isinstance(error, PluginError):
        known = error.plugin if error.plugin is not None else plugin
        if known is not None and known.builtin:  # a built-in refused: cosim's own bug
            return InternalError(
                f"({known.describe()}) {error.problem}",
                doing=error.doing or doing,
                t_ns=t_ns,
                details=details,
            )
        return PluginError(
            known, error.problem, doing=error.doing or doing, t_ns=t_ns, details=details
        )
    if isinstance(error, CosimError) and plugin is None:
        error.details = details  # type: ignore[attr-defined]
        return error
    if isinstance(error, Hung):
        problem = f"did not return within {error.timeout_s:g} s (scenario.hang_timeout_s)"
    else:
        problem = f"raised {_exception_line(error)}"
    if where:
        problem += f" in {where}"
    if plugin is None:
        return InternalError(problem, doing=doing, t_ns=t_ns, details=details)
    return PluginError(plugin, problem, doing=doing, t_ns=t_ns, details=details)


@contextlib.contextmanager
def plugin_faults_named(doing: str) -> Iterator[None]:
    """While inside, an exception from a plugin's code becomes its :class:`PluginError`.

    Before a run starts (building it, checking a scenario) nothing is kept: an exception
    whose traceback holds no plugin's frame (cosim's own bug, bad input) goes on as it is.
    """
    try:
        yield
    except Exception as error:
        if isinstance(error, CosimError) and not isinstance(error, PluginError):
            raise
        fault = fault_of(error, doing=doing, t_ns=None)
        if isinstance(fault, PluginError):
            raise fault from None
        raise


def blame(trace: TracebackType | None) -> tuple[PluginInfo | None, str]:
    """The plugin whose frame is innermost in ``trace``, and where in its code.

    Returns:
        (the plugin, ``Class.method (package/module.py:line)``) for the innermost frame
        of a plugin's module; (None, the innermost frame of cosim's code) when no plugin's
        frame is there.
    """
    frames = [frame for frame, _line in traceback.walk_tb(trace)]
    lines = [line for _frame, line in traceback.walk_tb(trace)]
    ours = ""
    for frame, line in zip(reversed(frames), reversed(lines), strict=True):
        module = frame.f_globals.get("__name__")
        info = plugin_of_module(module) if isinstance(module, str) else None
        if info is None:
            continue
        if info.builtin:
            ours = ours or _where(frame, line)
            continue
        owner = frame.f_locals.get("self")
        exact = plugin_of(owner) if owner is not None else None
        if exact is not None and not exact.builtin and exact.name:
            info = exact
        return info, _where(frame, line)
    return None, ours


def failure_text(error: CosimError) -> str:
    """What a run folder's :data:`FAILURE_FILE` holds: the one-line error, its traceback."""
    details = getattr(error, "details", "") or ""
    return f"{error}\n\n{details}"


def _where(frame: FrameType, line: int | None) -> str:
    code = frame.f_code
    path = Path(code.co_filename)
    short = "/".join(path.parts[-2:])
    return f"{code.co_qualname} ({short}:{line})"


def _exception_line(error: BaseException) -> str:
    text = str(error).strip().replace("\n", " ")
    name = type(error).__name__
    return f"{name}: {text}" if text else name
