"""The plate described by its centerline (section 4.3, Eqs. 12-13, Fig. 10; App. F, Eqs. F.1-F.2).

Measured at dL/L = 1/2, dW/L = 0.3, L/b = 1181 (structured meshes of 846 / 546 triangles for
W/L = 1/20, 1/6): mean delta 1.8e-4, 1.7e-3 and max delta 8.9e-4, 1.37e-2 (of L). Rod-based
edge (F.1) mean error 3.5e-4, 3.8e-3; ribbon-based (F.2) 1.7e-2, 3.8e-2, worst next to a sign
change of kappa^(2) (s/L = 0.758 and 0.963; eta = tau / kappa^(2) diverges there).
"""
from __future__ import annotations

import numpy as np
import pytest

import ddg
from ddg.analysis.centerline_approx import centerline_error_field, centerline_frame, edge_reconstruction
from ddg.studies.centerline_error import centerline_error_study
from ddg.studies.curvature_studies import states_at_shears
from ddg.models.plate import PlateModel


def _plate_state(width_ratio, shear, triangles):
    strip = ddg.Strip.from_ratios(width_ratio, 0.5)
    ((model, state),) = list(states_at_shears("plate", strip, 0.5, [shear], triangles, max_step=0.05))
    return model, state


def test_rigid_motion_of_the_flat_plate_is_reproduced_exactly():
    """Eq. (12) is exact for a flat strip moved rigidly (rotated and translated): delta = 0."""
    strip = ddg.Strip.from_ratios(1 / 6, 0.5)
    model = PlateModel(strip, 300)
    q = model.rest_state()
    x = model.positions(q)
    c, s = np.cos(0.7), np.sin(0.7)
    rotation = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]) @ np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])
    q[model.node_dofs] = x @ rotation.T + np.array([0.01, -0.02, 0.03])
    field = centerline_error_field(model, q)
    assert field["max"] < 1e-12
    edges = edge_reconstruction(model, q)
    assert edges["rod_max"] < 1e-12


def test_centerline_approximation_error_is_small_for_narrow_plates_and_grows_with_width():
    """Section 4.3: at dW/L = 0.3 the error of Eq. (12) stays within 2 % of L for W/L <= 1/6 and
    grows with the width; the rod-based edge (F.1) matches the plate better than the
    ribbon-based one (F.2), whose worst point lies near an inflection point."""
    narrow, wide = _plate_state(1 / 20, 0.3, 800), _plate_state(1 / 6, 0.3, 600)
    f_narrow = centerline_error_field(*narrow[:1], narrow[1].q)
    f_wide = centerline_error_field(*wide[:1], wide[1].q)
    for f in (f_narrow, f_wide):
        assert f["max"] < 0.02
    assert f_wide["mean"] > 3 * f_narrow["mean"] and f_wide["max"] > 3 * f_narrow["max"]
    # the error grows from the centerline (w = 0, where it vanishes) towards the edges
    w = np.abs(f_wide["w_over_L"])
    assert np.max(f_wide["delta"][w < 1e-9]) < 1e-12
    edge = w > 0.9 * w.max()
    assert f_wide["delta"][edge].mean() > 3 * f_wide["delta"][(w > 0) & (w < 0.5 * w.max())].mean()
    for model, state in (narrow, wide):
        e = edge_reconstruction(model, state.q)
        assert e["rod_mean"] < 0.5 * e["ribbon_mean"]
        frame = centerline_frame(model, state.q)
        k2, s = frame["kappa2"][1:-1], frame["s"][1:-1] / model.strip.length
        inflections = s[np.flatnonzero(np.sign(k2[1:]) * np.sign(k2[:-1]) < 0)]
        worst = e["s_over_L"][np.argmax(e["ribbon_error"])]
        assert np.min(np.abs(inflections - worst)) < 0.05


@pytest.mark.slow
def test_fig10_mean_error_grows_with_width_at_each_shear():
    """Fig. 10: mean error against L/W in {2, 3, 6, 12, 20} at dW/L in {0.1, 0.3, 0.5}: it
    falls as the plate narrows (L/W from 2 to 20) at each shear reached."""
    rows = centerline_error_study(triangles=800)
    for shear in (0.1, 0.3, 0.5):
        mine = sorted((r for r in rows if r["dW_over_L"] == pytest.approx(shear) and np.isfinite(r["mean_error"])),
                      key=lambda r: r["L_over_W"])
        assert len(mine) >= 4
        errors = np.array([r["mean_error"] for r in mine])
        assert errors[0] > 5 * errors[-1]
        assert np.all(np.diff(errors) < 0)


def test_centerline_error_command_writes_csv_and_png(tmp_path):
    """`python -m ddg centerline-error` on two narrow coarse plates: CSV rows per (W/L, dW/L), a PNG."""
    pytest.importorskip("matplotlib")
    import csv

    from ddg.cli import main

    out = tmp_path / "e"
    assert main(["centerline-error", "--width-ratios", "0.05,0.1", "--shear-ratios", "0.1", "--resolution", "300",
                 "--out", str(out)]) == 0
    with open(out / "centerline_error.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert [float(r["L_over_W"]) for r in rows] == [20.0, 10.0]
    assert float(rows[1]["mean_error"]) > float(rows[0]["mean_error"]) > 0
    assert (out / "centerline_error.png").stat().st_size > 1000
    assert main(["centerline-error", "--width-ratios", "1.5", "--out", str(tmp_path / "bad")]) == 2


def test_the_centerline_error_figure_has_log_axes_and_skips_unreached_states():
    """Fig. 10 as the command draws it: L/W and delta on log axes (L/W = 20 beside 2), mean and
    max per dW/L; a state the run did not reach (NaN) is left out; a zero error keeps y linear."""
    pytest.importorskip("matplotlib")
    from ddg.cli import centerline_error_figure

    rows = [{"L_over_W": lw, "dW_over_L": 0.1, "mean_error": e, "max_error": 3 * e}
            for lw, e in ((2.0, 1e-2), (20.0, 1e-4), (6.0, float("nan")))]
    ax = centerline_error_figure(rows, [0.1]).axes[0]
    assert ax.get_xscale() == "log" and ax.get_yscale() == "log"
    assert [len(line.get_xdata()) for line in ax.get_lines()] == [2, 2]
    rows[0]["mean_error"] = 0.0
    assert centerline_error_figure(rows, [0.1]).axes[0].get_yscale() == "linear"
