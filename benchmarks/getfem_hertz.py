#!/usr/bin/python3
"""GetFEM's nodal P1 contact on the Hertz line contact of demos/hertz.py: the same scene, load
and p(x) error measure, the reference of benchmarks/work_precision.py's time-to-accuracy ratios.

Problem (demos/hertz.py defaults, dolfinx_forms/app/study.py CASE): a half-cylinder R = 10 mm (flat
face on top) on a block [-20, 20] x [-20, 0] clamped at its bottom, both E = 1e4, nu = 0.3,
linear elasticity in plane strain, frictionless, line load P = 430 N/mm; Hertz:
E* = E / (2 (1 - nu^2)), a = sqrt(4 P R / (pi E*)) = 0.998 mm, p(x) = p0 sqrt(1 - x^2/a^2).

Mesh. gmsh (python3-gmsh, the mesher of our body-fitted path) meshes both bodies with P1
triangles, sized like the committed meshes/hertz.py: gmsh target 0.75 h on the zone |x|, |y| <=
1.6 a, the size growing with slope 0.25 outside up to h_far = min(R, depth) / 8 = 1.25 (--zone,
--growth, --h-far; zone 1.2 a, slope 0.5 and h_far 5 cost GetFEM accuracy: 1.36 % instead of
0.92 % at a/40). Both bodies have a vertex at the origin. The nodes and triangles go to GetFEM
in memory (Mesh('ptND')), one GetFEM mesh per body. gmsh's time counts in "mesh", as in ours.

Contact brick: Model.add_nodal_contact_between_nonmatching_meshes_brick (small sliding, nodal),
GetFEM's contact between two deformable bodies for P1 displacements, the one its two-body
examples use (contrib/static_contact_gears: the gears and the planetary gear script, under its
former name add_nonmatching_meshes_contact_brick), and the "nodal P1" of issue 12. Every slave
node (the cylinder arc, |x| <= 1.6 a: our contact band) is paired with its closest master node
(block top, |x| <= 2.4 a) and projected on the master faces in the reference configuration, so
gap and normal (e_y) are fixed, as in our small-deformation contact. One multiplier per slave
node, the equivalent nodal normal force, by the non-symmetric Alart-Curnier augmented
Lagrangian (semi-smooth Newton), r = E (the documentation: close to the Young modulus). Not the
integral brick (add_integral_contact_between_nonmatching_meshes_brick): its multiplier is a
pressure field that needs an inf-sup stable space, not the nodal method; not the large sliding
brick, which re-projects (raytracing) at every iteration, beyond a small-sliding Hertz problem.

Load: force control inside the one Newton solve, as GetFEM's demo_wheel_contact.py loads its
wheel. The cylinder's top face moves rigidly, u = alpha e_y (u_x = 0, as our cylinder_top
Dirichlet condition), imposed by a P1 vector multiplier lambda_D on the face; the scalar
unknown alpha has the equation int_top lambda_D . e_y = P (a linear generic-assembly brick), so
the load is P exactly, without secant iterations. The block bottom is clamped by elimination
(Dirichlet condition with simplification). Newton starts from the rigid interference guess
alpha0 = -a_H^2 / (2 R) (u = alpha0 e_y on the cylinder, active set |x| < a_H; from zero the
first tangent is singular: no active node holds the cylinder); with that active set Newton
converges in 1-2 iterations. GetFEM's default linear solver (sequential MUMPS, LU: the model is
not symmetric) and line search; residual 1e-9.

Error measure, the definition of dolfinx_forms/analysis/compare.py: p(x) relative L2 error
sqrt(int (p - p_H)^2 / int p_H^2) along the slave surface against Hertz *at the computed load*
(P_c = the sum of the nodal contact forces, P to the solver tolerance), with the quadrature of
our demo (--gauss 2): 2 Gauss points per slave segment, at their reference x. The nodal forces
F_i become nodal pressures p_i = F_i / int phi_i (row-sum lumped P1 boundary mass: the tributary
length) and p(x) is their P1 interpolant. Also reported: pressure_rel_l2_error_nodes, the same
sum over the slave nodes with their tributary lengths as weights (the nodal method's own
points); it scatters more between neighbouring h (0.4 ... 1.7 % over a/12 ... a/34), since the
last active node's lumped pressure depends on where it falls near the edge. a: half the
distance between the zone ends, each the midpoint between the last active and the first
inactive slave node (the fallback of dolfinx_forms.solvers.problem.zone_ends: with exact multipliers
an active node's gap is 0, there is no sign change to interpolate); p0: the largest p_i.

Times: in-process wall times (perf_counter), without interpreter start-up and imports: mesh
(gmsh and the GetFEM meshes), setup (FEM spaces, regions, bricks, initial guess), solve
(Model.solve: assembly, contact pairing, factorisations), post (errors); total their sum.

Usage: /usr/bin/python3 benchmarks/getfem_hertz.py [--h H] [--zone 1.6] [--growth 0.25]
           [--h-far 1.25] [--json]
  --h: mesh size at the contact (default a/20); --json: the result as one JSON object on the
  last line of stdout (GetFEM 5.4.2 itself prints "ok here" on stdout while pairing).
Needs python3-getfem (Debian; `make bench` installs it) and python3-gmsh. Results beside ours:
benchmarks/results/work_precision_getfem.{json,csv,png} (benchmarks/work_precision.py).
"""

import argparse
import json
import math
import sys
import time

import numpy as np

R, WIDTH, DEPTH = 10.0, 40.0, 20.0
E, NU, LOAD = 1.0e4, 0.3, 430.0
ZONE = 1.6  # half-size of the zone meshed at h, in units of a (meshes/hertz.py as committed)
GROWTH = 0.25  # size slope outside the zone (meshes/hertz.py GROWTH)
H_FAR = min(R, DEPTH) / 8  # far-field size (meshes/hertz.py default)
FAC = 0.75  # gmsh target in the zone, in units of h (meshes/hertz.py's first try)
BAND = 1.6  # slave arc |x| <= 1.6 a (demos/hertz.py's contact band: the gap at x = 1.6 a)
MASTER = 1.5  # master half-width in slave half-widths (covers every slave projection)
GAUSS = 2  # Gauss points per slave segment (demos/hertz.py --gauss default)


def hertz(P=LOAD):
    """E*, a, p0 of the case at line load P."""
    E_star = E / (2 * (1 - NU**2))
    a = math.sqrt(4 * P * R / (math.pi * E_star))
    return E_star, a, 2 * P / (math.pi * a)


def mesh_bodies(h, zone, h_far, growth):
    """gmsh P1 triangles of the cylinder and of the block: [(points 2 x n, triangles 3 x m)] in
    that order; target FAC h on |x|, |y| <= zone, growing with slope `growth` up to h_far. The
    two bodies have separate vertices at the origin (no shared node)."""
    # quiet, sizes from the field only; cleaned up after
    from dolfinx_forms.mesh.scene import gmsh_model

    # comm None: no MPI (a GetFEM user's process initialises none; MPI_Init costs 0.1-0.4 s)
    with gmsh_model(None, "getfem_hertz") as gmsh:
        geo, W = gmsh.model.geo, WIDTH / 2
        c = [geo.addPoint(x, y, 0.0) for x, y in ((-R, R), (0, 0), (R, R), (0, R))]
        arcs = [geo.addCircleArc(c[0], c[3], c[1]), geo.addCircleArc(c[1], c[3], c[2])]
        cyl = geo.addPlaneSurface([geo.addCurveLoop([*arcs, geo.addLine(c[2], c[0])])])
        corners = ((-W, -DEPTH), (W, -DEPTH), (W, 0), (0, 0), (-W, 0))
        b = [geo.addPoint(x, y, 0.0) for x, y in corners]
        sides = [geo.addLine(b[i], b[(i + 1) % 5]) for i in range(5)]
        block = geo.addPlaneSurface([geo.addCurveLoop(sides)])
        geo.synchronize()
        f = gmsh.model.mesh.field.add("Box")
        size = dict(VIn=FAC * h, VOut=h_far, Thickness=(h_far - FAC * h) / growth)
        for k, v in dict(size, XMin=-zone, XMax=zone, YMin=-zone, YMax=zone).items():
            gmsh.model.mesh.field.setNumber(f, k, v)
        gmsh.model.mesh.field.setAsBackgroundMesh(f)
        gmsh.model.mesh.generate(2)
        tags, xyz, _ = gmsh.model.mesh.getNodes()
        xy = np.zeros((2, int(tags.max()) + 1))
        xy[:, tags.astype(np.int64)] = xyz.reshape(-1, 3)[:, :2].T
        out = []
        for s in (cyl, block):
            etypes, _, enodes = gmsh.model.mesh.getElements(2, s)
            if list(etypes) != [2]:
                raise RuntimeError(f"gmsh: not only 3-node triangles (element types {etypes})")
            used, tri = np.unique(enodes[0].astype(np.int64), return_inverse=True)
            out.append((xy[:, used], tri.reshape(-1, 3).T))
        return out


def solve(
    h=None,
    zone=ZONE,
    h_far=H_FAR,
    growth=GROWTH,
    band=BAND,
    r=E,
    max_res=1e-9,
    max_iter=40,
    verbose=False,
):
    """GetFEM nodal P1 Hertz (module docstring): mesh size h (default a/20) on the zone |x|, |y|
    <= zone a, growing with slope `growth` up to h_far; slave arc |x| <= band a; Alart-Curnier
    parameter r; Newton to the residual max_res. Returns dict(h, num_dofs, newton_iterations,
    load, contact_half_width, peak_pressure, analytic, errors, timing_s, ...); RuntimeError if
    Newton does not converge."""
    import getfem as gf

    _, a_H, _ = hertz()
    h = a_H / 20 if h is None else float(h)
    z, zs, h_far = zone * a_H, band * a_H, max(h, float(h_far))
    gf.util_trace_level(1 if verbose else 0)
    t = {}

    t0 = time.perf_counter()
    (pc, tc), (pb, tb) = mesh_bodies(h, z, h_far, growth)
    m1, m2 = gf.Mesh("ptND", pc, tc), gf.Mesh("ptND", pb, tb)  # cylinder, block
    t["mesh"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    tol = 1e-7 * R
    SLAVE, TOP, MASTER_RG, BOTTOM = 1, 2, 3, 4
    m1.set_region(SLAVE, m1.outer_faces_in_box([-zs, -tol], [zs, zs]))
    m1.set_region(TOP, m1.outer_faces_in_box([-R - tol, R - tol], [R + tol, R + tol]))
    zm = MASTER * zs
    m2.set_region(MASTER_RG, m2.outer_faces_in_box([-zm, -tol], [zm, tol]))
    m2.set_region(BOTTOM, m2.outer_faces_in_box([-WIDTH, -DEPTH - tol], [WIDTH, -DEPTH + tol]))
    mfu1, mfu2 = gf.MeshFem(m1, 2), gf.MeshFem(m2, 2)
    mfu1.set_classical_fem(1)
    mfu2.set_classical_fem(1)
    mim1, mim2 = gf.MeshIm(m1, 2), gf.MeshIm(m2, 2)
    md = gf.Model("real")
    md.add_fem_variable("u1", mfu1)
    md.add_fem_variable("u2", mfu2)
    md.add_initialized_data("lambda", [E * NU / ((1 + NU) * (1 - 2 * NU))])  # plane strain
    md.add_initialized_data("mu", [E / (2 * (1 + NU))])
    md.add_isotropic_linearized_elasticity_brick(mim1, "u1", "lambda", "mu")
    md.add_isotropic_linearized_elasticity_brick(mim2, "u2", "lambda", "mu")
    md.add_initialized_data("zero", [0.0, 0.0])
    md.add_Dirichlet_condition_with_simplification("u2", BOTTOM, "zero")
    # rigid top u1 = alpha e_y with int_top lambda_D . e_y = P: force control inside Newton
    md.add_filtered_fem_variable("lambda_D", mfu1, TOP)
    md.add_variable("alpha", 1)
    md.add_initialized_data("F", [LOAD / (2 * R)])  # per unit length of the top face
    md.add_linear_generic_assembly_brick(
        mim1,
        "lambda_D.Test_u1 + (u1 - alpha*[0;1]).Test_lambda_D + (F - lambda_D.[0;1])*Test_alpha",
        TOP,
    )
    slave_dofs = np.sort(mfu1.basic_dof_on_region(SLAVE))
    slave_dofs = slave_dofs[slave_dofs % 2 == 0]  # the brick's nodes: ascending first dofs
    md.add_initialized_data("r", [r])
    md.add_nodal_contact_between_nonmatching_meshes_brick(
        mim1, mim2, "u1", "u2", "lambda_n", "r", SLAVE, MASTER_RG
    )
    alpha0 = -(a_H**2) / (2 * R)  # rigid interference: active set |x| < a_H
    u1 = np.zeros(mfu1.nbdof())
    u1[1::2] = alpha0
    md.set_variable("u1", u1)
    md.set_variable("alpha", [alpha0])
    t["setup"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    its, converged = md.solve(
        "max_res", max_res, "max_iter", max_iter, *(["noisy"] if verbose else [])
    )
    t["solve"] = time.perf_counter() - t0
    if not converged:
        raise RuntimeError(f"GetFEM Newton did not converge in {its} iterations (h = {h:g})")

    t0 = time.perf_counter()
    # the slave arc |x| <= band a is a graph over x: sorted by x, consecutive nodes are its
    # segments
    xy = mfu1.basic_dof_nodes(slave_dofs)
    order = np.argsort(xy[0])
    force = -np.asarray(md.variable("lambda_n"))[order]  # nodal normal forces, compression > 0
    res = pressure_errors(xy[0][order], xy[1][order], force)
    t["post"] = time.perf_counter() - t0
    t["total"] = sum(t.values())
    return dict(
        h=h,
        mesh_sizing=dict(zone_a=zone, h_far=h_far, growth=growth, target_in_zone=FAC * h),
        band_a=band,
        num_dofs=int(mfu1.nbdof() + mfu2.nbdof()),
        model_dofs=int(md.nbdof()),
        num_cells=int(m1.nbcvs() + m2.nbcvs()),
        slave_nodes=int(slave_dofs.size),
        newton_iterations=int(its),
        approach=float(md.variable("alpha")[0]),
        **res,
        timing_s=t,
    )


def pressure_errors(x, y, force, gauss=GAUSS):
    """The measures of nodal normal forces `force` (compression > 0) at the slave nodes (x, y)
    (sorted by x, one polyline) against Hertz at their total (module docstring): dict(load,
    contact_half_width, peak_pressure, analytic={contact_half_width, peak_pressure},
    errors={half_width_rel_error, peak_pressure_rel_error, pressure_rel_l2_error,
    pressure_rel_l2_error_nodes}, profile={x, p}: the slave nodes' x and pressures p_i, for
    work_precision.py's error against a fine reference)."""
    seg = np.hypot(np.diff(x), np.diff(y))
    trib = np.zeros(x.size)  # int phi_i over the arc: row sums of the P1 boundary mass
    trib[:-1] += 0.5 * seg
    trib[1:] += 0.5 * seg
    p = force / trib
    P = float(force.sum())
    _, a_H, p0_H = hertz(P)

    def p_hertz(xs):
        return p0_H * np.sqrt(np.clip(1 - (xs / a_H) ** 2, 0.0, None))

    def rel_l2(w, pc, ph):  # dolfinx_forms.analysis.compare.rel_l2
        return float(np.sqrt(np.sum(w * (pc - ph) ** 2) / np.sum(w * ph**2)))

    s, gw = np.polynomial.legendre.leggauss(gauss)
    lam = 0.5 * (s + 1)[None, :]  # Gauss points along each segment, 0 .. 1
    xg = x[:-1, None] + lam * np.diff(x)[:, None]
    pg = p[:-1, None] + lam * np.diff(p)[:, None]  # the P1 interpolant of the p_i
    wg = 0.5 * seg[:, None] * gw[None, :]
    active = np.flatnonzero(force > 0)
    a = float("nan")
    if active.size:
        ends = [
            x[k] if nb < 0 or nb >= x.size else 0.5 * (x[k] + x[nb])
            for k, nb in ((active[0], active[0] - 1), (active[-1], active[-1] + 1))
        ]
        a = float(0.5 * (ends[1] - ends[0]))
    p0 = float(p.max())
    return dict(
        load=P,
        contact_half_width=a,
        peak_pressure=p0,
        profile=dict(x=x.tolist(), p=p.tolist()),  # the nodal pressures (their P1 interpolant)
        analytic=dict(contact_half_width=a_H, peak_pressure=p0_H),
        errors=dict(
            half_width_rel_error=abs(a - a_H) / a_H,
            peak_pressure_rel_error=abs(p0 - p0_H) / p0_H,
            pressure_rel_l2_error=rel_l2(wg, pg, p_hertz(xg)),
            pressure_rel_l2_error_nodes=rel_l2(trib, p, p_hertz(x)),
        ),
    )


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--h", type=float, default=None, help="mesh size at the contact (a/20)")
    ap.add_argument("--zone", type=float, default=ZONE, help=f"fine zone / a ({ZONE})")
    ap.add_argument("--growth", type=float, default=GROWTH, help=f"size slope ({GROWTH})")
    ap.add_argument("--h-far", type=float, default=H_FAR, help=f"far-field size ({H_FAR})")
    ap.add_argument("--json", action="store_true", help="print the result as JSON")
    ap.add_argument("--verbose", action="store_true", help="GetFEM's Newton output")
    a = ap.parse_args(argv)
    for k in ("h", "zone", "growth", "h_far"):
        v = getattr(a, k)
        if v is not None and not (math.isfinite(v) and v > 0):
            ap.error(f"--{k.replace('_', '-')} must be in (0, inf), got {v}")
    res = solve(a.h, a.zone, a.h_far, a.growth, verbose=a.verbose)
    if a.json:
        print(json.dumps(res, allow_nan=False))
        return 0
    e, t = res["errors"], res["timing_s"]
    print(
        f"getfem nodal P1: h = {res['h']:.5g}, {res['num_dofs']} dofs, "
        f"{res['newton_iterations']} Newton iterations, P = {res['load']:.6g} N/mm, "
        f"a = {res['contact_half_width']:.5g} (Hertz {res['analytic']['contact_half_width']:.5g}), "
        f"p(x) L2 error {e['pressure_rel_l2_error']:.3%} (nodes "
        f"{e['pressure_rel_l2_error_nodes']:.3%}), a error {e['half_width_rel_error']:.3%}; "
        + ", ".join(f"{k} {v:.3f} s" for k, v in t.items())
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
