"""The verification scenes (meshes/): disjoint bodies, exact areas, named boundaries, Hertz mesh
size, and (under `mpirun -n 2`, marker mpi) the contact-box partitioner."""

import numpy as np
import pytest

pytest.importorskip("gmsh")
import dolfinx  # noqa: E402
import dolfinx.cpp  # noqa: E402
from mpi4py import MPI  # noqa: E402

from meshes import (  # noqa: E402
    hertz_contact_box,
    hertz_scene,
    incline_scene,
    patch_scene,
    two_blocks_scene,
)
from dolfinx_forms.mesh.scene import (
    _EDGES,
    _facet_neighbours,
    box_hits,
    cell_bboxes,
    cell_edges,
    max_edge_in_box,
)  # noqa: E402

R, W, D = 10.0, 20.0, 20.0  # hertz defaults (width 40, depth 20)
S, SLOPE, C0 = 1000.0, 0.2, 458.6  # incline defaults


def close(a, b, tol=1e-8):
    return np.isclose(a, b, atol=tol)


def on_sides(x):  # incline: x = 0 or x = S
    return close(x[:, 0], 0, 1e-6) | close(x[:, 0], S, 1e-6)


def on_line(x):  # incline: the interface
    return close(x[:, 1], SLOPE * x[:, 0] + C0, 1e-6)


# name -> (builder(quads), {body: exact area or None},
#          {boundary: (body, predicate on points (n, 2), total length or None)})
SCENES = {
    "hertz": (
        lambda q: hertz_scene(MPI.COMM_SELF, h=0.2, quads=q),
        {"block": 2 * W * D, "cylinder": None},  # the half-disc: chord error, see test_hertz_arc
        {
            "block_bottom": ("block", lambda x: close(x[:, 1], -D), 2 * W),
            "block_sides": ("block", lambda x: close(abs(x[:, 0]), W), 2 * D),
            "block_top": ("block", lambda x: close(x[:, 1], 0), 2 * W),
            "cylinder_top": ("cylinder", lambda x: close(x[:, 1], R) & (abs(x[:, 0]) <= R), 2 * R),
            "cylinder_arc": ("cylinder", lambda x: close(np.hypot(x[:, 0], x[:, 1] - R), R), None),
        },
    ),
    "hertz_layers": (  # the same scene meshed without gmsh (meshes/layers.py), triangles only
        lambda q: hertz_scene(MPI.COMM_SELF, h=0.2, mesher="layers"),
        {"block": 2 * W * D, "cylinder": None},
        {},  # "hertz"'s, below
    ),
    "two_blocks": (
        lambda q: two_blocks_scene(MPI.COMM_SELF, h=2.0, quads=q),
        {"lower": 400.0, "upper": 200.0},
        {
            "lower_bottom": ("lower", lambda x: close(x[:, 1], 0), 40.0),
            "lower_left": ("lower", lambda x: close(x[:, 0], 0), 10.0),
            "lower_right": ("lower", lambda x: close(x[:, 0], 40), 10.0),
            "lower_top": ("lower", lambda x: close(x[:, 1], 10), 40.0),
            "upper_top": ("upper", lambda x: close(x[:, 1], 20), 20.0),
            "upper_bottom": ("upper", lambda x: close(x[:, 1], 10) & (abs(x[:, 0] - 20) <= 10), 20),
            "upper_sides": ("upper", lambda x: close(x[:, 0], 10) | close(x[:, 0], 30), 20.0),
        },
    ),
    "incline": (
        lambda q: incline_scene(MPI.COMM_SELF, h=100.0, quads=q),
        {"lower": S * (C0 + SLOPE * S / 2), "upper": S * (S - C0 - SLOPE * S / 2)},
        {
            "lower_bottom": ("lower", lambda x: close(x[:, 1], 0, 1e-6), S),
            "upper_top": ("upper", lambda x: close(x[:, 1], S, 1e-6), S),
            "lower_sides": ("lower", on_sides, 2 * C0 + SLOPE * S),
            "upper_sides": ("upper", on_sides, 2 * S - 2 * C0 - SLOPE * S),
            "lower_interface": ("lower", on_line, S * np.hypot(1, SLOPE)),
            "upper_interface": ("upper", on_line, S * np.hypot(1, SLOPE)),
        },
    ),
    "patch": (
        lambda q: patch_scene(MPI.COMM_SELF, nx=4, ny=2, quads=q, nx_upper=5),
        {"lower": 0.5, "upper": 0.5},
        {
            "lower_bottom": ("lower", lambda x: close(x[:, 1], 0), 1.0),
            "lower_left": ("lower", lambda x: close(x[:, 0], 0) & (x[:, 1] <= 0.5), 0.5),
            "lower_right": ("lower", lambda x: close(x[:, 0], 1) & (x[:, 1] <= 0.5), 0.5),
            "lower_top": ("lower", lambda x: close(x[:, 1], 0.5), 1.0),
            "upper_bottom": ("upper", lambda x: close(x[:, 1], 0.5), 1.0),
            "upper_top": ("upper", lambda x: close(x[:, 1], 1), 1.0),
            "upper_left": ("upper", lambda x: close(x[:, 0], 0) & (x[:, 1] >= 0.5), 0.5),
            "upper_right": ("upper", lambda x: close(x[:, 0], 1) & (x[:, 1] >= 0.5), 0.5),
        },
    ),
}
SCENES["hertz_layers"][2].update(SCENES["hertz"][2])
_cache = {}


def scene(name, quads):
    if (name, quads) not in _cache:
        _cache[name, quads] = SCENES[name][0](quads)
    return _cache[name, quads]


def local_cells(s):
    """(x (n, 2), cells (m, nv) in DOLFINx order, tags (m,)) of all local cells."""
    m = s.mesh
    n = m.topology.index_map(2).size_local + m.topology.index_map(2).num_ghosts
    return m.geometry.x[:, :2], m.geometry.dofmap.array.reshape(n, -1), s.cell_tags.values


def areas(x, cells):
    """Cell areas; quads in tensor order are the polygon 0-1-3-2 (a wrong order gives a bowtie)."""
    ring = cells if cells.shape[1] == 3 else cells[:, [0, 1, 3, 2]]
    px, py = x[ring][..., 0], x[ring][..., 1]
    return 0.5 * np.abs(np.sum(px * np.roll(py, -1, 1) - np.roll(px, -1, 1) * py, 1))


def facet_points(s, name):
    """(facets (k,), vertex coordinates (k, 2, 2)) of the facets tagged `name`."""
    facets = s.facet_tags.indices[s.facet_tags.values == s.boundaries[name]]
    g = dolfinx.cpp.mesh.entities_to_geometry(s.mesh._mesh, 1, facets, False)  # 0.5.2: C++ mesh
    return facets, s.mesh.geometry.x[g][..., :2]


CASES = [(n, q) for n in SCENES for q in (False, True) if not (n == "hertz_layers" and q)]
HERTZ = [("hertz", False), ("hertz", True), ("hertz_layers", False)]


@pytest.mark.parametrize("name,quads", CASES)
def test_bodies_disjoint_and_tagged(name, quads):
    s = scene(name, quads)
    x, cells, tags = local_cells(s)
    assert s.cell_type == ("quadrilateral" if quads else "triangle")
    assert s.mesh.topology.cell_type == dolfinx.mesh.to_type(s.cell_type)
    assert np.array_equal(s.cell_tags.indices, np.arange(len(cells)))
    assert [b.tag for b in s.bodies] == [1, 2] and s.pairs == [(0, 1)]
    assert set(np.unique(tags)) == {1, 2}
    # each vertex belongs to cells of one body only (no shared vertex between bodies)
    vt = np.unique(np.stack([cells.ravel(), np.repeat(tags, cells.shape[1])], 1), axis=0)
    assert len(vt) == len(np.unique(cells))
    # ... although the bodies touch: coincident vertices of different bodies exist
    xv = np.round(x[vt[:, 0]], 9)
    both = {tuple(p) for p in xv[vt[:, 1] == 1]} & {tuple(p) for p in xv[vt[:, 1] == 2]}
    assert len(both) >= 1
    # each cell's centroid is inside its own body's shape, and the bbox holds its vertices
    cen = x[cells].mean(axis=1)
    for b in s.bodies:
        mine = tags == b.tag
        assert np.all(np.asarray(b.shape(cen[mine])) < 0)
        xb = x[cells[mine]].reshape(-1, 2)
        assert np.all(xb >= b.bbox[0] - 1e-9) and np.all(xb <= b.bbox[1] + 1e-9)


@pytest.mark.parametrize("name,quads", CASES)
def test_areas_exact(name, quads):
    s = scene(name, quads)
    x, cells, tags = local_cells(s)
    a = areas(x, cells)
    assert np.all(a > 0)
    for b in s.bodies:
        exact = SCENES[name][1][b.name]
        if exact is not None:  # straight-sided bodies: exact up to round-off
            assert np.isclose(a[tags == b.tag].sum(), exact, rtol=1e-10), b.name


@pytest.mark.parametrize("name,quads", HERTZ)
def test_hertz_arc(name, quads):
    """Half-disc area: mesh area + the circular segments cut off by the arc facets = pi R^2 / 2
    (to round-off: the arc nodes lie on the circle). The chord error itself is O(h^2): a chord c
    cuts off R^2/2 (t - sin t) ~ c^3 / (12 R), t = 2 asin(c / 2R), so the total over arc length
    pi R is <= pi R c_max^2 / (12 R), i.e. relative to pi R^2 / 2 at most c_max^2 / (6 R^2)."""
    s = scene(name, quads)
    x, cells, tags = local_cells(s)
    mesh_area = areas(x, cells)[tags == 2].sum()
    _, p = facet_points(s, "cylinder_arc")
    c = np.linalg.norm(p[:, 0] - p[:, 1], axis=1)
    t = 2 * np.arcsin(c / (2 * R))
    exact = np.pi * R**2 / 2
    assert np.isclose(mesh_area + np.sum(R**2 / 2 * (t - np.sin(t))), exact, rtol=1e-10)
    assert 0 < (exact - mesh_area) / exact <= c.max() ** 2 / (6 * R**2)
    # both bodies have a vertex at the origin (gap 0 there)
    at0 = np.unique(tags[np.any(np.linalg.norm(x[cells], axis=2) < 1e-12, axis=1)])
    assert list(at0) == [1, 2]


@pytest.mark.parametrize("name,quads", CASES)
def test_facet_tags(name, quads):
    s = scene(name, quads)
    checks = SCENES[name][2]
    assert set(s.boundaries) == set(checks)
    assert len(set(s.boundaries.values())) == len(checks)
    _, _, tags = local_cells(s)
    s.mesh.topology.create_connectivity(1, 2)
    f2c = s.mesh.topology.connectivity(1, 2)
    for bname, (body, pred, length) in checks.items():
        facets, p = facet_points(s, bname)
        assert len(facets) > 0, bname
        assert np.all(pred(p.reshape(-1, 2))), bname
        body_tag = [b.tag for b in s.bodies if b.name == body][0]
        assert np.all(tags[f2c.array[f2c.offsets[facets]]] == body_tag), bname
        total = np.linalg.norm(p[:, 0] - p[:, 1], axis=1).sum()
        if length is not None:
            assert np.isclose(total, length, rtol=1e-10), bname
        else:  # the arc: chords are a bit shorter than pi R
            assert 0.995 * np.pi * R < total < np.pi * R
    assert np.all(np.diff(s.facet_tags.indices) > 0)


@pytest.mark.parametrize("name,quads", HERTZ)
@pytest.mark.parametrize("h", [0.2, 0.1])
def test_hertz_mesh_size(h, name, quads):
    mesher = "layers" if name == "hertz_layers" else "gmsh"
    s = (
        scene(name, quads)
        if h == 0.2
        else hertz_scene(MPI.COMM_SELF, h=h, quads=quads, mesher=mesher)
    )
    x, cells, _ = local_cells(s)
    zone = [[-1.5, -1.5], [1.5, 1.5]]
    assert s.h_contact == h
    assert max_edge_in_box(x, cells, zone) <= 1.05 * h
    # the zone is really resolved (not just a few tiny cells)
    lo, hi = cell_bboxes(x, cells)
    inside = np.all((lo >= -1.5) & (hi <= 1.5), axis=1)
    assert cell_edges(x, cells[inside]).mean() > (0.6 if not quads else 0.8) * h
    # layers: the cells across |x| = 1.5 or y = +-1.5 (layers h / sqrt(2) apart) do not count
    assert areas(x, cells[inside]).sum() > (0.85 if mesher == "layers" else 0.9) * 2 * 3.0 * 1.5


def test_patch_nonmatching():
    s = scene("patch", True)
    for name, n in [("lower_top", 4), ("upper_bottom", 5)]:
        facets, _ = facet_points(s, name)
        assert len(facets) == n


def test_gmsh_left_as_found():
    """A caller's gmsh session survives a generator, with its options restored."""
    import gmsh

    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("mine")
        gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 1)
        patch_scene(MPI.COMM_SELF, 2, 1)
        assert "mine" in gmsh.model.list()
        assert gmsh.option.getNumber("Mesh.MeshSizeFromPoints") == 1
    finally:
        gmsh.finalize()
    patch_scene(MPI.COMM_SELF, 2, 1)  # and it initializes gmsh itself again


def test_box_hits_is_the_scan_of_every_cell():
    """The partitioner's cells per box by the broad phase (`box_hits`) are a scan of every
    cell's bounding box against the box, box by box: cells of two sizes, boxes inside, across,
    at a cell's edge (closed sets), degenerate, inverted (empty) and outside."""
    rng = np.random.default_rng(3)
    lo = rng.uniform(0, 10, (2000, 2))
    hi = lo + rng.choice([0.1, 0.7], (2000, 1)) * [1.0, 1.3]
    lo[0], hi[0] = [5.0, 5.0], [5.5, 5.5]  # a box touching its edge hits it
    boxes = [[[4.0, 4.0], [5.0, 6.0]], [[-1, -1], [11, 11]], [[2, 3], [2, 3]], [[20, 0], [21, 1]],
             [[6, 6], [5, 7]]]  # fmt: skip
    boxes = np.vstack([np.array(boxes, float), np.sort(rng.uniform(0, 10, (30, 2, 2)), axis=1)])
    hits = box_hits(lo, hi, boxes)
    for box, hit in zip(boxes, hits):
        assert np.array_equal(hit, np.flatnonzero(np.all((lo <= box[1]) & (hi >= box[0]), 1)))
    assert 0 in hits[0] and len(hits[1]) == 2000 and len(hits[3]) == 0 and len(hits[4]) == 0
    assert [len(h) for h in box_hits(lo[:0], hi[:0], boxes[:2])] == [0, 0]


# ------------------------------------------------------------------------ mpirun -n 2


@pytest.mark.mpi
@pytest.mark.parametrize("name,quads", HERTZ)
def test_contact_box_cells_on_rank0(name, quads):
    comm = MPI.COMM_WORLD
    assert comm.size == 2, "this test is meant for mpirun -n 2"
    mesher = "layers" if name == "hertz_layers" else "gmsh"
    s = hertz_scene(comm, h=0.2, quads=quads, mesher=mesher)
    serial = hertz_scene(MPI.COMM_SELF, h=0.2, quads=quads, mesher=mesher)
    m = s.mesh
    nloc = m.topology.index_map(2).size_local
    x, cells, tags = local_cells(s)
    lo, hi = cell_bboxes(x, cells[:nloc])
    box = hertz_contact_box()
    hit = np.all((lo <= box[1]) & (hi >= box[0]), axis=1)
    nserial = serial.mesh.topology.index_map(2).size_local
    assert m.topology.index_map(2).size_global == nserial
    assert comm.allreduce(nloc) == nserial
    assert comm.allreduce(int(hit.sum())) > 0
    if comm.rank != 0:
        assert nloc > 0 and not hit.any()
    # per-body cell counts and named-facet counts are the serial ones
    for b in s.bodies:
        n_ser = np.sum(serial.cell_tags.values == b.tag)
        assert comm.allreduce(int(np.sum(tags[:nloc] == b.tag))) == n_ser
    owned_f = s.facet_tags.indices < m.topology.index_map(1).size_local
    for tag in s.boundaries.values():
        n_ser = np.sum(serial.facet_tags.values == tag)
        assert comm.allreduce(int(np.sum(s.facet_tags.values[owned_f] == tag))) == n_ser
    # shared_facet ghosting from the partitioner: interior-facet integrals match serial
    import ufl

    val = {}
    for key, sc in [("par", s), ("ser", serial)]:
        form = dolfinx.fem.form(dolfinx.fem.Constant(sc.mesh, 1.0) * ufl.dS(domain=sc.mesh))
        val[key] = sc.mesh.comm.allreduce(dolfinx.fem.assemble_scalar(form))
    assert np.isclose(val["par"], val["ser"], rtol=1e-12)


@pytest.mark.mpi
def test_build_error_raises_on_all_ranks(monkeypatch):
    comm = MPI.COMM_WORLD
    assert comm.size == 2
    import meshes.hertz

    def fail(*args, **kwargs):  # gmsh's build runs on rank 0 only
        raise RuntimeError("gmsh build failed")

    monkeypatch.setattr(meshes.hertz, "_build", fail)
    with pytest.raises(RuntimeError, match="gmsh build failed"):
        hertz_scene(comm, h=0.2)
    comm.Barrier()
    # the tall arc rising above the zone's top at x = zone: refused on every rank, before
    # any meshing (it would fold the layers, and gmsh's zone over)
    for mesher in ("gmsh", "layers"):
        with pytest.raises(ValueError, match="must lie inside both bodies"):
            hertz_scene(comm, R=2.0, Ry=20.0, h=0.2, zone=1.9, mesher=mesher)
    comm.Barrier()


@pytest.mark.parametrize("kind", ["conforming", "cut"])
def test_hertz_scenes_refuse_sizes_they_cannot_mesh(kind):
    """h outside meshes.hertz.mesh_size_bounds, or a zone outside a body: a ValueError before
    any meshing (hertz_scene(h=1e-7) ran gmsh for minutes towards 1e14 cells)."""
    from meshes.cut import hertz_cut_scene
    from meshes.hertz import mesh_size_bounds

    make = hertz_cut_scene if kind == "cut" else hertz_scene
    lo, hi = mesh_size_bounds(10.0, 40.0, 20.0, 1.5)
    assert (lo, hi) == (1.5 / 2000, 0.75)
    for h in (1e-7, 0.9 * lo, 1.1 * hi):
        with pytest.raises(ValueError, match="outside"):
            make(MPI.COMM_SELF, h=h)
    with pytest.raises(ValueError, match="inside both bodies"):
        make(MPI.COMM_SELF, h=0.5, zone=12.0)


@pytest.mark.parametrize(
    "module, builder, kwargs",
    [
        ("meshes.incline", "incline_scene", dict(h=1e-6)),
        ("meshes.two_blocks", "two_blocks_scene", dict(h=1e-6)),
        ("meshes.patch", "patch_scene", dict(nx=10**6, ny=10**6)),
        ("meshes.cut", "incline_cut_scene", dict(h=1e-6)),
        ("meshes.cut", "two_blocks_cut_scene", dict(h=1e-6)),
        ("meshes.cut", "patch_cut_scene", dict(n=10**5, nx=10**5)),
    ],
)
def test_scene_builders_refuse_more_cells_than_they_can_hold(module, builder, kwargs):
    """dolfinx_forms.mesh.scene.check_cells: an estimate of the cells above MAX_CELLS is a
    ValueError naming the builder, before gmsh or numpy start (they ran for minutes or died on
    memory)."""
    import importlib

    make = getattr(importlib.import_module(module), builder)
    with pytest.raises(ValueError, match=f"{builder}: the sizes give"):
        make(MPI.COMM_SELF, **kwargs)


@pytest.mark.parametrize("cell_name", ["quadrilateral", "triangle"])
def test_facet_neighbours_are_the_cells_sharing_an_edge(cell_name):
    # the partitioner's edge neighbours against a dictionary of edges, on a grid of cells with
    # shuffled vertex numbers (and, for triangles, each quad split in two)
    n = 7
    v = np.random.default_rng(3).permutation((n + 1) ** 2).reshape(n + 1, n + 1)
    quads = np.array([[v[j, i], v[j, i + 1], v[j + 1, i], v[j + 1, i + 1]]
                      for j in range(n) for i in range(n)])  # fmt: skip
    cells = quads if cell_name == "quadrilateral" else np.concatenate([quads[:, :3], quads[:, 1:]])
    a, b = _facet_neighbours(cells, cell_name)
    edges = {}
    for c, cell in enumerate(cells):
        for p, q in _EDGES[cell_name]:
            edges.setdefault(tuple(sorted((cell[p], cell[q]))), []).append(c)
    expected = sorted(tuple(cs) for cs in edges.values() if len(cs) == 2)
    assert sorted(tuple(sorted(p)) for p in zip(a.tolist(), b.tolist())) == expected
    assert len(expected) == 2 * n * (n - 1) + (n * n if cell_name == "triangle" else 0)
