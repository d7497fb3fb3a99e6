"""The last quasi-static step's displacement increment as the next step's Newton predictor.

Each MPM step solves for its own increment du from du = 0 on a new cut mesh. Under a steady
load path (platens moved by equal steps) the increments of consecutive steps nearly agree, so
the last one, per unit of step, is the natural first iterate: 100 grains, 30 compression steps
(`demos/grain_assembly.py`): 3.7 Newton iterations (sparse factorisations) a step instead of
6.8, the same plate forces to 1e-12; the coarse Brazilian disc 2 instead of 4.

The meshes of two steps differ, but their nodes are nodes of the one background grid, each
owned by one body: a node is keyed by (body tag, grid node), and a node the last step did not
have starts from 0. Newton takes the predicted u only where it lowers the first residual
(`newton.newton`): where the load path turns (the first step after contact closes,
compression turning to shear) it starts from du = 0 as before. The law points the prediction
closes join the contact tangent's sparsity up front (`ContactProblem._coupling_points`), or
the first iteration would grow it and build the matrices again.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Increment:
    """A converged step's increment per unit of step, on every rank: rate[k] (2,) at the
    node of key keys[k] (sorted)."""

    keys: np.ndarray  # int64 (n,), sorted
    rate: np.ndarray  # (n, 2)


def node_keys(problem, grid):
    """An int64 key per local node (owned and ghost) of problem.V: its body's tag and its
    grid node (i, j); grid: (origin (x0, y0), spacing h, (nx, ny) grid lines)."""
    (origin, h, shape), V, ct = grid, problem.V, problem.scene.cell_tags
    ij = np.rint((V.tabulate_dof_coordinates()[:, :2] - np.asarray(origin)) / h).astype(np.int64)
    tags = np.zeros(len(ij), np.int64)
    cells = V.dofmap.list.array.reshape(len(ct.values), -1)
    tags[cells[ct.indices].ravel()] = np.repeat(ct.values.astype(np.int64), cells.shape[1])
    return (tags * shape[0] + ij[:, 0]) * shape[1] + ij[:, 1]


def record(problem, grid, fraction):
    """The Increment of problem's converged u, a step of `fraction` of the whole: gathered
    from the owned nodes of every rank."""
    n, comm = problem.n_owned // problem.bs, problem.comm
    keys = np.concatenate(comm.allgather(node_keys(problem, grid)[:n]))
    u = np.concatenate(comm.allgather(problem.u.x.array[: problem.n_owned].reshape(-1, 2)))
    order = np.argsort(keys, kind="stable")
    return Increment(keys[order], u[order] / fraction)


def predictor(increment, grid):
    """`ContactProblem`'s predictor: for a problem, guess(problem, lam), u += rate (lam -
    committed lam) at the nodes the increment knows (a node new to this step's mesh stays)."""

    def make(problem):
        keys = node_keys(problem, grid)
        pos = np.minimum(np.searchsorted(increment.keys, keys), len(increment.keys) - 1)
        known = np.flatnonzero(increment.keys[pos] == keys)
        rate = increment.rate[pos[known]]

        def guess(problem, lam):
            u = problem.u.x.array.reshape(-1, 2)
            u[known] += (lam - problem.lam) * rate
            problem.u.x.scatter_forward()

        return guess

    return make
