import numpy as np

from adapters.assignment.protocols import SimplexProtocol
from cosim.messages import Message, SimplexBasis
from models.assignment.problem import AssignmentProblem


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
