"""A 2D pose graph: scan poses tied by relative-pose measurements, solved by least squares.

Nodes are the poses of the scans that updated the map. An edge ``(a, b, z)`` says that
node ``b`` was measured at ``z`` (x, y, yaw) in node ``a``'s frame: consecutive scans by
scan matching, far-apart scans by a loop closure. Each edge carries its information
(inverse covariance) as a square root ``S`` (``S^T S = Sigma^-1``): a loop closure matched
in a corridor is sure across the corridor and unsure along it, and its information says
so. The optimum moves every node so that the whitened residuals
``S (R_a^T (t_b - t_a) - z_t, wrap(yaw_b - yaw_a - z_yaw))`` are least, with the first node
held fixed: the formulation of Karto and slam_toolbox (SPA, Konolige et al., IROS 2010),
solved by Levenberg-Marquardt on the sparse normal equations (:meth:`PoseGraph.optimize`).
Which loop closures may enter the graph is decided before and after a solve
(:mod:`models.mapping.loops`), not by the solver.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from scipy.sparse import csr_matrix, diags
from scipy.sparse.linalg import spsolve

from models.arrays import FloatArray
from models.geometry.angles import wrap_angle, wrap_angles
from models.geometry.se2 import Pose


class Edge(NamedTuple):
    """A measured relative pose between two nodes.

    Attributes:
        a, b: node indices.
        z: node ``b``'s pose in node ``a``'s frame (x m, y m, yaw rad).
        sigma_m: standard deviation of the translation (m), when ``sqrt_info`` is None.
        sigma_rad: standard deviation of the rotation (rad), when ``sqrt_info`` is None.
        sqrt_info: a 3 x 3 square root of the measurement's information in node ``a``'s
            frame (x, y, yaw), or None for ``diag(1/sigma_m, 1/sigma_m, 1/sigma_rad)``.
    """

    a: int
    b: int
    z: Pose
    sigma_m: float
    sigma_rad: float
    sqrt_info: FloatArray | None = None

    def whitening(self) -> FloatArray:
        """The edge's square-root information ``S`` (3 x 3)."""
        if self.sqrt_info is not None:
            return np.asarray(self.sqrt_info, dtype=np.float64)
        return np.diag([1 / self.sigma_m, 1 / self.sigma_m, 1 / self.sigma_rad])


def sqrt_information(covariance: FloatArray) -> FloatArray:
    """``S`` with ``S^T S`` the inverse of ``covariance`` (3 x 3, positive definite)."""
    info = np.linalg.inv(np.asarray(covariance, dtype=np.float64))
    info = 0.5 * (info + info.T)
    root: FloatArray = np.asarray(np.linalg.cholesky(info).T, dtype=np.float64)  # S^T S = info
    return root


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

    def residuals(self, poses: list[Pose] | None = None) -> FloatArray:
        """Every edge's squared whitened residual (a chi-square with 3 degrees of freedom)."""
        p = np.array(self.nodes if poses is None else poses, dtype=np.float64)
        a, b, z, s = self._arrays()
        white = np.einsum("mij,mj->mi", s, _errors(p, a, b, z))
        chi2: FloatArray = (white * white).sum(axis=1)
        return chi2

    def optimize(self, *, max_iterations: int = 30, tolerance: float = 1e-6) -> list[Pose]:
        """The node poses fitting the edges best, node 0 fixed (no change to the graph).

        Levenberg-Marquardt on the sparse normal equations, solved directly (the way SPA,
        Konolige et al. IROS 2010, solves Karto's graphs).

        Args:
            max_iterations: most Levenberg-Marquardt steps.
            tolerance: stop once no node moves more than this (m or rad).
        """
        n = len(self.nodes)
        if n < 2 or not self.edges:
            return list(self.nodes)
        a, b, z, s = self._arrays()
        p = np.array(self.nodes, dtype=np.float64)
        lam = 1e-4
        cost = _cost(p, a, b, z, s)
        for _ in range(max_iterations):
            jac = _jacobian(p, a, b, s, n).tocsc()
            r = np.einsum("mij,mj->mi", s, _errors(p, a, b, z)).ravel()
            h = (jac.T @ jac).tocsc()
            g = jac.T @ r
            diag = h.diagonal()
            while True:
                step = spsolve(h + diags(lam * (diag + 1e-9)), -g)
                q = p.copy()
                q[1:] += step.reshape(n - 1, 3)
                q[:, 2] = wrap_angles(q[:, 2])
                trial = _cost(q, a, b, z, s)
                if trial <= cost:
                    p, cost, lam = q, trial, max(lam / 10, 1e-9)
                    break
                lam *= 10
                if lam > 1e6:
                    break
            if lam > 1e6 or np.abs(step).max() < tolerance:
                break
        return [(float(x), float(y), wrap_angle(float(t))) for x, y, t in p]

    def _arrays(self) -> tuple[np.ndarray, np.ndarray, FloatArray, FloatArray]:
        a = np.array([e.a for e in self.edges])
        b = np.array([e.b for e in self.edges])
        z = np.array([e.z for e in self.edges], dtype=np.float64).reshape(-1, 3)
        s = np.array([e.whitening() for e in self.edges], dtype=np.float64).reshape(-1, 3, 3)
        return a, b, z, s


def _cost(p: FloatArray, a: np.ndarray, b: np.ndarray, z: FloatArray, s: FloatArray) -> float:
    """The least-squares cost: the sum of the edges' squared whitened residuals."""
    white = np.einsum("mij,mj->mi", s, _errors(p, a, b, z))
    return float((white * white).sum())


def _errors(p: FloatArray, a: np.ndarray, b: np.ndarray, z: FloatArray) -> FloatArray:
    dx = p[b, 0] - p[a, 0]
    dy = p[b, 1] - p[a, 1]
    c, s = np.cos(p[a, 2]), np.sin(p[a, 2])
    ex = c * dx + s * dy - z[:, 0]
    ey = -s * dx + c * dy - z[:, 1]
    et = wrap_angles(p[b, 2] - p[a, 2] - z[:, 2])
    return np.stack([ex, ey, et], axis=1)


def _jacobian(p: FloatArray, a: np.ndarray, b: np.ndarray, w: FloatArray, n: int) -> csr_matrix:
    """The whitened residuals' derivatives by the free poses (node 0 is fixed), sparse."""
    m = len(a)
    dx = p[b, 0] - p[a, 0]
    dy = p[b, 1] - p[a, 1]
    c, s = np.cos(p[a, 2]), np.sin(p[a, 2])
    # raw derivatives of (ex, ey, et) by node a's and node b's (x, y, yaw)
    ja = np.zeros((m, 3, 3))
    jb = np.zeros((m, 3, 3))
    ja[:, 0, 0], ja[:, 0, 1], ja[:, 0, 2] = -c, -s, -s * dx + c * dy
    ja[:, 1, 0], ja[:, 1, 1], ja[:, 1, 2] = s, -c, -c * dx - s * dy
    ja[:, 2, 2] = -1.0
    jb[:, 0, 0], jb[:, 0, 1] = c, s
    jb[:, 1, 0], jb[:, 1, 1] = -s, c
    jb[:, 2, 2] = 1.0
    wa = np.einsum("mij,mjk->mik", w, ja)
    wb = np.einsum("mij,mjk->mik", w, jb)
    rows = np.repeat(np.arange(m) * 3, 9).reshape(m, 3, 3) + np.arange(3)[None, :, None]
    rows_list: list[np.ndarray] = []
    cols_list: list[np.ndarray] = []
    vals_list: list[np.ndarray] = []
    for node, weighted in ((a, wa), (b, wb)):
        keep = node > 0
        cols = (node[:, None, None] - 1) * 3 + np.arange(3)[None, None, :]
        cols = np.broadcast_to(cols, (m, 3, 3))
        rows_list.append(rows[keep].ravel())
        cols_list.append(cols[keep].ravel())
        vals_list.append(weighted[keep].ravel())
    return csr_matrix(
        (np.concatenate(vals_list), (np.concatenate(rows_list), np.concatenate(cols_list))),
        shape=(3 * m, 3 * (n - 1)),
    )
