"""A body-fitted disc between two rigid platens (the body-fitted reference of the disc crush).

The disc of radius R centred at the origin is meshed by gmsh as two half discs that share the
line x = 0 (nodes on it: the u_x = 0 symmetry condition of the demos), unstructured of size h,
triangles or recombined quadrilaterals. The platens are the rigid half planes y > R (moved down
by `step_displacement` per step) and y < -R (fixed), the same obstacles as the MPM Brazilian
disc's (`meshes.mpm.disc_platens`).
Run: /usr/bin/python3 -m meshes.disc [--h 1] [--quads]
"""

from __future__ import annotations

import numpy as np

from dolfinx_forms.mesh.scene import Body, check_cells, gmsh_model, scene_from_gmsh, summary
from dolfinx_forms.solvers.newton import NewtonOptions


# the ranks that compute the top and the bottom platen's contact (modulo the ranks)
PLATEN_RANKS = (0, 1)


def fitted_disc(comm, R=10.0, h=0.5, quads=True):
    """The Scene of the disc (body "disc", tag 1) with cells of size about h; the cells near
    the two poles on the ranks PLATEN_RANKS (`contact_ranks`)."""
    import dolfinx_forms as df

    check_cells("fitted_disc", 1.3 * np.pi * (R / h) ** 2 if h > 0 else 0.0)
    with gmsh_model(comm, "disc") as gmsh:
        if comm.rank == 0:
            geo = gmsh.model.geo
            c = geo.addPoint(0.0, 0.0, 0.0)
            t, b = geo.addPoint(0.0, R, 0.0), geo.addPoint(0.0, -R, 0.0)
            r, left = geo.addPoint(R, 0.0, 0.0), geo.addPoint(-R, 0.0, 0.0)
            axis = geo.addLine(t, b)
            right_arcs = [geo.addCircleArc(b, c, r), geo.addCircleArc(r, c, t)]
            left_arcs = [geo.addCircleArc(t, c, left), geo.addCircleArc(left, c, b)]
            s1 = geo.addPlaneSurface([geo.addCurveLoop([*right_arcs, axis])])
            s2 = geo.addPlaneSurface([geo.addCurveLoop([*left_arcs, -axis])])
            if quads:
                geo.mesh.setRecombine(2, s1)
                geo.mesh.setRecombine(2, s2)
            geo.synchronize()
            gmsh.model.addPhysicalGroup(2, [s1, s2], 1)
            # quads: triangles of size 2h recombined, then every cell split into quads of ~h
            size = 2 * h if quads else h
            gmsh.option.setNumber("Mesh.MeshSizeMin", size)
            gmsh.option.setNumber("Mesh.MeshSizeMax", size)
            gmsh.option.setNumber("Mesh.SubdivisionAlgorithm", 1 if quads else 0)
            gmsh.model.mesh.generate(2)
        disc = Body("disc", 1, df.Circle((0.0, 0.0), R), np.array([[-R, -R], [R, R]]))
        # the cells that meet a platen up to a closure of half the diameter (material within
        # about 60 degrees of a pole): the top ones on rank 0, the bottom ones on rank 1 (as
        # ghosts where another rank owns them), where the two contacts are computed
        x, y = 0.9 * R + 2 * h, 0.45 * R - 2 * h
        box = np.array([[[-x, y], [x, R + h]], [[-x, -R - h], [x, -y]]])
        return scene_from_gmsh(
            comm, [disc], {}, [], h, contact_box=dict(boxes=box, owners=PLATEN_RANKS)
        )


def contact_ranks(comm):
    """The ContactProblem contact_rank map of `fitted_disc`: each platen's pair on its rank."""
    ranks = [r % comm.size for r in PLATEN_RANKS]
    return {(0, "platen_top"): ranks[0], (0, "platen_bottom"): ranks[1]}


def plastic_fraction(ul, tag=1):
    """A function () -> the area fraction of body `tag` of an `UpdatedLagrangian` where its
    law's last history component (J2's alpha) is positive, in the current configuration (0 for
    a law without history). Its forms are compiled once: they read the moving mesh's nodes."""
    import ufl
    from dolfinx import fem

    h = ul.history[tag]
    if h is None:
        return lambda: 0.0
    md = {"quadrature_degree": ul.degree}
    dx = ufl.Measure("dx", domain=ul.mesh, subdomain_data=ul.scene.cell_tags, metadata=md)(tag)
    alpha = h[ul.laws[tag].history_size - 1]
    plastic = fem.form(ufl.conditional(ufl.gt(alpha, 0.0), 1.0, 0.0) * dx)
    area = fem.form(fem.Constant(ul.mesh, 1.0) * dx)
    total = lambda f: ul.comm.allreduce(fem.assemble_scalar(f))  # noqa: E731
    return lambda: float(total(plastic) / total(area))


# the columns of crush_reference's rows (reference.csv of demos/disc_crush.py)
REFERENCE_COLUMNS = [
    "h",
    "step",
    "force",
    "force_bottom",
    "half_width",
    "plastic_fraction",
    "newton_iterations",
]


# Newton iterations a reference step may take: with perfect plasticity (J2, H = 0) hundreds of
# contact points slip on the Coulomb cone, and an increment of any size re-sorts them into
# stick and slip a few an iteration (the slip front moves about a node an iteration): 21-29
# iterations from 1e-5 to 1e-3 of a move at step 39 (h = 0.25), where the default 25 failed
# at every cut-back. With 40 the three levels complete (docs/demos/disc_crush.md)
REFERENCE_NEWTON_ITERATIONS = 40


def crush_reference(
    comm, R, sizes, law, steps, step_displacement, substeps=1, log=None, **problem_kw
):
    """The body-fitted reference of the disc crush at each cell size in `sizes`: the disc of
    `fitted_disc` (quadrilaterals) between the platens of `meshes.mpm.disc_platens`, u_x = 0 on
    x = 0, `law` at finite strain on a mesh that follows the material
    (`fem.updated.UpdatedLagrangian`), one step per platen move. Returns the rows
    (REFERENCE_COLUMNS; force: on the top platen, positive in compression) of every size;
    substeps: load steps per platen move (`UpdatedLagrangian.step`; J2 too converges from a
    whole move).
    problem_kw: `solvers.options` keywords (an MPM's levelset_update is ignored)."""
    kw = {k: v for k, v in problem_kw.items() if k != "levelset_update"}  # the MPM's own
    kw.setdefault("contact_rank", contact_ranks(comm))
    kw.setdefault("newton", NewtonOptions(max_iterations=REFERENCE_NEWTON_ITERATIONS))
    return [row for h in sizes for row in _crush(comm, R, h, law, steps, step_displacement,
                                                 substeps, log, kw)]  # fmt: skip


def _crush(comm, R, h, law, steps, step_displacement, substeps, log, problem_kw):
    from dolfinx_forms.fem.boundary import Dirichlet
    from dolfinx_forms.fem.updated import UpdatedLagrangian
    from meshes.mpm import disc_platens

    scene = fitted_disc(comm, R, h)
    axis = Dirichlet(lambda x: np.isclose(x[0], 0.0, atol=1e-9 * R), 0, 0.0)
    ul = UpdatedLagrangian(
        scene,
        {1: law},
        obstacles=disc_platens(R, step_displacement),
        dirichlet=[axis],
        log=log or (lambda *a, **k: None),
        **problem_kw,
    )
    rows, fraction = [], plastic_fraction(ul)
    for k in range(steps):
        problem = ul.step(substeps=substeps)
        top, bottom = ul.record["platen_top"], ul.record["platen_bottom"]
        rows.append(
            dict(
                step=k + 1,
                h=h,
                force=top["fy"],
                force_bottom=-bottom["fy"],
                half_width=top["half_width"],
                plastic_fraction=fraction(),
                newton_iterations=int(sum(s.iterations for s in problem.steps)),
            )
        )
    ul.problem.destroy()
    return rows


def refinement(rows):
    """The refinement study of `crush_reference` rows at several h: (levels, finest first;
    {h: force per step}; the finest level's own error estimate |F_h / F_2h - 1| per step (first
    order: the error of F_h is about F_h - F_2h); the first-order extrapolation 2 F_h - F_2h)."""
    levels = sorted({r["h"] for r in rows})
    F = {h: np.array([r["force"] for r in rows if r["h"] == h]) for h in levels}
    fine, next_ = F[levels[0]], F[levels[1]]
    return levels, F, np.abs(fine / next_ - 1), 2 * fine - next_


def _main(argv=None):
    import argparse

    from mpi4py import MPI

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--R", type=float, default=10.0)
    p.add_argument("--h", type=float, default=1.0)
    p.add_argument("--quads", action="store_true")
    a = p.parse_args(argv)
    print(summary(fitted_disc(MPI.COMM_WORLD, a.R, a.h, a.quads)))


if __name__ == "__main__":
    _main()
