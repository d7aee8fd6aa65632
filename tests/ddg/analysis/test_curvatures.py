"""Centerline curvatures (Figs. A.12-A.14) of the rod, the ribbon and the plate, W/L = 1/20, dL/L = 1/2.

Measured (M = 101; plate 846 triangles, 48 stations):
- dW/L = 0.3, across the inflection point near s = L/4: the jump of k2 L is 16.6 times the typical
  step between neighbouring nodes for the direct ribbon (tau L: 6.9 times), 1.00 (0.02) for the
  rod; at dW/L = 0.45: 86 (20) for the ribbon. The ribbon's twist does not change sign there: it
  stays near tau L = 2.3 and jumps by 0.33 while k2 jumps from +2.4 to -2.4.
- compressed (dW = 0): the plate's k2 L within 0.18 of the rod's (max |k2 L| = 9.9), k1 and tau 0.
"""
from __future__ import annotations

import numpy as np
import pytest

import ddg
from ddg.analysis.curvatures import CURVATURE_COLUMNS, centerline_curvatures, framed_curve_curvatures, inflection_jumps
from ddg.studies.curvature_studies import states_at_shears, write_curvatures_csv
from ddg.geometry.strip import InputError

STRIP = ddg.Strip.from_ratios(0.05, 0.5)


def _profile(model_name, shear, resolution, **kw):
    ((model, state),) = list(states_at_shears(model_name, STRIP, 0.5, [shear], resolution, **kw))
    return centerline_curvatures(model, state.q)


def test_helix_has_the_exact_curvature_and_twist():
    """A helix of radius a and pitch 2 pi c framed by its principal normal has, per unit length,
    curvature a / (a^2 + c^2) (all of it geodesic, about m1 = the normal of the binormal-spanned
    strip) and twist c / (a^2 + c^2): the discrete values converge at second order."""
    a, c = 1.0, 0.4
    errors = []
    for n in (200, 400):
        phi = np.linspace(0.0, 4 * np.pi, n)
        x = np.stack([a * np.cos(phi), a * np.sin(phi), c * phi], axis=1)
        mid = 0.5 * (phi[1:] + phi[:-1])
        binormal = np.stack([c * np.sin(mid), -c * np.cos(mid), a * np.ones_like(mid)], axis=1) / np.hypot(a, c)
        t = x[1:] - x[:-1]
        t /= np.linalg.norm(t, axis=1)[:, None]
        m1 = binormal - np.einsum("ij,ij->i", binormal, t)[:, None] * t
        m1 /= np.linalg.norm(m1, axis=1)[:, None]
        k1, k2, tau = framed_curve_curvatures(x, m1)
        ds = np.hypot(a, c) * (phi[1] - phi[0])
        errors.append((np.max(np.abs(np.abs(k1) / ds - a / (a * a + c * c))), np.max(np.abs(k2 / ds)),
                       np.max(np.abs(np.abs(tau) / ds - c / (a * a + c * c)))))
    assert errors[1][0] < 1e-4 and errors[1][1] < 1e-3 * a / (a * a + c * c) and errors[1][2] < 1e-4
    assert errors[0][0] / errors[1][0] == pytest.approx(4.0, rel=0.1)


def test_ribbon_curvatures_jump_at_the_inflection_points_where_the_rods_are_smooth():
    """Fig. A.12: the rod's k2 and tau are smooth across the inflection points (k2 = 0); the
    ribbon's k2 and tau jump there, the more so the larger the shear."""
    rod = inflection_jumps(_profile("rod", 0.3, 101))
    ribbon = inflection_jumps(_profile("ribbon", 0.3, 101))
    assert len(rod) == len(ribbon) == 2
    for j in rod:
        assert j["k2_jump_ratio"] < 1.5 and j["tau_jump_ratio"] < 1.5
    for j in ribbon:
        assert j["k2_jump_ratio"] > 8.0 and j["tau_jump_ratio"] > 3.0
        assert abs(j["k2_jump_L"]) > 3.0
    rod_initialised = inflection_jumps(_profile("ribbon", 0.3, 101, ribbon_init="rod"))
    assert all(j["k2_jump_ratio"] > 8.0 for j in rod_initialised)


def test_plate_centerline_curvature_matches_the_rod_when_compressed(tmp_path):
    """The planar buckled strip: the plate's centerline (frame from the surface normals) has the
    rod's k2 profile to 2 % of its peak, and no geodesic curvature or twist. Also writes the CSV."""
    rod = _profile("rod", 0.0, 101)
    ((model, state),) = list(states_at_shears("plate", STRIP, 0.5, [0.0], 800, max_step=0.05))
    plate = centerline_curvatures(model, state.q)
    rod_k2 = np.interp(plate["s_over_L"], rod["s_over_L"], rod["k2_L"])
    peak = np.max(np.abs(rod["k2_L"]))
    assert peak == pytest.approx(9.94, rel=0.01)
    assert np.max(np.abs(plate["k2_L"] - rod_k2)) < 0.02 * peak
    assert np.max(np.abs(plate["k1_L"])) < 1e-8 and np.max(np.abs(plate["tau_L"])) < 1e-8
    path = tmp_path / "curvatures.csv"
    write_curvatures_csv(path, [{"model": "plate", "step": 0, "dL_over_L": 0.5, "dW_over_L": 0.0, "profile": plate}])
    lines = path.read_text().splitlines()
    assert lines[0].split(",") == list(CURVATURE_COLUMNS)
    assert len(lines) == 1 + len(plate["s_over_L"])


def test_bad_shear_request_is_an_input_error():
    with pytest.raises(InputError, match="shear limit"):
        list(states_at_shears("rod", STRIP, 0.5, [0.9], 21))


@pytest.mark.slow
def test_plate_twist_at_the_inflection_falls_as_the_plate_thins():
    """Figs. A.13-A.14: at dW/L = 0.3 the plate's centerline twist at its inflection points falls
    as L/b grows from 300 to 1200 (the surface tends to a developable one), for W/L = 1/20 and
    1/6. Measured (846 / 952 triangles): tau L = 3.00, 2.76, 2.31 and 1.82, 1.44, 1.21; as a
    share of the largest |tau L|: 0.66, 0.59, 0.47 and 0.32, 0.24, 0.20."""
    from ddg.studies.curvature_studies import inflection_twist_study

    rows = inflection_twist_study()
    for ratio in (1 / 20, 1 / 6):
        mine = sorted((r for r in rows if r["W_over_L"] == ratio), key=lambda r: r["L_over_b"])
        assert [r["inflections"] for r in mine] == [2, 2, 2]
        twist = np.array([r["tau_inflection_L"] for r in mine])
        share = np.array([r["tau_inflection_over_max"] for r in mine])
        assert np.all(np.diff(twist) < 0) and np.all(np.diff(share) < 0)
        assert twist[-1] < 0.85 * twist[0]


def test_curvatures_command_writes_csv_and_png(tmp_path):
    """`python -m ddg curvatures`: one CSV row per station and requested shear, a PNG; bad input exits 2."""
    pytest.importorskip("matplotlib")
    from ddg.cli import main

    out = tmp_path / "c"
    assert main(["curvatures", "--model", "ribbon", "--shear-ratios", "0,0.2", "--resolution", "41",
                 "--out", str(out)]) == 0
    lines = (out / "curvatures.csv").read_text().splitlines()
    assert lines[0].split(",") == list(CURVATURE_COLUMNS)
    assert len(lines) == 1 + 2 * 39
    assert (out / "curvatures.png").stat().st_size > 1000
    assert main(["curvatures", "--shear-ratios", "0.3,x", "--out", str(tmp_path / "bad")]) == 2
    assert main(["curvatures", "--model", "rod", "--zeta", "1", "--out", str(tmp_path / "bad")]) == 2
