"""Triangle meshes of the flat strip for the Discrete Elastic Plate (paper section 3.2, Fig. 4).

Reference coordinates: x along the length, y across the width (-W/2 <= y <= W/2), z = 0.
Clamp convention (section 4, "first two and last two columns"): the mesh spans x in
[-c, L + c] and every node with x <= c moves rigidly with the fixed clamp, every node with
x >= L - c with the moving one. On the structured mesh c is half a column spacing, so the two
clamped columns at x = -h/2 and +h/2 straddle the clamp line x = 0 (as the rod's clamped
edges straddle its clamp points): the rigid triangles between them carry the clamped
slope, and a triangle's normal is the slope at the middle of its chord, x = 0. The free plate
between the clamp lines is then exactly L, and the clamped elastica converges as O(h^2).
(Clamping the columns at x = -h and 0 instead puts the clamped slope at x = -h/2, lengthens
the plate by one spacing and biases H_mid by O(h): docs/physics/conventions.md.)
A mesh given without c (a file) is held to the same convention: its clamp zone at each end is
its first layer of triangles, 2c deep, and it must be L + 2c long to round-off.

Meshes are validated (mesh_from_arrays: one flat disc covering the rectangle, no duplicate
nodes, holes, folds...) and sized (MAX_TRIANGLES, plate_memory_estimate_bytes) with one-line
InputErrors before any work.

Nodes are ordered by x (then y): clamped-left nodes first, clamped-right last, and the
Hessian has a narrow band (about six times the nodes per column) for a strip.
All connectivity (edges, hinges) is built with sorting, O(N log N).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..limits import check_integer, check_memory
from ..limits import InputError

#: Default target triangle count, as in the paper (N_mesh ~ 2000).
DEFAULT_TRIANGLES = 2000


@dataclass(frozen=True, eq=False)
class PlateMesh:
    """A flat triangle mesh of the strip with its clamp zones.

    nodes (N, 2) reference positions, triangles (T, 3) node indices, counter-clockwise
    (normals +z in the flat state), length L between the clamp lines x = 0 and x = L,
    width W, clamp_depth c; clamp_tolerance: how far (m) beyond x = c (x = L - c) a node still
    counts as clamped (at least 1e-9 L; a file's round-off, see coordinate_tolerance).
    Build with `mesh_from_arrays` (validates and orders).
    """

    nodes: np.ndarray
    triangles: np.ndarray
    length: float
    width: float
    clamp_depth: float
    clamp_tolerance: float = 0.0

    # ------------------------------------------------------------------ counts
    @property
    def node_count(self) -> int:
        return len(self.nodes)

    @property
    def triangle_count(self) -> int:
        return len(self.triangles)

    # ------------------------------------------------------------------ geometry
    @cached_property
    def triangle_areas(self) -> np.ndarray:
        p = self.nodes[self.triangles]
        d1, d2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
        return 0.5 * (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])

    @cached_property
    def node_areas(self) -> np.ndarray:
        """Lumped (barycentric) area per node: a third of each adjacent triangle."""
        return np.bincount(self.triangles.ravel(), weights=np.repeat(self.triangle_areas / 3.0, 3),
                           minlength=self.node_count)

    @cached_property
    def clamped_left(self) -> np.ndarray:
        return self.nodes[:, 0] <= self.clamp_depth + self._clamp_tolerance

    @cached_property
    def clamped_right(self) -> np.ndarray:
        return self.nodes[:, 0] >= self.length - self.clamp_depth - self._clamp_tolerance

    @property
    def _clamp_tolerance(self) -> float:
        return max(1e-9 * self.length, self.clamp_tolerance)

    # ------------------------------------------------------------------ connectivity
    @cached_property
    def _edge_data(self):
        t = self.triangles
        # local edge k of a triangle runs from vertex k to vertex k+1 (counter-clockwise)
        start = t.ravel()
        end = t[:, [1, 2, 0]].ravel()
        lo, hi = np.minimum(start, end), np.maximum(start, end)
        key = lo.astype(np.int64) * self.node_count + hi
        unique, first, inverse, counts = np.unique(key, return_index=True, return_inverse=True, return_counts=True)
        if np.any(counts > 2):
            raise InputError("mesh is not a manifold: an edge is shared by more than two triangles")
        edges = np.stack([lo[first], hi[first]], axis=1)
        return edges, inverse, counts

    @cached_property
    def edges(self) -> np.ndarray:
        """Unique edges (E, 2), lower node index first."""
        return self._edge_data[0]

    @cached_property
    def edge_triangle_areas(self) -> np.ndarray:
        """Sum of the reference areas of the (one or two) triangles sharing each edge."""
        _, inverse, _ = self._edge_data
        return np.bincount(inverse, weights=np.repeat(self.triangle_areas, 3), minlength=len(self.edges))

    @cached_property
    def _hinge_data(self):
        _, inverse, counts = self._edge_data
        occurrences = np.argsort(inverse, kind="stable")  # the (triangle, local edge) slots grouped by edge
        interior = np.flatnonzero(counts == 2)
        group_start = np.r_[0, np.cumsum(counts)[:-1]]
        slot_a = occurrences[group_start[interior]]
        slot_b = occurrences[group_start[interior] + 1]
        tri_a, k_a = np.divmod(slot_a, 3)
        tri_b, k_b = np.divmod(slot_b, 3)
        t = self.triangles
        v0 = t[tri_a, k_a]
        v1 = t[tri_a, (k_a + 1) % 3]
        opposite_a = t[tri_a, (k_a + 2) % 3]
        opposite_b = t[tri_b, (k_b + 2) % 3]
        if np.any(t[tri_b, k_b] != v1):
            raise InputError("mesh triangles are not consistently oriented")
        hinges = np.stack([v0, v1, opposite_a, opposite_b], axis=1)
        return hinges, np.stack([tri_a, tri_b], axis=1), interior

    @cached_property
    def hinges(self) -> np.ndarray:
        """Bending pairs (H, 4): shared edge (v0, v1), then the vertex opposite it in triangle a
        = (v0, v1, a) and in triangle b = (v1, v0, b), both counter-clockwise."""
        return self._hinge_data[0]

    @cached_property
    def hinge_triangles(self) -> np.ndarray:
        """The two triangles (a, b) of each bending pair, (H, 2)."""
        return self._hinge_data[1]

    @cached_property
    def hinge_edges(self) -> np.ndarray:
        """Index into `edges` of each hinge's shared edge."""
        return self._hinge_data[2]

    # ------------------------------------------------------------------ queries
    def locate(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Containing triangle and barycentric weights (Q, 3) of reference points (Q, 2).

        Used once per model for a handful of points (centre, centerline stations), so a
        vectorised scan over triangles in chunks is enough.
        """
        points = np.atleast_2d(np.asarray(points, dtype=float))
        p = self.nodes[self.triangles]
        tri = np.full(len(points), -1)
        weights = np.zeros((len(points), 3))
        a, b, c = p[:, 0], p[:, 1], p[:, 2]
        det = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
        tol = 1e-10
        for chunk in range(0, len(points), 64):
            q = points[chunk:chunk + 64, None, :]
            l1 = ((q[..., 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (q[..., 1] - a[:, 1]) * (c[:, 0] - a[:, 0])) / det
            l2 = ((b[:, 0] - a[:, 0]) * (q[..., 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (q[..., 0] - a[:, 0])) / det
            l0 = 1.0 - l1 - l2
            inside = np.minimum(np.minimum(l0, l1), l2) >= -tol
            found = inside.any(axis=1)
            first = np.argmax(inside, axis=1)
            rows = np.arange(len(first))
            tri[chunk:chunk + 64] = np.where(found, first, -1)
            weights[chunk:chunk + 64] = np.stack([l0[rows, first], l1[rows, first], l2[rows, first]], axis=1)
        if np.any(tri < 0):
            bad = points[np.argmax(tri < 0)]
            raise InputError(f"point ({bad[0]:g}, {bad[1]:g}) m lies outside the mesh")
        return tri, weights

    def interpolation_matrix(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(node indices (Q, 3), weights (Q, 3)) so that f(points) = sum(w * f[nodes], axis=1)."""
        tri, weights = self.locate(points)
        return self.triangles[tri], weights

    def bandwidth_nodes(self) -> int:
        """Largest node-index distance within a bending pair (sets the Hessian's band)."""
        h = self.hinges if len(self.hinges) else self.triangles
        return int(np.max(h.max(axis=1) - h.min(axis=1)))

    def as_dict(self) -> dict:
        return {"nodes": self.node_count, "triangles": self.triangle_count, "edges": len(self.edges),
                "hinges": len(self.hinges), "clamp_depth": self.clamp_depth}


#: Hard cap on the triangles of a plate mesh: a 1e6-triangle strip already needs tens of GiB
#: for its banded Hessian (plate_memory_estimate_bytes), and the paper uses ~2000.
MAX_TRIANGLES = 1_000_000

#: Band storages (each (3 b + 3) x 3N doubles for b = bandwidth_nodes) alive at once during a
#: run, measured (14, by tracking every SymmetricBanded on a complete 500-triangle path with its
#: thresholds) and rounded up: the current state's Hessian, its free block and Cholesky factor,
#: the same for the state being solved and for the snapshots the thresholds restart from
#: (compressed, last U, last US, first S), a shifted copy and its factor when the Hessian is
#: indefinite, and the LU fallback (its (2u+1)-row copy and LAPACK's (3u+1)-row work array).
RUN_BAND_COPIES = 16

#: Bytes per triangle besides the bands, measured with tracemalloc: 3.5 kB kept by the model
#: (edges, hinges, rest lengths, stiffnesses, the assembler's scatter indices) and 5.6 kB of
#: element blocks while a Hessian is assembled; rounded up.
RUN_BYTES_PER_TRIANGLE = 10_000

#: x-ordered unstructured (gmsh) meshes have a wider band than the structured mesh of the same
#: size: 1.26x to 1.43x measured at W/L = 1/20, 1/6, 1/2 (2000 and 8000 triangles).
UNSTRUCTURED_BAND_FACTOR = 1.5


def structured_size(length: float, width: float, triangles: int) -> tuple[int, int]:
    """(n, n_y) of the structured mesh with about `triangles` triangles in [0, L] (see structured_mesh)."""
    # 2 n n_y triangles in [0, L] with h_x = sqrt(3)/2 h_y
    h_y = math.sqrt(2.0 * length * width / (0.5 * math.sqrt(3.0) * triangles))
    n_y = _round_even(width / h_y, 2)
    n = max(3, 2 * int(0.5 * length / (0.5 * math.sqrt(3.0) * width / n_y)) + 1)  # nearest odd
    return n, n_y


def plate_memory_estimate_bytes(length: float, width: float, triangles: int, *, nodes: int | None = None,
                                bandwidth_nodes: int | None = None, unstructured: bool = False) -> float:
    """Estimated peak memory (bytes) of a plate run on a mesh of the L x W strip.

    Without `nodes` and `bandwidth_nodes` they are those of the structured mesh for a target of
    `triangles` (structured_mesh's construction: n + 2 columns of about n_y + 1.5 nodes, a
    hinge spanning two columns, bandwidth ~ 2 (n_y + 2) nodes), widened by
    UNSTRUCTURED_BAND_FACTOR for an unstructured (gmsh) mesh; give them for an actual mesh
    (a file: its node count and PlateMesh.bandwidth_nodes()). The run holds RUN_BAND_COPIES
    banded matrices of 3N columns and 3 b + 3 rows (ddg.solve.banded; the plate's bandwidth
    is 3 b + 2) and RUN_BYTES_PER_TRIANGLE per triangle; fixed overheads (recorded rows,
    eigensolver work) are left out, so it underestimates small runs (docs/findings/measured.md)
    and is meant for the large sizes the machine cannot run, where the bands dominate
    (ddg.limits.check_memory refuses them).
    """
    if nodes is None or bandwidth_nodes is None:
        n, n_y = structured_size(length, width, triangles)
        nodes = (n + 2) * (n_y + 1.5) if nodes is None else nodes
        if bandwidth_nodes is None:
            bandwidth_nodes = 2 * (n_y + 2) * (UNSTRUCTURED_BAND_FACTOR if unstructured else 1.0)
        triangles = max(triangles, (n + 1) * (2 * n_y + 1))
    band_bytes = 8.0 * (3.0 * bandwidth_nodes + 3.0) * 3.0 * nodes
    return RUN_BAND_COPIES * band_bytes + RUN_BYTES_PER_TRIANGLE * float(triangles)


def check_plate_size(length: float, width: float, triangles, *, unstructured: bool = False) -> int:
    """The target triangle count as an int in [16, MAX_TRIANGLES] whose run fits in memory
    (InputError otherwise, one line, before any mesh is built)."""
    if not (isinstance(triangles, (int, np.integer)) and not isinstance(triangles, bool) and triangles >= 16):
        raise InputError(f"triangles = {triangles!r} must be an integer >= 16 (the paper uses ~2000)")
    triangles = check_integer("triangles", triangles, 16, MAX_TRIANGLES,
                              "the plate's banded Hessian grows as triangles^1.5 (the paper uses ~2000)")
    check_memory("triangles", triangles,
                 plate_memory_estimate_bytes(length, width, triangles, unstructured=unstructured))
    return triangles


def check_mesh_memory(mesh: "PlateMesh") -> None:
    """Refuse a mesh whose plate run would not fit in memory (its actual size and band)."""
    band = mesh.bandwidth_nodes()
    estimate = plate_memory_estimate_bytes(mesh.length, mesh.width, mesh.triangle_count, nodes=mesh.node_count,
                                           bandwidth_nodes=band)
    check_memory("triangles", f"{mesh.triangle_count} ({mesh.node_count} nodes, a Hessian band of {band} nodes)",
                 estimate)


def coordinate_tolerance(length: float, coordinates: np.ndarray, dtype=np.float64) -> float:
    """Distance (m) below which two mesh positions or lengths count as equal.

    1e-6 L: below it nothing physical changes (a strip 1e-6 L too long moves H_mid by ~1e-6
    relative) and it is far below any mesh spacing the size cap allows (h > 1e-4 L at 1e6
    triangles), so distinct nodes are never merged; it is far above double round-off. Plus
    16 units in the last place of the largest coordinate in the file's precision: a file in
    single precision (eps 1.2e-7) at an offset of metres is good to only ~1e-7 m.
    """
    eps = np.finfo(dtype).eps if np.issubdtype(dtype, np.floating) else 0.0
    magnitude = float(np.max(np.abs(coordinates))) if coordinates.size else 0.0
    return 1e-6 * length + 16.0 * eps * magnitude


def _count(number: int, noun: str) -> str:
    return f"{number} {noun}{'' if number == 1 else 's'}"


def _at(point) -> str:
    return "(" + ", ".join(f"{v:.6g}" for v in point) + ")"


def _check_numbers(nodes, triangles):
    """Shape, dtype, index range and finiteness: (nodes (N, 2 or 3) float, triangles int64, dtype)."""
    try:
        raw = np.asarray(nodes)
    except (TypeError, ValueError):  # ragged nested lists
        raise InputError("mesh nodes must be an (N, 2) or (N, 3) array of real coordinates") from None
    if raw.dtype.kind not in "iuf":  # complex, text, objects, booleans
        raise InputError(f"mesh nodes have dtype {raw.dtype}; expected real coordinates")
    dtype, nodes = raw.dtype, raw.astype(float)
    if nodes.ndim != 2 or nodes.shape[1] not in (2, 3):
        raise InputError(f"mesh nodes have shape {nodes.shape}; expected (N, 2) or (N, 3)")
    if len(nodes) == 0:
        raise InputError("mesh has no nodes")
    try:
        triangles = np.asarray(triangles)
    except (TypeError, ValueError):
        raise InputError("mesh triangles must be a (T, 3) array of integer node indices") from None
    if triangles.ndim != 2 or triangles.shape[1] != 3:
        raise InputError(f"mesh triangles have shape {triangles.shape}; expected (T, 3)")
    if len(triangles) == 0:
        raise InputError("mesh has no triangles")
    if not np.issubdtype(triangles.dtype, np.integer):
        raise InputError(f"mesh triangles must be integer node indices, not {triangles.dtype}")
    bad = (triangles < 0) | (triangles >= len(nodes))
    if np.any(bad):
        count = int(bad.sum())
        raise InputError(f"mesh has triangle node index {triangles[bad][0]} out of range 0..{len(nodes) - 1} "
                         f"({count} such {'index' if count == 1 else 'indices'})")
    finite = np.all(np.isfinite(nodes), axis=1)
    if not np.all(finite):
        k = int(np.argmin(finite))
        raise InputError(f"mesh has {_count(int((~finite).sum()), 'node')} with non-finite coordinates "
                         f"(e.g. node {k}: {_at(nodes[k])})")
    return nodes, triangles.astype(np.int64), dtype


def _check_flat(nodes: np.ndarray, tol: float) -> np.ndarray:
    if nodes.shape[1] == 3:
        spread = float(np.ptp(nodes[:, 2]))
        if spread > tol:
            raise InputError(f"mesh is not flat: its z coordinates vary by {spread:.3g} m (allowed {tol:.2g} m); "
                             "give the flat reference strip in the x-y plane")
        nodes = nodes[:, :2]
    return nodes


def _check_shared_nodes(nodes: np.ndarray, triangles: np.ndarray, tol: float) -> None:
    """A triangle soup (no node shared) and coincident (unmerged) nodes."""
    if len(triangles) > 1 and len(nodes) == 3 * len(triangles):
        raise InputError(f"mesh is a triangle soup: its {len(triangles)} triangles share no nodes or edges (each has "
                         "its own 3 nodes, as from an unmerged export); merge coincident nodes")
    from scipy.spatial import cKDTree

    pairs = cKDTree(nodes).query_pairs(tol, output_type="ndarray")
    if len(pairs):
        count = len(np.unique(pairs.max(axis=1)))  # all but one node of each cluster
        raise InputError(f"mesh has {_count(count, 'duplicate node')} (e.g. at {_at(nodes[pairs[0, 0]])}, "
                         f"within {tol:.2g} m); merge them")


def _signed_areas(nodes: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    p = nodes[triangles]
    d1, d2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    return 0.5 * (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])


def _check_disc(nodes: np.ndarray, triangles: np.ndarray, areas: np.ndarray, tol: float) -> None:
    """The counter-clockwise triangles must form one flat disc covering the bounding rectangle:
    no repeated triangle, no edge of more than two triangles, no overlap (fold), one piece,
    no pinched node, no hole, a rectangular outline."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    n, t = len(nodes), triangles
    rows, repeats = np.unique(np.sort(t, axis=1), axis=0, return_counts=True)
    if np.any(repeats > 1):
        example = rows[np.argmax(repeats > 1)]
        raise InputError(f"mesh has {_count(int((repeats - 1).sum()), 'duplicate triangle')} (e.g. the one with "
                         f"corners {', '.join(_at(nodes[k]) for k in example)}); remove them")
    start, end = t.ravel(), t[:, [1, 2, 0]].ravel()
    lo, hi = np.minimum(start, end), np.maximum(start, end)
    key = lo * n + hi
    edges, counts = np.unique(key, return_counts=True)
    if np.any(counts > 2):
        a, b = divmod(int(edges[np.argmax(counts > 2)]), n)
        raise InputError(f"mesh is not a manifold: {_count(int((counts > 2).sum()), 'edge')} shared by more than two "
                         f"triangles (e.g. the edge from {_at(nodes[a])} to {_at(nodes[b])})")
    # a shared edge runs once each way around its two counter-clockwise triangles; twice the same
    # way means both lie on the same side of it: they overlap (a fold or an inverted triangle)
    directed, dcounts = np.unique(start * n + end, return_counts=True)
    if np.any(dcounts > 1):
        a, b = divmod(int(directed[np.argmax(dcounts > 1)]), n)
        raise InputError(f"mesh has overlapping (folded or inverted) triangles: the two triangles at the edge from "
                         f"{_at(nodes[a])} to {_at(nodes[b])} lie on the same side of it")
    order = np.argsort(key, kind="stable")
    shared = key[order[1:]] == key[order[:-1]]
    tri_a, tri_b = order[:-1][shared] // 3, order[1:][shared] // 3
    graph = coo_matrix((np.ones(len(tri_a)), (tri_a, tri_b)), shape=(len(t), len(t)))
    pieces, labels = connected_components(graph, directed=False)
    if pieces > 1:
        largest = int(np.bincount(labels).max())
        raise InputError(f"mesh has {pieces} disconnected pieces (triangles joined by no shared edge; the largest "
                         f"has {largest} of {len(t)} triangles); the strip must be one piece")
    boundary = np.stack(divmod(edges[counts == 1], n), axis=1)
    degree = np.bincount(boundary.ravel(), minlength=n)
    if np.any(degree > 2):
        raise InputError(f"mesh is not a manifold at the node {_at(nodes[int(np.argmax(degree > 2))])}: "
                         "pieces of it meet only at that node")
    on_boundary = np.flatnonzero(degree)
    loop_graph = coo_matrix((np.ones(len(boundary)), (boundary[:, 0], boundary[:, 1])), shape=(n, n))
    loops = connected_components(loop_graph, directed=False)[0] - (n - len(on_boundary))
    euler = n - len(edges) + len(t)
    if loops != 1 or euler != 1:
        raise InputError(f"mesh has a hole ({max(loops, 2 - euler)} boundary loops, Euler characteristic "
                         f"V - E + F = {euler}; the strip must be simply connected)")
    # a disc covering less than its bounding rectangle has a notched outline; the tolerance is
    # the area of a band `tol` wide along the perimeter (boundary nodes off the sides by round-off)
    span = np.ptp(nodes, axis=0)
    rectangle, covered = float(span[0] * span[1]), float(np.abs(areas).sum())
    if abs(covered - rectangle) > 2.0 * tol * float(span.sum()):
        raise InputError(f"mesh covers {covered:.6g} m^2 but the rectangle it spans, {span[0]:.6g} x {span[1]:.6g} m, "
                         f"is {rectangle:.6g} m^2: its outline is not a rectangle (a notch or a cut corner?)")


def _inferred_clamp_depth(x: np.ndarray, triangles: np.ndarray, length: float, tol: float) -> float:
    """Clamp depth c of a mesh given without one: the mesh spans L + 2c, and the clamped band
    [-c, c] around each clamp line (2c deep, from the end of the mesh) holds the mesh's first
    layer of triangles, as on the structured and gmsh meshes (one layer of rigid triangles
    centred on the clamp line; a deeper band would move the clamp inward and shorten the free
    plate). So 2c must lie between the shallowest and the deepest triangle touching each end:
    exactly the layer's depth, to `tol`, when the ends are one structured layer."""
    x0, x1 = float(x.min()), float(x.max())
    span = x1 - x0
    tx = x[triangles]
    windows = []
    for depth, touches in ((tx.max(axis=1) - x0, np.any(tx <= x0 + tol, axis=1)),
                           (x1 - tx.min(axis=1), np.any(tx >= x1 - tol, axis=1))):
        windows.append((float(depth[touches].min()), float(depth[touches].max())))
    (left_lo, left_hi), (right_lo, right_hi) = windows
    lo, hi = max(left_lo, right_lo), min(left_hi, right_hi)
    if lo > hi + 2.0 * tol:
        raise InputError(f"mesh has first layers of triangles of different depths at its two ends "
                         f"({left_lo:.6g} to {left_hi:.6g} m at x = {x0:.6g}, {right_lo:.6g} to {right_hi:.6g} m at "
                         f"x = {x1:.6g}); the clamp zones 2c at both ends must match")
    lo, hi = min(lo, hi), max(lo, hi)
    if not lo - tol <= span - length <= hi + tol:
        if hi - lo <= 2.0 * tol:  # one structured layer at each end: 2c is known
            expected = f"L + 2c = {length + 0.5 * (lo + hi):.6g} m (+- {tol:.2g} m)"
            zone = f"2c = {0.5 * (lo + hi):.6g} m, the depth of the mesh's first layer of triangles"
        else:
            expected = f"L + 2c between {length + lo:.6g} and {length + hi:.6g} m (+- {tol:.2g} m)"
            zone = f"2c from {lo:.6g} to {hi:.6g} m, ending within the mesh's first layer of triangles"
        raise InputError(f"mesh is {span:.6g} m long but the strip needs {expected}: L = {length:.6g} m between "
                         f"the clamp lines and a clamp zone {zone}, at each end")
    return 0.5 * (span - length)


def mesh_from_arrays(nodes, triangles, length: float, width: float, *, clamp_depth: float | None = None,
                     allow_unused_nodes: bool = True) -> PlateMesh:
    """Validate a flat triangle mesh of [x0, x1] x [-W/2, W/2] and bring it to our convention.

    The mesh must be one flat disc covering the rectangle L + 2c by W (c > 0; nodes within 2c
    of each end, i.e. in the band [-c, c] around a clamp line, are clamped); it is shifted so
    the clamp lines sit at x = 0 and x = L, triangles are made counter-clockwise, unused nodes
    dropped (refused with allow_unused_nodes=False) and nodes ordered by x. Without
    clamp_depth, c is inferred: the clamp zone at each end is the mesh's first layer of
    triangles (`_inferred_clamp_depth`), so a mesh of the wrong length is refused, not clamped
    deeper. Every defect (shape, dtype, indices, non-finite or non-flat nodes, a triangle soup,
    duplicate nodes or triangles, degenerate, overlapping or non-manifold triangles, pieces,
    holes, outline, size) raises a one-line InputError starting "mesh ".
    """
    for name, value in (("length", length), ("width", width)):
        if isinstance(value, bool) or not (isinstance(value, (int, float, np.integer, np.floating))
                                           and math.isfinite(value) and value > 0):
            raise InputError(f"{name} = {value!r} must be a positive finite number of metres")
    nodes, triangles, dtype = _check_numbers(nodes, triangles)
    tol = coordinate_tolerance(length, nodes, dtype)
    nodes = _check_flat(nodes, tol)
    # unused nodes are dropped here and, if refused, only after the checks below: a hole cut
    # out of a mesh leaves its nodes behind, and "has a hole" is the message that explains it
    used = np.unique(triangles)
    unused = np.setdiff1d(np.arange(len(nodes)), used)
    unused_at = nodes[unused[0]] if len(unused) else None
    if len(unused):
        remap = np.full(len(nodes), -1)
        remap[used] = np.arange(len(used))
        nodes, triangles = nodes[used], remap[triangles]
    _check_shared_nodes(nodes, triangles, tol)

    x0, x1 = nodes[:, 0].min(), nodes[:, 0].max()
    y0, y1 = nodes[:, 1].min(), nodes[:, 1].max()
    span = x1 - x0
    signed = _signed_areas(nodes, triangles)
    degenerate = np.abs(signed) <= 1e-12 * max(span, y1 - y0) ** 2
    if np.any(degenerate):
        example = triangles[np.argmax(degenerate)]
        raise InputError(f"mesh has {_count(int(degenerate.sum()), 'degenerate (zero-area) triangle')} (e.g. the "
                         f"one with corners {', '.join(_at(nodes[k]) for k in example)})")
    triangles = np.where((signed < 0)[:, None], triangles[:, [0, 2, 1]], triangles)
    _check_disc(nodes, triangles, signed, tol)

    if abs((y1 - y0) - width) > tol + 1e-6 * width:
        hint = "; the strip must lie along x" if y1 - y0 > span else ""
        raise InputError(f"mesh width {y1 - y0:.6g} m differs from the strip width W = {width:.6g} m "
                         f"by more than {tol + 1e-6 * width:.2g} m{hint}")
    if clamp_depth is None:
        clamp_depth = _inferred_clamp_depth(nodes[:, 0], triangles, length, tol)
    elif not (clamp_depth > 1e-9 * length and math.isclose(span, length + 2 * clamp_depth, rel_tol=1e-9)):
        raise InputError(
            f"mesh is {span:.6g} m long but the strip needs L + 2c = {length + 2 * clamp_depth:.6g} m "
            f"(L = {length:.6g} m plus a clamp zone c = {clamp_depth:.6g} m beyond each clamp line; nodes within 2c "
            "of each end are clamped)"
        )
    if len(unused) and not allow_unused_nodes:
        raise InputError(f"mesh has {_count(len(unused), 'node')} used by no triangle (e.g. node {unused[0]} at "
                         f"{_at(unused_at)}); remove them")
    nodes = nodes - np.array([x0 + clamp_depth, 0.5 * (y0 + y1)])

    order = np.lexsort((nodes[:, 1], nodes[:, 0]))
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    mesh = PlateMesh(nodes[order], rank[triangles], float(length), float(width), float(clamp_depth), tol)
    if not mesh.clamped_left.any() or not mesh.clamped_right.any():
        raise InputError("mesh has no nodes in a clamp band")
    if mesh.clamped_left.sum() + mesh.clamped_right.sum() >= mesh.node_count:
        raise InputError(f"clamp_depth c = {clamp_depth:g} m leaves no free nodes; allowed 0 < c < L/2")
    return mesh


def _round_even(value: float, minimum: int) -> int:
    return max(minimum, 2 * int(round(0.5 * value)))


def equilateral_columns(length: float, width: float, n_y: int) -> np.ndarray:
    """Column positions x of an exactly equilateral lattice with n_y rows across W: spacing
    h_x = sqrt(3)/2 W/n_y about a regular column at L/2, and the two clamped columns at each end
    at -h_x/2, +h_x/2 (L - h_x/2, L + h_x/2). The strip between a clamp column and the first
    lattice column is g in [h_x/2, 3 h_x/2) wide (the remainder of L / h_x): only its triangles
    are not equilateral."""
    h_x = 0.5 * math.sqrt(3.0) * width / n_y
    c = 0.5 * h_x
    k = int(math.floor((0.5 * length - c - 0.5 * h_x) / h_x + 1e-12))
    lattice = 0.5 * length + h_x * np.arange(-k, k + 1)
    return np.r_[-c, c, lattice, length - c, length + c]


def structured_mesh(length: float, width: float, triangles: int = DEFAULT_TRIANGLES, *,
                    equilateral: bool = False) -> PlateMesh:
    """Near-equilateral structured mesh of the strip with about `triangles` triangles in [0, L].

    equilateral=True: the columns of equilateral_columns instead of equally spaced ones (every
    triangle equilateral except in the strip next to each clamp), so that the rounding of the
    counts does not make the lattice anisotropic (the column spacing otherwise differs from the
    equilateral one: data/plate_modes/modes.md); the rest as below.

    Columns of nodes at x = (j - 1/2) h_x, j = 0..n + 1, with n = L / h_x odd: the two clamped
    columns at each end straddle the clamp lines (module docstring). Regular columns hold
    n_y + 1 nodes at y = -W/2 + k h_y; the columns between them are shifted by h_y / 2 and keep
    nodes on both edges, so interior triangles have sides h_y and sqrt(h_x^2 + h_y^2 / 4) with
    h_x ~ sqrt(3)/2 h_y (equilateral up to the rounding of n and n_y), and the edge rows hold
    half-size triangles. n_y is even and the middle column x = L/2 is regular, so the plate's
    centre (L/2, 0) is a node. `triangles` is an integer in [16, MAX_TRIANGLES] whose plate run
    fits in memory (check_plate_size).
    """
    triangles = check_plate_size(length, width, triangles)
    n, n_y = structured_size(length, width, triangles)
    if equilateral:
        return equilateral_mesh(length, width, n_y)
    return _column_mesh(length, width, n_y, (np.arange(n + 2) - 0.5) * (length / n))


def equilateral_mesh(length: float, width: float, rows: int) -> PlateMesh:
    """The exactly equilateral structured mesh with `rows` (even, >= 2) rows of triangles
    across W (equilateral_columns; structured_mesh(..., equilateral=True) picks rows from a
    triangle count). Uniform refinement: rows times r gives every spacing divided by r."""
    rows = check_integer("rows", rows, 2, 100_000, "an even number of triangle rows across W")
    if rows % 2:
        raise InputError(f"rows = {rows} is odd; it must be even (the centre y = 0 is a row of nodes)")
    column_x = equilateral_columns(length, width, rows)
    check_plate_size(length, width, 2 * (len(column_x) - 2) * rows)
    return _column_mesh(length, width, rows, column_x)


def _column_mesh(length: float, width: float, n_y: int, column_x: np.ndarray) -> PlateMesh:
    """The structured mesh on columns at column_x (n + 2 of them, n odd, the two first and two
    last clamped) with n_y rows (structured_mesh's docstring)."""
    nodes, tris = _zipper(width, n_y, column_x)
    return mesh_from_arrays(nodes, tris, length, width, clamp_depth=float(column_x[1]))


def ghost_clamp_mesh(length: float, width: float, triangles: int = DEFAULT_TRIANGLES, *,
                     rows: int | None = None, columns: int | None = None) -> PlateMesh:
    """Structured mesh whose clamp lines are node columns, for the mid-edge plate.

    Columns at x = k L / n, k = -1 .. n + 1 (n even, so the centre (L/2, 0) is a node), rows
    n_y across W (even), h_x = L / n nearest to sqrt(3)/2 W / n_y (or n = `columns` given: an
    anisotropic mesh, h_x independent of h_y); about `triangles` triangles
    in [0, L] (structured_size's rows), or `rows` = n_y given. The nodes of the columns x <= 0
    and x >= L are clamped (clamp_depth 0): the clamp columns x = 0 and x = L carry the clamped
    edges, and the columns at -h_x and L + h_x make one layer of rigid ghost triangles, whose
    normal is the clamp's (ddg.energies.midedge_bending). The free plate is exactly [0, L]."""
    if rows is None:
        triangles = check_plate_size(length, width, triangles)
        _, rows = structured_size(length, width, triangles)
    rows = check_integer("rows", rows, 2, 100_000, "an even number of triangle rows across W")
    if rows % 2:
        raise InputError(f"rows = {rows} is odd; it must be even (the centre y = 0 is a row of nodes)")
    if columns is None:
        n = max(2, 2 * int(round(length / (math.sqrt(3.0) * width / rows))))
    else:
        n = check_integer("columns", columns, 2, 1_000_000, "an even number of element columns along L")
        if n % 2:
            raise InputError(f"columns = {n} is odd; it must be even (the centre x = L/2 is a column of nodes)")
    check_plate_size(length, width, 2 * n * rows)
    h_x = length / n
    nodes, tris = _zipper(width, rows, h_x * np.arange(-1, n + 2))
    signed = _signed_areas(nodes, tris)
    tris = np.where((signed < 0)[:, None], tris[:, [0, 2, 1]], tris)
    order = np.lexsort((nodes[:, 1], nodes[:, 0]))
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    return PlateMesh(nodes[order], rank[tris], float(length), float(width), 0.0, 0.0)


def _zipper(width: float, n_y: int, column_x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Nodes (N, 2) and triangles (T, 3) of the zipper triangulation between columns at column_x
    (an odd count, the middle one regular) with n_y rows (structured_mesh's docstring)."""
    n = len(column_x) - 2
    h_y = width / n_y
    columns = np.arange(n + 2)
    middle = (n + 1) // 2
    regular = (columns - middle) % 2 == 0
    counts = np.where(regular, n_y + 1, n_y + 2)
    first = np.r_[0, np.cumsum(counts)[:-1]]

    k = np.arange(n_y + 2)
    y_regular = -0.5 * width + k[: n_y + 1] * h_y
    y_shifted = np.r_[-0.5 * width, -0.5 * width + (k[1: n_y + 1] - 0.5) * h_y, 0.5 * width]
    xs, ys = [], []
    for j in columns:  # n + 2 columns: setting up coordinates, not a hot path
        y = y_regular if regular[j] else y_shifted
        xs.append(np.full(len(y), column_x[j]))
        ys.append(y)
    nodes = np.stack([np.concatenate(xs), np.concatenate(ys)], axis=1)

    # zipper triangulation of each strip between a regular column A and a shifted column B:
    # (a0, b0, b1), then (a_{k-1}, b_k, a_k) and (a_k, b_k, b_{k+1}) for k = 1..n_y
    left = columns[:-1]
    a_first = np.where(regular[left], first[left], first[left + 1])
    b_first = np.where(regular[left], first[left + 1], first[left])
    kk = np.arange(1, n_y + 1)
    tri_first = np.stack([a_first, b_first, b_first + 1], axis=1)
    tri_up = np.stack([a_first[:, None] + kk - 1, b_first[:, None] + kk, a_first[:, None] + kk], axis=2)
    tri_down = np.stack([a_first[:, None] + kk, b_first[:, None] + kk, b_first[:, None] + kk + 1], axis=2)
    tris = np.concatenate([tri_first, tri_up.reshape(-1, 3), tri_down.reshape(-1, 3)])
    return nodes, tris
