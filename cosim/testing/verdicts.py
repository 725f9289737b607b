"""How one check of ``cosim check-plugin`` came out: ok, warn, FAIL or skip, and why."""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum


class Verdict(Enum):
    """How a check came out."""

    OK = "ok"
    WARN = "warn"
    FAIL = "FAIL"
    SKIP = "skip"


@dataclass(frozen=True)
class Outcome:
    """One check of one entry.

    Attributes:
        check: the check's name (``contract``, ``runs``, ``assigns``).
        verdict: ok, warn (passed, with something to fix that breaks nothing), FAIL
            or skip.
        detail: what was found (for ok), why it failed, or why it was skipped: one line.
    """

    check: str
    verdict: Verdict
    detail: str

    @property
    def failed(self) -> bool:
        """Whether the check failed."""
        return self.verdict is Verdict.FAIL

    def line(self) -> str:
        """``ok   contract: ...``, ``FAIL assigns: ...``: how ``cosim check-plugin`` prints it."""
        return f"{self.verdict.value:<4} {self.check}: {self.detail}"


def ok(check: str, detail: str) -> Outcome:
    """A passed check."""
    return Outcome(check, Verdict.OK, detail)


def warn(check: str, why: str) -> Outcome:
    """A passed check that found something to fix (it breaks nothing)."""
    return Outcome(check, Verdict.WARN, why)


def fail(check: str, why: str) -> Outcome:
    """A failed check."""
    return Outcome(check, Verdict.FAIL, why)


def skip(check: str, why: str) -> Outcome:
    """A check that does not apply."""
    return Outcome(check, Verdict.SKIP, why)
