"""The report's figures and their data: the stability map's outcome per run and its colours, every
figure kind drawn from hand-made rows (PNG, PDF and CSV), and the 3D snapshots drawn from the frames
a plate run kept."""
import pytest

import ddg
from validation import runs as R


# ---------------------------------------------------------------------------- stability map
def test_stability_map_outcome_follows_each_run_summary():
    """Each label on both sides of its test: converged or not, dW1 located, left unresolved by
    the mesh or never bracketed, the rod's dW1 within 0.03 of the reference's or beyond."""
    from types import SimpleNamespace

    from validation.report_data import stability_map

    rows = [{"stage": "shear", "dW_over_L": 0.5}]

    def run(**summary):
        return SimpleNamespace(rows=rows, summary={"converged": True, "dW_max_over_L": 0.7, **summary})

    gold = SimpleNamespace(summary={"dW1_over_L": 0.30})
    cases = {
        R.RunSpec("plate", 0.05, 0.5, 100): (run(dW1_over_L=0.3), "ok"),
        R.RunSpec("plate", 0.05, 0.5, 200): (run(converged=False, dW1_over_L=0.3), "Newton failure"),
        R.RunSpec("plate", 0.05, 0.5, 300): (run(dW1_over_L=None, unresolved_thresholds={"dW1_over_L": {
            "value": 0.3, "reason": "turn 31 degrees"}}), "dW1 unresolved by the mesh"),
        R.RunSpec("plate", 0.05, 0.5, 400): (run(dW1_over_L=None, unresolved_thresholds={}), "missed pitchfork"),
        R.RunSpec("rod", 0.05, 0.5, 100): (run(dW1_over_L=0.3 + 0.029), "ok"),
        R.RunSpec("rod", 0.05, 0.5, 200): (run(dW1_over_L=0.3 + 0.031), "rod width error"),
        R.RunSpec("plate", 0.05, 0.5, 500): (run(dW1_over_L=0.3, resolved_up_to_dW_over_L=0.4),
                                              "ok (mesh unresolved near dW_max)"),
    }
    smap = stability_map({spec: r for spec, (r, _) in cases.items()}, {(0.5, 0.05): gold}, [])
    got = {(e["model"], e["resolution"]): e["outcome"] for e in smap}
    assert got == {(spec.model, spec.resolution): outcome for spec, (_, outcome) in cases.items()}


def test_stability_map_colours_the_mesh_unresolved_outcome_as_its_own():
    """The map's "ok (mesh unresolved near dW_max)" used to take plain "ok"'s colour (a startswith
    test that matched the shorter category first)."""
    from validation.figures import STABILITY_CATEGORIES, stability_category

    assert STABILITY_CATEGORIES[stability_category("ok (mesh unresolved near dW_max)")] == \
        "ok (mesh unresolved near dW_max)"
    assert STABILITY_CATEGORIES[stability_category("ok")] == "ok"
    assert STABILITY_CATEGORIES[stability_category("missed pitchfork (rod width error 0.2)")] == "rod width error"


# ---------------------------------------------------------------------------- figures
def test_a_figure_is_drawn_from_its_rows_alone(tmp_path):
    """Every figure kind from hand-made rows and marks (no run), saved as PNG, PDF and CSV."""
    pytest.importorskip("matplotlib")
    from validation import figures
    from validation.report import draw_figures
    from validation.report_data import FigureData

    curve = [["rod", 0.5, 0.05, 0.1 * i, 0.01 * i] for i in range(5)] + [["fem", 0.5, 0.05, 0.2, 0.02]]
    marks = {"panels": [(0.5, 0.05)], "thresholds": [{"model": "rod", "compression_ratio": 0.5, "width_ratio": 0.05,
                                                      "dW1_over_L": 0.2, "dW2_over_L": None}]}
    items = [
        FigureData("elastica", "elastica", "", ["model", "width_ratio", "dL_over_L", "H_mid_over_L", "exact"],
                   [["rod", 0.05, 0.1, 0.2, 0.2], ["fem", 1 / 6, 0.1, 0.21, 0.2]], {"exact": [(0.0, 0.0), (0.1, 0.2)]}),
        FigureData("shear", "shear_curves", "",
                   ["model", "compression_ratio", "width_ratio", "dW_over_L", "H_mid_over_L"], curve,
                   {**marks, "paper": [{"width_ratio": 0.05, "key": "dW1", "value": 0.36}]}),
        FigureData("force", "shear_force", "", ["model", "compression_ratio", "width_ratio", "dW_over_L",
                                                "F_shear_norm", "error_bar"],
                   [row + [None] for row in curve] + [["fem (converged)", 0.5, 0.05, 0.1 * i, 0.011 * i, 0.002]
                                                      for i in range(5)], marks),
        FigureData("stability", "stability_map", "", ["model", "compression_ratio", "width_ratio", "outcome",
                                                      "reached_percent_of_dW_max"],
                   [["rod", 0.5, 0.05, "ok", 100.0], ["plate", 0.25, 0.1, "missed pitchfork", None]]),
    ]
    assert set(figures.DRAW) >= {item.kind for item in items}
    draw_figures(items, tmp_path)
    for item in items:
        assert item.png.startswith(b"\x89PNG")
        for path in item.files.values():
            assert (tmp_path / path).stat().st_size > 0
        assert (tmp_path / item.files["csv"]).read_text().count("\n") == len(item.rows) + 1


def test_snapshots_show_the_plate_states_from_its_frames(tmp_path):
    """3D snapshots (paper Fig. 1) come from the frames the plate run kept: one panel per phase
    the run passes (a coarse W/L = 1/6 plate passes U and US), the CSV holds the frame's nodes.
    546 triangles (resolution 400): at 300 the triangles turn by 31 degrees at the pitchfork, so dW1
    is left unresolved (summary unresolved_thresholds) and the US panel has no dW1 to sit after."""
    pytest.importorskip("meshio", reason="the plate frames are VTU files read with meshio (python3-meshio)")
    import csv

    import numpy as np

    from validation import report, report_data
    from validation.studies import Profile

    strip = ddg.Strip.from_ratios(1 / 6, 1 / 2)
    protocol = ddg.LoadingProtocol(1 / 2, compression_steps=20, shear_steps=40)
    ddg.simulate(strip, protocol, model="plate", resolution=400, branches=False, frames=True, out=tmp_path / "run")
    spec = R.RunSpec("plate", 1 / 6, 1 / 2, 400, frames=True)
    run = R.load(tmp_path / "run", spec)
    states = report_data.snapshot_states(run)
    phases = [phase.rstrip("+-") for phase, _, _ in states]
    assert phases[:2] == ["U", "US"]
    dw1 = run.summary["dW1_over_L"]
    assert states[0][1] < dw1 < states[1][1]
    profile = Profile("test", [], {"plate": 400}, [], [], (), {}, {})
    figure, snapshots = report_data.snapshot_data({spec: run}, profile)
    assert snapshots.shapes == len(states) and snapshots.skipped is None
    assert report.sentence("snapshots", snapshots).startswith(f"{len(states)} shapes")
    report.draw_figures([figure], tmp_path / "out")
    for ext in ("png", "pdf", "csv"):
        assert (tmp_path / "out" / "figures" / f"snapshots_3d.{ext}").stat().st_size > 0
    with open(tmp_path / "out" / "figures" / "snapshots_3d.csv") as f:
        rows = [r for r in csv.DictReader(f) if r["phase"] == states[0][0]]
    import meshio

    nodes = meshio.read(states[0][2]).points / strip.length
    assert np.allclose([[float(r[k]) for k in ("x_over_L", "y_over_L", "z_over_L")] for r in rows], nodes)
