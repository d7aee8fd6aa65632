"""The structured meshes of the flat strip (structured_mesh, its equilateral variant and
ghost_clamp_mesh): construction, connectivity, the clamp columns, the size against its target, the
hard cap on triangles and the memory estimate."""
from __future__ import annotations

import math

import numpy as np
import pytest

from ddg.geometry.plate_mesh import MAX_TRIANGLES, plate_memory_estimate_bytes, structured_mesh
from ddg.geometry.strip import InputError

from mesh_checks import boundary_edges, edge_lengths, signed_areas

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


def on_boundary_side(mesh, edges) -> np.ndarray:
    """Edges with both ends on the same side of the rectangle [-c, L + c] x [-W/2, W/2]."""
    x0, x1 = -mesh.clamp_depth, mesh.length + mesh.clamp_depth
    p, q = mesh.nodes[edges[:, 0]], mesh.nodes[edges[:, 1]]
    tol = 1e-12 * mesh.length
    same = np.zeros(len(edges), dtype=bool)
    for axis, value in ((0, x0), (0, x1), (1, -0.5 * mesh.width), (1, 0.5 * mesh.width)):
        same |= (np.abs(p[:, axis] - value) < tol) & (np.abs(q[:, axis] - value) < tol)
    return same


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
