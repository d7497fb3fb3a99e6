"""The structured cut-cell scenes (meshes/cut.py): graded lines, disjoint bodies, cell kinds from
the vertex signs, ghost-penalty facets, grid-aligned boundaries, direct counts from the grid, and
1 rank vs 2 ranks (mpirun -n 2 on this file, or the mpi-marked test under make test-mpi)."""

import json
import os
import shutil
import subprocess
import sys

import dolfinx
import dolfinx.cpp
import dolfinx.fem
import numpy as np
import pytest
from mpi4py import MPI

from dolfinx_forms.fem.cut import CUT, INTERIOR, levelset_values
from dolfinx_forms.mesh.cut_scene import CutBody, cut_scene, graded_lines, half_plane
from meshes.cut import hertz_cut_scene, incline_cut_scene, patch_cut_scene, two_blocks_cut_scene

BUILDERS = {
    "hertz": lambda comm: hertz_cut_scene(comm, h=0.2),
    "patch": lambda comm: patch_cut_scene(comm, n=5),
    "two_blocks": lambda comm: two_blocks_cut_scene(comm, h=2.0),
    "incline": lambda comm: incline_cut_scene(comm, h=100.0),
}
# name -> {boundary: (body index, [(axis, grid line value)]) or None (cut boundary: no facet)}
BOUNDARIES = {
    "hertz": {
        "block_bottom": (0, [(1, -20.0)]),
        "block_sides": (0, [(0, -20.0), (0, 20.0)]),
        "block_top": (0, [(1, 0.0)]),
        "cylinder_top": (1, [(1, 10.0)]),
        "cylinder_arc": None,
    },
    "patch": {
        "lower_bottom": (0, [(1, 0.0)]),
        "lower_left": (0, [(0, 0.0)]),
        "lower_right": (0, [(0, 1.0)]),
        "lower_top": None,
        "upper_bottom": None,
        "upper_left": (1, [(0, 0.0)]),
        "upper_right": (1, [(0, 1.0)]),
        "upper_top": (1, [(1, 1.0)]),
    },
    "two_blocks": {
        "lower_bottom": (0, [(1, 0.0)]),
        "lower_left": (0, [(0, 0.0)]),
        "lower_right": (0, [(0, 40.0)]),
        "lower_top": None,
        "upper_top": (1, [(1, 20.0)]),
        "upper_bottom": None,
        "upper_sides": (1, [(0, 10.0), (0, 30.0)]),
    },
    "incline": {
        "lower_bottom": (0, [(1, 0.0)]),
        "upper_top": (1, [(1, 1000.0)]),
        "lower_sides": (0, [(0, 0.0), (0, 1000.0)]),
        "upper_sides": (1, [(0, 0.0), (0, 1000.0)]),
        "lower_interface": None,
        "upper_interface": None,
    },
}
# the same names and tags as the gmsh scenes
TAGS = {
    "hertz": ["block_bottom", "block_sides", "block_top", "cylinder_top", "cylinder_arc"],
    "patch": [
        "lower_bottom",
        "lower_left",
        "lower_right",
        "lower_top",
        "upper_bottom",
        "upper_left",
        "upper_right",
        "upper_top",
    ],
    "two_blocks": [
        "lower_bottom",
        "lower_left",
        "lower_right",
        "lower_top",
        "upper_top",
        "upper_bottom",
        "upper_sides",
    ],
    "incline": [
        "lower_bottom",
        "upper_top",
        "lower_sides",
        "upper_sides",
        "lower_interface",
        "upper_interface",
    ],
}
EDGES = [(0, 1), (0, 2), (1, 3), (2, 3)]  # DOLFINx quadrilateral edges (tensor vertex order)
_cache = {}


def scene(name):
    if name not in _cache:
        _cache[name] = BUILDERS[name](MPI.COMM_SELF)
    return _cache[name]


def local(s):
    """(x (n, 2), cells (m, 4) geometry nodes, body tags (m,), kinds (m,)) of the local cells."""
    m = s.mesh
    n = m.topology.index_map(2).size_local + m.topology.index_map(2).num_ghosts
    assert np.array_equal(s.cell_tags.indices, np.arange(n))
    assert np.array_equal(s.cut.kind_tags.indices, np.arange(n))
    cells = m.geometry.dofmap.array.reshape(n, 4)
    return m.geometry.x[:, :2], cells, s.cell_tags.values, s.cut.kind_tags.values


def vertex_phi(s, x, cells, tags):
    """(m, 4) cut level set of each cell's own body at its vertices."""
    phi = np.zeros(cells.shape)
    for tag, shape in s.cut.levelsets.items():
        mine = tags == tag
        phi[mine] = shape(np.ascontiguousarray(x[cells[mine]].reshape(-1, 2))).reshape(-1, 4)
    return phi


def edge_table(cells):
    """(unique sorted vertex pairs (k, 2), the cells of each (k, 2), -1 if only one)."""
    e = np.sort(np.concatenate([cells[:, list(p)] for p in EDGES]), axis=1)
    owner = np.tile(np.arange(len(cells)), len(EDGES))
    pairs, inv = np.unique(e, axis=0, return_inverse=True)
    inv = inv.ravel()
    order = np.argsort(inv, kind="stable")
    first = np.searchsorted(inv[order], np.arange(len(pairs)))
    cnt = np.bincount(inv, minlength=len(pairs))
    second = np.where(cnt == 2, owner[order[np.minimum(first + 1, len(order) - 1)]], -1)
    return pairs, np.stack([owner[order[first]], second], axis=1)


def facet_nodes(s, facets):
    """Sorted geometry node pairs (k, 2) of the given facets."""
    g = dolfinx.cpp.mesh.entities_to_geometry(s.mesh._mesh, 1, np.asarray(facets, np.int32), False)
    return np.sort(g.reshape(-1, 2), axis=1)


def as_set(pairs):
    return {tuple(p) for p in np.asarray(pairs).reshape(-1, 2)}


def check_local(s):
    """Checks valid on any rank for its owned + ghost cells (used in serial and under mpirun)."""
    x, cells, tags, kinds = local(s)
    assert s.cell_type == "quadrilateral" and s.cut is not None
    # disjoint: no geometry node used by two bodies
    body_of = np.full(len(x), -1)
    for tag in np.unique(tags):
        body_of[np.unique(cells[tags == tag])] = tag
    assert np.all(body_of[cells] == tags[:, None])
    # the cells sit inside their windows, on the grid lines, kinds from the vertex signs
    for tag, w in s.cut.windows.items():
        xc = x[cells[tags == tag]]
        assert np.all((xc >= w[0] - 1e-12) & (xc <= w[1] + 1e-12))
        assert np.all(np.isin(xc[..., 0], s.cut.xlines))
        assert np.all(np.isin(xc[..., 1], s.cut.ylines))
    phi = vertex_phi(s, x, cells, tags)
    assert np.all(phi.min(axis=1) < 0)  # active
    assert np.array_equal(kinds, np.where(phi.max(axis=1) > 0, CUT, INTERIOR))
    cut = kinds == CUT
    assert np.all((phi[cut].min(axis=1) < 0) & (phi[cut].max(axis=1) > 0))  # a sign change
    # ghost facets: exactly the (locally) interior facets with a cut neighbour
    pairs, nb = edge_table(cells)
    interior = nb[:, 1] >= 0
    assert np.all(tags[nb[interior, 0]] == tags[nb[interior, 1]])
    want = interior & (cut[nb[:, 0]] | (interior & cut[np.maximum(nb[:, 1], 0)]))
    gf = s.cut.ghost_facets
    assert np.all(gf.values == 1) and np.all(np.diff(gf.indices) > 0)
    assert as_set(facet_nodes(s, gf.indices)) == as_set(pairs[want])
    # levelset_values: at each Q1 dof the level set of its body
    V = dolfinx.fem.FunctionSpace(s.mesh, ("Lagrange", 1))
    f = levelset_values(s, V)
    dofs = V.dofmap.list.array.reshape(len(cells), 4)
    assert np.allclose(f.x.array[dofs], phi, rtol=0, atol=1e-12)
    return x, cells, tags, kinds


def global_counts(s):
    """Collective: global counts of owned cells per (body, kind), ghost facets, named facets."""
    comm, top = s.mesh.comm, s.mesh.topology
    nc, nf = top.index_map(2).size_local, top.index_map(1).size_local
    tags, kinds = s.cell_tags.values[:nc], s.cut.kind_tags.values[:nc]
    out = {
        f"{b.name}/{k}": comm.allreduce(int(np.sum((tags == b.tag) & (kinds == k))))
        for b in s.bodies
        for k in (INTERIOR, CUT)
    }
    out["ghost_facets"] = comm.allreduce(int(np.sum(s.cut.ghost_facets.indices < nf)))
    owned_f = s.facet_tags.indices < nf
    for name, tag in s.boundaries.items():
        out[name] = comm.allreduce(int(np.sum(s.facet_tags.values[owned_f] == tag)))
    return out


# ------------------------------------------------------------------------ graded lines
def test_graded_lines_hertz_like():
    h, g, hf = 0.05, 1.2, 1.25
    req = [-20.0, -10.0, 0.0, 10.0, 20.0]
    x = graded_lines(-20, 20, (-1.5, 1.5), h, g, hf, required=req)
    s = np.diff(x)
    assert np.all(s > 0) and x[0] == -20 and x[-1] == 20
    assert np.all(np.isin(req + [-1.5, 1.5], x))  # exact lines
    fine = (x[:-1] >= -1.5) & (x[1:] <= 1.5)
    assert fine.sum() == 60 and np.allclose(s[fine], h, rtol=1e-12, atol=0)
    assert np.all(s[~fine] >= h * (1 - 1e-12)) and np.all(s <= hf * (1 + 1e-12))
    assert np.all(s[1:] / s[:-1] <= g * (1 + 1e-9)) and np.all(s[:-1] / s[1:] <= g * (1 + 1e-9))
    assert np.allclose(x, -x[::-1], atol=1e-12)  # symmetric
    y = graded_lines(-20, 10, (-1.5, 1.5), h, g, None, required=[0.0])
    sy = np.diff(y)
    assert y[0] == -20 and y[-1] == 10 and 0.0 in y and np.all(sy > 0)
    assert np.all(sy[1:] / sy[:-1] <= g * (1 + 1e-9)) and sy.max() > hf  # no cap
    u = graded_lines(0, 1, (0, 1), 0.1)
    assert len(u) == 11 and np.allclose(np.diff(u), 0.1)


def test_graded_lines_short_segments_and_errors():
    x = graded_lines(0, 1, (0.3, 0.5), 0.1, required=[0.95, 0.4])
    s = np.diff(x)
    assert x[0] == 0 and x[-1] == 1 and 0.95 in x and 0.4 in x and np.all(s >= 0.05 - 1e-12)
    with pytest.raises(ValueError, match="fine"):
        graded_lines(0, 1, (0.3, 0.55), 0.1)
    with pytest.raises(ValueError, match="required"):
        graded_lines(0, 1, (0.3, 0.5), 0.1, required=[0.42])
    with pytest.raises(ValueError, match="required"):
        graded_lines(0, 1, (0.3, 0.5), 0.1, required=[1.5])


# ------------------------------------------------------------------------ scenes (1 rank)
@pytest.mark.parametrize("name", list(BUILDERS))
def test_scene_consistent(name):
    s = scene(name)
    check_local(s)
    assert [b.tag for b in s.bodies] == [1, 2] and s.pairs == [(0, 1)]
    assert list(s.boundaries) == TAGS[name]
    assert [s.boundaries[n] for n in TAGS[name]] == list(range(1, len(TAGS[name]) + 1))
    x, cells, tags, kinds = local(s)
    cen = x[cells].mean(axis=1)
    for b in s.bodies:  # Body.shape = window ∩ cut shape: interior cells are inside
        inner = (tags == b.tag) & (kinds == INTERIOR)
        assert np.all(b.shape(cen[inner]) < 0)
        assert np.all(b.bbox[0] <= cen[inner]) and np.all(cen[inner] <= b.bbox[1])


@pytest.mark.parametrize("name", list(BUILDERS))
def test_body_cells_are_the_tags_find(name):
    """Scene.body_cells (one sort per scene) returns what MeshTags.find does, body by body,
    read-only, and no cells for a tag no cell has."""
    s = scene(name)
    for b in s.bodies:
        cells = s.body_cells(b.tag)
        assert cells.dtype == np.int32 and not cells.flags.writeable
        assert np.array_equal(cells, s.cell_tags.find(b.tag)) and len(cells)
    assert len(s.body_cells(99)) == 0


@pytest.mark.parametrize("name", list(BUILDERS))
def test_counts_from_the_grid(name):
    """Active cells per body = the window's grid cells with a negative vertex (direct count)."""
    s = scene(name)
    xl, yl = s.cut.xlines, s.cut.ylines
    X, Y = np.meshgrid(xl, yl)
    counts = global_counts(s)
    for b in s.bodies:
        w = s.cut.windows[b.tag]
        phi = s.cut.levelsets[b.tag](np.stack([X.ravel(), Y.ravel()], 1)).reshape(X.shape)
        corners = np.stack([phi[:-1, :-1], phi[:-1, 1:], phi[1:, :-1], phi[1:, 1:]])
        cx, cy = np.meshgrid(0.5 * (xl[1:] + xl[:-1]), 0.5 * (yl[1:] + yl[:-1]))
        inside = (cx > w[0, 0]) & (cx < w[1, 0]) & (cy > w[0, 1]) & (cy < w[1, 1])
        active = inside & (corners.min(axis=0) < 0)
        ncut = np.sum(active & (corners.max(axis=0) > 0))
        assert counts[f"{b.name}/{CUT}"] == ncut
        assert counts[f"{b.name}/{INTERIOR}"] == active.sum() - ncut
    if name != "hertz":  # an interface across the grid: both bodies have cut cells
        assert all(counts[f"{b.name}/{CUT}"] > 0 for b in s.bodies)


@pytest.mark.parametrize("name", list(BUILDERS))
def test_boundaries_on_grid_lines(name):
    s = scene(name)
    x, cells, tags, _ = local(s)
    pairs, nb = edge_table(cells)
    exterior = nb[:, 1] < 0
    for bname, spec in BOUNDARIES[name].items():
        facets = s.facet_tags.indices[s.facet_tags.values == s.boundaries[bname]]
        if spec is None:  # a cut boundary: not grid aligned, no facet
            assert len(facets) == 0, bname
            continue
        body, lines = spec
        on = np.zeros(len(pairs), bool)
        for axis, value in lines:
            assert value in (s.cut.xlines if axis == 0 else s.cut.ylines)
            on |= np.all(x[pairs][..., axis] == value, axis=1)
        want = exterior & on & (tags[nb[:, 0]] == s.bodies[body].tag)
        assert want.any() and as_set(facet_nodes(s, facets)) == as_set(pairs[want]), bname


def test_hertz_geometry():
    s = scene("hertz")
    x, cells, tags, kinds = local(s)
    assert not np.any((tags == 1) & (kinds == CUT))  # the block is not cut
    cyl = tags == 2
    at0 = np.any(np.all(x[cells] == 0.0, axis=2), axis=1)
    assert list(np.unique(tags[at0])) == [1, 2]  # both bodies have a vertex at the origin
    assert np.sum(at0 & cyl) == 2 and np.all(kinds[at0 & cyl] == CUT)
    ymin = x[cells][..., 1].min(axis=1)
    assert ymin[cyl].min() == 0.0  # the cylinder's lowest cells: the row above the origin
    lowest = cyl & (ymin == 0.0)
    xs = x[cells[lowest]][..., 0]
    assert np.all(kinds[lowest] == CUT) and np.isclose(xs.min(), -xs.max())
    assert np.isclose(s.bodies[1].shape(np.zeros((1, 2)))[0], 0.0)
    assert s.h_contact == 0.2 and np.all(np.isin([-10.0, 0.0, 10.0, -1.6, 1.6], s.cut.xlines))
    # facet lengths of the grid-aligned sides
    for bname, length in [
        ("block_bottom", 40),
        ("block_sides", 40),
        ("block_top", 40),
        ("cylinder_top", 20),
    ]:
        p = x[facet_nodes(s, s.facet_tags.indices[s.facet_tags.values == s.boundaries[bname]])]
        assert np.isclose(np.linalg.norm(p[:, 0] - p[:, 1], axis=1).sum(), length), bname


def test_interface_windows():
    """patch (n = 5) and two_blocks (h = 2: ny = 11): the interface is mid-cell, the windows end
    on the lines just beyond it, and the cut rows are the overlap of the two windows."""
    p, t = scene("patch"), scene("two_blocks")
    assert np.allclose(p.cut.ylines, np.linspace(0, 1, 6)) and np.allclose(p.cut.xlines[1], 0.2)
    assert np.allclose([p.cut.windows[1][1, 1], p.cut.windows[2][0, 1]], [0.6, 0.4])
    ty = np.linspace(0, 20, 12)
    assert np.allclose(t.cut.ylines, ty) and 10.0 not in t.cut.ylines
    assert np.allclose(t.cut.xlines, np.linspace(0, 40, 21))
    assert np.all(np.isin([10, 30], t.cut.xlines))
    assert t.cut.windows[1][1, 1] == t.cut.ylines[6] and t.cut.windows[2][0, 1] == t.cut.ylines[5]
    assert np.array_equal(t.cut.windows[2][:, 0], [10.0, 30.0])
    for s in (p, t):
        x, cells, tags, kinds = local(s)
        ymid = x[cells][..., 1].mean(axis=1)
        assert np.ptp(ymid[kinds == CUT]) < 1e-12  # one row of cut cells, in both bodies
        assert set(tags[kinds == CUT]) == {1, 2}


def test_cut_scene_small_and_errors():
    import dolfinx_forms as df

    lines = np.linspace(0, 1, 5)
    circle = df.Circle((0.5, 0.5), 0.45)
    with pytest.raises(ValueError, match="window x bounds"):
        cut_scene(MPI.COMM_SELF, lines, lines, [("a", 1, [[0.1, 0], [1, 1]], circle)], {}, [], 0.25)
    with pytest.raises(ValueError, match="no active cell"):
        cut_scene(
            MPI.COMM_SELF,
            lines,
            lines,
            [CutBody("a", 1, np.array([[0, 0], [1, 1]]), df.Circle((5, 5), 0.3))],
            {},
            [],
            0.25,
        )
    with pytest.raises(ValueError, match="grid line"):
        patch_cut_scene(MPI.COMM_SELF, n=4)  # interface 0.5 on a line
    s = cut_scene(MPI.COMM_SELF, lines, lines, [("a", 1, [[0, 0], [1, 1]], circle)], {}, [], 0.25)
    _, _, _, kinds = check_local(s)
    assert len(kinds) == 16 and np.sum(kinds == INTERIOR) == 4  # the middle 2 x 2 are inside
    assert np.allclose(s.bodies[0].bbox, [[0.05, 0.05], [0.95, 0.95]])  # from the grid crossings
    # the zero contour on a grid line: cells touching it from inside are interior, the ones
    # beyond (phi = 0 at their lowest vertices) are not active: no cut cell at all
    s = cut_scene(
        MPI.COMM_SELF,
        lines,
        lines,
        [("a", 1, [[0, 0], [1, 1]], half_plane((0, 0.5), (0, 1), 10))],
        {},
        [],
        0.25,
    )
    _, _, _, kinds = check_local(s)
    assert len(kinds) == 8 and np.all(kinds == INTERIOR) and len(s.cut.ghost_facets.indices) == 0
    assert np.allclose(s.bodies[0].bbox, [[0, 0], [1, 0.5]])


# ------------------------------------------------------------------------ 1 vs 2 ranks
def two_rank_report(comm):
    """Collective: per scene, the local checks on every rank plus the global counts; cells
    touching the contact box are all owned by rank 0."""
    from meshes.hertz import hertz_contact_box
    from dolfinx_forms.mesh.scene import cell_bboxes

    with pytest.raises(ValueError, match="grid line"):  # raised on every rank, no hang
        patch_cut_scene(comm, n=4)
    with pytest.raises(ValueError, match="no active cell"):
        lines = np.linspace(0, 1, 3)
        cut_scene(
            comm,
            lines,
            lines,
            [("a", 1, [[0, 0], [1, 1]], half_plane((0, -1), (0, 1), 9))],
            {},
            [],
            0.5,
        )
    # the second body's cells are made on rank 1: its error still reaches every rank
    with pytest.raises(ValueError, match="body 'b'.*no active cell"):
        lines = np.linspace(0, 1, 3)
        good, bad = half_plane((0, 0.5), (0, 1), 9), half_plane((0, -1), (0, 1), 9)
        cut_scene(comm, lines, lines, [("a", 1, [[0, 0], [1, 1]], good),
                                       ("b", 2, [[0, 0], [1, 1]], bad)], {}, [], 0.5)  # fmt: skip
    report = {}
    for name, build in BUILDERS.items():
        s = build(comm)
        x, cells, _, _ = check_local(s)
        nloc = s.mesh.topology.index_map(2).size_local
        report[name] = global_counts(s)
        report[name]["ghost_cells"] = comm.allreduce(s.mesh.topology.index_map(2).num_ghosts)
        if comm.rank != 0:
            lo, hi = cell_bboxes(x, cells[:nloc])
            if name == "hertz":
                box = hertz_contact_box()
                assert not np.any(np.all((lo <= box[1]) & (hi >= box[0]), axis=1))
    return report


def _serial_counts():
    return {name: global_counts(scene(name)) for name in BUILDERS}


def _compare(report):
    for name, counts in _serial_counts().items():
        par = dict(report[name])
        assert par.pop("ghost_cells") > 0, name
        assert par == counts, name


def test_two_ranks_match_one_rank():
    mpirun = shutil.which("mpirun")
    if mpirun is None or MPI.COMM_WORLD.size > 1:
        pytest.skip("no mpirun, or already under mpirun (no nested launch)")
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    r = subprocess.run(
        [mpirun, "--oversubscribe", "-n", "2", sys.executable, __file__],
        capture_output=True,
        text=True,
        env=env,
        timeout=120,
    )
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    _compare(json.loads(r.stdout.strip().splitlines()[-1]))


@pytest.mark.mpi
def test_two_ranks_in_process():
    comm = MPI.COMM_WORLD
    if comm.size == 1:
        pytest.skip("run under mpirun -n 2 (test_two_ranks_match_one_rank spawns it)")
    assert comm.size == 2, "this test is meant for mpirun -n 2"
    _compare(two_rank_report(comm))


if __name__ == "__main__":
    out = two_rank_report(MPI.COMM_WORLD)
    if MPI.COMM_WORLD.rank == 0:
        print(json.dumps(out))
