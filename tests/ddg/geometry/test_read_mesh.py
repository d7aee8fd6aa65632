"""Meshes read from files (read_mesh, ddg/geometry/mesh_io.py): a mesh written anywhere in the plane
comes back in the plate convention (clamp lines x = 0 and x = L, counter-clockwise triangles); a
wrong size, a missing clamp zone, a file without triangles, a defective mesh (issue 13) or a mesh too
large for the machine raises a one-line InputError naming the file and the defect, and the command
line refuses such a mesh before running."""
from __future__ import annotations

import sys

import numpy as np
import pytest

from ddg.output.frames import FrameWriter, polyline_cells
from ddg.geometry.mesh_io import read_mesh
from ddg.geometry.plate_mesh import structured_mesh
from ddg.geometry.strip import InputError

from mesh_checks import L, W, one_line_error


def _triangle_set(mesh, digits: int = 12) -> set:
    """Each triangle as the sorted tuple of its rounded vertex coordinates (order-free)."""
    p = np.round(mesh.nodes[mesh.triangles] / mesh.length, digits) + 0.0  # + 0.0 folds -0.0
    return {tuple(sorted(map(tuple, tri))) for tri in p}


def _write(meshio, path, points, cells, **kwargs):
    meshio.write(path, meshio.Mesh(points, cells), **kwargs)


# --------------------------------------------------------------------------- read_mesh
@pytest.mark.parametrize("suffix, options", [(".msh", {"file_format": "gmsh22", "binary": False}),
                                             (".vtu", {})])
def test_read_mesh_round_trip_of_a_shifted_structured_mesh(tmp_path, suffix, options):
    """A structured mesh written anywhere in the plane (offset, z = const, boundary lines
    alongside) reads back as the same triangles in the clamp-line convention."""
    meshio = pytest.importorskip("meshio")
    mesh = structured_mesh(L, W, 400)
    offset = np.array([3.0 * L, -7.0 * W, 0.25])
    points = np.column_stack([mesh.nodes, np.zeros(mesh.node_count)]) + offset
    # clockwise on purpose: read_mesh must orient them
    cells = [("line", mesh.edges[:5]), ("triangle", mesh.triangles[:, [0, 2, 1]])]
    path = tmp_path / f"strip{suffix}"
    _write(meshio, path, points, cells, **options)

    back = read_mesh(path, L, W)
    assert back.node_count == mesh.node_count and back.triangle_count == mesh.triangle_count
    assert back.clamp_depth == pytest.approx(mesh.clamp_depth, rel=1e-9)
    assert np.all(back.triangle_areas > 0)
    np.testing.assert_allclose(np.sort(back.triangle_areas), np.sort(mesh.triangle_areas), rtol=1e-9)
    np.testing.assert_allclose(back.nodes[np.lexsort(back.nodes.T[::-1])],
                               mesh.nodes[np.lexsort(mesh.nodes.T[::-1])], atol=1e-12 * L)
    assert _triangle_set(back, 9) == _triangle_set(mesh, 9)
    assert back.clamped_left.sum() == mesh.clamped_left.sum()
    assert back.clamped_right.sum() == mesh.clamped_right.sum()


def test_read_mesh_rejects_a_wrong_width(tmp_path):
    meshio = pytest.importorskip("meshio")
    mesh = structured_mesh(L, W, 200)
    path = tmp_path / "strip.vtu"
    _write(meshio, path, np.column_stack([mesh.nodes, np.zeros(mesh.node_count)]), [("triangle", mesh.triangles)])
    with pytest.raises(InputError) as excinfo:
        read_mesh(path, L, 2 * W)
    one_line_error(excinfo, "strip.vtu", f"W = {2 * W:.6g}", f"{W:.6g}")


def test_read_mesh_rejects_a_mesh_without_clamp_zones(tmp_path):
    """A mesh exactly L long has no room for the clamped bands around the clamp lines."""
    meshio = pytest.importorskip("meshio")
    mesh = structured_mesh(L, W, 200)
    squeezed = mesh.nodes.copy()
    squeezed[:, 0] = (squeezed[:, 0] + mesh.clamp_depth) * L / (L + 2 * mesh.clamp_depth)
    path = tmp_path / "no_clamps.msh"
    _write(meshio, path, np.column_stack([squeezed, np.zeros(mesh.node_count)]), [("triangle", mesh.triangles)],
           file_format="gmsh22", binary=False)
    with pytest.raises(InputError) as excinfo:
        read_mesh(path, L, W)
    one_line_error(excinfo, "no_clamps.msh", f"L = {L:.6g}", "clamp zone")


def test_read_mesh_rejects_files_without_triangles_missing_or_unreadable(tmp_path, capsys):
    meshio = pytest.importorskip("meshio")
    lines = tmp_path / "polyline.vtu"
    _write(meshio, lines, np.random.default_rng(0).random((5, 3)), [("line", polyline_cells(5))])
    with pytest.raises(InputError) as excinfo:
        read_mesh(lines, L, W)
    one_line_error(excinfo, "polyline.vtu", "no triangle cells", "found: line")

    with pytest.raises(InputError) as excinfo:
        read_mesh(tmp_path / "absent.msh", L, W)
    one_line_error(excinfo, "absent.msh")

    # meshio itself prints and calls sys.exit(1) on such a file; we must raise instead
    junk = tmp_path / "junk.msh"
    junk.write_text("not a mesh\n")
    with pytest.raises(InputError) as excinfo:
        read_mesh(junk, L, W)
    one_line_error(excinfo, "junk.msh", "cannot read")
    assert capsys.readouterr().out == ""

    with pytest.raises(InputError) as excinfo:
        read_mesh(lines, -L, W)
    one_line_error(excinfo, f"length = {-L!r}")

    for not_a_path in (123, None, b"strip.msh"):
        with pytest.raises(InputError) as excinfo:
            read_mesh(not_a_path, L, W)
        one_line_error(excinfo, f"mesh = {not_a_path!r} must be the path of a mesh file")


def test_missing_meshio_gives_an_install_hint(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "meshio", None)  # makes `import meshio` raise ImportError
    with pytest.raises(InputError) as excinfo:
        read_mesh(tmp_path / "strip.msh", L, W)
    one_line_error(excinfo, "python3-meshio")
    with pytest.raises(InputError) as excinfo:
        FrameWriter(tmp_path / "frames", polyline_cells(3))
    one_line_error(excinfo, "python3-meshio")


# --------------------------------------------------------------------------- read_mesh: bad meshes (issue 13)
def _strip_arrays(triangles: int = 200):
    """Nodes (N, 3), triangles and clamp depth of a structured mesh of the L x W strip."""
    mesh = structured_mesh(L, W, triangles)
    return np.column_stack([mesh.nodes, np.zeros(mesh.node_count)]), mesh.triangles.copy(), mesh


def _write_mesh(tmp_path, name, points, triangles, **options):
    meshio = pytest.importorskip("meshio")
    path = tmp_path / name
    if name.endswith(".msh"):
        options = {"file_format": "gmsh22", "binary": False} | options
    cells = triangles if isinstance(triangles, list) else [("triangle", np.asarray(triangles))]
    _write(meshio, path, np.asarray(points, dtype=float), cells, **options)
    return path


def _refused(path, *fragments, length=L, width=W):
    with pytest.raises(InputError) as excinfo:
        read_mesh(path, length, width)
    one_line_error(excinfo, f"mesh file {str(path)!r}", *fragments)
    return str(excinfo.value)


def test_read_mesh_refuses_a_stretched_mesh_stating_both_lengths(tmp_path):
    """Issue 13 item 4.1: a valid mesh 1.5 times too long was clamped 0.25 L deep at each end
    (H_mid 0.189 instead of 0.374); the clamp zone is the first layer of triangles, so the
    expected length is known and a mismatch refused."""
    points, tris, mesh = _strip_arrays()
    expected = L + 2 * mesh.clamp_depth
    stretched = points * [1.5, 1.0, 1.0]
    message = _refused(_write_mesh(tmp_path, "long.msh", stretched, tris),
                       f"is {1.5 * expected:.6g} m long", f"L + 2c = {L + 1.5 * 2 * mesh.clamp_depth:.6g} m",
                       f"L = {L:.6g} m", "clamp zone", "+- ")
    assert "first layer of triangles" in message
    # shorter than L, exactly L (no clamp zones) and 1e-4 L too long: refused too
    for name, factor in (("short.vtu", 0.9), ("exact.vtu", L / expected), ("slightly.vtu", 1 + 1e-4)):
        _refused(_write_mesh(tmp_path, name, points * [factor, 1.0, 1.0], tris), f"L = {L:.6g} m", "clamp zone")
    # the round-off of a file (here 1e-9 L) is accepted, with the same clamped nodes
    back = read_mesh(_write_mesh(tmp_path, "roundoff.vtu", points * [1 + 1e-9, 1.0, 1.0], tris), L, W)
    assert back.clamped_left.sum() == mesh.clamped_left.sum()
    assert back.clamped_right.sum() == mesh.clamped_right.sum()
    assert back.clamp_depth == pytest.approx(mesh.clamp_depth, rel=1e-6)


def test_read_mesh_accepts_a_gmsh_mesh_written_to_a_file(tmp_path, gmsh_strip):
    """The gmsh mesh's clamped bands are one layer of triangles: read back, the inferred clamp
    depth is the one gmsh_mesh chose."""
    mesh, _ = gmsh_strip
    path = _write_mesh(tmp_path, "gmsh.vtu", np.column_stack([mesh.nodes, np.zeros(mesh.node_count)]),
                       mesh.triangles)
    back = read_mesh(path, L, W)
    assert back.clamp_depth == pytest.approx(mesh.clamp_depth, rel=1e-9)
    assert back.clamped_left.sum() == mesh.clamped_left.sum()
    assert back.clamped_right.sum() == mesh.clamped_right.sum()


def _split_along_a_column(points, tris):
    """The mesh cut along an interior node column: the triangles right of it use copies of its
    nodes (an unmerged export). Returns points, triangles and the number of copies."""
    x = points[:, 0]
    column = np.unique(np.round(x, 12))[len(np.unique(np.round(x, 12))) // 2 + 1]
    on = np.flatnonzero(np.abs(x - column) < 1e-12)
    copies = np.arange(len(points)), np.arange(len(points), len(points) + len(on))
    relabel = copies[0].copy()
    relabel[on] = copies[1]
    right = points[tris, 0].mean(axis=1) > column
    tris = tris.copy()
    tris[right] = relabel[tris[right]]
    return np.vstack([points, points[on]]), tris, len(on)


def test_read_mesh_refuses_duplicate_nodes(tmp_path):
    points, tris, _ = _strip_arrays()
    split, split_tris, count = _split_along_a_column(points, tris)
    _refused(_write_mesh(tmp_path, "unmerged.vtu", split, split_tris), f"has {count} duplicate nodes (e.g. at (",
             "merge them")


def test_read_mesh_refuses_a_triangle_soup(tmp_path):
    points, tris, _ = _strip_arrays()
    soup = points[tris].reshape(-1, 3)
    _refused(_write_mesh(tmp_path, "soup.msh", soup, np.arange(len(soup)).reshape(-1, 3)),
             "triangle soup", f"its {len(tris)} triangles share no nodes or edges", "merge")


def test_read_mesh_refuses_a_negative_node_index(tmp_path):
    points, tris, _ = _strip_arrays()
    tris[5, 1] = -1
    _refused(_write_mesh(tmp_path, "negative.vtu", points, tris),
             f"triangle node index -1 out of range 0..{len(points) - 1}")


def test_read_mesh_refuses_a_mesh_with_a_hole(tmp_path):
    """The triangles around the plate's centre removed (their inner nodes left in the file):
    the hole, not the unused nodes, is reported."""
    points, tris, _ = _strip_arrays()
    centroid = points[tris, :2].mean(axis=1)
    hole = np.linalg.norm(centroid - [0.5 * L, 0.0], axis=1) < 0.25 * W
    _refused(_write_mesh(tmp_path, "holed.vtu", points, tris[~hole]),
             "has a hole (2 boundary loops", "the strip must be simply connected")


def _fold(points, tris, mesh):
    folded = points.copy()
    centre = int(np.argmin(np.linalg.norm(points[:, :2] - [0.5 * L, 0.0], axis=1)))
    folded[centre, 0] += 3.0 * mesh.clamp_depth  # past its right neighbours: its triangles invert
    return folded, tris


def _bad_mesh_cases():
    """name: (file name, points, cells or triangles, message fragments), all from a 200-triangle strip."""
    points, tris, mesh = _strip_arrays()
    n = len(points)
    hinge = mesh.hinges[len(mesh.hinges) // 2]
    apex = points[hinge[[0, 1, 2]]].mean(axis=0)  # inside triangle a of the hinge: not a duplicate
    bottom = np.flatnonzero(np.abs(points[:, 1] + 0.5 * W) < 1e-12)[:3]  # three collinear nodes
    centroid = points[tris, :2].mean(axis=1)
    on_bottom = np.sum(np.abs(points[tris, 1] + 0.5 * W) < 1e-12, axis=1) == 2
    notch = np.flatnonzero(on_bottom & (np.abs(centroid[:, 0] - 0.5 * L) < 2 * mesh.clamp_depth))[0]
    nan = points.copy()
    nan[7, 0] = np.nan
    inf = points.copy()
    inf[7, 1] = np.inf
    bumpy = points.copy()
    bumpy[:, 2] = 1e-3 * np.sin(200 * points[:, 0])
    return {
        "non-manifold edge": ("nonmanifold.vtu", np.vstack([points, apex]), np.vstack([tris, [hinge[0], hinge[1], n]]),
                              ("is not a manifold: 1 edge shared by more than two triangles",)),
        "disconnected pieces": ("two.vtu", np.vstack([points, points + [2 * L, 0, 0]]), np.vstack([tris, tris + n]),
                                ("has 2 disconnected pieces", "one piece")),
        "folded (inverted) triangles": ("folded.vtu", *_fold(points, tris, mesh),
                                        ("overlapping (folded or inverted) triangles",)),
        "degenerate triangle": ("degenerate.vtu", points, np.vstack([tris, bottom]),
                                ("has 1 degenerate (zero-area) triangle",)),
        "duplicate triangle": ("twice.vtu", points, np.vstack([tris, tris[:1, ::-1]]), ("has 1 duplicate triangle",)),
        "notched outline": ("notch.vtu", points, np.delete(tris, notch, axis=0), ("outline is not a rectangle",)),
        "unused node": ("unused.vtu", np.vstack([points, [0.5 * L, 1e-4, 0]]), tris,
                        (f"has 1 node used by no triangle (e.g. node {n} at (",)),
        "NaN coordinate": ("nan.vtu", nan, tris, ("has 1 node with non-finite coordinates", "nan")),
        "inf coordinate": ("inf.msh", inf, tris, ("non-finite coordinates",)),
        "not flat (3D)": ("bumpy.vtu", bumpy, tris, ("is not flat: its z coordinates vary by",)),
        "strip along y": ("turned.vtu", points[:, [1, 0, 2]], tris, ("width", "the strip must lie along x")),
        "empty mesh (msh)": ("empty.msh", points, np.zeros((0, 3), dtype=np.int64),
                             ("no triangle cells (found: none)",)),
        "empty mesh (vtu)": ("empty.vtu", points, np.zeros((0, 3), dtype=np.int64), ("cannot read", "holds no cells")),
        "quads only": ("quads.vtu", points, [("quad", np.array([[0, 1, 2, 3]]))], ("no triangle cells (found: quad)",)),
        "quads besides triangles": ("mixed.vtu", points, [("triangle", tris), ("quad", np.array([[0, 1, 2, 3]]))],
                                    ("has quad cells besides its triangles",)),
        "float indices": ("float.vtu", points, [("triangle", tris.astype(float))], ("cannot read",)),
    }


BAD_MESHES = _bad_mesh_cases()


@pytest.mark.parametrize("case", sorted(BAD_MESHES))
def test_read_mesh_refuses_a_bad_mesh_naming_the_file_and_the_defect(tmp_path, case):
    name, points, cells, fragments = BAD_MESHES[case]
    _refused(_write_mesh(tmp_path, name, points, cells), *fragments)


def test_read_mesh_refuses_an_empty_file(tmp_path):
    empty = tmp_path / "empty.msh"
    empty.write_bytes(b"")
    _refused(empty, "is empty (0 bytes)")


def test_read_mesh_refuses_a_mesh_too_large_for_the_machine(tmp_path, monkeypatch):
    """The memory estimate of a run applies to a file's actual size and band; the hard cap on
    triangles applies before the mesh is even checked."""
    import ddg.limits

    points, tris, mesh = _strip_arrays()
    path = _write_mesh(tmp_path, "strip.vtu", points, tris)
    monkeypatch.setattr(ddg.limits, "available_memory_bytes", lambda: 1e6)
    _refused(path, f"triangles = {mesh.triangle_count} ({mesh.node_count} nodes, a Hessian band of "
                   f"{mesh.bandwidth_nodes()} nodes) needs about", "GiB")
    monkeypatch.setattr("ddg.geometry.mesh_io.MAX_TRIANGLES", 100)
    _refused(path, f"triangles = {mesh.triangle_count} outside the allowed range [1, 100]")


def test_cli_refuses_the_stretched_mesh_before_running(tmp_path, capsys, monkeypatch):
    """python -m ddg simulate --model plate --mesh FILE: exit 2, one line on stderr, no solve."""
    from ddg.cli import main
    from ddg.models.plate import PlateModel

    def tripwire(*args, **kwargs):
        raise AssertionError("the plate was evaluated: the mesh was accepted")

    monkeypatch.setattr(PlateModel, "evaluate", tripwire)
    length = 75e-3 / (1 - 0.5)
    mesh = structured_mesh(length, 0.1667 * length, 200)
    points = np.column_stack([mesh.nodes * [1.5, 1.0], np.zeros(mesh.node_count)])
    path = _write_mesh(tmp_path, "long.msh", points, mesh.triangles)
    capsys.readouterr()
    assert main(["simulate", "--model", "plate", "--width-ratio", "0.1667", "--compression-ratio", "0.5",
                 "--mesh", str(path), "--out", str(tmp_path / "o"), "--quiet"]) == 2
    captured = capsys.readouterr()
    err = captured.err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("error: mesh file"), captured
    assert "long.msh" in err and f"L = {length:.6g} m" in err and "Traceback" not in captured.out + captured.err
