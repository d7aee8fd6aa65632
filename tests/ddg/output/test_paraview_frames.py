"""Frames for ParaView from ddg.simulate(frames=True) (issue 18 item 7): deformed points with the
flat reference beside them (never a displacement too), the .pvd's time = dW/L on the shear, the
rod drawn as the ribbon it stands for, per-element curvature and energy density fields."""
import xml.etree.ElementTree as ET

import numpy as np
import pytest

import ddg
from ddg.output.frames import read_frame

meshio = pytest.importorskip("meshio")


def _run(tmp_path, model, resolution):
    strip = ddg.Strip.from_ratios(1 / 6 if model == "plate" else 1 / 20, 0.5)
    protocol = ddg.LoadingProtocol(0.5, shear_ratio=0.4, compression_steps=4, shear_steps=8)
    result = ddg.simulate(strip, protocol, model=model, resolution=resolution, frames=True, out=tmp_path,
                          branches=False, thresholds=False)
    datasets = list(ET.parse(tmp_path / "frames" / "frames.pvd").getroot().iter("DataSet"))
    return strip, result, datasets


def test_the_collection_time_is_the_shear(tmp_path):
    strip, result, datasets = _run(tmp_path, "rod", 30)
    times = [float(d.get("timestep")) for d in datasets]
    assert np.all(np.diff(times) > 0)                              # one monotone axis for ParaView
    for d, row in zip(datasets, result.rows):
        t = float(d.get("timestep"))
        if row["stage"] == "shear":
            assert t == pytest.approx(row["dW_over_L"])
        else:
            assert t == pytest.approx(row["dL_over_L"] - 0.5) and t <= 0.0


def test_the_rod_is_drawn_as_a_ribbon_of_its_width(tmp_path):
    strip, result, datasets = _run(tmp_path, "rod", 30)
    points, arrays, meta = read_frame(tmp_path / "frames" / datasets[-1].get("file"))
    mesh = meshio.read(tmp_path / "frames" / datasets[-1].get("file"))
    assert [c.type for c in mesh.cells] == ["triangle"] and len(mesh.cells[0].data) == 2 * (30 - 1)
    assert "displacement" not in arrays
    flat = arrays["flat_position"]
    assert np.ptp(flat[:, 1]) == pytest.approx(strip.width) and np.all(flat[:, 2] == 0.0)
    # the two sides of each node are W apart, centred on the centreline
    centre = result.model.positions(result.final_state.q)
    np.testing.assert_allclose(0.5 * (points[0::2] + points[1::2]), centre, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(points[1::2] - points[0::2], axis=1), strip.width, rtol=1e-12)
    # curvature fields per triangle; the buckled, sheared rod bends (k2) and twists (tau)
    assert {"cell:k1_L", "cell:k2_L", "cell:tau_L"} <= set(arrays)
    assert np.max(np.abs(arrays["cell:k2_L"])) > 1.0 and np.max(np.abs(arrays["cell:tau_L"])) > 0.1


def test_plate_frames_carry_turn_angle_and_bending_energy_density(tmp_path):
    strip, result, datasets = _run(tmp_path, "plate", 300)
    points, arrays, meta = read_frame(tmp_path / "frames" / datasets[-1].get("file"))
    np.testing.assert_allclose(points, result.model.positions(result.final_state.q))
    turn, density = arrays["cell:turn_angle_deg"], arrays["cell:bending_energy_density"]
    assert turn.max() == pytest.approx(result.rows[-1]["max_turn_angle_deg"], rel=1e-9)
    # the densities over the rest areas add up to the plate's bending energy (Eq. 11b)
    mesh = result.model.mesh
    tri = mesh.nodes[mesh.triangles]
    area = 0.5 * np.abs(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]))
    from ddg.energies.hinge_bending import hinge_bending_energy

    total = hinge_bending_energy(points, mesh.triangles, mesh.hinge_triangles, result.model.hinge_stiffness,
                                 gradient=False)[0].sum()
    assert np.sum(density * area) == pytest.approx(total, rel=1e-12)
