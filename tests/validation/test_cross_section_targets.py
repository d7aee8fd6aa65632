"""Issue 30's targets for the 1D model with its cross-section (ribbon-cross-section), measured
against the converged FEM studies on the committed data: the error map's rows (data/error_map,
`python -m validation.error_map --models ribbon-cross-section`, M = 51/101/201 on every map scene)
and the speed benchmark (benchmarks/results/cross_section_path.json).

The bounds are the issue's, fixed before these data existed: dW1/L and dW2/L within 0.005 of the
FEM and H_mid/L within 0.01 away from the thresholds at dL/L = 1/2 and 1/4, W/L = 1/20 and 1/12;
within 0.01 at W/L = 1/6; within 0.005 at W/L = 1/20, L/b = 300 and 4000 where the FEM has the
value; the M = 101 and 201 thresholds within 1e-3 of each other; the wall time at most 2x the
rod's at the same M. Each case is one (scene, quantity); a case not met is a strict expected
failure whose reason carries the measured figures (M = 201 unless said), computed from the data the
test asserts on (so they cannot go stale), and a change that meets it shows up as an unexpected pass.
Which cases are not met is fixed here (True in the tables below); only the figures are computed.
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


def _unmet(request, reason: str) -> None:
    """Mark the running test a strict expected failure with `reason`, the figures of the data it
    asserts on; only an AssertionError is the expected miss (missing data fails before this)."""
    request.applymarker(pytest.mark.xfail(strict=True, raises=AssertionError, reason=reason))


def _fmt(value: float | None, spec: str = ".4f") -> str:
    return "none" if value is None else format(value, spec)


def _accuracy_figures(scene: str, quantity: str, bound: float) -> str:
    """What the error map measured for one case: the M = 201 value against the shell's (with its
    error bar) and its error, or the H_mid error, with M = 101's and 51's for comparison."""
    rows = {label: _row(scene, label) for label in ("M201", "M101", "M51")}
    if quantity == "H_mid":
        errors = {label: _value(r, "H_mid_error") for label, r in rows.items()}
        text = f"H_mid error {_fmt(errors['M201'])} (M = 101: {_fmt(errors['M101'])})"
        if _value(rows["M201"], "dW1") is None:
            text += "; the path has no pitchfork"
    else:
        row = rows["M201"]
        value, ref = _value(row, quantity), _value(row, f"ref_{quantity}")
        bar = _value(row, f"{quantity}_ref_error_bar")
        shell = f"the shell's {_fmt(ref)} +- {_fmt(bar)}"
        if value is None:
            text = f"no {quantity} (run {row['status']}; {shell})"
        else:
            text = f"{quantity} {_fmt(value)} against {shell}: error {_fmt(_value(row, f'{quantity}_error'))}"
        text += (f" (M = 101: {_fmt(_value(rows['M101'], quantity))}, "
                 f"M = 51: {_fmt(_value(rows['M51'], quantity))})")
    return f"issue 30 target not met at {scene}: {text}; bound {bound:g} (data/error_map/error_map.csv)"


#: (scene, quantity, bound, not met: a strict expected failure whose figures _accuracy_figures computes)
ACCURACY_CASES = [
    ("dL0.5_W0.05_Lb1181", "dW1", 0.005, False),
    ("dL0.5_W0.05_Lb1181", "dW2", 0.005, False),
    ("dL0.5_W0.05_Lb1181", "H_mid", 0.01, True),
    ("dL0.5_W0.08333_Lb1181", "dW1", 0.005, True),
    ("dL0.5_W0.08333_Lb1181", "dW2", 0.005, False),
    ("dL0.5_W0.08333_Lb1181", "H_mid", 0.01, True),
    ("dL0.25_W0.05_Lb787", "dW1", 0.005, False),
    ("dL0.25_W0.05_Lb787", "dW2", 0.005, False),
    ("dL0.25_W0.05_Lb787", "H_mid", 0.01, False),
    ("dL0.25_W0.08333_Lb787", "dW1", 0.005, True),
    ("dL0.25_W0.08333_Lb787", "dW2", 0.005, False),
    # 0.0108 under the map's rules version 2; 0.0097 under version 3 (issue 32: the band about the
    # run's own thresholds left out too, a rule change made for every model, not for this case)
    ("dL0.25_W0.08333_Lb787", "H_mid", 0.01, False),
    ("dL0.5_W0.1667_Lb1181", "dW1", 0.01, True),
    ("dL0.5_W0.1667_Lb1181", "dW2", 0.01, True),
    ("dL0.25_W0.1667_Lb787", "dW1", 0.01, True),
    ("dL0.25_W0.1667_Lb787", "dW2", 0.01, True),
    ("dL0.5_W0.05_Lb300", "dW1", 0.005, False),
    ("dL0.5_W0.05_Lb300", "dW2", 0.005, False),
    ("dL0.5_W0.05_Lb4000", "dW1", 0.005, True),
]


@pytest.mark.parametrize("scene, quantity, bound, unmet", [
    pytest.param(*case, id=f"{case[0]}-{case[1]}") for case in ACCURACY_CASES])
def test_cross_section_model_is_within_the_issues_bound_of_the_converged_fem(request, scene, quantity, bound, unmet):
    """|model - FEM| (the error map's error column, M = 201) within the issue's bound; a missing
    value (no threshold found, or H_mid compared nowhere) is not met, nor is H_mid on a path that
    stops before its pitchfork (it is then compared on the U branch's start only)."""
    row = _row(scene)
    if unmet:
        _unmet(request, _accuracy_figures(scene, quantity, bound))
    error = _value(row, f"{quantity}_error")
    if quantity == "H_mid":
        assert _value(row, "dW1") is not None, "the path has no pitchfork"
    assert error is not None and error <= bound, error


#: (scene, quantity, not met: a strict expected failure with the two values and their difference)
#: of the narrow target scenes.
CONVERGENCE_CASES = [
    ("dL0.5_W0.05_Lb1181", "dW1", True),
    ("dL0.5_W0.05_Lb1181", "dW2", False),
    ("dL0.25_W0.05_Lb787", "dW1", True),
    ("dL0.25_W0.05_Lb787", "dW2", False),
    ("dL0.25_W0.08333_Lb787", "dW1", False),
    ("dL0.25_W0.08333_Lb787", "dW2", False),
    ("dL0.5_W0.08333_Lb1181", "dW1", True),
]


@pytest.mark.parametrize("scene, quantity, unmet", [
    pytest.param(*case, id=f"{case[0]}-{case[1]}") for case in CONVERGENCE_CASES])
def test_thresholds_at_101_and_201_nodes_agree_to_1e_3(request, scene, quantity, unmet):
    coarse, fine = _value(_row(scene, "M101"), quantity), _value(_row(scene, "M201"), quantity)
    if unmet:
        difference = "none" if coarse is None or fine is None else f"{abs(coarse - fine):.3g}"
        _unmet(request, f"issue 30 target not met at {scene}: {quantity} at M = 101 / 201 {_fmt(coarse)} / "
                        f"{_fmt(fine)}: {difference} apart; bound 1e-3 (data/error_map/error_map.csv)")
    assert coarse is not None and fine is not None and abs(coarse - fine) <= 1e-3, (coarse, fine)


def test_map_has_the_models_rows_on_every_scene_at_three_resolutions():
    rows = [r for r in read_table(MAP) if r["model"] == MODEL]
    scenes = {r["scene"] for r in read_table(MAP)}
    expected = {(s, m) for s in scenes for m in ("M51", "M101", "M201")}
    assert {(r["scene"], r["resolution_label"]) for r in rows} == expected


def _wall_time_figures(report: dict) -> str:
    """The speed benchmark's figures: the ratios, the runs that meet 2x, the Newton iterations of the
    others against the rod's, and how many runs stop before dW_max."""
    model, rows = MODEL, report["rows"]

    def run(r):
        return f"W/L = 1/{round(1 / r['width_ratio'])}, dL/L = {r['compression_ratio']:g}, M = {r['nodes']}"

    ratios = [r["wall_time_ratio"] for r in rows]
    met = [r for r in rows if r["wall_time_ratio"] <= 2.0]
    others = [r for r in rows if r["wall_time_ratio"] > 2.0]
    text = (f"wall time {min(ratios):.1f}x to {max(ratios):.1f}x the rod's at the same M on the four narrow scenes "
            f"(benchmarks/results/cross_section_path.json, best of {report.get('repeat')}): ")
    text += "met at " + "; ".join(
        f"{run(r)} ({r[f'{model}_newton_iterations']} Newton iterations, {r[f'{model}_wall_time_s']:.2f} s against "
        f"the rod's {r['rod_newton_iterations']}, {r['rod_wall_time_s']:.2f} s)" for r in met) if met else "met nowhere"
    if others:
        iterations = [r[f"{model}_newton_iterations"] for r in others]
        rod = [r["rod_newton_iterations"] for r in others]
        text += (f"; elsewhere {min(iterations)}-{max(iterations)} iterations against the rod's {min(rod)}-{max(rod)}, "
                 f"spent in fold snaps and branch switching where the path leaves the model's long-wavelength "
                 f"range near dW_max")
    stopped = sum(r[f"{model}_status"] != "complete" for r in rows)
    return text + f" ({stopped} of {len(rows)} runs stop before it); the target is 2x"


def test_wall_time_is_at_most_twice_the_rods(request):
    report = json.loads(SPEED.read_text())
    _unmet(request, _wall_time_figures(report))
    ratios = [r["wall_time_ratio"] for r in report["rows"]]
    assert len(ratios) == 8 and max(ratios) <= 2.0, ratios
