"""Meshes given as arrays (mesh_from_arrays) and what every PlateMesh offers: hinge bookkeeping on a
structured and a jittered mesh, the normalisation of a scrambled copy, the refusal of bad input and
defective meshes (issue 13 item 4), point location and interpolation, and the clamp zone of a mesh
given without one."""
from __future__ import annotations

import numpy as np
import pytest

from ddg.energies.hinge_bending import hinge_bending_energy
from ddg.energies.stretch import stretching_energy
from ddg.geometry.plate_mesh import mesh_from_arrays, structured_mesh
from ddg.geometry.strip import InputError

from mesh_checks import boundary_edges, edge_lengths, signed_areas

LENGTH = 1.0
ROUNDOFF = 1e-12


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
