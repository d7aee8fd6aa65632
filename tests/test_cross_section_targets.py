"""Issue 30's targets for the 1D model with its cross-section (ribbon-cross-section), measured
against the converged FEM studies on the committed data: the error map's rows (data/error_map,
`python -m validation.error_map --models ribbon-cross-section`, M = 51/101/201 on every map scene)
and the speed benchmark (benchmarks/results/cross_section_path.json).

The bounds are the issue's, fixed before these data existed: dW1/L and dW2/L within 0.005 of the
FEM and H_mid/L within 0.01 away from the thresholds at dL/L = 1/2 and 1/4, W/L = 1/20 and 1/12;
within 0.01 at W/L = 1/6; within 0.005 at W/L = 1/20, L/b = 300 and 4000 where the FEM has the
value; the M = 101 and 201 thresholds within 1e-3 of each other; the wall time at most 2x the
rod's at the same M. Each case is one (scene, quantity); a case not met is a strict expected
failure whose reason carries the measured figure (M = 201 unless said), so a change that meets it
shows up as an unexpected pass.
"""
from __future__ import annotations

import json

import pytest

from validation.error_map import ROOT, read_table

MODEL = "ribbon-cross-section"
MAP = ROOT / "data" / "error_map" / "error_map.csv"
SPEED = ROOT / "benchmarks" / "results" / "cross_section_path.json"
NARROW = ("dL0.5_W0.05_Lb1181", "dL0.5_W0.08333_Lb1181", "dL0.25_W0.05_Lb787", "dL0.25_W0.08333_Lb787")


def _row(scene: str, label: str = "M201") -> dict:
    rows = [r for r in read_table(MAP)
            if r["model"] == MODEL and r["scene"] == scene and r["resolution_label"] == label]
    assert len(rows) == 1, (scene, label)
    return rows[0]


def _value(row: dict, column: str) -> float | None:
    return float(row[column]) if row[column] not in ("", None) else None


def _unmet(reason: str):
    return pytest.mark.xfail(strict=True, reason=reason)


#: (scene, quantity, bound, measured figures when not met)
ACCURACY_CASES = [
    ("dL0.5_W0.05_Lb1181", "dW1", 0.005, None),
    ("dL0.5_W0.05_Lb1181", "dW2", 0.005, None),
    ("dL0.5_W0.05_Lb1181", "H_mid", 0.01, "H_mid error 0.0159 (M = 101: 0.0139)"),
    ("dL0.5_W0.08333_Lb1181", "dW1", 0.005, "dW1 0.3161 against 0.3275: error 0.0114"),
    ("dL0.5_W0.08333_Lb1181", "dW2", 0.005, None),
    ("dL0.5_W0.08333_Lb1181", "H_mid", 0.01, "H_mid error 0.0646"),
    ("dL0.25_W0.05_Lb787", "dW1", 0.005, None),
    ("dL0.25_W0.05_Lb787", "dW2", 0.005, None),
    ("dL0.25_W0.05_Lb787", "H_mid", 0.01, None),
    ("dL0.25_W0.08333_Lb787", "dW1", 0.005, "dW1 0.2024 against 0.2084: error 0.0060"),
    ("dL0.25_W0.08333_Lb787", "dW2", 0.005, None),
    # 0.0108 under the map's rules version 2; 0.0097 under version 3 (issue 32: the band about the
    # run's own thresholds left out too, a rule change made for every model, not for this case)
    ("dL0.25_W0.08333_Lb787", "H_mid", 0.01, None),
    ("dL0.5_W0.1667_Lb1181", "dW1", 0.01, "dW1 0.2421 against 0.2654: error 0.0232"),
    ("dL0.5_W0.1667_Lb1181", "dW2", 0.01, "no dW2: the path stops in US (the shell's 0.4308)"),
    ("dL0.25_W0.1667_Lb787", "dW1", 0.01, "dW1 0.1467 against 0.1610: error 0.0142"),
    ("dL0.25_W0.1667_Lb787", "dW2", 0.01, "dW2 0.2357 against 0.2594: error 0.0237"),
    ("dL0.5_W0.05_Lb300", "dW1", 0.005, None),
    ("dL0.5_W0.05_Lb300", "dW2", 0.005, None),
    ("dL0.5_W0.05_Lb4000", "dW1", 0.005, "dW1 0.3234 against the shell's 0.3466 +- 0.0573: error 0.0232 (M = 51 "
                                          "and 101 stop before it)"),
]


@pytest.mark.parametrize("scene, quantity, bound", [
    pytest.param(scene, quantity, bound, marks=() if figures is None else _unmet(figures), id=f"{scene}-{quantity}")
    for scene, quantity, bound, figures in ACCURACY_CASES])
def test_cross_section_model_is_within_the_issues_bound_of_the_converged_fem(scene, quantity, bound):
    """|model - FEM| (the error map's error column, M = 201) within the issue's bound; a missing
    value (no threshold found, or H_mid compared nowhere) is not met, nor is H_mid on a path that
    stops before its pitchfork (it is then compared on the U branch's start only)."""
    row = _row(scene)
    error = _value(row, f"{quantity}_error")
    if quantity == "H_mid":
        assert _value(row, "dW1") is not None, "the path has no pitchfork"
    assert error is not None and error <= bound, error


#: (scene, quantity, measured |M101 - M201|) of the narrow target scenes.
CONVERGENCE_CASES = [
    ("dL0.5_W0.05_Lb1181", "dW1", "0.3460 / 0.3472: 0.0012"),
    ("dL0.5_W0.05_Lb1181", "dW2", None),
    ("dL0.25_W0.05_Lb787", "dW1", "0.2172 / 0.2162: 0.00104"),
    ("dL0.25_W0.05_Lb787", "dW2", None),
    ("dL0.25_W0.08333_Lb787", "dW1", None),
    ("dL0.25_W0.08333_Lb787", "dW2", None),
    ("dL0.5_W0.08333_Lb1181", "dW1", "0.3067 / 0.3161: 0.0094"),
]


@pytest.mark.parametrize("scene, quantity", [
    pytest.param(scene, quantity, marks=() if figures is None else _unmet(figures), id=f"{scene}-{quantity}")
    for scene, quantity, figures in CONVERGENCE_CASES])
def test_thresholds_at_101_and_201_nodes_agree_to_1e_3(scene, quantity):
    coarse, fine = _value(_row(scene, "M101"), quantity), _value(_row(scene, "M201"), quantity)
    assert coarse is not None and fine is not None and abs(coarse - fine) <= 1e-3, (coarse, fine)


def test_map_has_the_models_rows_on_every_scene_at_three_resolutions():
    rows = [r for r in read_table(MAP) if r["model"] == MODEL]
    scenes = {r["scene"] for r in read_table(MAP)}
    expected = {(s, m) for s in scenes for m in ("M51", "M101", "M201")}
    assert {(r["scene"], r["resolution_label"]) for r in rows} == expected


@pytest.mark.xfail(strict=True, reason="wall time 1.9x to 20x the rod's at the same M on the four narrow scenes "
                                       "(benchmarks/results/cross_section_path.md, best of 2): met only at W/L = 1/20, "
                                       "dL/L = 1/4, M = 201 (881 Newton iterations, 1.29 s against the rod's 871, "
                                       "0.70 s); elsewhere 4192-15968 iterations against the rod's 872-1400, spent in "
                                       "fold snaps and branch switching where the path leaves the model's "
                                       "long-wavelength range near dW_max (6 of 8 runs stop there); the target is 2x")
def test_wall_time_is_at_most_twice_the_rods():
    report = json.loads(SPEED.read_text())
    ratios = [r["wall_time_ratio"] for r in report["rows"]]
    assert len(ratios) == 8 and max(ratios) <= 2.0, ratios
