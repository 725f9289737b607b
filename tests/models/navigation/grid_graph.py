"""The planner's grid as an explicit graph, for checking A* and its bounds against scipy."""

import math

import numpy as np
from scipy.sparse import coo_matrix, csr_matrix

from models.navigation.costmap import INSCRIBED

MOVES = [(1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (1, -1), (-1, 1), (-1, -1)]
AGAINST_LANE = {1: (-1, 0), 2: (1, 0), 3: (0, -1), 4: (0, 1)}  # lane: the sign it refuses


def planner_graph(cost, weight, lanes=None, against=1.0, lethal=INSCRIBED) -> csr_matrix:
    """The planner's directed 8-connected graph (scipy CSR), edge costs in cells.

    No step enters a cell at or above ``lethal`` or cuts a corner of one; a step costs
    1 or sqrt(2) times ``1 + weight * cost / 252`` of the cell it enters, and ``against``
    times more when it runs against that cell's lane.
    """
    h, w = cost.shape
    src, dst, wt = [], [], []
    for y in range(h):
        for x in range(w):
            for dx, dy in MOVES:
                nx, ny = x + dx, y + dy
                if not (0 <= nx < w and 0 <= ny < h) or cost[ny, nx] >= lethal:
                    continue
                if dx and dy and (cost[y, nx] >= lethal or cost[ny, x] >= lethal):
                    continue
                step = math.sqrt(2.0) if dx and dy else 1.0
                step *= 1.0 + weight * cost[ny, nx] / 252.0
                if lanes is not None and lanes[ny, nx] in AGAINST_LANE:
                    sx, sy = AGAINST_LANE[int(lanes[ny, nx])]
                    if (sx and np.sign(dx) == sx) or (sy and np.sign(dy) == sy):
                        step *= against
                src.append(y * w + x)
                dst.append(ny * w + nx)
                wt.append(step)
    return coo_matrix((wt, (src, dst)), shape=(h * w, h * w)).tocsr()
