"""Exit statuses of the ``cosim`` command line, and the lines that say why.

- 0: done;
- 1: cosim's own code failed (a bug): the traceback is printed, and written to the run
  folder's ``failure.txt`` with the results so far when the run had started;
- 2: invalid input (one line on stderr naming the file, the key, the value and what was
  expected), or an external system (a robot, a motion-capture server) failed mid-run;
- 3: a plugin's code failed (raised, hung, or handed back a value cosim refuses): one line
  naming the plugin, what it was doing and the simulated time; its traceback and the
  results so far in the run folder;
- 4: a study finished, but some of its runs failed (``report.md`` lists them);
- 128 + N: stopped by signal N (130: Ctrl-C), what ran kept.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

from cosim.core.errors import CosimError

EXIT_OK = 0
"""Done."""
EXIT_BUG = 1
"""cosim's own code failed: a bug, to report with its traceback."""
EXIT_INPUT = 2
"""Invalid input: a file, a key, a flag (one line, no traceback)."""
EXIT_PLUGIN = 3
"""A plugin's code failed: raised, hung, or handed back a value cosim refuses."""
EXIT_RUNS_FAILED = 4
"""A study finished, but some of its runs failed."""

EXIT_STATUSES = {
    EXIT_OK: "done",
    EXIT_BUG: "cosim's own code failed (a bug): the traceback is printed and, once a run "
    "had started, written to its folder's failure.txt with the results so far",
    EXIT_INPUT: "invalid input (a file, a key, a flag), or an external system (a robot, a "
    "motion-capture server) failed mid-run",
    EXIT_PLUGIN: "a plugin's code failed (raised, hung past scenario.hang_timeout_s, or "
    "handed back a value cosim refuses): one line naming it; its traceback in the run "
    "folder's failure.txt, the results so far kept; for `cosim check-plugin`, a check failed",
    EXIT_RUNS_FAILED: "a study finished, but some of its runs failed (report.md lists them, "
    "each run's folder holds its failure.txt)",
    130: "interrupted (Ctrl-C); 128 + N for signal N: what ran is kept",
}
"""Every exit status, for the command-line reference."""


def say_error(error: CosimError) -> int:
    """One line on stderr for an error cosim names, and the exit status of its kind."""
    from cosim.core.plugins import PluginError
    from cosim.runner.faults import InternalError

    if isinstance(error, PluginError):
        print(f"cosim: plugin error: {error}", file=sys.stderr)
        if error.kept is None and error.details:  # no run folder holds it
            print(error.details, file=sys.stderr, end="")
        return EXIT_PLUGIN
    if isinstance(error, InternalError):
        print(error.details, file=sys.stderr, end="")
        print(
            f"cosim: internal error (a bug; please report it with the traceback above): {error}",
            file=sys.stderr,
        )
        return EXIT_BUG
    print(f"cosim: error: {error}", file=sys.stderr)
    return EXIT_INPUT


def failed_runs_line(results: Any, out: Path) -> str:
    """``3 of 40 runs failed (2 in a plugin, 1 in cosim): ...`` for a study's results."""
    failed = results[results["status"] != "ok"]
    kinds = failed["failure_kind"].value_counts() if "failure_kind" in failed else None
    words = {"plugin": "in a plugin", "cosim": "in cosim", "input": "on bad input"}
    split = (
        " (" + ", ".join(f"{n} {words.get(k, k)}" for k, n in kinds.items()) + ")"
        if kinds is not None and len(kinds)
        else ""
    )
    ids = ", ".join(str(r) for r in failed["run_id"].head(5))
    more = ", ..." if len(failed) > 5 else ""
    return (
        f"{len(failed)} of {len(results)} runs failed{split}: {ids}{more}; their errors are "
        f"in {out}/report.md and results.parquet (column error), their tracebacks in "
        f"{out}/runs/RUN/failure.txt"
    )
