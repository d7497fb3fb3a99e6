"""Demo outputs: tractions.csv, XDMF, traction plots (atomic folders: results.py)."""

import csv
from pathlib import Path

import numpy as np

from dolfinx_forms.contact.contact_set import STATE_NAMES
from dolfinx_forms.io import plot_worker

TRACTION_COLUMNS = ("x", "y", "p_n", "p_t", "gap_n", "slip", "state")


def gather_points(problem):
    """All ranks' contact points on rank 0, sorted by x (None on other ranks)."""
    local = problem.contact_points()
    keys = ("x", "y", "w", "p_n", "p_t", "gap_n", "slip", "state")
    mine = {k: np.concatenate([p[k] for p in local]) if local else np.zeros(0) for k in keys}
    allp = problem.comm.gather(mine, root=0)
    if problem.comm.rank != 0:
        return None
    pts = {k: np.concatenate([p[k] for p in allp]) for k in keys}
    order = np.argsort(pts["x"], kind="stable")
    return {k: v[order] for k, v in pts.items()}


def write_table(path, columns, rows, float_format=None):
    """The one CSV writer of every table a run writes: a header of `columns`, then one line
    per row (a sequence in column order, or a dict by column name); floats in
    `float_format` (e.g. ".12e"), else as Python prints them."""
    with open(path, "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(columns)
        for row in rows:
            values = [row[c] for c in columns] if isinstance(row, dict) else row
            if float_format is not None:
                values = [
                    format(v, float_format) if isinstance(v, (float, np.floating)) else v
                    for v in values
                ]
            w.writerow(values)


def write_tractions(folder, pts, frictionless=False):
    """tractions.csv: the contact points (TRACTION_COLUMNS), their state by name: open, stick
    or slip; without friction an active point is "active" (nothing sticks or slips)."""
    names = {**STATE_NAMES, **({1: "active", 2: "active"} if frictionless else {})}
    state = [names[int(s)] for s in pts["state"]]
    columns = [pts[k] for k in ("x", "y", "p_n", "p_t", "gap_n", "slip")]
    rows = zip(*columns, state)
    write_table(Path(folder) / "tractions.csv", TRACTION_COLUMNS, rows, ".12e")


def write_columns(path, **columns):
    """A CSV file of equally long columns {name: values} (write_table, %.12e values)."""
    write_table(path, list(columns), zip(*columns.values()), ".12e")


def write_fields(folder, problem, name="solution"):
    """<name>.xdmf + <name>.h5: ONE uniform grid (the mesh) with every field of the run, so
    that ParaView and meshio (`meshio.read`) both open it: displacement (P1, node), each
    body's level set `levelset_<body>` (its exact signed distance at the nodes, < 0 inside),
    the Cauchy stress (the laws' own, cellwise constant), the body tag `body` and, on a cut
    scene, `cut` (1: a cut cell, 0: interior) per cell. Paths inside are relative to the
    .xdmf file. Collective."""
    from dolfinx import fem, io

    mesh, scene = problem.mesh, problem.scene
    V1 = fem.VectorFunctionSpace(mesh, ("Lagrange", 1))
    u1 = fem.Function(V1, name="displacement")
    u1.interpolate(problem.u)
    fields = [u1]
    S1 = fem.FunctionSpace(mesh, ("Lagrange", 1))
    x = S1.tabulate_dof_coordinates()[:, :2]
    for b in scene.bodies:
        phi = fem.Function(S1, name=f"levelset_{b.name}")
        phi.x.array[:] = np.asarray(b.shape(np.ascontiguousarray(x)), dtype=float)
        fields.append(phi)
    fields.append(problem.stress(("DG", 0)))  # the laws' own output stress
    fields.append(_cell_field(mesh, scene.cell_tags, "body"))
    if getattr(scene, "cut", None) is not None:
        fields.append(_cell_field(mesh, scene.cut.kind_tags, "cut"))
    path = Path(folder) / f"{name}.xdmf"
    with io.XDMFFile(mesh.comm, str(path), "w") as f:
        f.write_mesh(mesh)
        for field in fields:
            f.write_function(field)
    if mesh.comm.rank == 0:
        one_grid(path)
    mesh.comm.barrier()


def _cell_field(mesh, tags, name):
    """A DG0 function of the values of cell tags `tags` (-1 where a cell has none)."""
    from dolfinx import fem

    V0 = fem.FunctionSpace(mesh, ("DG", 0))
    f = fem.Function(V0, name=name)
    f.x.array[:] = -1.0
    dofs = V0.dofmap.list.array.reshape(-1)  # one dof per cell
    f.x.array[dofs[tags.indices]] = tags.values
    return f


def one_grid(path):
    """Rewrite the XDMF file DOLFINx wrote (the mesh, then one temporal collection per
    function) as one uniform grid carrying every function as an attribute: meshio reads one
    grid only ("Only supports one grid", then it exits), ParaView reads both; float arrays
    declare their 8 bytes."""
    import xml.etree.ElementTree as ET

    tree = ET.parse(path)
    domain = tree.getroot().find("Domain")
    grids = domain.findall("Grid")
    mesh = grids[0]
    for g in grids[1:]:
        for a in g.iter("Attribute"):
            mesh.append(a)
        domain.remove(g)
    mesh.set("Name", "solution")
    # DOLFINx writes float64 arrays but leaves Precision out, and XDMF then means 4 bytes:
    # ParaView read every value in single precision
    for item in domain.iter("DataItem"):
        if item.get("NumberType", "Float") == "Float" and "Precision" not in item.attrib:
            item.set("NumberType", "Float")  # ParaView's readers ignore Precision without it
            item.set("Precision", "8")
    ET.indent(tree)
    tree.write(path, xml_declaration=True, encoding="unicode")


def plot_tractions(path, pts, analytic=None, title="", xlabel="x (mm)", ylabel="traction (MPa)"):
    """Computed p_n, p_t at the contact points against analytic curves {label: (x, y)}."""
    lines = {"p_n computed": (pts["x"], pts["p_n"], ".")}
    if np.any(pts["p_t"] != 0):
        lines["p_t computed"] = (pts["x"], pts["p_t"], ".")
    lines.update({label: (x, y, "-") for label, (x, y) in (analytic or {}).items()})
    plot_lines(path, lines, title, xlabel, ylabel)


def plot_lines(path, lines, title="", xlabel="x (mm)", ylabel="", vlines=()):
    """Curves {label: (x, y, style)} (style "-": a line, ".": points) and dotted vertical lines
    at the abscissae `vlines`, in one PNG (plot_worker.draw; in the worker of
    `start_plot_worker`, or the demo's early one, if one was started and is unused)."""
    global _worker
    worker, _worker = _worker or plot_worker.take_early(), None
    if worker is None or not worker.plot(path, lines, title, xlabel, ylabel, vlines):
        plot_worker.draw(path, lines, title, xlabel, ylabel, vlines)


_worker = None  # plot_worker.Worker of start_plot_worker, until plot_lines uses it


def start_plot_worker():
    """Start a worker process for the next plot_lines figure (plot_worker.py); a previous
    unused one is ended."""
    global _worker
    stop_plot_worker()
    _worker = plot_worker.take_early() or plot_worker.start()


def stop_plot_worker():
    """End the worker of start_plot_worker if plot_lines did not use it."""
    global _worker
    worker, _worker = _worker, None
    if worker is not None:
        worker.close()


def window_average(x, p, width):
    """Mean of p over the points within |x' - x| <= width / 2 of each point (vectorised).

    Penalty tractions carry an element-scale ripple (amplitude ~ 1/eps0) that differs between
    meshes; averaging over one cell width compares the resolved profiles of two
    discretisations."""
    x, p = np.asarray(x, float), np.asarray(p, float)
    order = np.argsort(x, kind="stable")
    xs, cs = x[order], np.concatenate([[0.0], np.cumsum(p[order])])
    lo = np.searchsorted(xs, x - width / 2, side="left")
    hi = np.searchsorted(xs, x + width / 2, side="right")
    return (cs[hi] - cs[lo]) / (hi - lo)
