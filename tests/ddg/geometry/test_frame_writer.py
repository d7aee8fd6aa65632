"""The ParaView frame writer (FrameWriter, ddg/output/frames.py): frames are complete VTU files
listed in order by a valid frames.pvd after every frame, polylines and triangles kept as cells, no
temporary file left behind when a write fails, bad frames refused with one line."""
from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pytest

from ddg.output.frames import FrameWriter, polyline_cells, read_frame
from ddg.geometry.plate_mesh import structured_mesh
from ddg.geometry.strip import InputError

from mesh_checks import L, W, one_line_error


def _pvd_datasets(path):
    root = ET.parse(path).getroot()
    assert root.tag == "VTKFile" and root.get("type") == "Collection"
    return root.find("Collection").findall("DataSet")


def test_frame_writer_writes_vtu_frames_and_a_collection(tmp_path):
    pytest.importorskip("meshio")
    mesh = structured_mesh(L, W, 200)
    directory = tmp_path / "out" / "frames"
    rng = np.random.default_rng(1)
    written = []
    with FrameWriter(directory, mesh) as writer:
        for k in range(4):
            positions = np.column_stack([mesh.nodes, np.zeros(mesh.node_count)]) + 1e-3 * rng.random((mesh.node_count,
                                                                                                      3))
            path = writer.write(positions, step=k, dL_over_L=0.5, dW_over_L=0.01 * k, stage="shear",
                                point_data={"height": positions[:, 2]},
                                cell_data={"area_index": np.arange(mesh.triangle_count, dtype=float)},
                                time=0.01 * k)
            written.append(positions)
            # the collection is valid after every frame (an interrupted run keeps it)
            datasets = _pvd_datasets(directory / "frames.pvd")
            assert [d.get("file") for d in datasets] == [f"frame_{j:05d}.vtu" for j in range(k + 1)]
            assert path == directory / f"frame_{k:05d}.vtu"

    datasets = _pvd_datasets(directory / "frames.pvd")
    assert [float(d.get("timestep")) for d in datasets] == [0.0, 0.01, 0.02, 0.03]   # the time given: dW/L
    assert [int(d.get("step")) for d in datasets] == [0, 1, 2, 3]
    assert [float(d.get("dW_over_L")) for d in datasets] == [0.0, 0.01, 0.02, 0.03]
    assert {d.get("stage") for d in datasets} == {"shear"}
    for k, positions in enumerate(written):
        points, point_data, meta = read_frame(directory / f"frame_{k:05d}.vtu")
        np.testing.assert_array_equal(points, positions)
        # the flat reference, not a displacement (Warp By Vector would deform twice)
        assert "displacement" not in point_data
        np.testing.assert_array_equal(point_data["flat_position"],
                                      np.column_stack([mesh.nodes, np.zeros(mesh.node_count)]))
        np.testing.assert_array_equal(point_data["height"], positions[:, 2])
        np.testing.assert_array_equal(point_data["cell:area_index"], np.arange(mesh.triangle_count))
        assert meta == {"step": k, "time": 0.01 * k, "dL_over_L": 0.5, "dW_over_L": 0.01 * k, "stage": "shear"}
    assert sorted(p.name for p in directory.iterdir()) == ["frame_00000.vtu", "frame_00001.vtu",
                                                           "frame_00002.vtu", "frame_00003.vtu", "frames.pvd"]


def test_frame_writer_writes_a_polyline_and_keeps_triangles_as_cells(tmp_path):
    meshio = pytest.importorskip("meshio")
    mesh = structured_mesh(L, W, 200)
    writer = FrameWriter(tmp_path / "plate", mesh)
    writer.write(mesh.nodes)  # (N, 2) is the flat state; step defaults to 0
    writer.close()
    plate = meshio.read(tmp_path / "plate" / "frame_00000.vtu")
    assert [c.type for c in plate.cells] == ["triangle"]
    np.testing.assert_array_equal(plate.cells[0].data, mesh.triangles)

    centerline = np.column_stack([np.linspace(0, L, 11), np.zeros(11), np.zeros(11)])
    rod = FrameWriter(tmp_path / "rod", polyline_cells(11), reference=centerline)
    for step in (0, 5):
        rod.write(centerline + [0, 0, 1e-3 * step], step=step, stage="compress")
    rod.close()
    assert [int(d.get("step")) for d in _pvd_datasets(tmp_path / "rod" / "frames.pvd")] == [0, 5]
    line = meshio.read(tmp_path / "rod" / "frame_00005.vtu")
    assert [c.type for c in line.cells] == ["line"] and len(line.cells[0].data) == 10
    np.testing.assert_allclose(line.points[:, 2], 5e-3)
    np.testing.assert_allclose(line.point_data["flat_position"], centerline)


def test_frame_writer_leaves_no_temporary_file_when_a_write_fails(tmp_path, monkeypatch):
    pytest.importorskip("meshio")
    mesh = structured_mesh(L, W, 200)
    directory = tmp_path / "frames"
    writer = FrameWriter(directory, mesh)
    writer.write(mesh.nodes, step=0)
    before = {p.name: p.read_bytes() for p in directory.iterdir()}

    def broken_write(path, *args, **kwargs):
        with open(path, "w") as fh:
            fh.write("<?xml half a file")
        raise OSError("disk full")

    monkeypatch.setattr(writer._meshio, "write", broken_write)
    with pytest.raises(OSError, match="disk full"):
        writer.write(mesh.nodes, step=1)
    assert {p.name: p.read_bytes() for p in directory.iterdir()} == before  # no temp file, pvd intact


@pytest.mark.parametrize("positions, kwargs, fragment", [
    (np.zeros((4, 3)), {}, "positions hold 4 nodes"),
    (np.zeros((10, 4)), {}, "positions have shape (10, 4)"),
    (None, {"step": -1}, "step = -1"),
    (None, {"point_data": {"bad": np.zeros(3)}}, "point array 'bad'"),
])
def test_frame_writer_rejects_bad_frames(tmp_path, positions, kwargs, fragment):
    pytest.importorskip("meshio")
    mesh = structured_mesh(L, W, 200)
    writer = FrameWriter(tmp_path, mesh)
    with pytest.raises(InputError) as excinfo:
        writer.write(mesh.nodes if positions is None else positions, **kwargs)
    one_line_error(excinfo, fragment)
    with pytest.raises(InputError) as excinfo:
        FrameWriter(tmp_path, polyline_cells(4), cell_type="triangle")
    one_line_error(excinfo, "triangle cells need 3 nodes")
