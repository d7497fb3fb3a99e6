"""The implicit MPM in parallel: a coarse Brazilian disc over 10 steps gives the same platen
forces, half-widths, material-point state and level sets on 2 ranks as on 1 (each rank also runs
it on COMM_SELF), to 1e-8 relative. Points and level sets are replicated on every rank; the
contact zones are kept on rank 0 by the scene's contact boxes. Grain assemblies: each contact
pair is computed on its own rank (the cells of its box owned elsewhere are ghost cells there),
also in a dense packing whose boxes chain across the whole assembly."""

import numpy as np
import pytest
from mpi4py import MPI
from test_mpm import disc_sim

from dolfinx_forms.solvers.newton import NewtonOptions


def run(comm, steps=10):
    # Newton to round-off: the penalty turns a 1e-10 residual into ~1e-8 force differences
    sim = disc_sim(comm, steps=steps, newton=NewtonOptions(rtol=1e-13))
    recs = [sim.step() for _ in range(steps)]
    return sim, recs


@pytest.mark.mpi
def test_brazilian_disc_two_ranks_match_one():
    assert MPI.COMM_WORLD.size == 2, "run under mpirun -n 2"
    par, rp = run(MPI.COMM_WORLD)
    ser, rs = run(MPI.COMM_SELF)
    for a, b in zip(rp, rs):
        for ob in ("platen_top", "platen_bottom"):
            assert a["obstacles"][ob]["fy"] == pytest.approx(b["obstacles"][ob]["fy"], rel=1e-8)
        wa = sorted(p["half_width"] for p in a["pairs"])
        wb = sorted(p["half_width"] for p in b["pairs"])
        assert np.allclose(wa, wb, rtol=1e-8, atol=0)
        assert a["newton_iterations"] == b["newton_iterations"]
        assert a["num_dofs"] == b["num_dofs"]
    # the points are gathered in rank order on 2 ranks: compare as sets (sorted by position)
    p, s = par.points[1], ser.points[1]
    op = np.lexsort(np.round(p.x.T / 1e-9))
    os_ = np.lexsort(np.round(s.x.T / 1e-9))
    assert np.allclose(p.x[op], s.x[os_], rtol=0, atol=1e-10)
    scale = np.max(np.abs(s.stress))
    assert np.max(np.abs(p.stress[op] - s.stress[os_])) <= 1e-8 * scale
    diff = np.abs(par.levelsets[1].values - ser.levelsets[1].values)
    assert np.max(diff) <= 1e-8 * par.h


def assembly(comm, steps=2, mu=np.tan(np.radians(15)), n=9):
    from test_mpm import quiet

    from dolfinx_forms.mpm.implicit import ImplicitMPM, MPMBody
    from meshes.assembly import grain_assembly

    grid, bodies, plates, build, _, _ = grain_assembly(comm, n, h=0.5, aspect=1.1, overlap=0.01)
    for name, v in (
        ("plate_left", (0.01, 0)),
        ("plate_right", (-0.01, 0)),
        ("plate_bottom", (0, 0.01)),
        ("plate_top", (0, -0.01)),
    ):
        plates[name].translation = np.array(v)
    sim = ImplicitMPM(
        comm,
        grid,
        [MPMBody(n, t, (100e3, 0.2), s) for n, t, s in bodies],
        build,
        obstacles=list(plates.values()),
        mu=mu,
        predictor_gap=0.25,
        newton=NewtonOptions(rtol=1e-13),
        **quiet,
    )
    return sim, [sim.step() for _ in range(steps)]


def assert_same_steps(rp, rs):
    """Step records of 2 ranks and of 1 agree: Newton iterations, plate forces and every pair's
    normal and tangential force to 1e-8, the pairs in the same order."""
    for a, b in zip(rp, rs):
        assert a["newton_iterations"] == b["newton_iterations"]
        for ob in a["obstacles"]:
            for c in ("fx", "fy"):
                assert a["obstacles"][ob][c] == pytest.approx(
                    b["obstacles"][ob][c], rel=1e-8, abs=1e-8
                )
        assert [(p["body_i"], p["body_j"]) for p in a["pairs"]] == [
            (p["body_i"], p["body_j"]) for p in b["pairs"]
        ]
        scale = max(p["normal_force"] for p in b["pairs"])
        for c in ("normal_force", "tangential_force"):
            diff = max(abs(p[c] - q[c]) for p, q in zip(a["pairs"], b["pairs"]))
            assert diff <= 1e-8 * scale, (c, diff, scale)


@pytest.mark.mpi
def test_assembly_contact_by_pair_on_two_ranks_matches_one():
    """Nine grains in rigid plates, mu = tan 15 deg: on 2 ranks each pair's contact is computed
    on its own rank (both ranks hold pairs); plate forces, pair forces and Newton iterations
    agree with one rank to 1e-8 over two steps. (Newton's cycling test once compared each
    rank's own active set: a rank whose part repeated cut the step back.)"""
    par, rp = assembly(MPI.COMM_WORLD)
    ser, rs = assembly(MPI.COMM_SELF)
    held = MPI.COMM_WORLD.allgather(len(par.problem.contact.pairs))
    assert min(held) > 0, held
    assert_same_steps(rp, rs)


@pytest.mark.mpi
def test_dense_assembly_pairs_split_evenly_over_two_ranks():
    """25 grains on a hexagonal lattice, every neighbour touching: the pairs' contact boxes
    chain across the whole packing, yet each rank computes half of the pairs (contiguous groups
    along the longest axis; the cells of a pair's box owned by the other rank are ghost cells
    here). Pair forces and plate forces (1e-8) and the displacements carried by the material
    points (1e-8 of the largest) agree with one rank over two steps."""
    comm = MPI.COMM_WORLD
    par, rp = assembly(comm, n=25)
    ser, rs = assembly(MPI.COMM_SELF, n=25)
    held = comm.allgather(len(par.problem.contact.pairs))
    total = len(ser.problem.contact.pairs)
    assert sum(held) == total
    assert max(held) - min(held) <= 1, held
    imap = par.scene.mesh.topology.index_map(2)
    # box cells reach the other rank as ghosts: contact rows of ghost dofs are assembled there
    pb = par.problem
    nloc = pb.V.dofmap.index_map.size_local
    blocks = [d for g in pb.contact.pairs for d in g.quadrature.coupling_dofs()]
    on_ghosts = int(np.sum(np.concatenate(blocks) >= nloc)) if blocks else 0
    assert comm.allreduce(imap.num_ghosts) > 0
    assert comm.allreduce(on_ghosts) > 0
    assert_same_steps(rp, rs)
    # the last step's displacement increment of every body on the grid nodes (the FE solution
    # extended off the body), and the points it moved
    du = max(np.max(np.abs(ser.grid_increment(n))) for n in ser.grid_increments)
    assert du > 0
    for name in ser.grid_increments:
        diff = par.grid_increment(name) - ser.grid_increment(name)
        assert np.max(np.abs(diff)) <= 1e-8 * du, name
    assert par.windows == ser.windows
    for tag in par.points:
        p, s = par.points[tag], ser.points[tag]
        op = np.lexsort(np.round(p.x.T / 1e-9))
        os_ = np.lexsort(np.round(s.x.T / 1e-9))
        assert np.max(np.abs(p.x[op] - s.x[os_])) <= 1e-8 * du
        scale = np.max(np.abs(s.stress))
        assert np.max(np.abs(p.stress[op] - s.stress[os_])) <= 1e-8 * scale


@pytest.mark.mpi
def test_finite_strain_j2_block_two_ranks_match_one():
    """The finite-strain path (F and J2's history at the points, projected per rank to the
    rank's cells; the point law on each rank's own helper mesh): platen forces and the points'
    F and plastic strain on 2 ranks equal to 1 rank's, 1e-8."""
    from dolfinx_forms.fem.boundary import Dirichlet
    from dolfinx_forms.fem.plasticity import J2Plasticity
    from dolfinx_forms.mpm.implicit import ImplicitMPM, MPMBody
    from meshes.mpm import block_between_platens

    out = []
    for comm in (MPI.COMM_WORLD, MPI.COMM_SELF):
        grid, (name, tag, shape), platens, build = block_between_platens(
            comm, 2.0, 2.0, 0.1, 0.1, 4
        )
        body = MPMBody(name, tag, J2Plasticity(1000.0, 0.3, 50.0, 100.0), shape)
        sym = Dirichlet(lambda x: np.isclose(x[0], 0.0), 0, 0.0)
        sim = ImplicitMPM(
            comm,
            grid,
            [body],
            build,
            obstacles=platens,
            dirichlet=[sym],
            mu=0.0,
            eps0=0.1,
            newton=NewtonOptions(rtol=1e-13),
            log=lambda *a, **k: None,
        )
        forces = [sim.step()["obstacles"]["platen_top"]["fy"] for _ in range(4)]
        p = sim.points[1]
        o = np.lexsort(np.round(p.x.T / 1e-9))
        out.append((forces, p.F[o], p.history[o, 4]))
    (fp, Fp, ap), (fs, Fs, as_) = out
    assert np.allclose(fp, fs, rtol=1e-8, atol=0) and max(as_) > 0
    assert np.allclose(Fp, Fs, rtol=0, atol=1e-8) and np.allclose(ap, as_, rtol=0, atol=1e-10)


@pytest.mark.mpi
def test_augmented_neo_hookean_block_two_ranks_match_one():
    """The augmented Lagrangian on a nonlinear bulk (its later solves keep their first
    tangent, NewtonOptions.al_frozen): platen forces and the points' F on 2 ranks equal to 1
    rank's within the loop's own tolerance (al_rtol = 1e-7 of the largest traction: 1e-6 here;
    measured 3e-16 on the demo's block)."""
    from dolfinx_forms.fem.boundary import Dirichlet
    from dolfinx_forms.fem.laws import NeoHookean
    from dolfinx_forms.mpm.implicit import ImplicitMPM, MPMBody
    from meshes.mpm import block_between_platens

    out = []
    for comm in (MPI.COMM_WORLD, MPI.COMM_SELF):
        grid, (name, tag, shape), platens, build = block_between_platens(
            comm, 2.0, 2.0, 0.1, 0.1, 4
        )
        body = MPMBody(name, tag, NeoHookean(1000.0, 0.3), shape)
        sym = Dirichlet(lambda x: np.isclose(x[0], 0.0), 0, 0.0)
        sim = ImplicitMPM(comm, grid, [body], build, obstacles=platens, dirichlet=[sym], mu=0.0,
                          enforcement="augmented", log=lambda *a, **k: None)  # fmt: skip
        recs = [sim.step() for _ in range(3)]
        p = sim.points[1]
        o = np.lexsort(np.round(p.x.T / 1e-9))
        out.append(([r["obstacles"]["platen_top"]["fy"] for r in recs], p.F[o]))
        assert sum(r["factorisations"] for r in recs) < sum(r["newton_iterations"] for r in recs)
    (fp, Fp), (fs, Fs) = out
    assert fs[-1] > 0 and np.allclose(fp, fs, rtol=1e-6, atol=0)
    assert np.allclose(Fp, Fs, rtol=0, atol=1e-6)


@pytest.mark.mpi
def test_dynamics_rolling_cylinder_two_ranks_match_one():
    """Newmark on the material-point path (mpm/dynamics.py: v, a and the density projected by
    rank, the points replicated): a neo-Hookean cylinder rolling on a floor for 5 steps, the
    points' positions and velocities on 2 ranks equal to 1 rank's, 1e-8."""
    from dolfinx_forms.fem.laws import NeoHookean
    from dolfinx_forms.mpm.dynamics import PointNewmark
    from dolfinx_forms.mpm.implicit import ImplicitMPM, MPMBody
    from meshes.mpm import cylinder_on_floor

    out = []
    for comm in (MPI.COMM_WORLD, MPI.COMM_SELF):
        grid, (name, tag, shape), floor, build = cylinder_on_floor(comm, 1.0, 0.2, 0.5)
        dyn = PointNewmark({tag: 1.0}, 0.1, gravity=(0.5, -0.866))
        sim = ImplicitMPM(comm, grid, [MPMBody(name, tag, NeoHookean(1e4, 0.3), shape)], build,
                          obstacles=[floor], dynamics=dyn, mu=0.5,
                          newton=NewtonOptions(rtol=1e-13), log=lambda *a, **k: None)  # fmt: skip
        for _ in range(5):
            sim.step()
        p = sim.points[tag]
        o = np.lexsort(np.round(p.x.T / 1e-6))
        out.append((p.x[o], p.v[o]))
    (xp, vp), (xs, vs) = out
    assert np.abs(vs).max() > 0.1
    assert np.allclose(xp, xs, rtol=0, atol=1e-8) and np.allclose(vp, vs, rtol=0, atol=1e-8)
