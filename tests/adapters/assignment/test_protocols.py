import numpy as np

from adapters.assignment.protocols import BasisDecoder, SimplexProtocol
from cosim.core.messages import Message, SimplexBasis
from models.assignment.dsimplex import SharedBasis
from models.assignment.problem import AssignmentProblem, Column, ColumnKind, LpShape
from models.assignment.simplex import columns_of


def test_the_simplex_protocol_sends_its_current_basis_every_round():
    rng = np.random.default_rng(3)
    problem = AssignmentProblem(("r0", "r1", "r2"), (10, 11, 12, 13), rng.uniform(1, 20, (3, 4)))
    agents = [SimplexProtocol(problem, i, f"r{i}", 1, 2) for i in range(3)]
    inboxes: list[list[Message]] = [[], [], []]
    changes = 0
    for now in range(12):
        sent = []
        for i, agent in enumerate(agents):
            message, changed = agent.round(inboxes[i], now)
            changes += changed
            assert isinstance(message, SimplexBasis)
            assert message.stamp_ns == now
            assert message.columns == tuple(
                (int(c.kind), c.robot, c.task, c.cost) for c in agent.agent.basis
            )
            sent.append(message)
        inboxes = [[m for j, m in enumerate(sent) if j != i] for i in range(3)]
    assert changes > 0
    assert all(agent.decided for agent in agents)


def test_a_basis_is_decoded_once_per_sender_until_its_wire_form_changes():
    decoder = BasisDecoder()
    wire = ((0, 1, 2, 3.5), (1, 0, -1, 1e6))
    first = decoder.decode(SimplexBasis(1, 0, "robot_1", 1, wire))
    assert first == (Column(ColumnKind(0), 1, 2, 3.5), Column(ColumnKind(1), 0, -1, 1e6))
    assert isinstance(first, SharedBasis)
    ranks = first.ranked_in(LpShape(2, 3))
    assert ranks is first.ranked_in(LpShape(2, 3))  # laid out once, for every receiver
    assert columns_of(LpShape(2, 3), ranks) == list(first)
    # the same wire tuple again (the sender kept it): the same basis, for every receiver
    assert decoder.decode(SimplexBasis(2, 0, "robot_1", 2, wire)) is first
    # an equal tuple that is another object is decoded again, and so is another sender's
    again = decoder.decode(SimplexBasis(3, 0, "robot_1", 3, tuple(list(wire))))
    assert again == first and again is not first
    assert decoder.decode(SimplexBasis(3, 0, "robot_2", 3, wire)) is not first
