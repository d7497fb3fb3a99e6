"""A contact band that follows the contact on the single-step paths (issue 29, item 4).

The Hertz set-up of benchmarks/orthotropic_paths.py with a circular indenter (R = 10, both
bodies the rotated OrthotropicElastic: the contact carries shear, Fx ~ 3 % of Fy with
friction), coarse (h = 0.2, a ~ 1 at an approach of 0.2), on both paths. Started with a band
of 0.05 (the initial gap at x = 1), the active points of the last load step reach 0.9 of it:
the band doubles to 0.1 and the step is done again from the committed state. The answer is
then the one of a band of 0.1, or of 0.4, from the start: every contact point of the grown
run is one of the wide run's (the rebuilt pair grids keep their lattices, and 0.4 - 0.05 is a
multiple of the grid spacing h/4) but the open ones of a segment its band clipped, the points
only the wide runs have are open, so the two solve the same equations, each Newton solve to
rtol 1e-10 of its first residual: they agree to ~1e-12 (measured), asserted to 1e-6 of each
reaction component, of the contact half-width and of the stick zone's ends, and of the
pressure and slip at every common contact point. A transfer that lost the committed plastic
slip (every point restarted open) moves Fx by 0.4 to 0.7 % in these runs, one that lost the
slip origin of friction switched on moves the slip.
"""

import numpy as np
import pytest
from mpi4py import MPI
from scipy.spatial import cKDTree

from benchmarks.orthotropic_paths import ortho_law, scene
from dolfinx_forms.fem.boundary import Dirichlet
from dolfinx_forms.io.output import gather_points
from dolfinx_forms.solvers import protocol
from dolfinx_forms.solvers.checks import contact_warnings
from dolfinx_forms.solvers.options import options
from dolfinx_forms.solvers.problem import ContactProblem, solver_metrics, zone_ends

GEOMETRY = dict(R=10.0, Ry=10.0, width=40.0, depth=20.0, zone=1.6)
H, NARROW, END, WIDE = 0.2, 0.05, 0.1, 0.4
RTOL = 1e-6


def run(path, band, protocol_kind, mu=0.0, band_growth=4, comm=MPI.COMM_WORLD, **kw):
    """Protocol "friction" (mu from the start): the indenter pressed 0.2 down in 2 steps,
    then moved 0.01 sideways in 2; "switched": 0.1 down frictionless, friction switched on,
    then down to 0.2 and sideways 0.01 together in 2 steps; "normal": 0.2 down in 2 steps."""
    sc = scene(path, H, comm, geometry=GEOMETRY)
    top_y, top_x = Dirichlet("cylinder_top", 1, 0.0), Dirichlet("cylinder_top", 0, 0.0)
    lines = []
    pb = ContactProblem(
        sc,
        {b.tag: ortho_law() for b in sc.bodies},
        dirichlet=[Dirichlet("block_bottom", None, 0.0), top_x, top_y],
        log=lines.append,
        **options(mu=mu, eps0=0.5, band=band, band_growth=band_growth, **kw),
    )
    if protocol_kind == "switched":
        protocol.ramp(pb, top_y, -0.1)
        protocol.friction_on(pb, 0.3)
        protocol.ramp(pb, [top_y, top_x], [-0.2, 0.01], steps=2)
    else:
        protocol.ramp(pb, top_y, -0.2, steps=2)
        if protocol_kind == "friction":
            protocol.ramp(pb, top_x, 0.01, steps=2)
    return pb, lines


def measures(pb):
    """Reaction, half-width, stick zone ends and the contact points (serial: all here)."""
    (pts,) = pb.contact_points()
    o = np.argsort(pts["x"])
    x, state = pts["x"][o], pts["state"][o]
    xl, xr = zone_ends(x, state != 0, pts["gap_n"][o])
    stick = zone_ends(x, state == 1) if np.any(state == 1) else (0.0, 0.0)
    return dict(F=pb.reaction("block_bottom"), a=0.5 * (xr - xl), stick=np.array(stick), pts=pts)


def same_answer(a, b):
    """a and b agree to RTOL (module doc); the contact points of a are points of b with the
    same pressure and slip, bar the open ones on a segment that a's band clipped."""
    for c in range(2):
        assert a["F"][c] == pytest.approx(b["F"][c], rel=RTOL), (c, a["F"], b["F"])
    assert a["a"] == pytest.approx(b["a"], rel=RTOL)
    assert np.allclose(a["stick"], b["stick"], rtol=0, atol=RTOL * b["a"])
    pa, pb = a["pts"], b["pts"]
    d, q = cKDTree(np.c_[pb["x"], pb["y"]]).query(np.c_[pa["x"], pa["y"]])
    same = d <= 1e-9 * H
    assert np.count_nonzero(~same) <= 4 and not np.any(pa["state"][~same])
    p_scale = np.abs(pb["p_n"]).max()
    assert np.allclose(pa["p_n"][same], pb["p_n"][q[same]], rtol=0, atol=RTOL * p_scale)
    s_scale = max(np.abs(pb["slip"]).max(), 1e-300)
    assert np.allclose(pa["slip"][same], pb["slip"][q[same]], rtol=0, atol=RTOL * s_scale)


@pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="serial: the points of one rank")
@pytest.mark.parametrize("path", ["fitted", "cut"])
@pytest.mark.parametrize("kind", ["friction", "switched"])
def test_grown_band_gives_the_wide_band_answer(path, kind):
    """Penalty with friction, the band grown within a stage (module doc): the answer of a band
    of 0.1 and of 0.4 from the start, with the same slip at every common point."""
    narrow, lines = run(path, NARROW, kind, mu=0.3 if kind == "friction" else 0.0)
    assert narrow.band_start == NARROW and narrow.band == END
    assert sum("contact band doubled to 0.1" in line for line in lines) == 1
    assert not any("band" in w for w in contact_warnings(narrow))
    assert solver_metrics(narrow)["band"] == {"start": NARROW, "end": END}
    m = measures(narrow)
    for band in (END, WIDE):
        ref, _ = run(path, band, kind, mu=0.3 if kind == "friction" else 0.0)
        assert ref.band == band
        same_answer(m, measures(ref))
    assert np.count_nonzero(m["pts"]["state"] == 1) > 0  # sticking points: the slip was tested


@pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="serial: the points of one rank")
@pytest.mark.parametrize("path", ["fitted", "cut"])
def test_grown_band_augmented(path):
    """The augmented Lagrangian (P1 multipliers, frictionless): its multiplier nodes lie at
    equal arc lengths along Gamma_c, which the band ends, so its answer is the one of the band
    it ends with (a band of 0.4 moves the reaction by ~1e-4 here, the node placement); the
    step done again starts from the carried-over tractions and converges to that band's
    fixed point (Uzawa to 1e-7 of the largest traction)."""
    narrow, _ = run(path, NARROW, "normal", enforcement="augmented")
    ref, _ = run(path, END, "normal", enforcement="augmented")
    assert narrow.band == END
    same_answer(measures(narrow), measures(ref))


@pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="serial")
def test_growth_bound_is_an_error_level_warning():
    """band_growth 1 from a band of 0.0125: 0.025 still cuts the zone off (gaps up to 0.05):
    the run ends with a ContactSolverError saying so (a demo: one line, exit 1, nothing
    written); band_growth 0 keeps the band (the MPM steps grow theirs) with the band check's
    warning only."""
    from dolfinx_forms.solvers.newton import ContactSolverError

    with pytest.raises(ContactSolverError, match="cut off at the band's edge") as e:
        run("cut", 0.0125, "normal", band_growth=1)
    assert "after 1 doublings of 0.0125" in str(e.value)
    fixed, lines = run("cut", 0.0125, "normal", band_growth=0)
    assert fixed.band == 0.0125 and not fixed.band_errors
    assert not any("band" in line for line in lines)
    assert any("within 10 % of the band" in x for x in contact_warnings(fixed))


@pytest.mark.mpi
@pytest.mark.parametrize("path", ["fitted", "cut"])
def test_grown_band_in_parallel(path):
    """On 2 ranks (Gamma_c on rank 0, the others' dofs coupled through it): the band grows on
    every rank together, and the answer is the one of a band of 0.1 from the start, and of one
    rank."""
    assert MPI.COMM_WORLD.size == 2, "run under mpirun -n 2"
    runs = {
        (band, comm.size): run(path, band, "friction", mu=0.3, comm=comm)[0]
        for band in (NARROW, END)
        for comm in (MPI.COMM_WORLD, MPI.COMM_SELF)
    }
    assert {k: pb.band for k, pb in runs.items()} == {k: END for k in runs}
    got = {}
    for key, pb in runs.items():
        pts = gather_points(pb)
        a = None
        if pts is not None:
            xl, xr = zone_ends(pts["x"], pts["state"] != 0, pts["gap_n"])
            a = 0.5 * (xr - xl)
        got[key] = (pb.reaction("block_bottom"), pb.comm.bcast(a, root=0))
    F, a = got[(NARROW, 2)]
    for ref in ((END, 2), (NARROW, 1), (END, 1)):
        for c in range(2):
            assert F[c] == pytest.approx(got[ref][0][c], rel=RTOL), (ref, c)
        assert a == pytest.approx(got[ref][1], rel=RTOL), ref
