"""A 2D pose graph: scan poses tied by relative-pose measurements, solved by least squares.

Nodes are the poses of the scans that updated the map. An edge ``(a, b, z)`` says that
node ``b`` was measured at ``z`` (x, y, yaw) in node ``a``'s frame: consecutive scans by
scan matching, far-apart scans by a loop closure. The optimum moves every node so that
the weighted residuals ``R_a^T (t_b - t_a) - z_t`` and ``wrap(yaw_b - yaw_a - z_yaw)`` are
least in a robust (Huber) sense, with the first node held fixed — the formulation of
Karto and slam_toolbox, solved here with SciPy's trust-region least squares on the
sparse analytic Jacobian instead of their sparse Cholesky (Ceres / SPA).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from scipy.optimize import least_squares
from scipy.sparse import csr_matrix

from models.arrays import FloatArray
from models.mapping.se2 import Pose, wrap


class Edge(NamedTuple):
    """A measured relative pose between two nodes.

    Attributes:
        a, b: node indices.
        z: node ``b``'s pose in node ``a``'s frame (x m, y m, yaw rad).
        sigma_m: standard deviation of the translation (m).
        sigma_rad: standard deviation of the rotation (rad).
    """

    a: int
    b: int
    z: Pose
    sigma_m: float
    sigma_rad: float


@dataclass
class PoseGraph:
    """Nodes and edges; :meth:`optimize` returns the poses that best fit the edges."""

    nodes: list[Pose]
    edges: list[Edge]

    def __init__(self) -> None:
        self.nodes = []
        self.edges = []

    def add_node(self, pose: Pose) -> int:
        """A new node at ``pose``; its index."""
        self.nodes.append(pose)
        return len(self.nodes) - 1

    def add_edge(self, edge: Edge) -> None:
        """A measurement between two existing nodes."""
        if not (0 <= edge.a < len(self.nodes) and 0 <= edge.b < len(self.nodes)):
            raise IndexError(f"edge between {edge.a} and {edge.b}: no such node")
        self.edges.append(edge)

    def optimize(self, *, huber: float = 5.0, max_nfev: int = 200) -> list[Pose]:
        """The node poses fitting the edges best, node 0 fixed (no change to the graph).

        Args:
            huber: residuals beyond this many standard deviations weigh linearly (a wrong
                loop closure pulls, but cannot tear the map).
            max_nfev: most residual evaluations.
        """
        n = len(self.nodes)
        if n < 2 or not self.edges:
            return list(self.nodes)
        start = np.array(self.nodes, dtype=np.float64)
        a = np.array([e.a for e in self.edges])
        b = np.array([e.b for e in self.edges])
        z = np.array([e.z for e in self.edges], dtype=np.float64)
        w = np.array([[1 / e.sigma_m, 1 / e.sigma_m, 1 / e.sigma_rad] for e in self.edges])
        fixed = start[0]

        def poses(free: FloatArray) -> FloatArray:
            return np.vstack([fixed, free.reshape(n - 1, 3)])

        def residuals(free: FloatArray) -> FloatArray:
            p = poses(free)
            weighted: FloatArray = (_errors(p, a, b, z) * w).ravel()
            return weighted

        def jacobian(free: FloatArray) -> csr_matrix:
            return _jacobian(poses(free), a, b, w, n)

        result = least_squares(
            residuals,
            start[1:].ravel(),
            jac=jacobian,
            loss="huber",
            f_scale=huber,
            max_nfev=max_nfev,
            method="trf",
            x_scale="jac",
        )
        out = poses(result.x)
        return [(float(x), float(y), wrap(float(t))) for x, y, t in out]


def _errors(p: FloatArray, a: np.ndarray, b: np.ndarray, z: FloatArray) -> FloatArray:
    dx = p[b, 0] - p[a, 0]
    dy = p[b, 1] - p[a, 1]
    c, s = np.cos(p[a, 2]), np.sin(p[a, 2])
    ex = c * dx + s * dy - z[:, 0]
    ey = -s * dx + c * dy - z[:, 1]
    et = np.remainder(p[b, 2] - p[a, 2] - z[:, 2] + np.pi, 2 * np.pi) - np.pi
    return np.stack([ex, ey, et], axis=1)


def _jacobian(p: FloatArray, a: np.ndarray, b: np.ndarray, w: FloatArray, n: int) -> csr_matrix:
    """The derivatives of the residuals by the free poses (node 0 is fixed), sparse."""
    m = len(a)
    dx = p[b, 0] - p[a, 0]
    dy = p[b, 1] - p[a, 1]
    c, s = np.cos(p[a, 2]), np.sin(p[a, 2])
    rows: list[np.ndarray] = []
    cols: list[np.ndarray] = []
    vals: list[np.ndarray] = []
    r = np.arange(m) * 3

    def put(row: np.ndarray, node: np.ndarray, k: int, value: np.ndarray) -> None:
        keep = node > 0
        rows.append(row[keep])
        cols.append((node[keep] - 1) * 3 + k)
        vals.append(value[keep])

    # ex = c dx + s dy, ey = -s dx + c dy, et = tb - ta
    put(r, a, 0, -c * w[:, 0])
    put(r, a, 1, -s * w[:, 0])
    put(r, a, 2, (-s * dx + c * dy) * w[:, 0])
    put(r, b, 0, c * w[:, 0])
    put(r, b, 1, s * w[:, 0])
    put(r + 1, a, 0, s * w[:, 1])
    put(r + 1, a, 1, -c * w[:, 1])
    put(r + 1, a, 2, (-c * dx - s * dy) * w[:, 1])
    put(r + 1, b, 0, -s * w[:, 1])
    put(r + 1, b, 1, c * w[:, 1])
    put(r + 2, a, 2, -np.ones(m) * w[:, 2])
    put(r + 2, b, 2, np.ones(m) * w[:, 2])
    return csr_matrix(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
        shape=(3 * m, 3 * (n - 1)),
    )
