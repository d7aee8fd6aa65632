"""Triangle meshes of the flat strip: the structured mesh's construction, connectivity,
hinge bookkeeping, normalisation and validation of arbitrary meshes, point location."""
from __future__ import annotations

import math

import numpy as np
import pytest

from ddg.energies.hinge_bending import hinge_bending_energy
from ddg.energies.stretch import stretching_energy
from ddg.geometry.plate_mesh import MAX_TRIANGLES, mesh_from_arrays, plate_memory_estimate_bytes, structured_mesh
from ddg.geometry.strip import InputError

LENGTH = 1.0
WIDTHS = (1 / 20, 1 / 6, 1 / 2)
TARGETS = (500, 1000, 2000, 4000)
ROUNDOFF = 1e-12


# --------------------------------------------------------------------------- helpers
def columns(mesh) -> np.ndarray:
    """Distinct x of the structured mesh's node columns."""
    return np.unique(np.round(mesh.nodes[:, 0], 12))


def rows(mesh) -> int:
    """n_y: the middle column x = L/2 is a regular one, with n_y + 1 nodes."""
    return int(np.isclose(mesh.nodes[:, 0], 0.5 * mesh.length, rtol=0, atol=1e-12).sum()) - 1


def signed_areas(points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    p = points[triangles]
    d1, d2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    return 0.5 * (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])


def edge_lengths(mesh, edges) -> np.ndarray:
    return np.linalg.norm(mesh.nodes[edges[:, 1]] - mesh.nodes[edges[:, 0]], axis=1)


def on_boundary_side(mesh, edges) -> np.ndarray:
    """Edges with both ends on the same side of the rectangle [-c, L + c] x [-W/2, W/2]."""
    x0, x1 = -mesh.clamp_depth, mesh.length + mesh.clamp_depth
    p, q = mesh.nodes[edges[:, 0]], mesh.nodes[edges[:, 1]]
    tol = 1e-12 * mesh.length
    same = np.zeros(len(edges), dtype=bool)
    for axis, value in ((0, x0), (0, x1), (1, -0.5 * mesh.width), (1, 0.5 * mesh.width)):
        same |= (np.abs(p[:, axis] - value) < tol) & (np.abs(q[:, axis] - value) < tol)
    return same


def boundary_edges(mesh) -> np.ndarray:
    """Edges of one triangle only: those not shared by a hinge."""
    interior = np.zeros(len(mesh.edges), dtype=bool)
    interior[mesh.hinge_edges] = True
    return ~interior


def count_bounds(length: float, width: float, target: int) -> tuple[float, float]:
    """Bounds on (triangles in [0, L]) / target from structured_mesh's construction.

    It aims at h_y* = sqrt(2 L W / (sqrt(3)/2 T)), i.e. nu = W / h_y* rows, and h_x = sqrt(3)/2
    h_y, i.e. n* = 2 L n_y / (sqrt(3) W) columns; it rounds to an even n_y (|n_y - nu| <= 1)
    and to n with |n - n*| <= 1, and holds n (2 n_y + 1) triangles in [0, L] (2 n_y + 1 per
    column strip, against the ideal 2 n* nu^2 / n_y = T). So the ratio is
    (n / n*) (n_y / nu)^2 (1 + 1 / (2 n_y)).
    """
    nu = width / math.sqrt(2.0 * length * width / (0.5 * math.sqrt(3.0) * target))
    n_y_lo, n_y_hi = max(nu - 1.0, 2.0), nu + 1.0
    n_star_lo = 2.0 * length * n_y_lo / (math.sqrt(3.0) * width)
    lo = (1.0 - 1.0 / n_star_lo) * (n_y_lo / nu) ** 2
    hi = (1.0 + 1.0 / n_star_lo) * (n_y_hi / nu) ** 2 * (1.0 + 1.0 / (2.0 * n_y_lo))
    return lo, hi


# --------------------------------------------------------------------------- structured mesh
@pytest.mark.parametrize("width", WIDTHS)
@pytest.mark.parametrize("target", TARGETS)
def test_structured_mesh_is_a_clean_disc(width, target):
    mesh = structured_mesh(LENGTH, width, target)
    area = (mesh.length + 2 * mesh.clamp_depth) * width
    assert np.all(mesh.triangle_areas > 0)  # counter-clockwise
    assert mesh.triangle_areas.sum() == pytest.approx(area, rel=ROUNDOFF)
    assert mesh.node_areas.sum() == pytest.approx(area, rel=ROUNDOFF)
    assert mesh.edge_triangle_areas.sum() == pytest.approx(3 * area, rel=ROUNDOFF)  # each triangle on 3 edges

    # a topological disc: Euler characteristic V - E + F = 1
    assert mesh.node_count - len(mesh.edges) + mesh.triangle_count == 1
    edges = mesh.edges
    assert np.all(edges[:, 0] < edges[:, 1]) and len(np.unique(edges, axis=0)) == len(edges)
    # every edge has one or two triangles (sum of 3 T edge slots), the single ones are
    # exactly the edges along the rectangle's sides, which they cover once
    boundary = boundary_edges(mesh)
    assert 3 * mesh.triangle_count == 2 * len(mesh.hinges) + boundary.sum()
    assert np.array_equal(boundary, on_boundary_side(mesh, edges))
    perimeter = 2 * (mesh.length + 2 * mesh.clamp_depth + width)
    assert edge_lengths(mesh, edges[boundary]).sum() == pytest.approx(perimeter, rel=ROUNDOFF)

    # nodes ordered by x, then y within a column
    x = np.round(mesh.nodes[:, 0], 12)
    assert np.array_equal(np.lexsort((mesh.nodes[:, 1], x)), np.arange(mesh.node_count))

    # the plate's centre is a node
    tri, weights = mesh.locate([[0.5 * mesh.length, 0.0]])
    corner = np.argmax(weights[0])
    assert weights[0, corner] == pytest.approx(1.0, abs=ROUNDOFF)
    assert np.allclose(mesh.nodes[mesh.triangles[tri[0], corner]], [0.5 * mesh.length, 0.0], rtol=0, atol=ROUNDOFF)


@pytest.mark.parametrize("width", WIDTHS)
@pytest.mark.parametrize("target", TARGETS)
def test_structured_mesh_clamps_two_columns_at_each_end(width, target):
    """Two columns per clamp, straddling the clamp line: x = -c and +c at the fixed end,
    L - c and L + c at the moving one (c = half the column spacing), and nothing else."""
    mesh = structured_mesh(LENGTH, width, target)
    x = columns(mesh)
    c = mesh.clamp_depth
    assert c == pytest.approx(0.5 * np.mean(np.diff(x)), rel=1e-9)
    assert x[:2] == pytest.approx([-c, c], abs=ROUNDOFF)
    assert x[-2:] == pytest.approx([mesh.length - c, mesh.length + c], abs=ROUNDOFF)
    left, right = mesh.clamped_left, mesh.clamped_right
    assert np.array_equal(left, mesh.nodes[:, 0] < 0.5 * (x[1] + x[2]))
    assert np.array_equal(right, mesh.nodes[:, 0] > 0.5 * (x[-2] + x[-3]))
    # clamped-left nodes first, clamped-right last (the band structure relies on it)
    assert np.all(np.flatnonzero(left) == np.arange(left.sum()))
    assert np.all(np.flatnonzero(right) == np.arange(mesh.node_count - right.sum(), mesh.node_count))


@pytest.mark.parametrize("width", WIDTHS)
@pytest.mark.parametrize("target", TARGETS)
def test_structured_mesh_size_and_shape_follow_the_construction(width, target):
    mesh = structured_mesh(LENGTH, width, target)
    n_y = rows(mesh)
    x = columns(mesh)
    h_x, h_y = float(np.mean(np.diff(x))), width / n_y
    strips = len(x) - 1
    n = LENGTH / h_x
    assert n == pytest.approx(round(n), abs=1e-9)  # the clamp lines x = 0, L lie midway between columns
    n = round(n)
    assert n_y % 2 == 0
    assert mesh.triangle_count == strips * (2 * n_y + 1)
    nu = width / math.sqrt(2.0 * LENGTH * width / (0.5 * math.sqrt(3.0) * target))
    assert abs(n_y - nu) <= 1.0
    n_star = 2.0 * LENGTH * n_y / (math.sqrt(3.0) * width)
    assert abs(n - n_star) <= 1.0
    lo, hi = count_bounds(LENGTH, width, target)
    assert lo <= n * (2 * n_y + 1) / target <= hi

    # shapes: 2 half triangles per column strip on the edges y = +-W/2 (legs h_x, h_y / 2),
    # all others with sides h_y and sqrt(h_x^2 + h_y^2 / 4), equilateral up to h_x / (sqrt(3)/2
    # h_y) = n* / n in [n* / (n* + 1), n* / (n* - 1)]
    p = mesh.nodes[mesh.triangles]
    sides = np.sort(np.linalg.norm(p - p[:, [1, 2, 0]], axis=2), axis=1)
    half = np.isclose(mesh.triangle_areas, 0.25 * h_x * h_y, rtol=1e-9)
    assert half.sum() == 2 * strips
    assert np.allclose(np.sort(sides[half], axis=1), np.sort([h_x, 0.5 * h_y, math.hypot(h_x, 0.5 * h_y)]), rtol=1e-9)
    assert np.all(np.isclose(np.abs(p[half][:, :, 1]), 0.5 * width).sum(axis=1) == 2)
    full = ~half
    assert np.allclose(mesh.triangle_areas[full], 0.5 * h_x * h_y, rtol=1e-9)
    ratio_lo, ratio_hi = n_star / (n_star + 1), n_star / (n_star - 1)
    diagonal_lo, diagonal_hi = math.sqrt(0.75 * ratio_lo**2 + 0.25), math.sqrt(0.75 * ratio_hi**2 + 0.25)
    aspect = sides[full, 2] / sides[full, 0]
    assert np.all(aspect <= max(diagonal_hi, 1 / diagonal_lo) * (1 + 1e-9))
    assert np.max(np.abs(sides[full] / h_y - 1.0)) <= max(diagonal_hi - 1, 1 - diagonal_lo) + 1e-9


def test_tiny_triangle_count_is_rejected():
    for bad in (5, 15, 2000.0, True):
        with pytest.raises(InputError, match="integer >= 16"):
            structured_mesh(LENGTH, 0.05, bad)


def test_large_mesh_connectivity(monkeypatch):
    """~50k triangles: connectivity is built by sorting, O(N log N) (no timing asserted). Only
    the mesh is built: the memory a plate run on it would need (~6 GiB) is not asked for."""
    import ddg.limits

    monkeypatch.setattr(ddg.limits, "available_memory_bytes", lambda: 1e15)
    width, target = 0.5, 50_000
    mesh = structured_mesh(LENGTH, width, target)
    lo, hi = count_bounds(LENGTH, width, target)
    assert lo * target <= mesh.triangle_count <= hi * target * (1 + 2 * mesh.clamp_depth / LENGTH)
    assert mesh.node_count - len(mesh.edges) + mesh.triangle_count == 1
    boundary = boundary_edges(mesh)
    assert np.array_equal(boundary, on_boundary_side(mesh, mesh.edges))
    assert len(mesh.hinges) == len(mesh.edges) - boundary.sum()
    h = mesh.hinges
    assert np.all(signed_areas(mesh.nodes, h[:, [0, 1, 2]]) > 0)
    assert np.all(signed_areas(mesh.nodes, h[:, [1, 0, 3]]) > 0)
    # the band: a hinge spans at most two neighbouring columns, about 2 (n_y + 2) nodes
    assert mesh.bandwidth_nodes() <= 2 * (rows(mesh) + 2)


# --------------------------------------------------------------------------- hinges
def irregular_mesh():
    """A structured mesh with its interior nodes jittered (still a valid, non-equilateral mesh)."""
    base = structured_mesh(LENGTH, 1 / 6, 300)
    rng = np.random.default_rng(7)
    nodes = base.nodes.copy()
    interior = ~base.clamped_left & ~base.clamped_right & (np.abs(nodes[:, 1]) < 0.5 * base.width - 1e-12)
    nodes[interior] += 0.15 * base.clamp_depth * rng.uniform(-1, 1, (interior.sum(), 2))
    return mesh_from_arrays(nodes, base.triangles, LENGTH, base.width)


@pytest.mark.parametrize("make", (lambda: structured_mesh(LENGTH, 0.2, 600), irregular_mesh),
                         ids=("structured", "jittered"))
def test_hinges_are_consistently_oriented_pairs(make):
    mesh = make()
    h, tri = mesh.hinges, mesh.hinge_triangles
    # triangle a = (v0, v1, a) and b = (v1, v0, b) are both counter-clockwise in the plane
    assert np.all(signed_areas(mesh.nodes, h[:, [0, 1, 2]]) > 0)
    assert np.all(signed_areas(mesh.nodes, h[:, [1, 0, 3]]) > 0)
    t = mesh.triangles
    # the listed triangles are those of the hinge: a = {v0, v1, a}, b = {v1, v0, b}
    for side, order in ((0, [0, 1, 2]), (1, [1, 0, 3])):
        assert np.array_equal(np.sort(t[tri[:, side]], axis=1), np.sort(h[:, order], axis=1))
    assert np.all(tri[:, 0] != tri[:, 1]) and len(np.unique(h, axis=0)) == len(h)
    # one hinge per interior edge
    assert np.array_equal(mesh.edges[mesh.hinge_edges], np.sort(h[:, :2], axis=1))
    assert len(np.unique(mesh.hinge_edges)) == len(h) == len(mesh.edges) - boundary_edges(mesh).sum()
    # shared edge slots: each triangle has at most 3 hinges, boundary triangles fewer
    per_triangle = np.bincount(tri.ravel(), minlength=mesh.triangle_count)
    assert per_triangle.max() == 3 and per_triangle.min() >= 1
    assert mesh.bandwidth_nodes() == np.max(h.max(axis=1) - h.min(axis=1))


# --------------------------------------------------------------------------- mesh_from_arrays
def deformation(points: np.ndarray) -> np.ndarray:
    """A smooth large deformation of the reference plane (a function of position only)."""
    x, y = points[:, 0], points[:, 1]
    z = 0.3 * np.sin(2.0 * x) + y * np.sin(0.7 * x) + 0.2 * x * y
    return np.stack([0.9 * x + 0.1 * y**2, y * np.cos(0.7 * x), z], axis=1)


def plate_energy(mesh) -> float:
    x = deformation(mesh.nodes)
    edges = mesh.edges
    rest = edge_lengths(mesh, edges)
    springs = mesh.edge_triangle_areas / rest**2
    stretch = stretching_energy(x[edges[:, 1]] - x[edges[:, 0]], rest, springs, gradient=False)[0]
    bend = hinge_bending_energy(x, mesh.triangles, mesh.hinge_triangles, np.ones(len(mesh.hinges)),
                                gradient=False)[0]
    return stretch.sum() + bend.sum()


def test_mesh_from_arrays_normalises_a_scrambled_copy():
    """Shuffled nodes, a third of the triangles clockwise, shifted and with constant z, plus an
    unused node: the same mesh after normalisation (nodes, triangles up to relabelling, CCW,
    clamp zone) and the same energy for the same deformation."""
    mesh = structured_mesh(LENGTH, 0.25, 400)
    rng = np.random.default_rng(11)
    perm = rng.permutation(mesh.node_count)
    inverse = np.argsort(perm)
    nodes = mesh.nodes[perm] + [3.7, -1.2]
    nodes = np.vstack([nodes, [[50.0, 50.0]]])  # unused
    nodes = np.c_[nodes, np.full(len(nodes), 0.25)]
    triangles = inverse[mesh.triangles]
    flip = rng.random(len(triangles)) < 1 / 3
    triangles[flip] = triangles[flip][:, [0, 2, 1]]
    triangles = triangles[rng.permutation(len(triangles))]

    copy = mesh_from_arrays(nodes, triangles, LENGTH, 0.25)
    assert copy.clamp_depth == pytest.approx(mesh.clamp_depth, rel=1e-9)
    assert copy.node_count == mesh.node_count and copy.triangle_count == mesh.triangle_count
    assert np.all(copy.triangle_areas > 0)
    # match nodes by position
    order_a = np.lexsort(np.round(mesh.nodes, 9).T)
    order_b = np.lexsort(np.round(copy.nodes, 9).T)
    assert np.allclose(mesh.nodes[order_a], copy.nodes[order_b], rtol=0, atol=1e-12)
    to_original = np.empty(copy.node_count, dtype=int)
    to_original[order_b] = order_a
    same = {tuple(sorted(t)) for t in mesh.triangles.tolist()}
    assert {tuple(sorted(t)) for t in to_original[copy.triangles].tolist()} == same
    assert len(copy.hinges) == len(mesh.hinges) and len(copy.edges) == len(mesh.edges)
    assert np.array_equal(copy.clamped_left[order_b], mesh.clamped_left[order_a])
    assert np.array_equal(copy.clamped_right[order_b], mesh.clamped_right[order_a])
    assert plate_energy(copy) == pytest.approx(plate_energy(mesh), rel=1e-12)


def _bad_inputs():
    mesh = structured_mesh(LENGTH, 0.25, 200)
    nodes, tris, w = mesh.nodes, mesh.triangles, mesh.width
    span = mesh.length + 2 * mesh.clamp_depth
    bottom = np.flatnonzero(np.isclose(nodes[:, 1], -0.5 * w))[:3]  # three collinear nodes
    bumpy = np.c_[nodes, 1e-3 * np.sin(7 * nodes[:, 0])]
    return {
        "wrong width": ((nodes, tris, LENGTH, 1.1 * w), "width"),
        "no clamp zone": ((nodes, tris, span, w), "clamp zone"),
        "clamp depth inconsistent": ((nodes, tris, LENGTH, w, 2 * mesh.clamp_depth), "clamp zone"),
        "not flat": ((bumpy, tris, LENGTH, w), "not flat"),
        "degenerate triangle": ((nodes, np.vstack([tris, bottom]), LENGTH, w), "degenerate"),
        "index too large": ((nodes, np.where(tris == tris.max(), len(nodes), tris), LENGTH, w),
                            f"triangle node index {len(nodes)} out of range 0..{len(nodes) - 1}"),
        "negative index": ((nodes, np.where(tris == 0, -1, tris), LENGTH, w),
                           f"triangle node index -1 out of range 0..{len(nodes) - 1}"),
        "float indices": ((nodes, tris.astype(float), LENGTH, w), "integer"),
        "nodes shape": ((np.c_[nodes, nodes], tris, LENGTH, w), "shape"),
        "triangles shape": ((nodes, tris[:, :2], LENGTH, w), "shape"),
    } | _defective_meshes(mesh)


def _defective_meshes(mesh):
    """Issue 13 item 4: every defect of a mesh given as arrays, with the reason expected."""
    nodes, tris, w, c = mesh.nodes, mesh.triangles, mesh.width, mesh.clamp_depth
    n = len(nodes)
    centroid = nodes[tris].mean(axis=1)
    # an unmerged cut along a node column: the triangles right of it use copies of its nodes
    column = np.unique(np.round(nodes[:, 0], 12))[5]
    on = np.flatnonzero(np.abs(nodes[:, 0] - column) < 1e-12)
    relabel = np.arange(n)
    relabel[on] = n + np.arange(len(on))
    unmerged = np.where((centroid[:, 0] > column)[:, None], relabel[tris], tris)
    soup = nodes[tris].reshape(-1, 2)
    hole = np.linalg.norm(centroid - [0.5 * LENGTH, 0.0], axis=1) < 0.3 * w
    hinge = mesh.hinges[len(mesh.hinges) // 2]
    folded = nodes.copy()
    folded[np.argmin(np.linalg.norm(nodes - [0.5 * LENGTH, 0.0], axis=1)), 0] += 3 * c
    on_bottom = np.sum(np.abs(nodes[tris, 1] + 0.5 * w) < 1e-12, axis=1) == 2
    notch = np.flatnonzero(on_bottom & (np.abs(centroid[:, 0] - 0.5 * LENGTH) < 2 * c))[0]
    non_finite = nodes.copy()
    non_finite[3] = [np.nan, np.inf]
    return {
        "triangle soup": ((soup, np.arange(len(soup)).reshape(-1, 3), LENGTH, w),
                          f"triangle soup: its {len(tris)} triangles share no nodes or edges"),
        "duplicate nodes": ((np.vstack([nodes, nodes[on]]), unmerged, LENGTH, w),
                            f"has {len(on)} duplicate nodes (e.g. at ("),
        "duplicate triangle": ((nodes, np.vstack([tris, tris[-1:]]), LENGTH, w), "has 1 duplicate triangle (e.g."),
        "hole": ((nodes, tris[~hole], LENGTH, w), "has a hole (2 boundary loops"),
        "two pieces": ((np.vstack([nodes, nodes + [0.0, 2 * w]]), np.vstack([tris, tris + n]), LENGTH, w),
                       "has 2 disconnected pieces"),
        "non-manifold edge": ((np.vstack([nodes, nodes[hinge[[0, 1, 2]]].mean(axis=0)]),
                               np.vstack([tris, [hinge[0], hinge[1], n]]), LENGTH, w),
                              "is not a manifold: 1 edge shared by more than two triangles"),
        "folded": ((folded, tris, LENGTH, w), "overlapping (folded or inverted) triangles"),
        "notched outline": ((nodes, np.delete(tris, notch, axis=0), LENGTH, w), "outline is not a rectangle"),
        "non-finite": ((non_finite, tris, LENGTH, w), "has 1 node with non-finite coordinates (e.g. node 3"),
        "complex nodes": ((nodes.astype(complex), tris, LENGTH, w), "dtype complex128"),
        "text nodes": ((nodes.astype(str), tris, LENGTH, w), "expected real coordinates"),
        "ragged nodes": (([[0.0, 1.0], [1.0]], tris, LENGTH, w), "array of real coordinates"),
        "bool triangles": ((nodes, tris > 0, LENGTH, w), "integer node indices, not bool"),
        "no triangles": ((nodes, np.zeros((0, 3), dtype=int), LENGTH, w), "has no triangles"),
        "no nodes": ((np.zeros((0, 2)), tris, LENGTH, w), "has no nodes"),
        "unused node refused": ((np.vstack([nodes, [0.5 * LENGTH, 0.01]]), tris, LENGTH, w),
                                f"has 1 node used by no triangle (e.g. node {n}", {"allow_unused_nodes": False}),
        "stretched 1.5x": ((nodes * [1.5, 1.0], tris, LENGTH, w),
                           f"is {1.5 * (LENGTH + 2 * c):.6g} m long but the strip needs L + 2c = "
                           f"{LENGTH + 3 * c:.6g} m"),
        "shorter than L": ((nodes * [0.8, 1.0], tris, LENGTH, w), f"L = {LENGTH:.6g} m between the clamp lines"),
        "bad length": ((nodes, tris, -1.0, w), "length = -1.0"),
    }


BAD_INPUTS = _bad_inputs()


@pytest.mark.parametrize("case", sorted(BAD_INPUTS))
def test_mesh_from_arrays_rejects_bad_input(case):
    args, keyword, *options = BAD_INPUTS[case]
    nodes, tris, length, width, *depth = args
    kwargs = ({"clamp_depth": depth[0]} if depth else {}) | (options[0] if options else {})
    with pytest.raises(InputError) as info:
        mesh_from_arrays(nodes, tris, length, width, **kwargs)
    message = str(info.value)
    assert keyword in message and "\n" not in message


# --------------------------------------------------------------------------- locate
def test_interpolation_is_exact_for_linear_fields():
    mesh = structured_mesh(LENGTH, 0.2, 800)
    rng = np.random.default_rng(5)
    c, w = mesh.clamp_depth, mesh.width
    points = np.c_[rng.uniform(-c, mesh.length + c, 300), rng.uniform(-0.5 * w, 0.5 * w, 300)]
    points = np.vstack([points, mesh.nodes[::17]])  # nodes and points on edges too
    tri, weights = mesh.locate(points)
    assert np.all(weights >= -1e-10) and np.allclose(weights.sum(axis=1), 1.0, rtol=0, atol=ROUNDOFF)
    nodes, w_interp = mesh.interpolation_matrix(points)
    assert np.array_equal(nodes, mesh.triangles[tri])
    field = 0.3 + 2.0 * mesh.nodes[:, 0] - 5.0 * mesh.nodes[:, 1]
    exact = 0.3 + 2.0 * points[:, 0] - 5.0 * points[:, 1]
    assert np.allclose(np.sum(w_interp * field[nodes], axis=1), exact, rtol=0, atol=1e-12)
    # the weights reproduce the points themselves (barycentric coordinates)
    assert np.allclose(np.einsum("qk,qkd->qd", w_interp, mesh.nodes[nodes]), points, rtol=0, atol=1e-12)


@pytest.mark.parametrize("point", ([1.2, 0.0], [0.5, 0.11], [-0.2, 0.0]))
def test_locate_rejects_points_outside(point):
    mesh = structured_mesh(LENGTH, 0.2, 800)
    with pytest.raises(InputError, match="outside the mesh"):
        mesh.locate([[0.5, 0.0], point])


# --------------------------------------------------------------------------- clamp zone of a mesh given without one
def jittered_ends(seed: int = 3):
    """A structured mesh whose second node column at each end is jittered in x by up to 0.2 c:
    the first layer of triangles at each end is between 1.8 c and 2.2 c deep."""
    mesh = structured_mesh(LENGTH, 0.25, 200)
    nodes = mesh.nodes.copy()
    rng = np.random.default_rng(seed)
    c = mesh.clamp_depth
    for x in (c, LENGTH - c):
        column = np.abs(nodes[:, 0] - x) < 1e-12
        nodes[column, 0] += 0.2 * c * rng.uniform(-1, 1, column.sum())
    return mesh, nodes


def test_clamp_zone_of_unstructured_ends_is_the_first_layer():
    """2c may lie anywhere within the first layer of triangles at each end (from the shallowest
    to the deepest triangle touching the end): accepted at 2c = 2 c_0; a mesh 5 % too long or 2 %
    too short is refused, stating the window of lengths it would need."""
    mesh, nodes = jittered_ends()
    copy = mesh_from_arrays(nodes, mesh.triangles, LENGTH, 0.25)
    assert copy.clamp_depth == pytest.approx(mesh.clamp_depth, rel=1e-9)
    assert copy.clamped_left.sum() >= mesh.width / (2 * mesh.clamp_depth)  # at least the end column
    for factor in (1.05, 0.98):
        with pytest.raises(InputError) as info:
            mesh_from_arrays(nodes * [factor, 1.0], mesh.triangles, LENGTH, 0.25)
        message = str(info.value)
        assert "L + 2c between" in message and "first layer of triangles" in message and "\n" not in message


def test_clamp_zone_must_match_at_both_ends():
    """A structured mesh whose last column spacing is doubled: first layers of 2c and 4c."""
    mesh = structured_mesh(LENGTH, 0.25, 200)
    nodes = mesh.nodes.copy()
    right = nodes[:, 0] > LENGTH
    nodes[right, 0] += 2 * mesh.clamp_depth
    with pytest.raises(InputError, match="first layers of triangles of different depths at its two ends"):
        mesh_from_arrays(nodes, mesh.triangles, LENGTH, 0.25)


def test_file_round_off_keeps_the_clamped_nodes():
    """A single-precision copy of a 75 mm strip 3 m off the origin, as a float32 file holds it:
    good to ~1.2e-7 m there, more than 1e-6 L = 7.5e-8 m (as float64 it is refused: its width is
    off by 2e-7 m). The file's round-off is allowed for and the same nodes are clamped."""
    length, width = 0.075, 0.0125
    mesh = structured_mesh(length, width, 200)
    single = (mesh.nodes + [3.0, 3.0]).astype(np.float32)
    with pytest.raises(InputError, match="width"):
        mesh_from_arrays(single.astype(np.float64), mesh.triangles, length, width)
    copy = mesh_from_arrays(single, mesh.triangles, length, width)
    assert copy.clamped_left.sum() == mesh.clamped_left.sum()
    assert copy.clamped_right.sum() == mesh.clamped_right.sum()
    assert copy.clamp_depth == pytest.approx(mesh.clamp_depth, rel=1e-3)


# --------------------------------------------------------------------------- sizes
def test_triangle_count_has_a_hard_cap():
    with pytest.raises(InputError) as info:
        structured_mesh(LENGTH, 0.05, MAX_TRIANGLES + 1)
    message = str(info.value)
    assert f"triangles = {MAX_TRIANGLES + 1} outside the allowed range [16, {MAX_TRIANGLES}]" in message
    assert "\n" not in message


def test_structured_mesh_refuses_a_size_beyond_the_memory(monkeypatch):
    """Refused from the estimate, before the mesh is built."""
    import ddg.limits

    monkeypatch.setattr(ddg.limits, "available_memory_bytes", lambda: 64 * 2.0**20)  # 48 MiB for a run
    structured_mesh(LENGTH, 0.05, 500)
    estimate = plate_memory_estimate_bytes(LENGTH, 0.05, 4000)
    with pytest.raises(InputError) as info:
        structured_mesh(LENGTH, 0.05, 4000)
    assert str(info.value) == (f"triangles = 4000 needs about {estimate / 2**30:.3g} GiB; this machine allows "
                               f"{48 / 1024:.3g} GiB for a run (75 % of its memory)")


@pytest.mark.parametrize("width", WIDTHS)
def test_memory_estimate_from_the_size_matches_the_mesh(width):
    """The estimate from (L, W, triangles) is the one from the structured mesh's actual node
    count and band (to 10 %), and it grows as triangles^1.5 (the band as sqrt(triangles))."""
    estimates = []
    for target in (2000, 8000):
        mesh = structured_mesh(LENGTH, width, target)
        actual = plate_memory_estimate_bytes(LENGTH, width, mesh.triangle_count, nodes=mesh.node_count,
                                             bandwidth_nodes=mesh.bandwidth_nodes())
        estimates.append(plate_memory_estimate_bytes(LENGTH, width, target))
        assert estimates[-1] == pytest.approx(actual, rel=0.1)
    assert 4.0 < estimates[1] / estimates[0] < 4.0**1.5 * 1.1
    assert plate_memory_estimate_bytes(LENGTH, width, 2000, unstructured=True) > estimates[0]


# --------------------------------------------------------------------------- equilateral structured mesh
@pytest.mark.parametrize("width", WIDTHS)
@pytest.mark.parametrize("target", TARGETS)
def test_equilateral_mesh_is_exactly_equilateral_between_its_end_strips(width, target):
    """structured_mesh(..., equilateral=True): the same rows as the default mesh, columns
    sqrt(3)/2 h_y apart about a regular column at L/2, the clamp columns at -c, c, L - c, L + c
    (c half a spacing), the remainder of L in the strip between a clamp column and the lattice
    (between 1/2 and 3/2 spacings); symmetric under the half turn about the centre; the centre a
    node; every triangle away from those strips equilateral."""
    mesh = structured_mesh(LENGTH, width, target, equilateral=True)
    default = structured_mesh(LENGTH, width, target)
    n_y = rows(mesh)
    assert n_y == rows(default)
    x = columns(mesh)
    h_x = 0.5 * math.sqrt(3.0) * width / n_y
    c = mesh.clamp_depth
    assert c == pytest.approx(0.5 * h_x, rel=1e-12)
    assert x[:2] == pytest.approx([-c, c], abs=ROUNDOFF) and x[-2:] == pytest.approx([LENGTH - c, LENGTH + c],
                                                                                       abs=ROUNDOFF)
    assert np.diff(x[2:-2]) == pytest.approx(np.full(len(x) - 5, h_x), rel=1e-9)
    assert 0.5 * h_x - ROUNDOFF <= x[2] - x[1] < 1.5 * h_x
    assert x[2] - x[1] == pytest.approx(x[-2] - x[-3], abs=ROUNDOFF)
    assert len(x) % 2 == 1 and x[len(x) // 2] == pytest.approx(0.5 * LENGTH, abs=ROUNDOFF)
    # the half turn (x, y) -> (L - x, -y) maps the node set onto itself
    turned = np.column_stack([LENGTH - mesh.nodes[:, 0], -mesh.nodes[:, 1]])
    key = lambda p: set(map(tuple, np.round(p / ROUNDOFF / LENGTH).astype(np.int64)))  # noqa: E731
    assert key(turned) == key(mesh.nodes)
    # equilateral: all three sides equal on every triangle whose nodes lie within the lattice
    p = mesh.nodes[mesh.triangles]
    inside = np.all((p[:, :, 0] >= x[2] - ROUNDOFF) & (p[:, :, 0] <= x[-3] + ROUNDOFF), axis=1)
    sides = np.linalg.norm(p - np.roll(p, 1, axis=1), axis=2)
    # (the edge rows hold the half-size triangles: those with a node on y = +-W/2 are left out)
    interior = inside & np.all(np.abs(p[:, :, 1]) < 0.5 * width - 0.4 * width / n_y, axis=1)
    assert np.allclose(sides[interior], width / n_y, rtol=1e-9)


@pytest.mark.parametrize("rows, columns", [(4, 12), (8, 40), (6, 2)])
def test_ghost_clamp_mesh_with_given_columns_spaces_them_evenly_along_L(rows, columns):
    """An anisotropic ghost-clamp mesh: `columns` element columns in [0, L] (one ghost column
    beyond each clamp), `rows` rows across W, the centre a node, the area exactly L W inside."""
    from ddg.geometry.plate_mesh import ghost_clamp_mesh

    length, width = 0.15, 0.05
    mesh = ghost_clamp_mesh(length, width, rows=rows, columns=columns)
    xs = np.unique(np.round(mesh.nodes[:, 0] / (length / columns), 9))
    assert xs.min() == -1 and xs.max() == columns + 1 and np.allclose(xs, np.round(xs))
    assert np.any(np.all(np.isclose(mesh.nodes, [length / 2, 0.0]), axis=1))
    inside = mesh.triangles[np.all((mesh.nodes[mesh.triangles, 0] >= -1e-12)
                                   & (mesh.nodes[mesh.triangles, 0] <= length + 1e-12), axis=1)]
    p = mesh.nodes[inside]
    area = 0.5 * np.abs((p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1])
                        - (p[:, 2, 0] - p[:, 0, 0]) * (p[:, 1, 1] - p[:, 0, 1]))
    assert area.sum() == pytest.approx(length * width, rel=1e-12)


@pytest.mark.parametrize("columns, word", [(7, "odd"), (0, "columns"), (2.5, "columns")])
def test_ghost_clamp_mesh_refuses_bad_columns(columns, word):
    from ddg.geometry.plate_mesh import ghost_clamp_mesh

    with pytest.raises(InputError, match=word):
        ghost_clamp_mesh(0.15, 0.05, rows=4, columns=columns)
