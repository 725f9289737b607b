"""How a check of ``cosim check-plugin`` is printed: one line, its verdict first."""

from cosim.testing.verdicts import Verdict, fail, ok, skip, warn


def test_a_check_is_one_line_with_its_verdict_padded_its_name_and_why():
    assert ok("loads", "labkit.auction:SequentialAuction").line() == (
        "ok   loads: labkit.auction:SequentialAuction"
    )
    assert fail("assigns", "no task claimed").line() == "FAIL assigns: no task claimed"
    assert skip("runs", "a live source").line() == "skip runs: a live source"
    assert warn("declared", "x declared nowhere").line() == "warn declared: x declared nowhere"


def test_only_a_failed_check_counts_as_failed():
    checks = (ok("a", ""), fail("b", ""), skip("c", ""), warn("d", ""))
    assert [o.failed for o in checks] == [False, True, False, False]
    assert fail("b", "").verdict is Verdict.FAIL
