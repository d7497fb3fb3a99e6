"""The implicit MPM step loop (dolfinx_forms.mpm.implicit): rigid motion, a block between rigid
platens, the Brazilian disc on a coarse grid, and rejected steps."""

import gc
import weakref

import numpy as np
import pytest
from mpi4py import MPI

import dolfinx_forms as df
from dolfinx_forms.fem.boundary import Dirichlet
from dolfinx_forms.fem.laws import NeoHookean
from dolfinx_forms.geometry.obstacles import RigidObstacle
from dolfinx_forms.mesh.cut_scene import half_plane
from dolfinx_forms.mpm.implicit import ImplicitMPM, MPMBody
from dolfinx_forms.solvers import linear
from dolfinx_forms.solvers.newton import ContactSolverError, NewtonOptions
from meshes.mpm import brazilian_disc, grid_scene, uniform_lines

COMM = MPI.COMM_SELF
quiet = dict(log=lambda *a, **k: None)


def disc_sim(comm=COMM, steps=10, h=0.5, mu=0.5, law=(100e3, 0.3), **kw):
    grid, (name, tag, shape), platens, build = brazilian_disc(comm, 10.0, h, 0.02, steps)
    sym = Dirichlet(lambda x: np.isclose(x[0], 0.0), 0, 0.0)
    body = MPMBody(name, tag, law, shape)
    return ImplicitMPM(
        comm, grid, [body], build, obstacles=platens, dirichlet=[sym], mu=mu, **quiet, **kw
    )


def test_rigid_translation_keeps_zero_stress_and_moves_points_exactly():
    """Every dof moved by d per step: grad du = 0, so the stress stays 0 and the points move by
    exactly d; the level set is advected by the constant extension of d."""
    h, E = 0.1, 1000.0
    lines = uniform_lines(-1.6, 1.6, h)
    d = np.array([0.013, -0.007])
    everywhere = lambda x: np.ones(x.shape[1], bool)  # noqa: E731
    bcs = [Dirichlet(everywhere, c, float(d[c])) for c in range(2)]
    body = MPMBody("disc", 1, (E, 0.3), df.Circle((0.0, 0.0), 0.77))
    sim = ImplicitMPM(
        COMM,
        (lines, lines),
        [body],
        grid_scene(COMM, lines, lines, [("disc", 1)]),
        dirichlet=bcs,
        **quiet,
    )
    rec = sim.step()
    pts = sim.points[1]
    x0 = pts.x - d
    area0 = rec["area_levelset"]["disc"]
    for _ in range(19):
        rec = sim.step()
    assert np.max(np.abs(pts.stress)) <= 1e-10 * E * np.linalg.norm(d) / h
    assert np.max(np.abs(pts.x - x0 - 20 * d)) <= 1e-12
    assert np.max(np.abs(pts.vol / pts.vol0 - 1)) <= 1e-12
    # WENO5 advection of a smooth disc by 20 steps of 0.15 h: area kept to 1e-4
    assert abs(rec["area_levelset"]["disc"] / area0 - 1) < 1e-4
    # the zero contour moved with the points (the cone tip at the centre is smoothed: not checked)
    t = np.linspace(0, 2 * np.pi, 50)
    ring = 20 * d + 0.77 * np.stack([np.cos(t), np.sin(t)], axis=1)
    assert np.max(np.abs(sim.levelsets[1].evaluate(ring)[0])) < 1e-3 * h


def test_levelset_windows_follow_a_translated_disc():
    """A small disc in a large grid: its level set lives on a window of the grid holding the
    disc with an outside border (not the grid); translated by 3 h per step the window grows
    along its path, keeps the old values where it overlaps and the initial shape's values on
    its new nodes, and the whole-grid view (levelset_values, grid_increment) agrees with it."""
    h, E, r = 0.1, 1000.0, 0.3
    lines = uniform_lines(-6.0, 6.0, h)
    d = np.array([0.3, 0.0])
    everywhere = lambda x: np.ones(x.shape[1], bool)  # noqa: E731
    bcs = [Dirichlet(everywhere, c, float(d[c])) for c in range(2)]
    shape = df.Circle((-1.5, 0.0), r)
    body = MPMBody("disc", 1, (E, 0.3), shape)
    sim = ImplicitMPM(
        COMM,
        (lines, lines),
        [body],
        grid_scene(COMM, lines, lines, [("disc", 1)]),
        dirichlet=bcs,
        **quiet,
    )
    w0 = sim.windows[1]
    v0 = sim.levelsets[1].values
    assert v0.size < 0.1 * len(lines) ** 2  # a window, not the grid
    assert min(v0[0].min(), v0[-1].min(), v0[:, 0].min(), v0[:, -1].min()) > 0
    grid = sim.subgrid(w0)
    assert np.array_equal(v0.ravel(), shape(grid.nodes()))  # sampled, as on the whole grid
    for _ in range(3):
        sim.step()
    i0, i1, j0, j1 = sim.windows[1]
    # grew along the motion (the last step: 6 cells past the disc moved by 6 cells plus the 3
    # of its step), by the evolution's margin across it (and a row more on either side: the
    # contour passes through grid nodes, where phi = +-1e-17 decides whether a cell is active)
    assert i0 <= w0[0] and i1 >= w0[1] + 6 and j0 <= w0[2] and j1 >= w0[3]
    assert (j1 - j0) - (w0[3] - w0[2]) <= 6
    full = sim.levelset_values(1)
    assert np.array_equal(full[j0 : j1 + 1, i0 : i1 + 1], sim.levelsets[1].values)
    assert np.all(full[:, i1 + 1 :] > 0)
    # the disc moved by 3 d: the contour follows it (the reference map: 0.007 h; advected,
    # 0.03 h)
    t = np.linspace(0, 2 * np.pi, 40)
    ring = np.array([-1.5, 0.0]) + 3 * d + r * np.stack([np.cos(t), np.sin(t)], axis=1)
    assert np.max(np.abs(sim.levelsets[1].evaluate(ring)[0])) < 0.05 * h
    du = sim.grid_increment("disc").reshape(len(lines), len(lines), 2)
    assert np.allclose(du[j0 : j1 + 1][np.abs(du[j0 : j1 + 1, :, 0]) > 0], d)


def test_block_between_frictionless_platens_gives_the_uniaxial_force():
    """A block squeezed by rigid frictionless platens over 10 steps: plane-strain uniaxial
    stress, F = W E' d / (H + 2 E' eps_n) with E' = E / (1 - nu^2) (the penalty compliance of
    both contacts in series), within 1 %. The block spans the grid's width (its sides are the
    grid's edges, traction free): a square's corners would enter Gamma_c, where the C1
    interpolant of a cornered distance bulges by ~0.1 h (see docs/demos/brazilian_disc.md)."""
    h, E, nu, L, step = 0.1, 1000.0, 0.3, 1.03, 0.0005
    xl, yl = uniform_lines(-1.0, 1.0, h), uniform_lines(-L - 0.3, L + 0.3, h)
    W = xl[-1] - xl[0]
    top = RigidObstacle(
        "top", half_plane((0, L), (0, -1), 100), bbox=[[-2, L], [2, 2]], translation=(0, -step)
    )
    bottom = RigidObstacle("bottom", half_plane((0, -L), (0, 1), 100), bbox=[[-2, -2], [2, -L]])
    body = MPMBody("block", 1, (E, nu), df.Box((-10.0, -L), (10.0, L)))
    sym = Dirichlet(lambda x: np.isclose(x[0], 0.0), 0, 0.0)
    sim = ImplicitMPM(
        COMM,
        (xl, yl),
        [body],
        grid_scene(COMM, xl, yl, [("block", 1)]),
        obstacles=[top, bottom],
        dirichlet=[sym],
        **quiet,
    )
    for _ in range(10):
        rec = sim.step()
    Ep = E / (1 - nu**2)
    eps_n = sim.problem.eps_n
    F = W * Ep * 10 * step / (2 * L + 2 * Ep * eps_n)
    assert rec["obstacles"]["top"]["fy"] == pytest.approx(F, rel=0.01)
    assert -rec["obstacles"]["bottom"]["fy"] == pytest.approx(F, rel=0.01)
    # uniform sigma_yy = -F / W, sigma_xx ~ 0 away from the grid's edges (where the last
    # contact segment is cut off by the grid: an end effect over ~2 h)
    pts = sim.points[1]
    s = pts.stress[np.abs(pts.x[:, 0]) < 0.6]
    # (2 %: points next to the cut boundary get the MLS fit's one-sided error)
    assert np.max(np.abs(s[:, 1] / (-F / W) - 1)) < 0.02
    assert np.median(np.abs(s[:, 0])) < 0.002 * F / W and np.max(np.abs(s[:, 0])) < 0.05 * F / W


def test_brazilian_disc_coarse():
    """h = 0.5: the free disc is in equilibrium (top and bottom forces equal to 1e-6), the
    points' mass is constant, the level-set area follows the points' volume, Newton converges
    in a few iterations every step, contact grows."""
    sim = disc_sim(steps=6)
    mass0, forces = None, []
    for _ in range(6):
        rec = sim.step()
        mass0 = mass0 or rec["mass"]["disc"]
        top, bot = rec["obstacles"]["platen_top"]["fy"], -rec["obstacles"]["platen_bottom"]["fy"]
        assert top > 0 and abs(top - bot) <= 1e-6 * top
        assert rec["mass"]["disc"] == mass0  # exactly: volumes at seeding never change
        assert abs(rec["area_levelset"]["disc"] / rec["volume_points"]["disc"] - 1) < 2e-3
        assert rec["newton_iterations"] <= 8 and rec["cutbacks"] == 0
        forces.append(top)
    assert np.all(np.diff(forces) > 0)
    widths = [p["half_width"] for p in rec["pairs"]]
    assert len(widths) == 2 and min(widths) > 0


def test_rejected_step_is_invisible():
    """A step that fails (Newton allowed no iteration, no cut-back) restores everything:
    the re-run step is bitwise identical to that of a run that never failed."""
    ref = disc_sim(steps=3)
    for _ in range(3):
        r_ref = ref.step()
    sim = disc_sim(steps=3)
    sim.step()
    sim.step()
    good = sim.problem_kw.get("newton")
    sim.problem_kw["newton"] = NewtonOptions(max_iterations=0, max_cutbacks=0)
    with pytest.raises(ContactSolverError):
        sim.step()
    sim.problem_kw["newton"] = good
    if good is None:
        del sim.problem_kw["newton"]
    r = sim.step()
    assert r["step"] == r_ref["step"] == 3
    for t in (1,):
        a, b = sim.points[t], ref.points[t]
        for f in ("x", "vol", "stress", "vol0"):
            assert np.array_equal(getattr(a, f), getattr(b, f)), f
        assert np.array_equal(sim.levelsets[t].values, ref.levelsets[t].values)
    for o, p in zip(sim.obstacles, ref.obstacles):
        assert np.array_equal(o.offset, p.offset) and o.angle == p.angle
    assert r["obstacles"] == r_ref["obstacles"]


@pytest.mark.parametrize("law", [(100e3, 0.3), NeoHookean(100e3, 0.3)], ids=["linear", "nh"])
def test_a_step_replaces_the_point_arrays_and_never_writes_into_them(law):
    """The snapshot of a step shares the points' arrays (`MaterialPoints.shared`, no copy):
    the step (small-strain or finite-strain update) must replace them, not write into them,
    so the snapshot still holds the state before the step, and restoring it gives that
    state back bitwise."""
    fields = ("x", "vol0", "vol", "stress", "F", "history", "v", "a", "X")
    sim = disc_sim(steps=3, law=law)
    sim.step()
    snap = sim.snapshot()
    before = {f: getattr(snap["points"][1], f).copy() for f in fields}
    sim.step()
    for f in fields:
        assert np.array_equal(getattr(snap["points"][1], f), before[f]), f
    assert not np.array_equal(sim.points[1].x, before["x"])  # the step did move them
    sim.restore(snap)
    for f in fields:
        assert np.array_equal(getattr(sim.points[1], f), before[f]), f


def test_each_step_frees_the_problem_it_replaces(monkeypatch):
    """petsc4py frees no PETSc object when garbage-collected (each step would keep its
    matrices and factorisation): a step destroys the problem it replaces, a failed step the
    problem it made, and the current problem stays whole but for its factorisation, freed
    once its step converged (the next step makes its own). The next step frees it before it
    builds its own, and a failed step falls back to no problem and no mesh (the step after
    it builds them again, and converges)."""
    from dolfinx_forms.solvers.problem import ContactProblem

    sim = disc_sim(steps=3)
    sim.step()
    old = sim.problem
    handles = [old.K, old.J, old.R, old.f]
    assert all(h.handle != 0 for h in handles)
    if isinstance(old.linear, linear.Condensed):
        assert old.linear.F is None  # released
    else:
        with pytest.raises(Exception):
            old.linear.ksp.getPC().getFactorMatrix()
    sim.step()
    assert sim.problem is not old and all(h.handle == 0 for h in handles)
    cur = sim.problem
    destroyed, destroy = [], ContactProblem.destroy
    monkeypatch.setattr(ContactProblem, "destroy", lambda p: (destroyed.append(p), destroy(p)))
    sim.problem_kw["newton"] = NewtonOptions(max_iterations=0, max_cutbacks=0)
    with pytest.raises(ContactSolverError):
        sim.step()
    # the last problem, then the whole step and its halves down to 2^-max_splits: one problem
    # each, all freed
    assert destroyed[0] is cur and len(destroyed) == sim.max_splits + 2
    assert all(p.K is None for p in destroyed)
    assert sim.problem is None and sim.scene is None
    sim.problem_kw["newton"] = NewtonOptions()
    assert sim.step()["step"] == 3 and sim.problem.K.handle != 0


def test_a_step_collects_the_problem_it_replaces():
    """A step's problem holds reference cycles (with its solver, pairs, scene): the step that
    replaces it collects them, so their memory is free before the next step allocates, not
    whenever Python's collector next runs (100 grains: peak memory 1.10 -> 0.66 GB)."""
    sim = disc_sim(steps=3)
    sim.step()
    old = weakref.ref(sim.problem)
    enabled = gc.isenabled()
    gc.disable()  # only the step's own collection
    try:
        sim.step()
        assert old() is None
    finally:
        if enabled:
            gc.enable()


def test_obstacle_motion_and_pose():
    """The pose maps the frame shape; a step's displacement is a rigid motion about the
    current centre; advance() moves the pose by it."""
    ob = RigidObstacle(
        "bar",
        df.Box((-1.0, -0.1), (1.0, 0.1)),
        bbox=[[-1, -0.1], [1, 0.1]],
        translation=(0.2, -0.1),
        rotation=0.3,
    )
    x = np.array([[1.0, 0.1], [-0.5, 0.0]])
    u = ob.step_displacement(x)
    ob.advance()
    assert np.allclose(ob.values(x + u), ob.shape(np.ascontiguousarray(x)), atol=1e-14)
    assert np.allclose(ob.current_center, [0.2, -0.1])
    with pytest.raises(ValueError, match="bbox"):
        RigidObstacle("bad", df.Circle((0, 0), 1.0))


def test_grid_levelset_obstacle_matches_its_polygon():
    """An obstacle given as a grid level set (from a polyline) and the same polygon as an exact
    shape, both rotated and translated: same signed distance near the boundary (to the grid
    level set's O(h^2)), and the same closest points (eq 25 on the grid) to O(h^2)."""
    verts = np.array([[-1.0, -0.2], [1.0, -0.2], [1.0, 0.2], [-1.0, 0.2]])
    grid = df.StructuredGrid.uniform([-1.5, -0.7], [1.5, 0.7], [300, 140])  # h = 0.01
    pose = dict(center=(0.0, 0.0), translation=(0.3, -0.1), rotation=0.4)
    exact = RigidObstacle("p", df.Polygon(verts), bbox=[[-1, -0.2], [1, 0.2]], **pose)
    onGrid = RigidObstacle("g", df.levelset_from_polyline(grid, verts, 3), **pose)
    for ob in (exact, onGrid):
        ob.advance()
    rng = np.random.default_rng(1)
    t = rng.uniform(-0.8, 0.8, 40)
    x = exact.push_forward(np.stack([t, np.full_like(t, 0.2 + rng.uniform(-0.03, 0.03, 40))], 1))
    assert np.max(np.abs(exact.values(x) - onGrid.values(x))) < 1e-4
    pair_grid = df.StructuredGrid.uniform([-2.0, -2.0], [2.0, 2.0], [400, 400])
    a = exact.closest_points(x, 0.01, exact.levelset(pair_grid))["points"]
    b = onGrid.closest_points(x, 0.01, onGrid.levelset(pair_grid))["points"]
    assert np.max(np.linalg.norm(a - b, axis=1)) < 1e-3


def test_disc_column_carries_the_load_through_every_contact(tmp_path, monkeypatch):
    """Three discs stacked between rigid platens, frictionless, found by the broad phase: every
    contact carries the same force (1e-6 relative; vertical resultants of the contact
    tractions) and every disc is in equilibrium (its contact resultant below 1e-8 of the
    force). Its output fields: the combined level set and the many-body point series."""
    from meshes.mpm import disc_column

    grid, bodies, platens, build = disc_column(COMM, 3, 10.0, 0.5, 0.1, 3)
    sim = ImplicitMPM(
        COMM,
        grid,
        [MPMBody(n, t, (100e3, 0.3), s) for n, t, s in bodies],
        build,
        obstacles=platens,
        dirichlet=[Dirichlet(lambda x: np.isclose(x[0], 0.0), 0, 0.0)],
        eps0=0.3,
        **quiet,
    )
    for _ in range(3):
        rec = sim.step()
        keys = sorted((p["body_i"], p["body_j"]) for p in rec["pairs"])
        assert keys == [
            ("disc0", "disc1"),
            ("disc0", "platen_bottom"),
            ("disc1", "disc2"),
            ("disc2", "platen_top"),
        ]
        F = np.array([abs(p["fy"]) for p in rec["pairs"]])
        assert np.ptp(F) <= 1e-6 * F.max()
        for name, f in rec["body_forces"].items():  # contacts + the symmetry line's support
            s = rec["support_forces"][name]
            assert np.hypot(f[0] + s[0], f[1] + s[1]) <= 1e-8 * F.max(), name
    assert rec["obstacles"]["platen_top"]["fy"] == pytest.approx(F.max(), rel=1e-6)
    # the output's combined grid fields (`union_fields`, O(grid)) against the per-body
    # whole-grid fields (O(bodies x grid)): their minimum, its body and that body's increment
    phi, body, du = sim.union_fields()
    full = np.stack([sim.levelset_values(b.tag).ravel() for b in sim.bodies])
    assert np.array_equal(phi, full.min(axis=0))
    at = np.flatnonzero(body >= 0)
    assert np.array_equal(full[body[at], at], phi[at])
    assert np.array_equal(np.unique(body[at]), [0, 1, 2])
    assert np.all(phi[body < 0] >= 0.5)  # beyond every window: the far value (>= h)
    incs = np.stack([sim.grid_increment(b.name) for b in sim.bodies])
    assert np.array_equal(du[at], incs[body[at], at])
    assert not du[body < 0].any() and np.abs(du).max() > 0
    _many_bodies_series(sim, rec, tmp_path, monkeypatch)


def _many_bodies_series(sim, rec, folder, monkeypatch):
    """Beyond SERIES_PER_BODY_MAX bodies (here 2 of 3): one point series of all bodies with
    their index, and the level-set grid with the combined fields only, read back by meshio."""
    import meshio

    from dolfinx_forms.app import mpm_run

    monkeypatch.setattr(mpm_run, "SERIES_PER_BODY_MAX", 2)
    points, grid = {}, mpm_run.Series("levelsets")
    x0 = {t: p.x for t, p in sim.points.items()}
    mpm_run.add_frames(sim, points, grid, rec["step"], x0)
    assert list(points) == ["all"]
    for series in [*points.values(), grid]:
        series.write(folder)
    assert sorted(p.name for p in folder.glob("*.xdmf")) == [
        "levelsets.xdmf",
        "material_points.xdmf",
    ]
    with meshio.xdmf.TimeSeriesReader(folder / "material_points.xdmf") as r:
        r.read_points_cells()
        data = r.read_data(0)[1]
    sizes = [len(sim.points[b.tag]) for b in sim.bodies]
    assert np.array_equal(np.bincount(data["body"].astype(int)), sizes)
    vol = np.concatenate([sim.points[b.tag].vol for b in sim.bodies])
    assert np.array_equal(data["volume"], vol)
    with meshio.xdmf.TimeSeriesReader(folder / "levelsets.xdmf") as r:
        r.read_points_cells()
        data = r.read_data(0)[1]
    assert sorted(data) == ["body", "du", "phi"]
    assert np.array_equal(data["phi"], sim.union_fields()[0])


def assembly_sim(d=0.01, **kw):
    """15 elliptic grains (aspect 1.1) on a hexagonal lattice, overlapping, in four rigid plates
    moved inward by d a step, mu = tan 15 deg; kw: more ImplicitMPM options."""
    from meshes.assembly import grain_assembly

    grid, bodies, plates, build, _, _ = grain_assembly(COMM, 15, h=0.5, aspect=1.1, overlap=0.01)
    for name, v in (
        ("plate_left", (d, 0)),
        ("plate_right", (-d, 0)),
        ("plate_bottom", (0, d)),
        ("plate_top", (0, -d)),
    ):
        plates[name].translation = np.array(v)
    return ImplicitMPM(
        COMM,
        grid,
        [MPMBody(n, t, (100e3, 0.2), s) for n, t, s in bodies],
        build,
        obstacles=list(plates.values()),
        mu=np.tan(np.radians(15)),
        **quiet,
        **kw,
    )


def test_hexagonal_assembly_of_ellipses_in_rigid_plates():
    """15 elliptic grains (aspect 1.1) on a hexagonal lattice, overlapping, in four rigid plates
    moved inward, mu = tan 15 deg: two compression steps converge, every grain is in
    equilibrium (its contact resultant below 1e-8 of the largest contact force) and so is the
    set of plates."""
    sim = assembly_sim(predictor_gap=0.25)
    for _ in range(2):
        rec = sim.step()
    fmax = max(p["normal_force"] for p in rec["pairs"])
    for name, f in rec["body_forces"].items():
        assert np.hypot(f[0], f[1]) <= 1e-8 * fmax, name
    ob = rec["obstacles"]  # the plates' forces balance (friction on them included)
    assert np.hypot(*np.sum([[o["fx"], o["fy"]] for o in ob.values()], axis=0)) <= 1e-8 * fmax
    assert (
        ob["plate_top"]["fy"] > 0 and len([p for p in rec["pairs"] if p["normal_force"] > 0]) >= 30
    )


def test_touching_points_stay_outside_the_sparsity():
    """The predictor's closed tangent at touching open points (gap below predictor_gap, 0.5 h
    here) does not enter J's sparsity, which holds the points closer than coupling_gap
    (`SolverOptions`; J drops the predictor's other blocks): on the 15-grain assembly's first
    compression step, fewer points coupled than touching, and the forces those of the
    sparsity of every law point to 1e-9."""
    recs, sims = {}, {}
    for gap in (None, 0.01):
        sims[gap] = sim = assembly_sim(predictor_gap=0.25, coupling_gap=gap)
        recs[gap] = sim.step()
    p = sims[0.01].problem
    coupled = sum(int(c.sum()) for c in p.coupled)
    touching = sum(int((p.contact.law_gaps0(k) < 0.25).sum()) for k in range(len(p.pairs)))
    assert 0 < coupled < touching and sims[None].problem.coupled is None
    full, limited = recs[None], recs[0.01]
    fmax = max(q["normal_force"] for q in full["pairs"])
    assert len(limited["pairs"]) == len(full["pairs"])
    for a, b in zip(full["pairs"], limited["pairs"]):
        assert abs(a["normal_force"] - b["normal_force"]) <= 1e-9 * fmax
        assert abs(a["tangential_force"] - b["tangential_force"]) <= 1e-9 * fmax


@pytest.mark.parametrize("enforcement", ["penalty", "augmented"])
def test_pairs_made_in_threads_are_the_serial_ones(monkeypatch, enforcement):
    """`contact_set.build_pairs` makes the pair geometries of a rank in threads: on the
    15-grain assembly (every grain pair and plate-grain candidate, a step into the
    compression) the pairs, their order and every array are the serial loop's, bit for bit,
    with 1 and with 3 threads and the multiplier nodes of the augmented Lagrangian too."""
    from dolfinx_forms.contact import contact_set

    sim = assembly_sim(enforcement=enforcement)
    sim.step()
    p = sim.problem
    monkeypatch.setattr(contact_set, "PAIRS_PER_THREAD", 1)

    def made(threads):
        monkeypatch.setenv("ILS_THREADS", str(threads))
        cs = contact_set.ContactSet(p.V, p.scene, band=p.band, **p._rebuild["settings"])
        return cs.index, cs.pairs

    index, serial = made(1)
    assert len(serial) >= 30  # grain pairs and plates: enough for every thread
    keys = ["points", "weights", "normals", "p_i", "p_j", "g_n0", "mult_nodes", "mult_weights"]
    for threads in (2, 3):
        index_t, pairs = made(threads)
        assert index_t == index
        for a, b in zip(serial, pairs):
            assert a.pair == b.pair and (a.obstacle is b.obstacle)
            for key in keys:
                x, y = getattr(a, key), getattr(b, key)
                assert (x is None and y is None) or np.array_equal(x, y), key
    if enforcement == "augmented":
        assert any(g.mult_nodes is not None for g in serial)


def test_mesh_kept_when_active_cells_do_not_change():
    """The block between platens moves by 0.0005 h per step: its active cells and their kinds
    stay, so the second step keeps the first step's DOLFINx mesh; the answer equals that of a
    step on a rebuilt mesh."""
    h, L = 0.1, 1.03
    xl, yl = uniform_lines(-1.0, 1.0, h), uniform_lines(-L - 0.3, L + 0.3, h)

    def sim():
        top = RigidObstacle(
            "top", half_plane((0, L), (0, -1), 100), bbox=[[-2, L], [2, 2]], translation=(0, -5e-5)
        )
        bottom = RigidObstacle("bottom", half_plane((0, -L), (0, 1), 100), bbox=[[-2, -2], [2, -L]])
        return ImplicitMPM(
            COMM,
            (xl, yl),
            [MPMBody("block", 1, (1000.0, 0.3), df.Box((-10.0, -L), (10.0, L)))],
            grid_scene(COMM, xl, yl, [("block", 1)]),
            obstacles=[top, bottom],
            dirichlet=[Dirichlet(lambda x: np.isclose(x[0], 0.0), 0, 0.0)],
            **quiet,
        )

    a, b = sim(), sim()
    a.step(), b.step()
    mesh = a.scene.mesh
    ra = a.step()
    b._key = None  # force the rebuild
    rb = b.step()
    assert not ra["mesh_rebuilt"] and a.scene.mesh is mesh and rb["mesh_rebuilt"]
    assert ra["obstacles"]["top"]["fy"] == pytest.approx(rb["obstacles"]["top"]["fy"], rel=1e-12)
    assert np.allclose(a.points[1].stress, b.points[1].stress, rtol=0, atol=1e-12)


def _sheared_block(stick_predictor):
    """A block pressed between rigid platens (mu = 0.5, 3 steps), then one step that moves the
    top platen sideways by 3e-4: the block sticks (|tau_t| ~ 0.03 against mu p ~ 0.4)."""
    h, E, nu, L = 0.1, 1000.0, 0.3, 1.03
    xl, yl = uniform_lines(-1.0, 1.0, h), uniform_lines(-L - 0.3, L + 0.3, h)
    top = RigidObstacle(
        "top", half_plane((0, L), (0, -1), 100), bbox=[[-2, L], [2, 2]], translation=(0, -5e-4)
    )
    bottom = RigidObstacle("bottom", half_plane((0, -L), (0, 1), 100), bbox=[[-2, -2], [2, -L]])
    sim = ImplicitMPM(
        COMM,
        (xl, yl),
        [MPMBody("block", 1, (E, nu), df.Box((-10.0, -L), (10.0, L)))],
        grid_scene(COMM, xl, yl, [("block", 1)]),
        obstacles=[top, bottom],
        mu=0.5,
        newton=NewtonOptions(stick_predictor=stick_predictor),
        **quiet,
    )
    for _ in range(3):
        sim.step()
    top.translation = np.array([3e-4, 0.0])
    return sim.step()


def test_stick_predictor_shear_step():
    """The step's first iteration lets every closed point stick (the elastic predictor): the
    stuck block is solved in one Newton iteration. With the slip the platen's motion predicts
    (trial |tau_t| = 3e-4 / eps_t = 3 > mu p) Newton cycled stick/slip and cut the step back
    to sixteenths; both reach the same state."""
    fast, slow = _sheared_block(True), _sheared_block(False)
    assert fast["newton_iterations"] == 1 and fast["cutbacks"] == 0
    assert slow["cutbacks"] > 0
    assert all(p["stick_fraction"] == 1.0 for p in fast["pairs"])
    fx = fast["obstacles"]["top"]["fx"]
    assert fx < 0 and fx == pytest.approx(slow["obstacles"]["top"]["fx"], rel=1e-8)


@pytest.mark.parametrize("cell", ["quadrilateral", "hexahedron"])
def test_q1_evaluate_is_basix_q1(cell):
    """_cpp.q1_evaluate (the points' displacement and its gradient) against basix's Q1 element
    on axis-aligned cells of random extents, inside the cell and extrapolated outside: values
    and gradients of a random 2-component field to round-off."""
    import basix

    from dolfinx_forms import _cpp

    rng = np.random.default_rng(0)
    d = 2 if cell == "quadrilateral" else 3
    n, nv = 200, 2**d
    el = basix.create_element(basix.ElementFamily.P, getattr(basix.CellType, cell), 1)
    X = rng.uniform(-0.3, 1.3, (n, d))
    e = rng.uniform(0.1, 2.0, (n, d))
    u = rng.normal(size=(3 * nv, 2))
    dofs = np.stack([rng.permutation(3 * nv)[:nv] for _ in range(n)]).astype(np.int32)
    tab = el.tabulate(1, X)[:, :, :, 0]  # (1 + d, n, nv)
    ref_u = np.einsum("pv,pvc->pc", tab[0], u[dofs])
    ref_g = np.einsum("apv,pvc->pca", tab[1:], u[dofs]) / e[:, None, :]
    r = _cpp.q1_evaluate(u, dofs, X, e)
    assert np.abs(r["values"] - ref_u).max() < 1e-12
    assert np.abs(r["grad"] - ref_g).max() < 1e-11
    with pytest.raises(ValueError, match="dofs"):
        _cpp.q1_evaluate(u, dofs + 3 * nv, X, e)


def test_binned_mean_is_the_pixel_mean():
    """mpm_output.binned_mean (the force-chain plot's background): the mean of the values of
    the points in each pixel, blank (NaN) where none falls, rows along y."""
    from dolfinx_forms.app.mpm_run import binned_mean

    # 4 points in each of the pixels (0, 0), (1, 0), (0, 1) of a 2 x 2 image of side 1
    c = np.array([[0.25, 0.25], [0.75, 0.25], [0.25, 0.75], [0.75, 0.75]]) * 0.5
    pix = {(0, 0): 1.0, (1, 0): 2.0, (0, 1): 3.0}
    x = np.concatenate([c + 0.5 * np.array(ij) for ij in pix])
    v = np.concatenate([val + np.array([-1.0, 1.0, -2.0, 2.0]) for val in pix.values()])
    x = np.vstack([x, [[1.0, 1.0]]])  # the far corner, so the extent is the unit square
    v = np.append(v, 7.0)
    image, extent = binned_mean(x, v, 0.5)
    assert image.shape == (2, 2) and np.allclose(extent, (0.125, 1.0, 0.125, 1.0))
    # pixel edges at 0.125 + k 0.4375: each pixel holds its 4 points (the corner joins (1, 1))
    assert np.isclose(image[0, 0], 1.0) and np.isclose(image[0, 1], 2.0)
    assert np.isclose(image[1, 0], 3.0)
    assert np.isclose(image[1, 1], 7.0)
    image, _ = binned_mean(x[:-1], v[:-1], 0.25)  # finer: some pixels empty
    assert np.isnan(image).any() and np.nanmax(image) <= 5.0


def test_band_grows_when_the_contact_reaches_its_edge():
    """A contact band too small for the contact zone (0.002 mm: on the MPM path the gaps are
    measured from the step's start, the active points' up to ~0.003 mm here): the step is
    done again with the band doubled until no active point lies near its edge. The platen
    force then matches the run started with a wide band, and the self-checks say nothing of
    the band (issue 29, item 4, on the multi-step path)."""
    from dolfinx_forms.solvers.checks import contact_warnings

    narrow, wide = disc_sim(steps=3, mu=0.0, band=0.002), disc_sim(steps=3, mu=0.0, band=1.6)
    for _ in range(3):
        rn, rw = narrow.step(), wide.step()
    assert rn["band"] > 0.002 and rw["band"] == 1.6
    assert not narrow.band_reached()
    assert not any("band" in w for w in contact_warnings(narrow.problem))
    fn, fw = rn["obstacles"]["platen_top"]["fy"], rw["obstacles"]["platen_top"]["fy"]
    assert fn == pytest.approx(fw, rel=1e-3)


def test_augmented_lagrangian_forces_do_not_depend_on_eps0():
    """The augmented Lagrangian on the multi-step path (multipliers and friction tractions
    carried from step to step): 3 steps of the coarse Brazilian disc give the same platen
    forces at eps0 = 1e-3 and 1e3 (the loop converges to al_rtol = 1e-7: 1e-5 here), with the
    multi-step default (the lumped projection) and the hybrid one; the next step's multipliers
    start from the carried tractions."""
    for mass in ({}, {"multiplier_mass": "hybrid"}):
        forces = {}
        for eps0 in (1e-3, 1e3):
            sim = disc_sim(steps=3, enforcement="augmented", eps0=eps0, **mass)
            forces[eps0] = [sim.step()["obstacles"]["platen_top"]["fy"] for _ in range(3)]
            carried = [v for v in sim.friction.values() if np.any(v[2] < 0)]
            assert carried  # closed points' normal tractions, for the next step's start
        assert np.allclose(forces[1e-3], forces[1e3], rtol=1e-5, atol=0)
        assert forces[1e3][0] > 0


def test_augmented_loop_on_a_nonlinear_bulk_keeps_its_tangent():
    """NewtonOptions.al_frozen: the later solves of an augmented loop on a neo-Hookean disc
    keep the tangent (and factorisation) of their first iteration while they converge; the
    platen forces are those of a fresh tangent at every iteration to 1e-8 (both solves to the
    same tolerance), with fewer factorisations."""
    forces, fact = {}, {}
    for frozen in (True, False):
        sim = disc_sim(steps=3, law=NeoHookean(100e3, 0.3), enforcement="augmented",
                       newton=NewtonOptions(al_frozen=frozen))  # fmt: skip
        recs = [sim.step() for _ in range(3)]
        forces[frozen] = np.array([r["obstacles"]["platen_top"]["fy"] for r in recs])
        fact[frozen] = sum(r["factorisations"] for r in recs)
    assert forces[True][0] > 0
    assert np.allclose(forces[True], forces[False], rtol=1e-8, atol=0)
    assert fact[True] < 0.6 * fact[False], fact


@pytest.mark.parametrize("update", ["flow", "reference-map"])
def test_each_levelset_update_moves_a_translated_disc(update):
    """A disc translated by 0.3 (3 h) per step through ImplicitMPM: "flow" adds nothing to a
    uniform increment, so its level sets equal advection's bit for bit; the reference map puts
    the contour on the moved circle within 0.01 h (measured 0.004 h: the C1 interpolant of the
    circle's samples; advection 0.03 h) and keeps the area within 1e-9 of the first step's (a
    translation by whole cells)."""
    h, r = 0.1, 0.3
    lines = uniform_lines(-2.0, 2.0, h)
    everywhere = lambda x: np.ones(x.shape[1], bool)  # noqa: E731
    bcs = [Dirichlet(everywhere, 0, 0.3), Dirichlet(everywhere, 1, 0.0)]

    def run(mode):
        body = MPMBody("disc", 1, (1000.0, 0.3), df.Circle((-1.0, 0.0), r))
        sim = ImplicitMPM(COMM, (lines, lines), [body],
                          grid_scene(COMM, lines, lines, [("disc", 1)]), dirichlet=bcs,
                          levelset_update=mode, **quiet)  # fmt: skip
        return sim, [sim.step()["area_levelset"]["disc"] for _ in range(3)]

    sim, areas = run(update)
    if update == "flow":
        ref, _ = run("advection")
        assert np.array_equal(sim.levelsets[1].values, ref.levelsets[1].values)
    else:
        t = np.linspace(0, 2 * np.pi, 40)
        ring = np.array([-0.1, 0.0]) + r * np.stack([np.cos(t), np.sin(t)], axis=1)
        assert np.max(np.abs(sim.levelsets[1].evaluate(ring)[0])) < 0.01 * h
        assert np.ptp(areas) < 1e-9 * areas[0]


def test_points_in_a_sliver_take_the_field_inward(monkeypatch):
    """A block whose left side lies 5 % of a cell past a grid line: its points in those sliver
    cells (material_points.SLIVER) take u and grad u from the cell one spacing inward. With
    u = A x on the block's nodes and a garbage value on the slivers' outer nodes (held by the
    ghost penalty alone in a solve), they get A x and A exactly; their own cell's gradient
    would carry the garbage."""
    import dolfinx_forms.mpm.material_points as mp

    h = 0.1
    lines = uniform_lines(-1.6, 1.6, h)
    everywhere = lambda x: np.ones(x.shape[1], bool)  # noqa: E731
    bcs = [Dirichlet(everywhere, c, 0.0) for c in range(2)]
    body = MPMBody("block", 1, (1000.0, 0.3), df.Box((-0.5 - 0.05 * h, -0.43), (0.43, 0.43)))
    sim = ImplicitMPM(
        COMM, (lines, lines), [body], grid_scene(COMM, lines, lines, [("block", 1)]),
        dirichlet=bcs, **quiet,
    )  # fmt: skip
    sim.step()
    problem, pts = sim.problem, sim.points[1]
    x = pts.x[pts.x[:, 0] < -0.5]
    assert len(x) > 0
    cells = mp.grid_locator(problem.scene, 1, 1).locate(x, h)[0]
    assert np.all(problem.integration.fraction[cells] < mp.SLIVER)
    A = np.array([[0.011, -0.004], [0.003, 0.007]])
    X = problem.V.tabulate_dof_coordinates()[:, :2]
    u = X @ A.T
    u[X[:, 0] < -0.55] += 1.0  # the slivers' outer nodes
    problem.u.x.array[:] = u.ravel()
    du, grad, _ = mp.displacement_at(problem, 1, x, h)
    assert np.abs(du - x @ A.T).max() <= 1e-13
    assert np.abs(grad - A).max() <= 1e-12
    monkeypatch.setattr(mp, "SLIVER", 0.0)  # each point its own cell: the garbage shows
    grad = mp.displacement_at(problem, 1, x, h)[1]
    assert np.abs(grad - A).max() > 1.0


def _disc(step_displacement, steps, **kw):
    grid, (name, tag, shape), platens, build = brazilian_disc(
        COMM, 10.0, 0.5, step_displacement, steps
    )
    sym = Dirichlet(lambda x: np.isclose(x[0], 0.0), 0, 0.0)
    body = MPMBody(name, tag, (100e3, 0.3), shape)
    return ImplicitMPM(COMM, grid, [body], build, obstacles=platens, dirichlet=[sym], mu=0.5,
                       **quiet, **kw)  # fmt: skip


def _fail_whole_steps(monkeypatch, below=1.0):
    """ContactProblem.solve fails for every load level from `below` up (lam_end: the fraction
    of the MPM step)."""
    from dolfinx_forms.solvers.problem import ContactProblem

    solve = ContactProblem.solve

    def failing(self, num_steps=1, lam_end=1.0, *a, **k):
        if lam_end >= below:
            raise ContactSolverError(f"forced failure at {lam_end}")
        return solve(self, num_steps, lam_end, *a, **k)

    monkeypatch.setattr(ContactProblem, "solve", failing)


def test_a_failed_step_is_done_again_in_halves(monkeypatch):
    """A quasi-static step whose solve fails is done again as two half steps, each on the cut
    cells of its own start: the state and forces of a run with half the platen travel per step
    over twice the steps, in one record (`substeps` 2, the iterations summed)."""
    ref = _disc(0.01, 4)
    r_ref = [ref.step() for _ in range(2)]
    sim = _disc(0.02, 2)
    _fail_whole_steps(monkeypatch)
    r = sim.step()
    assert r["step"] == sim.step_count == 1 and r["substeps"] == 2
    assert r["newton_iterations"] == sum(x["newton_iterations"] for x in r_ref)
    assert len(r["residuals"]) == sum(len(x["residuals"]) for x in r_ref)
    a, b = sim.points[1], ref.points[1]
    assert np.abs(a.x - b.x).max() <= 1e-12 * 10.0
    assert np.abs(a.stress - b.stress).max() <= 1e-8 * np.abs(b.stress).max()
    for o, p in zip(sim.obstacles, ref.obstacles):
        assert np.allclose(o.offset, p.offset, rtol=0, atol=1e-15)
    for name, f in r_ref[-1]["obstacles"].items():
        assert abs(f["fy"]) > 100  # loaded
        for k in ("fx", "fy"):
            assert r["obstacles"][name][k] == pytest.approx(f[k], rel=1e-8, abs=1e-8 * abs(f["fy"]))


def test_a_step_failing_at_every_split_names_the_depth_and_is_undone(monkeypatch):
    """Still failing at 2^-max_splits of the step: ContactSolverError naming that fraction, the
    simulation as before the step. max_splits 0 keeps the step whole."""
    sim = _disc(0.02, 2, max_splits=2)
    _fail_whole_steps(monkeypatch, below=0.0)
    with pytest.raises(ContactSolverError, match=r"forced failure at 0.25 \(at 1/4 of the step\)"):
        sim.step()
    assert sim.step_count == 0 and sim.points is None
    assert all(np.array_equal(o.offset, np.zeros(2)) for o in sim.obstacles)
    whole = _disc(0.02, 2, max_splits=0)
    with pytest.raises(ContactSolverError, match=r"^forced failure at 1.0$"):
        whole.step()
    with pytest.raises(ValueError, match="max_splits"):
        _disc(0.02, 2, max_splits=-1)


def test_the_last_increment_predicts_the_next_step():
    """Newton starts each step from the last step's increment (`mpm/increment.py`) where that
    lowers the first residual: the same steps to Newton's tolerance in fewer iterations. A
    reversed increment raises the first residual and is not taken: Newton starts from du = 0."""
    runs = {}
    for extrapolate in (False, True):
        sim = disc_sim(steps=6, extrapolate=extrapolate)
        runs[extrapolate] = (sim, [sim.step() for _ in range(6)])
    (off, a), (on, b) = runs[False], runs[True]
    assert [r["predicted"] for r in a] == [0] * 6
    assert sum(r["predicted"] for r in b) >= 4 and b[0]["predicted"] == 0
    assert sum(r["newton_iterations"] for r in b) < sum(r["newton_iterations"] for r in a)
    for ra, rb in zip(a, b):
        for name, f in ra["obstacles"].items():
            assert abs(f["fy"]) > 100  # loaded
            assert rb["obstacles"][name]["fy"] == pytest.approx(f["fy"], rel=1e-8)
    assert np.abs(on.points[1].x - off.points[1].x).max() <= 1e-10 * 10.0
    # the guess a step takes is the last increment per unit of step, node by node
    inc = on.increment
    assert np.all(np.diff(inc.keys) > 0) and len(inc.keys) == on.problem.num_dofs // 2
    reverse = type(inc)(inc.keys, -inc.rate)
    on.increment, off.increment = reverse, None
    off.extrapolate = False
    r_rev, r_off = on.step(), off.step()
    assert r_rev["predicted"] == 0
    # started from du = 0: the first residual of the run without a guess (the two states agree
    # to Newton's tolerance, not bitwise: iteration counts could differ by a round-off flip)
    assert r_rev["residuals"][0] == pytest.approx(r_off["residuals"][0], rel=1e-6)


def test_increment_keys_and_predictor_round_trip():
    """Each local node has its own (body, grid node) key, and the predictor of a recorded
    increment puts the recorded u back at lam = fraction."""
    from dolfinx_forms.mpm import increment

    sim = disc_sim(steps=2)
    sim.step()
    p = sim.problem
    keys = increment.node_keys(p, sim.grid_key)
    assert len(np.unique(keys)) == len(keys) == len(p.u.x.array) // 2
    u = p.u.x.array.copy()
    assert np.abs(u).max() > 1e-3
    inc = increment.record(p, sim.grid_key, 0.5)
    p.u.x.array[:] = 0.0
    lam = p.lam
    p.lam = 0.0
    increment.predictor(inc, sim.grid_key)(p)(p, 0.5)
    p.lam = lam
    assert np.allclose(p.u.x.array, u, rtol=1e-15, atol=0.0)


def test_an_mpm_step_factorises_with_the_short_lived_ordering(monkeypatch):
    """An MPM step's problem serves one load step: `Factorised` has MUMPS order it by AMD
    (ICNTL(7) = 0, INFOG(7) the ordering used) for that analysis only; the option does not
    stay in PETSc's options for the problems that follow."""
    from petsc4py import PETSc

    from dolfinx_forms.solvers.linear import SHORT_LIVED_ORDERING

    used = []  # INFOG(7) of each factorisation, read before a converged step frees it
    release = linear.Factorised.release

    def read_then_release(lin):
        used.append(lin.ksp.getPC().getFactorMatrix().getMumpsInfog(7))
        release(lin)

    monkeypatch.setattr(linear.Factorised, "release", read_then_release)
    sim = disc_sim(steps=2, linear_solver="factorised")
    sim.step()
    lin = sim.problem.linear
    assert lin.name == "factorised" and lin.ordering == SHORT_LIVED_ORDERING == 0
    assert used == [SHORT_LIVED_ORDERING]
    assert not PETSc.Options().hasName("ils_mat_mumps_icntl_7")
    user = disc_sim(steps=2, linear_solver="factorised", petsc_options={"mat_mumps_icntl_7": 4})
    user.step()
    assert user.problem.linear.ordering is None  # the user's choice stands
    assert used == [SHORT_LIVED_ORDERING, 4]  # PORD


def test_the_path_chooses_the_newton_start_and_the_rise_limit():
    """ImplicitMPM's defaults where the user leaves them (None): a quasi-static step starts
    from the last increment unless a body's law carries a history (J2: from du = 0, fewer
    Newton iterations: mpm/implicit.py), and a quasi-static step's Newton halves a
    step that raises the residual across an active-set change (`implicit.RISE_LIMIT`; not in
    dynamics); a user's choice stands."""
    from dolfinx_forms.fem.plasticity import J2Plasticity
    from dolfinx_forms.mpm import implicit
    from dolfinx_forms.mpm.dynamics import PointNewmark

    j2 = J2Plasticity(100e3, 0.3, 200.0, 100.0)
    assert disc_sim(law=(100e3, 0.3)).extrapolate
    assert disc_sim(law=NeoHookean(100e3, 0.3)).extrapolate
    assert not disc_sim(law=j2).extrapolate
    assert disc_sim(law=j2, extrapolate=True).extrapolate
    assert disc_sim().problem_kw["newton"].rise_limit == implicit.RISE_LIMIT == 1.0
    mine = disc_sim(newton=NewtonOptions(rise_limit=np.inf)).problem_kw["newton"]
    assert mine.rise_limit == np.inf
    dyn = PointNewmark({1: 1.0}, 0.01, "dissipative")  # dynamics: whole steps
    assert disc_sim(dynamics=dyn).problem_kw.get("newton") is None
    assert NewtonOptions().rise_limit is None  # elsewhere: steps across a change taken whole
