"""Scene data contract and the gmsh -> DOLFINx conversion shared by all generators.

A *scene* is several elastic bodies meshed into ONE DOLFINx mesh. The bodies are disjoint:
each one is its own gmsh surface with its own curves, so bodies that touch along a line
have duplicate (coincident but distinct) vertices there. Cells are tagged with their body's
tag (1, 2, ...) by the exact signed distance of the bodies' shapes at the cell centroid.

Usage inside a generator (gmsh runs on rank 0 only)::

    with gmsh_model(comm, "name"):
        if comm.rank == 0:
            ...                      # build the gmsh geometry, gmsh.model.mesh.generate(2)
        scene = scene_from_gmsh(comm, bodies, markers, pairs, h_contact, contact_box)
    return scene

Parallel layout: every cell whose vertex bounding box intersects the contact box is owned by
rank 0, where the contact geometry is computed (a Python cell partitioner, see
:func:`contact_partitioner`); the rest is split geometrically. Without an explicit
``contact_box`` the box is derived from the contact pairs (:func:`pairs_contact_boxes`: the
overlap of each pair's bounding boxes inflated by CONTACT_BOX_MARGIN h_contact, one box per
pair); ``contact_box=False`` selects DOLFINx's default graph partitioner (no contact on rank 0).
With {"boxes", "owners"} (the multi-step MPM) each box goes to its own rank, its cells owned
elsewhere sent there as ghost cells.
"""

from __future__ import annotations

import contextlib
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    import dolfinx.mesh

__all__ = [
    "Body",
    "Scene",
    "scene_from_gmsh",
    "scene_from_arrays",
    "gmsh_model",
    "check_cells",
    "contact_partitioner",
    "cell_bboxes",
    "box_hits",
    "add_polygon",
    "on_box_side",
    "summary",
    "cell_edges",
    "max_edge_in_box",
    "extract_gmsh",
    "tag_boundaries",
    "pairs_contact_boxes",
    "partitioner_kwargs",
    "CONTACT_BOX_MARGIN",
]

# Default contact box: each pair's bbox overlap inflated by this many h_contact. The contact
# search (dolfinx_forms.geometry.pairs) covers the overlap inflated by band + h_contact (default
# band 2 h_contact) and locates closest points up to h_contact / 2 outside a cell: 4 covers it. A
# larger band needs an explicit contact_box.
CONTACT_BOX_MARGIN = 4.0
# the most cells a scene builder makes: ~2e7 quadrilaterals are ~4e7 dofs, beyond any 2D run
# this code is measured on (1e6 dofs take 2-3.5 GB); above it gmsh or numpy would run for
# minutes or abort on memory instead of a message (`check_cells`)
MAX_CELLS = 2e7


def check_cells(builder, cells, hint="use a larger h"):
    """ValueError unless 0 < cells <= MAX_CELLS (an estimate of the cells `builder` would make,
    checked before any meshing or allocation)."""
    if not 0 < cells <= MAX_CELLS:
        raise ValueError(
            f"{builder}: the sizes give ~{cells:.3g} cells, outside (0, {MAX_CELLS:.0e}] ({hint})"
        )


@dataclass
class Body:
    name: str
    tag: int  # its value in Scene.cell_tags (1, 2, ...)
    shape: object  # dolfinx_forms shape: exact signed distance (shape(points (n,2))), < 0 inside
    bbox: np.ndarray  # (2, 2) [[xmin, ymin], [xmax, ymax]] (reference configuration)


@dataclass
class CutData:
    """The structured grid of a cut-cell scene (dolfinx_forms/mesh/cut_scene.py)."""

    xlines: np.ndarray
    ylines: np.ndarray
    windows: dict[int, np.ndarray]  # body tag -> (2, 2) window
    levelsets: dict[int, object]  # body tag -> cut shape
    kind_tags: dolfinx.mesh.MeshTags  # cells (owned + ghost): INTERIOR 0 / CUT 1
    ghost_facets: dolfinx.mesh.MeshTags  # value 1 on the interior facets touching a cut cell


_NO_CELLS = np.zeros(0, np.int32)
_NO_CELLS.flags.writeable = False


@dataclass
class Scene:
    mesh: dolfinx.mesh.Mesh  # all bodies in ONE mesh, disjoint (no shared vertices)
    cell_tags: dolfinx.mesh.MeshTags  # body tag per cell (owned and ghost cells)
    facet_tags: dolfinx.mesh.MeshTags  # boundary facets, values from `boundaries`
    boundaries: dict[str, int]  # name -> facet tag value
    bodies: list[Body]
    pairs: list[tuple[int, int]]  # contact pairs as indices into bodies (i, j)
    h_contact: float  # mesh size at the contact
    cell_type: str  # "triangle" or "quadrilateral"
    cut: CutData | None = None  # structured cut-cell scenes (meshes/cut.py) only

    def body_cells(self, tag) -> np.ndarray:
        """The cells of body `tag` on this rank (owned and ghost, ascending; read-only): what
        `cell_tags.find(tag)` returns, from one sort of the tags per scene. A scan of every cell
        per body made each step of N grains O(N^2): 2000 scans a step at 400 grains."""
        cache = self.__dict__.get("_body_cells")
        if cache is None:
            values, indices = self.cell_tags.values, self.cell_tags.indices
            order = np.argsort(values, kind="stable")  # each body's cells stay ascending
            tags, start = np.unique(values[order], return_index=True)
            bounds = np.append(start, len(values))
            cache = {}
            for k, t in enumerate(tags):
                cells = np.ascontiguousarray(indices[order[bounds[k] : bounds[k + 1]]])
                cells.flags.writeable = False
                cache[int(t)] = cells
            self.__dict__["_body_cells"] = cache
        return cache.get(int(tag), _NO_CELLS)


# --------------------------------------------------------------------------- gmsh session
_GMSH_CELLS = {2: ("triangle", 3), 3: ("quadrilateral", 4)}  # gmsh element type -> (name, nv)
_EDGES = {"triangle": [(0, 1), (1, 2), (2, 0)], "quadrilateral": [(0, 1), (0, 2), (1, 3), (2, 3)]}
_state = {"status_pending": False}
_OPTIONS = {  # quiet, sizes only from fields/transfinite, no merging of duplicate points
    "General.Terminal": 0,
    "Geometry.AutoCoherence": 0,
    "Mesh.MeshSizeFromPoints": 0,
    "Mesh.MeshSizeFromCurvature": 0,
    "Mesh.MeshSizeExtendFromBoundary": 0,
    "Mesh.ElementOrder": 1,
    "Mesh.RecombineAll": 0,
    "Mesh.RecombinationAlgorithm": 1,  # blossom
    "Mesh.SubdivisionAlgorithm": 0,
}


def import_gmsh():
    """The gmsh module, its library loaded with RTLD_DEEPBIND first where it is not loaded yet.

    Why: gmsh.py loads libgmsh (18 MB, ~90 dependencies) with ctypes, RTLD_NOW. After DOLFINx's
    import has put PETSc, DOLFINx and their dependencies in the global symbol scope, each of
    libgmsh's symbol lookups first searches those: 0.40 s here, against 0.16 s with
    RTLD_DEEPBIND (its own dependencies searched first; the same shared objects, already
    loaded, are bound). gmsh.py's own load then finds the library open. Where the preload is
    not possible (no libgmsh, no RTLD_DEEPBIND) gmsh.py loads it as usual."""
    import signal
    import sys

    first, handler = "gmsh" not in sys.modules, signal.getsignal(signal.SIGINT)
    if first:
        _preload_libgmsh()
    import gmsh

    # gmsh.py sets SIGINT to the default action (a plain kill, no clean-up) at import; the
    # program's own handling (Python's KeyboardInterrupt) comes back
    if first and handler is not None:
        signal.signal(signal.SIGINT, handler)
    return gmsh


def _preload_libgmsh():
    import ctypes
    import importlib.util
    import os
    from ctypes.util import find_library

    spec = importlib.util.find_spec("gmsh")
    if spec is None or spec.origin is None or not hasattr(os, "RTLD_DEEPBIND"):
        return
    # gmsh.py's own search: libgmsh.so beside it, else the linker's
    path = os.path.join(os.path.dirname(os.path.realpath(spec.origin)), "libgmsh.so")
    path = path if os.path.exists(path) else find_library("gmsh")
    if path is None:
        return
    try:  # kept open by the loader: gmsh.py's CDLL(path) gets the same object
        ctypes.CDLL(path, mode=os.RTLD_LOCAL | os.RTLD_DEEPBIND)
    except OSError:
        pass  # gmsh.py's own load reports what is wrong


def _gmsh_initialized(gmsh) -> bool:
    """gmsh 4.8 has no isInitialized(): model.list() is [] before the first initialize and
    raises after a finalize, printing 'Gmsh has not been initialized' to fd 2 (silenced here)."""
    import os
    import sys

    sys.stderr.flush()
    saved, devnull = os.dup(2), os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 2)
    try:
        return len(gmsh.model.list()) > 0
    except Exception:
        return False
    finally:
        os.dup2(saved, 2)
        os.close(saved)
        os.close(devnull)


@contextlib.contextmanager
def gmsh_model(comm, name: str):
    """Rank 0: an initialized, quiet gmsh with a fresh current model `name`; other ranks: nothing.
    comm None: this process alone, without MPI (GetFEM's benchmark meshes without mpi4py).

    If gmsh was not initialized it is initialized here and finalized on exit; otherwise only the
    model is removed and the options changed here are restored. If the body raises on rank 0,
    the error is broadcast (matching the first collective of :func:`scene_from_gmsh`) so the
    other ranks raise too instead of hanging.
    """
    if comm is not None and comm.rank != 0:
        yield None
        return
    gmsh = import_gmsh()

    own = not _gmsh_initialized(gmsh)
    if own:
        gmsh.initialize()
    saved = {k: gmsh.option.getNumber(k) for k in _OPTIONS}
    for k, v in _OPTIONS.items():
        gmsh.option.setNumber(k, v)
    gmsh.model.add(name)
    _state["status_pending"] = True  # scene_from_gmsh has not broadcast its status yet
    try:
        yield gmsh
    except BaseException as e:
        if comm is not None and comm.size > 1 and _state["status_pending"]:
            comm.bcast(("error", f"rank 0 failed building gmsh model {name!r}: {e!r}"), root=0)
        raise
    finally:
        _state["status_pending"] = False
        if own:
            gmsh.finalize()
        else:
            gmsh.model.remove()
            for k, v in saved.items():
                gmsh.option.setNumber(k, v)


def add_polygon(gmsh, points, n=None, quads=False) -> int:
    """Rank 0: a plane surface bounded by the closed polygon `points` (own points and lines,
    built-in kernel, not synchronized); returns the surface tag. With n = (nx, ny) and 4
    points, a transfinite (structured) surface: edges 0 and 2 get nx cells, 1 and 3 get ny;
    `quads` recombines it into quadrilaterals (else structured triangles)."""
    geo = gmsh.model.geo
    p = [geo.addPoint(float(q[0]), float(q[1]), 0.0) for q in points]
    lines = [geo.addLine(p[i], p[(i + 1) % len(p)]) for i in range(len(p))]
    surface = geo.addPlaneSurface([geo.addCurveLoop(lines)])
    if n is not None:
        assert len(points) == 4
        for i, line in enumerate(lines):
            geo.mesh.setTransfiniteCurve(line, int(n[i % 2]) + 1)
        geo.mesh.setTransfiniteSurface(surface, cornerTags=p)
        if quads:
            geo.mesh.setRecombine(2, surface)
    return surface


def on_box_side(lo, hi, sides, tol):
    """Predicate for locate_entities_boundary: x on any of the given sides of the box
    [lo, hi] (sides from "left", "right", "bottom", "top")."""
    checks = {"left": (0, lo[0]), "right": (0, hi[0]), "bottom": (1, lo[1]), "top": (1, hi[1])}
    return lambda x: np.any([np.isclose(x[checks[s][0]], checks[s][1], atol=tol) for s in sides], 0)


# --------------------------------------------------------------------------- partitioner
def cell_bboxes(x: np.ndarray, cells: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Vertex bounding boxes (lo, hi), each (num_cells, 2), of cells (num_cells, nv) into x."""
    xc = x[cells][..., :2]
    return xc.min(axis=1), xc.max(axis=1)


def cell_edges(x: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """Edge lengths (num_cells, num_edges) of triangles or quads (DOLFINx vertex order)."""
    edges = _EDGES["triangle" if cells.shape[1] == 3 else "quadrilateral"]
    xc = x[:, :2]
    return np.stack(
        [np.linalg.norm(xc[cells[:, i]] - xc[cells[:, j]], axis=1) for i, j in edges], axis=1
    )


def max_edge_in_box(x: np.ndarray, cells: np.ndarray, box) -> float:
    """Longest edge of the cells whose vertices all lie in box [[xmin, ymin], [xmax, ymax]]."""
    xc = x[cells][..., :2]
    inside = np.all((xc >= np.asarray(box)[0]) & (xc <= np.asarray(box)[1]), axis=(1, 2))
    return float(cell_edges(x, cells[inside]).max(initial=0.0))


def _facet_neighbours(cells: np.ndarray, cell_name: str) -> tuple[np.ndarray, np.ndarray]:
    """Pairs (a, b) of cells sharing an edge; `cells` in DOLFINx vertex order."""
    edges = _EDGES[cell_name]
    e = np.sort(np.concatenate([cells[:, list(p)] for p in edges]), axis=1).astype(np.int64)
    owner = np.tile(np.arange(len(cells)), len(edges))
    # an edge as one integer: a sort of keys, not np.unique(axis=0)'s of rows (0.12 s of the
    # 0.2 s this partition took a step at 100 grains on 2 ranks)
    key = e[:, 0] * (int(e.max(initial=0)) + 1) + e[:, 1]
    order = np.argsort(key, kind="stable")
    _, cnt = np.unique(key[order], return_counts=True)
    shared = np.repeat(cnt, cnt) == 2  # interior edges appear twice, consecutively after sorting
    pair_start = order[shared][::2], order[shared][1::2]
    return owner[pair_start[0]], owner[pair_start[1]]


def box_hits(lo: np.ndarray, hi: np.ndarray, boxes: np.ndarray) -> list[np.ndarray]:
    """For each box (2, 2) of `boxes` the cells (ascending) whose bounding box [lo, hi] (n, 2)
    meets it (closed sets): the broad phase's pairs between the boxes and the cells
    (`_cpp.candidate_pairs_between`, a sort and sweep per grid cell: O(n log n + hits)). A scan
    per box made the partition of N grains' mesh O(N^2) (1181 boxes x 150k cells at 400
    grains); a sort along x and a range per box still cost 0.16 s a step there."""
    from dolfinx_forms import _cpp

    boxes = np.asarray(boxes, float).reshape(-1, 2, 2)
    valid = np.flatnonzero(np.all(boxes[:, 0] <= boxes[:, 1], axis=1))  # an empty box hits none
    out = [np.zeros(0, np.int64) for _ in boxes]
    if len(lo) == 0 or len(valid) == 0:
        return out
    cells = np.ascontiguousarray(np.stack([lo, hi], axis=1), dtype=float)
    pairs = _cpp.candidate_pairs_between(np.ascontiguousarray(boxes[valid]), cells)
    starts = np.searchsorted(pairs[:, 0], np.arange(1, len(valid)))
    for k, hit in zip(valid, np.split(pairs[:, 1].astype(np.int64), starts)):
        out[k] = hit
    return out


def pairs_contact_boxes(bodies, pairs, h_contact, margin=CONTACT_BOX_MARGIN) -> np.ndarray:
    """Boxes (k, 2, 2) whose union holds every contact: for each pair (i, j) whose bounding
    boxes, inflated by margin h_contact, overlap, that overlap (k = 0: no pair can touch)."""
    d = float(margin) * float(h_contact)
    boxes = []
    for i, j in pairs:
        bi, bj = (np.asarray(bodies[k].bbox, float) for k in (i, j))
        lo = np.maximum(bi[0], bj[0]) - d
        hi = np.minimum(bi[1], bj[1]) + d
        if np.all(lo < hi):
            boxes.append([lo, hi])
    return np.array(boxes, dtype=float).reshape(-1, 2, 2)


def partitioner_kwargs(comm, x, cells, cell_name, contact_box, bodies, pairs, h_contact) -> dict:
    """create_mesh keyword arguments: the contact partitioner for `contact_box` ((2, 2) or
    (k, 2, 2)); None: boxes from the pairs (in parallel only; nothing to do on one rank);
    False: none (DOLFINx's graph partitioner). Same result on every rank (bodies, pairs and
    h_contact are collective data)."""
    if contact_box is False:
        return {}
    if contact_box is None:
        if comm.size == 1:
            return {}
        contact_box = pairs_contact_boxes(bodies, pairs, h_contact)
        if len(contact_box) == 0:
            return {}
    return {"partitioner": contact_partitioner(x, cells, cell_name, contact_box)}


def contact_partitioner(x: np.ndarray, cells: np.ndarray, cell_name: str, contact_box):
    """A DOLFINx cell partitioner (comm, nparts, tdim, cells, ghost_mode) -> AdjacencyList_int32.

    `x`, `cells` are the arrays given to create_mesh on this rank (all of them on rank 0, empty
    elsewhere); the partitioner receives the cells in that order. Cells whose vertex bbox
    intersects `contact_box` ((2, 2), or (k, 2, 2): a union of boxes) go to rank 0, topped up
    with the cells nearest to the box up to an equal share; the rest is cut into equal chunks
    along the longest axis of the bounding box for ranks 1..nparts-1. With contact_box a dict
    {"boxes": (k, 2, 2), "owners": (k,)} the contact is computed by pair on several ranks:
    each cell hit by a box is owned by the rank of the first box that hits it and is a ghost
    cell on the ranks of the other boxes that hit it (every rank holds all the cells of its
    boxes, whatever their owner); the rest fills the ranks up to equal shares.
    GhostMode.none: one destination per cell (the dict form still sends the box ghosts);
    shared_facet (and shared_vertex, treated alike): owner first, then the owners of its edge
    neighbours (the ranks that must hold it as a ghost). If the box holds more than 1/nparts of
    the cells, rank 0 simply gets more than its share.
    """
    owners = None
    if isinstance(contact_box, dict):  # {"boxes": (k, 2, 2), "owners": (k,)}: one rank per box
        owners = np.asarray(contact_box["owners"], np.int32)
        contact_box = contact_box["boxes"]
    boxes = np.asarray(contact_box, dtype=float).reshape(-1, 2, 2)
    import dolfinx.cpp  # dolfinx where meshes are made: gmsh_model alone needs none (GetFEM)
    import dolfinx.mesh

    AdjacencyList_int32 = dolfinx.cpp.graph.AdjacencyList_int32

    def partition(comm, nparts, tdim, graph, ghost_mode):
        n = graph.num_nodes
        if n == 0:
            return AdjacencyList_int32(np.zeros(0, np.int32), np.zeros(1, np.int32))
        assert n == len(cells), "partitioner got cells other than the ones passed to create_mesh"
        owner = np.zeros(n, np.int32)
        if nparts > 1 and owners is not None:
            # each box's cells to its owner (the first box that hits a cell wins); the rest,
            # sorted along the longest axis, fills every rank up to an equal share
            lo, hi = cell_bboxes(x, cells)
            centroid = 0.5 * (lo + hi)
            owner[:] = -1
            box_cells = []  # (cells, rank) of each box, last box first
            for hit, r in zip(box_hits(lo, hi, boxes[::-1]), owners[::-1] % nparts):
                owner[hit] = r
                box_cells.append((hit, r))
            rest = np.flatnonzero(owner < 0)
            axis = int(np.argmax(np.ptp(centroid, axis=0)))
            rest = rest[np.argsort(centroid[rest, axis], kind="stable")]
            need = np.maximum(0, -(-n // nparts) - np.bincount(owner[owner >= 0], minlength=nparts))
            take = np.minimum(np.cumsum(need), len(rest))
            for r, (a, b) in enumerate(zip(np.concatenate([[0], take[:-1]]), take)):
                owner[rest[a:b]] = r
            owner[rest[take[-1] :]] = nparts - 1
        elif nparts > 1:
            lo, hi = cell_bboxes(x, cells)
            centroid = 0.5 * (lo + hi)
            hit = np.zeros(n, bool)
            for box in boxes:
                hit |= np.all((lo <= box[1]) & (hi >= box[0]), axis=1)
            rest = np.flatnonzero(~hit)
            # rank 0 tops up to an equal share with the cells nearest to the boxes
            n0 = max(0, -(-n // nparts) - int(hit.sum()))
            c = centroid[rest]
            d = np.full(len(rest), np.inf)
            for box in boxes:
                d = np.minimum(
                    d, np.linalg.norm(np.maximum(0.0, np.maximum(box[0] - c, c - box[1])), axis=1)
                )
            near = np.argsort(d, kind="stable")
            others = rest[near[n0:]]
            axis = int(np.argmax(np.ptp(centroid[others], axis=0))) if len(others) else 0
            others = others[np.argsort(centroid[others, axis], kind="stable")]
            for r, chunk in enumerate(np.array_split(others, nparts - 1)):
                owner[chunk] = r + 1
        # ghosts: (cell, rank) of the box cells owned by another rank than the box's
        ga, gb = np.zeros(0, np.int64), np.zeros(0, np.int32)
        if nparts > 1 and owners is not None:
            ga = np.concatenate([ga] + [hit for hit, r in box_cells])
            gb = np.concatenate([gb] + [np.full(len(hit), r, np.int32) for hit, r in box_cells])
        if nparts == 1 or (ghost_mode == dolfinx.mesh.GhostMode.none and len(ga) == 0):
            return AdjacencyList_int32(owner.reshape(-1, 1))
        if ghost_mode != dolfinx.mesh.GhostMode.none:
            # each cell is also sent to the owners of its edge neighbours
            a, b = _facet_neighbours(cells, cell_name)
            ga = np.concatenate([ga, a, b])
            gb = np.concatenate([gb, owner[b], owner[a]])
        keep = gb != owner[ga]
        dests = np.unique(np.stack([ga[keep], gb[keep]], axis=1), axis=0)  # sorted by cell
        counts = 1 + np.bincount(dests[:, 0], minlength=n)
        offsets = np.zeros(n + 1, np.int32)
        offsets[1:] = np.cumsum(counts)
        data = np.empty(offsets[-1], np.int32)
        data[offsets[:-1]] = owner
        rank_in_cell = np.arange(len(dests)) - np.searchsorted(dests[:, 0], dests[:, 0])
        slot = offsets[dests[:, 0]] + 1 + rank_in_cell
        data[slot] = dests[:, 1]
        return AdjacencyList_int32(data, offsets)

    return partition


# --------------------------------------------------------------------------- gmsh -> Scene
def extract_gmsh(gmsh):
    """Rank 0: (gmsh element type, x (n, 2), cells (m, nv) int64 in DOLFINx vertex order)."""
    tags, coords, _ = gmsh.model.mesh.getNodes()
    types, _, nodes = gmsh.model.mesh.getElements(dim=2)
    types = [int(t) for t in types]
    if len(types) != 1 or types[0] not in _GMSH_CELLS:
        raise RuntimeError(
            f"need one first-order cell type (3-node triangles or 4-node quads), "
            f"gmsh gave types {types}"
        )
    gtype = types[0]
    name, nv = _GMSH_CELLS[gtype]
    lut = np.full(int(tags.max()) + 1, -1, np.int64)
    lut[tags.astype(np.int64)] = np.arange(len(tags))
    cells = lut[nodes[0].astype(np.int64)].reshape(-1, nv)
    used, cells = np.unique(cells, return_inverse=True)  # drop nodes used by no cell
    cells = cells.reshape(-1, nv)
    import dolfinx.io.gmshio  # imports gmsh (0.3 s): only where gmsh meshes are converted

    perm = dolfinx.io.gmshio.cell_perm_array(dolfinx.mesh.to_type(name), nv)
    x = coords.reshape(-1, 3)[used, :2]
    return gtype, np.ascontiguousarray(x), np.ascontiguousarray(cells[:, perm]).astype(np.int64)


def tag_boundaries(mesh, cell_values, bodies, boundary_markers):
    """(facet_tags named "boundaries", boundaries name -> tag value) from boundary_markers
    (name -> (tag, predicate[, body]), see :func:`scene_from_gmsh`); cell_values: body tag of
    every local cell (owned and ghost), used by the markers restricted to one body."""
    import dolfinx.mesh

    tdim = mesh.topology.dim
    mesh.topology.create_connectivity(tdim - 1, tdim)
    f2c = mesh.topology.connectivity(tdim - 1, tdim)
    fmap = mesh.topology.index_map(tdim - 1)
    nfacets = fmap.size_local + fmap.num_ghosts
    fvalues = np.zeros(nfacets, np.int32)
    names = [b.name for b in bodies]
    boundaries = {}
    for name, spec in boundary_markers.items():
        tag, pred = spec[0], spec[1]
        boundaries[name] = int(tag)
        facets = dolfinx.mesh.locate_entities_boundary(mesh, tdim - 1, pred)
        if len(spec) > 2 and len(facets):
            body = spec[2] if not isinstance(spec[2], str) else names.index(spec[2])
            first_cell = f2c.array[f2c.offsets[facets]]
            facets = facets[cell_values[first_cell] == bodies[body].tag]
        facets = facets[fvalues[facets] == 0]
        fvalues[facets] = tag
    marked = np.flatnonzero(fvalues).astype(np.int32)
    facet_tags = dolfinx.mesh.meshtags(mesh, tdim - 1, marked, fvalues[marked])
    facet_tags.name = "boundaries"
    return facet_tags, boundaries


def scene_from_gmsh(
    comm,
    bodies,
    boundary_markers,
    pairs,
    h_contact,
    contact_box=None,
    ghost_mode=None,
) -> Scene:
    """Collective: build the Scene from the meshed gmsh model on rank 0 (first-order 2D cells).

    boundary_markers: name -> (tag, predicate) or (tag, predicate, body), predicate(x) for x of
    shape (3, n) -> bool (all facet vertices must pass, as in locate_entities_boundary); `body`
    (index into `bodies` or its name) restricts the name to facets of that body's cells, needed
    where two bodies have coincident facets. A facet gets the first matching name (dict order).
    contact_box: (2, 2) [[xmin, ymin], [xmax, ymax]] (or (k, 2, 2), a union of boxes) whose
    cells are all owned by rank 0; None (default): derived from the pairs and the bodies' bboxes
    (:func:`pairs_contact_boxes`); False: DOLFINx's graph partitioner. ghost_mode: DOLFINx's
    GhostMode (default shared_facet).
    """
    status = None
    if comm.rank == 0:
        gmsh = import_gmsh()

        gtype, x, cells = extract_gmsh(gmsh)
        status = ("ok", gtype)
    status = comm.bcast(status, root=0)  # also receives a build error from gmsh_model
    _state["status_pending"] = False
    if status[0] != "ok":
        raise RuntimeError(status[1])
    cell_name, nv = _GMSH_CELLS[status[1]]
    if comm.rank != 0:
        x, cells = np.zeros((0, 2)), np.zeros((0, nv), np.int64)
    return scene_from_arrays(
        comm,
        x,
        cells,
        cell_name,
        bodies,
        boundary_markers,
        pairs,
        h_contact,
        contact_box,
        ghost_mode,
    )


def scene_from_arrays(
    comm,
    x,
    cells,
    cell_name,
    bodies,
    boundary_markers,
    pairs,
    h_contact,
    contact_box=None,
    ghost_mode=None,
) -> Scene:
    """Collective: the Scene of the first-order cells (m, nv) int64 (DOLFINx vertex order) on
    the nodes x (n, 2) given on rank 0 (the other ranks pass empty arrays of those shapes);
    cell_name "triangle" or "quadrilateral", on every rank. The other arguments as in
    :func:`scene_from_gmsh`, which converts gmsh's mesh and calls this."""
    import dolfinx.mesh
    import ufl

    ghost_mode = dolfinx.mesh.GhostMode.shared_facet if ghost_mode is None else ghost_mode
    domain = ufl.Mesh(ufl.VectorElement("Lagrange", getattr(ufl, cell_name), 1))
    kwargs = partitioner_kwargs(comm, x, cells, cell_name, contact_box, bodies, pairs, h_contact)
    mesh = dolfinx.mesh.create_mesh(comm, cells, x, domain, ghost_mode=ghost_mode, **kwargs)

    # cell tags: the body whose shape is most negative at the centroid (owned + ghost cells)
    tdim = 2
    imap = mesh.topology.index_map(tdim)
    ncells = imap.size_local + imap.num_ghosts
    dofs = mesh.geometry.dofmap.array.reshape(ncells, 3 if cell_name == "triangle" else 4)
    centroid = mesh.geometry.x[dofs][..., :2].mean(axis=1)
    cvalues = np.zeros(ncells, np.int32)
    if ncells:
        phi = np.stack([np.asarray(b.shape(centroid)) for b in bodies])
        cvalues[:] = np.array([b.tag for b in bodies], np.int32)[np.argmin(phi, axis=0)]
    cell_tags = dolfinx.mesh.meshtags(mesh, tdim, np.arange(ncells, dtype=np.int32), cvalues)
    cell_tags.name = "bodies"

    facet_tags, boundaries = tag_boundaries(mesh, cvalues, bodies, boundary_markers)

    return Scene(
        mesh=mesh,
        cell_tags=cell_tags,
        facet_tags=facet_tags,
        boundaries=boundaries,
        bodies=list(bodies),
        pairs=[tuple(p) for p in pairs],
        h_contact=float(h_contact),
        cell_type=cell_name,
    )


def summary(scene: Scene) -> str:
    """One line: global cells and vertices per body (collective)."""
    comm, top = scene.mesh.comm, scene.mesh.topology
    top.create_connectivity(2, 0)
    c2v = top.connectivity(2, 0).array.reshape(len(scene.cell_tags.values), -1)
    owned_cells, owned_vertices = top.index_map(2).size_local, top.index_map(0).size_local
    counts = np.zeros((len(scene.bodies), 2), np.int64)
    for k, b in enumerate(scene.bodies):
        cells = scene.body_cells(b.tag)
        counts[k] = np.sum(cells < owned_cells), np.sum(np.unique(c2v[cells]) < owned_vertices)
    counts = comm.allreduce(counts)  # one reduction, not two per body
    parts = [f"{b.name}: {nc} cells, {nv} vertices" for b, (nc, nv) in zip(scene.bodies, counts)]
    head = f"{scene.cell_type}, {comm.size} rank(s), h_contact={scene.h_contact:g}; "
    return head + "; ".join(parts)
