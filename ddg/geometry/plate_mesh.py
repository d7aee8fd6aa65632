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
the plate by one spacing and biases H_mid by O(h): +0.84 % at the default mesh, measured.)

Nodes are ordered by x (then y): clamped-left nodes first, clamped-right last, and the
Hessian has a narrow band (about six times the nodes per column) for a strip.
All connectivity (edges, hinges) is built with sorting, O(N log N).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from .strip import InputError

#: Default target triangle count, as in the paper (N_mesh ~ 2000).
DEFAULT_TRIANGLES = 2000


@dataclass(frozen=True, eq=False)
class PlateMesh:
    """A flat triangle mesh of the strip with its clamp zones.

    nodes (N, 2) reference positions, triangles (T, 3) node indices, counter-clockwise
    (normals +z in the flat state), length L between the clamp lines x = 0 and x = L,
    width W, clamp_depth c. Build with `mesh_from_arrays` (validates and orders).
    """

    nodes: np.ndarray
    triangles: np.ndarray
    length: float
    width: float
    clamp_depth: float

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
        return 1e-9 * self.length

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


def mesh_from_arrays(nodes, triangles, length: float, width: float, *, clamp_depth: float | None = None) -> PlateMesh:
    """Validate a flat triangle mesh of [x0, x1] x [-W/2, W/2] and bring it to our convention.

    The mesh must span the width W and a length L + 2c (c > 0; nodes within 2c of each end,
    i.e. in the band [-c, c] around a clamp line, are clamped); it is shifted so the clamp
    lines sit at x = 0 and x = L, triangles are made counter-clockwise, unused nodes dropped
    and nodes ordered by x.
    """
    nodes = np.asarray(nodes, dtype=float)
    triangles = np.asarray(triangles)
    if nodes.ndim != 2 or nodes.shape[1] not in (2, 3):
        raise InputError(f"mesh nodes have shape {nodes.shape}; expected (N, 2) or (N, 3)")
    if nodes.shape[1] == 3:
        if np.ptp(nodes[:, 2]) > 1e-9 * max(np.ptp(nodes[:, 0]), 1e-300):
            raise InputError("mesh is not flat: its z coordinates vary; give the flat reference strip")
        nodes = nodes[:, :2]
    if triangles.ndim != 2 or triangles.shape[1] != 3 or len(triangles) == 0:
        raise InputError(f"mesh triangles have shape {triangles.shape}; expected (T, 3) with T > 0")
    if not np.issubdtype(triangles.dtype, np.integer):
        raise InputError("mesh triangles must be integer node indices")
    if triangles.min() < 0 or triangles.max() >= len(nodes):
        raise InputError(f"mesh triangles index nodes outside 0..{len(nodes) - 1}")
    if not np.all(np.isfinite(nodes)):
        raise InputError("mesh nodes contain non-finite coordinates")
    used = np.unique(triangles)
    remap = np.full(len(nodes), -1)
    remap[used] = np.arange(len(used))
    nodes, triangles = nodes[used], remap[triangles]

    x0, x1 = nodes[:, 0].min(), nodes[:, 0].max()
    y0, y1 = nodes[:, 1].min(), nodes[:, 1].max()
    if not math.isclose(y1 - y0, width, rel_tol=1e-6):
        raise InputError(f"mesh width {y1 - y0:.6g} m differs from the strip width W = {width:.6g} m")
    span = x1 - x0
    if clamp_depth is None:
        clamp_depth = 0.5 * (span - length)
    if not (clamp_depth > 1e-9 * length and math.isclose(span, length + 2 * clamp_depth, rel_tol=1e-9)):
        raise InputError(
            f"mesh length {span:.6g} m must exceed the strip length L = {length:.6g} m by a clamp zone at each end "
            "(the mesh spans L + 2c; nodes within 2c of each end are clamped)"
        )
    nodes = nodes - np.array([x0 + clamp_depth, 0.5 * (y0 + y1)])

    p = nodes[triangles]
    d1, d2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    signed = 0.5 * (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])
    if np.any(np.abs(signed) <= 1e-12 * span**2):
        raise InputError("mesh has degenerate (zero-area) triangles")
    triangles = np.where((signed < 0)[:, None], triangles[:, [0, 2, 1]], triangles)

    order = np.lexsort((nodes[:, 1], nodes[:, 0]))
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    mesh = PlateMesh(nodes[order], rank[triangles], float(length), float(width), float(clamp_depth))
    if not mesh.clamped_left.any() or not mesh.clamped_right.any():
        raise InputError("mesh has no nodes in a clamp band")
    if mesh.clamped_left.sum() + mesh.clamped_right.sum() >= mesh.node_count:
        raise InputError(f"clamp_depth c = {clamp_depth:g} m leaves no free nodes; allowed 0 < c < L/2")
    return mesh


def _round_even(value: float, minimum: int) -> int:
    return max(minimum, 2 * int(round(0.5 * value)))


def structured_mesh(length: float, width: float, triangles: int = DEFAULT_TRIANGLES) -> PlateMesh:
    """Near-equilateral structured mesh of the strip with about `triangles` triangles in [0, L].

    Columns of nodes at x = (j - 1/2) h_x, j = 0..n + 1, with n = L / h_x odd: the two clamped
    columns at each end straddle the clamp lines (module docstring). Regular columns hold
    n_y + 1 nodes at y = -W/2 + k h_y; the columns between them are shifted by h_y / 2 and keep
    nodes on both edges, so interior triangles have sides h_y and sqrt(h_x^2 + h_y^2 / 4) with
    h_x ~ sqrt(3)/2 h_y (equilateral up to the rounding of n and n_y), and the edge rows hold
    half-size triangles. n_y is even and the middle column x = L/2 is regular, so the plate's
    centre (L/2, 0) is a node.
    """
    if not (isinstance(triangles, (int, np.integer)) and not isinstance(triangles, bool) and triangles >= 16):
        raise InputError(f"triangles = {triangles!r} must be an integer >= 16 (the paper uses ~2000)")
    # 2 n n_y triangles in [0, L] with h_x = sqrt(3)/2 h_y
    h_y = math.sqrt(2.0 * length * width / (0.5 * math.sqrt(3.0) * triangles))
    n_y = _round_even(width / h_y, 2)
    n = max(3, 2 * int(0.5 * length / (0.5 * math.sqrt(3.0) * width / n_y)) + 1)  # nearest odd
    h_x, h_y = length / n, width / n_y
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
        xs.append(np.full(len(y), (j - 0.5) * h_x))
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
    return mesh_from_arrays(nodes, tris, length, width, clamp_depth=0.5 * h_x)
