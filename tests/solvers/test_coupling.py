"""The contact tangent's sparsity (`SolverOptions.coupling_gap`): with `Factorised`, J holds
the tangent blocks of the law points near contact only, not of every law point of the band.
A point outside it that closes drops its block (J ignores new nonzeros); the problem finds it
(`law_coupled`), grows the sparsity and evaluates again. So the iterates are those of the full
sparsity: the same linear systems, solved by the same direct solver in another ordering
(round-off apart), on the frictional Hertz path of test_linear (normal force, then tangential).
"""

import numpy as np
import pytest
from mpi4py import MPI

from tests.solvers.test_linear import mindlin, scene


def run(kind, gap):
    return mindlin(scene(kind), "factorised", coupling_gap=gap)


@pytest.mark.parametrize("kind", ["conforming", "cut"])
def test_grown_sparsity_gives_the_full_sparsity_answer(kind):
    full, grown = run(kind, None), run(kind, 0.0)
    assert full.coupled is None and full.coupling_rebuilds == 0
    # with coupling_gap 0 the sparsity starts with the overlapping points alone: the contact
    # zone's growth under the normal force must add the rest
    assert grown.coupling_rebuilds >= 1
    comm = grown.comm  # the pairs live on the rank that holds Gamma_c
    in_sparsity = comm.allreduce(sum(int(c.sum()) for c in grown.coupled), op=MPI.SUM)
    law_points = comm.allreduce(sum(g.num_law_points for g in grown.pairs), op=MPI.SUM)
    assert 0 < in_sparsity < law_points
    nnz = [p.comm.allreduce(p.J.getInfo()["nz_used"], op=MPI.SUM) for p in (full, grown)]
    assert nnz[1] < nnz[0]
    # the same Newton path: iterations, the displacement to round-off, the forces reached
    assert [s.iterations for s in grown.steps] == [s.iterations for s in full.steps]
    uf = np.concatenate(full.comm.allgather(full.u.x.array[: full.n_owned]))
    ug = np.concatenate(grown.comm.allgather(grown.u.x.array[: grown.n_owned]))
    assert np.abs(ug - uf).max() <= 1e-9 * np.abs(uf).max()
    assert grown.reached == pytest.approx(full.reached, rel=1e-9)
    # every law point that closed is in the sparsity
    for s, c in zip(grown.contact.last, grown.coupled):
        assert c[np.flatnonzero(s["law_coupled"])].all()
    for p in (full, grown):
        p.destroy()


def test_growth_past_the_bound_takes_the_whole_band(monkeypatch):
    """Past MAX_STEP_GROWTHS growths before a step is accepted the sparsity takes every law
    point of the band (a failing step's iterates would grow it again and again): with the
    bound at 0 the first growth does, and the answer is still the full sparsity's."""
    from dolfinx_forms.solvers import problem

    full = run("conforming", None)
    monkeypatch.setattr(problem, "MAX_STEP_GROWTHS", 0)
    bounded = run("conforming", 0.0)
    assert bounded.coupled is None and bounded.coupling_rebuilds >= 1
    nnz = [p.comm.allreduce(p.J.getInfo()["nz_used"], op=MPI.SUM) for p in (full, bounded)]
    assert nnz[1] == nnz[0]
    uf = np.concatenate(full.comm.allgather(full.u.x.array[: full.n_owned]))
    ub = np.concatenate(bounded.comm.allgather(bounded.u.x.array[: bounded.n_owned]))
    assert np.abs(ub - uf).max() <= 1e-9 * np.abs(uf).max()
    assert bounded.reached == pytest.approx(full.reached, rel=1e-9)
    for p in (full, bounded):
        p.destroy()


def test_coupling_gap_is_checked():
    with pytest.raises(ValueError, match="coupling_gap"):
        run("conforming", -1.0)


@pytest.mark.mpi
def test_grown_sparsity_on_two_ranks():
    test_grown_sparsity_gives_the_full_sparsity_answer("conforming")
