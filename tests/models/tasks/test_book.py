import pytest

from models.tasks.book import ClaimOutcome, TaskBook, TaskStatus

ROBOTS = ["robot_1", "robot_2", "robot_3"]


def _book(preemption=False):
    book = TaskBook(ROBOTS, claim_timeout_ns=5_000_000_000, preemption=preemption)
    book.create(0, 1.0, 2.0, frozenset(ROBOTS), 0)
    book.create(1, 3.0, 4.0, frozenset(ROBOTS[:2]), 0)
    return book


def test_the_lower_cost_claim_wins_and_equal_costs_go_to_the_earlier_robot():
    book = _book()
    assert book.claim(0, "robot_2", 5.0, 10) is ClaimOutcome.ACCEPTED
    assert book.claim(0, "robot_3", 6.0, 11) is ClaimOutcome.REJECTED
    assert book.claim(0, "robot_1", 5.0, 12) is ClaimOutcome.REPLACED
    assert book.tasks[0].claim.robot == "robot_1"
    assert book.conflicts == 2
    assert book.tasks[0].reassignments == 1


def test_a_task_is_granted_to_one_robot_only():
    book = _book()
    book.claim(0, "robot_1", 5.0, 10)
    assert not book.request_service(0, "robot_2", 20)
    assert book.request_service(0, "robot_1", 21)
    assert book.request_service(0, "robot_1", 22)  # a repeated request (lost reply)
    assert not book.request_service(0, "robot_2", 23)
    assert book.tasks[0].status is TaskStatus.SERVING and book.tasks[0].server == "robot_1"


def test_an_unclaimed_task_goes_to_the_first_eligible_robot_asking():
    book = _book()
    assert not book.request_service(1, "robot_3", 5)  # not eligible
    assert book.request_service(1, "robot_2", 6)
    assert not book.request_service(1, "robot_1", 7)


def test_done_counts_once_and_only_from_the_server():
    book = _book()
    book.request_service(0, "robot_1", 5)
    assert not book.done(0, "robot_2", 6)
    assert book.done(0, "robot_1", 7)
    assert not book.done(0, "robot_1", 8)
    assert book.tasks[0].completed_ns == 7


def test_a_silent_claim_is_released_after_the_timeout():
    book = _book()
    book.claim(0, "robot_2", 5.0, 0)
    assert book.expire(4_000_000_000) == []
    book.claim(0, "robot_2", 5.0, 4_000_000_000)  # repeated: refreshed
    assert book.expire(8_000_000_000) == []
    assert book.expire(9_500_000_000) == [0]
    assert book.tasks[0].claim is None


def test_held_tasks_stay_in_the_problem_with_their_holder_until_done():
    book = _book()
    book.claim(0, "robot_2", 1.0, 0)
    assert [t.task_id for t in book.offered()] == [0, 1]
    assert [book.holder(t) for t in book.offered()] == ["robot_2", ""]
    book.request_service(0, "robot_2", 1)
    assert book.holder(book.tasks[0]) == "robot_2"
    book.done(0, "robot_2", 2)
    assert [t.task_id for t in book.offered()] == [1]


def test_a_release_by_another_robot_does_nothing():
    book = _book()
    book.claim(0, "robot_1", 1.0, 0)
    assert not book.release(0, "robot_2")
    assert book.release(0, "robot_1")
    assert book.tasks[0].claim is None


def test_a_repeated_task_id_is_refused():
    with pytest.raises(ValueError, match="exists already"):
        _book().create(0, 0.0, 0.0, frozenset(ROBOTS), 0)
