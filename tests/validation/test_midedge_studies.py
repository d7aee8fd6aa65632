"""The mid-edge plate's mesh studies (data/midedge_gold, validation/plate_gold.py --model
plate-midedge) against the FEM gold (data/fem_gold): issue 29's cross-check and targets.

The rules were fixed before the studies they check were run (issue 29):
- agreement: at each of the ten benchmark scenes the two converged thresholds differ by at most
  the sum of their error bars (the rule of data/fem_gold/README.md; validation.claims);
- the locking targets at W/L = 1/6 and 1/2, dL/L = 1/2: the dW1 sequence monotone with observed
  order in [1.5, 4] (the asymptotic window); the coarsest mesh (8 rows at 1/6, 16 at 1/2)
  within 0.008 L of the FEM's dW1, the middle one (12 rows, about 2000 triangles at 1/6; 24 at
  1/2) within 0.003 L for dW1 and 0.005 L for dW2;
- the path: on the two finer meshes of every study the stable path leaves U through the
  pitchfork (no fold before the first asymmetric state) and reaches S through one transition
  (at most one fold up to the last state the mesh resolves), as the shell's does.
A target not met is a strict expected failure carrying the measured figures. Missing data fails.
"""
from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
MIDEDGE = ROOT / "data" / "midedge_gold"

#: The ten benchmark scenes (dL/L, W/L): validation/benchmark.py.
SCENES = [(0.5, 1 / 20), (0.5, 1 / 12), (0.5, 1 / 6), (0.5, 1 / 3), (0.5, 1 / 2),
          (0.25, 1 / 20), (0.25, 1 / 12), (0.25, 1 / 6), (0.25, 1 / 3), (0.25, 1 / 2)]
#: The issue's bounds (units of L).
COARSE_DW1, MIDDLE_DW1, MIDDLE_DW2, LOWEST_ORDER = 0.008, 0.003, 0.005, 1.5
#: An observed order above 4 is no order (the asymptotic window of fem_reference.convergence).
HIGHEST_ORDER = 4.0


def _threshold_rule():
    from validation.claims import CLAIMS

    return CLAIMS["plate_vs_fem_narrow_thresholds"]


#: How the report judges a threshold's agreement with the shell (bound 0.02 L, decided where the
#: combined error bar is at most 0.02 L): assert_agreement_where_decided.
THRESHOLD_RULE = _threshold_rule()

#: Scenes whose mid-edge study has not been run yet (issue 29 item 3 in progress; resumable:
#: `python -m validation.plate_gold --model plate-midedge --out data/midedge_gold --only NAME`).
NOT_YET_RUN: list[str] = []  # whose study is not complete on its three meshes

#: Targets not met, as the studies were run: a strict expected failure each, whose reason the test
#: computes from the data it asserts on (_order_figures, _coarse_figures, _path_figures), so the
#: figures cannot go stale. Which targets are unmet is fixed here; only the figures are computed.
UNMET = {"order W1/6", "order W1/2", "coarse W1/6", "coarse W1/2", "path dL0.5_W1/6", "path dL0.5_W1/2",
         "path dL0.5_W1/3", "path dL0.25_W1/12", "path dL0.25_W1/6", "path dL0.25_W1/2",
         "speed targets", "speedup"}
NOT_RUN = {key: f"no complete mid-edge study of {name} stored yet (issue 29 item 3 in progress)"
           for name in NOT_YET_RUN for key in (f"agree {name} dW1", f"agree {name} dW2", f"path {name}")}


def _id(c, w):
    return f"dL{c:g}_W1/{round(1 / w)}"


def _xfail_if_not_run(request, key):
    """A study not run yet: a strict expected failure (before the study is looked for)."""
    if key in NOT_RUN:
        request.applymarker(pytest.mark.xfail(strict=True, reason=NOT_RUN[key]))


def _xfail_if_unmet(request, key, figures):
    """A target not met (UNMET): a strict expected failure whose reason is figures(), called once
    the data are loaded (missing data fail), and only an AssertionError is the expected miss."""
    if key in UNMET:
        request.applymarker(pytest.mark.xfail(strict=True, raises=AssertionError,
                                              reason=f"issue 29 target not met: {figures()}"))


def _scene_text(study) -> str:
    return f"dL/L = {study.compression_ratio:g}, W/L = 1/{round(1 / study.width_ratio)}"


def _f4(value) -> str:
    return "none" if value is None else f"{value:.4f}"


def _order_figures(study) -> str:
    values = [m.dW1 for m in study.meshes]
    steps = "" if None in values else " (differences " + ", ".join(
        f"{b - a:+.4f}" for a, b in zip(values, values[1:])) + ")"
    estimate = study.dW1
    order = "no observed order" if estimate is None or estimate.order is None else \
        f"observed order {estimate.order:.2f}, outside [{LOWEST_ORDER:g}, {HIGHEST_ORDER:g}]"
    return (f"{_scene_text(study)}, dW1/L {'/'.join(_f4(v) for v in values)} on "
            f"{'/'.join(m.label for m in study.meshes)}{steps}: {order}")


def _coarse_figures(study, fem) -> str:
    def off(value, reference):
        if value is None:
            return "none"
        return f"{value:.4f}, {value - reference.value:+.4f} from the FEM's {reference.value:.4f}"
    coarse, middle = study.meshes[0], study.meshes[1]
    return (f"{_scene_text(study)}: {coarse.label} dW1/L {off(coarse.dW1, fem.dW1)} (bound {COARSE_DW1:g}); "
            f"{middle.label} dW1/L {off(middle.dW1, fem.dW1)} (bound {MIDDLE_DW1:g}), dW2/L "
            f"{off(middle.dW2, fem.dW2)} (bound {MIDDLE_DW2:g})")


def _path_figures(study) -> str:
    """The two finer meshes' paths: phases (the first five), folds up to the last resolved state."""
    parts = []
    for mesh in study.meshes[1:]:
        phases, folds, resolved = path_transitions(mesh.folder)
        shown = " -> ".join(phases[:5]) + (" ..." if len(phases) > 5 else "")
        inside = [f for f in folds if f <= resolved]
        where = ("without a fold" if not inside else
                 f"{len(inside)} fold{'s' if len(inside) > 1 else ''} at dW/L " + ", ".join(f"{f:.4f}" for f in inside))
        parts.append(f"{mesh.label}: {shown} ({len(phases) - 1} phase changes), {where} up to the last resolved "
                     f"state {resolved:.3f}")
    return f"{_scene_text(study)}, " + "; ".join(parts)


def _study(model, c, w):
    from validation.estimates import load_study

    study = load_study(model, c, w)
    assert study is not None, f"no stored {model} study of dL/L = {c}, W/L = {w:.4g}"
    return study


def assert_agreement_where_decided(midedge, fem, quantity):
    """Issue 29's rule (|difference| <= the combined error bar) where the error bars can decide, as
    the report's threshold claims judge (validation.claims.Claim.outcome_at with the bound and
    error-bar limit of plate_vs_fem_narrow_thresholds, 0.02 L each): a combined error bar above
    the limit cannot tell agreement from disagreement, so the entry is undecided and skipped (with
    its figures), not counted as agreeing, unless the difference exceeds the bound even beyond the
    combined error bar, which fails it. tests/test_readme.py counts the decided entries of
    data/benchmark/benchmark.csv by the same rule."""
    from validation.claims import threshold_agreement

    agreement = threshold_agreement(midedge, fem, quantity)
    assert agreement is not None, (quantity, midedge.threshold(quantity), fem.threshold(quantity))
    difference, combined = agreement.difference, agreement.combined_error_bar
    outcome = THRESHOLD_RULE.outcome_at(difference, combined)
    assert outcome != "fails", (agreement, outcome)
    if combined > THRESHOLD_RULE.error_bar_limit:
        pytest.skip(f"undecided: {agreement.where}: |difference| {difference:.4f} L, combined error bar "
                    f"{combined:.4f} L > {THRESHOLD_RULE.error_bar_limit:g} L (validation.claims)")
    assert difference <= combined, agreement


@pytest.mark.parametrize("quantity", ["dW1", "dW2"])
@pytest.mark.parametrize("scene", SCENES, ids=[_id(*s) for s in SCENES])
def test_midedge_and_fem_thresholds_agree_within_their_combined_error_bars(request, scene, quantity):
    """Where the error bars decide (assert_agreement_where_decided); measured on the committed
    studies: 15 of the 20 entries decided, all within their combined error bars (|diff|/combined at
    most 0.74); undecided the dW1 at dL/L = 1/2, W/L = 1/6 (combined 0.023 L) and the dW2 at
    dL/L = 1/2, W/L = 1/6, 1/3, 1/2 and dL/L = 1/4, W/L = 1/2 (0.14-0.23 L)."""
    _xfail_if_not_run(request, f"agree {_id(*scene)} {quantity}")
    assert len(_study("plate-midedge", *scene).meshes) >= 3, "a study rests on three meshes"
    fem, midedge = (_study(m, *scene) for m in ("fem", "plate-midedge"))
    assert_agreement_where_decided(midedge, fem, quantity)


#: The error map's scenes (fem_reference.gold.MAP_SCENES), checked by the same rule where both
#: studies have the threshold (at L/b = 4000 both pass the fold of US since issue 31). Measured: 14
#: of the 17 entries decided, all within their combined error bars; undecided the dW2 at W/L = 1/8,
#: 1/10 and 1/4, dL/L = 1/2 (combined 0.025-0.051 L).
MAP_SCENES = [("dL0.5_W0.125", 0.5, 1 / 8), ("dL0.25_W0.125", 0.25, 1 / 8), ("dL0.5_W0.25", 0.5, 1 / 4),
              ("dL0.5_W0.05_Lb300", 0.5, 1 / 20), ("dL0.5_W0.1667_Lb300", 0.5, 1 / 6),
              ("dL0.25_W0.25", 0.25, 1 / 4), ("dL0.5_W0.1", 0.5, 1 / 10), ("dL0.25_W0.1", 0.25, 1 / 10),
              ("dL0.5_W0.05_Lb4000", 0.5, 1 / 20)]
#: (scene, quantity) not met: a strict expected failure whose reason _withheld_figures computes.
MAP_UNMET = {"dL0.5_W0.1667_Lb300 dW2"}


def _withheld_figures(name, quantity, midedge, fem) -> str:
    """Why the mid-edge study has no `quantity`: each mesh's withheld value and its reason (the
    small-strain limit of ddg.protocol.validity), against the shell's."""
    key = f"{quantity}_over_L"
    parts = []
    for mesh in midedge.meshes:
        summary = json.loads((mesh.folder / "summary.json").read_text())
        withheld = (summary.get("unresolved_thresholds") or {}).get(key)
        parts.append(f"{mesh.label}: " + ("reported" if withheld is None else
                                          f"{withheld['value']:.4f} withheld: {withheld['reason']}"))
    shell = fem.threshold(quantity)
    return (f"no mid-edge {quantity} reported at {name} (the shell's {_f4(shell and shell.value)} +- "
            f"{_f4(shell and shell.error_bar)}): " + "; ".join(parts))


@pytest.mark.parametrize("quantity", ["dW1", "dW2"])
@pytest.mark.parametrize("scene", MAP_SCENES, ids=[s[0] for s in MAP_SCENES])
def test_midedge_and_fem_agree_at_the_error_maps_scenes(request, scene, quantity):
    name, c, w = scene
    from validation.estimates import load_study

    fem, midedge = (load_study(m, c, w, name=name) for m in ("fem", "plate-midedge"))
    assert midedge is not None and len(midedge.meshes) >= 3, f"no complete mid-edge study of {name}"
    if f"{name} {quantity}" in MAP_UNMET:
        request.applymarker(pytest.mark.xfail(strict=True, raises=AssertionError,
                                              reason=_withheld_figures(name, quantity, midedge, fem)))
    if fem.threshold(quantity) is None:
        pytest.skip(f"the shell's study of {name} has no {quantity}")
    assert_agreement_where_decided(midedge, fem, quantity)


@pytest.mark.parametrize("width", [1 / 6, 1 / 2], ids=["W1/6", "W1/2"])
def test_midedge_dW1_sequence_is_monotone_and_converges_at_order_1_5(request, width):
    study = _study("plate-midedge", 0.5, width)
    _xfail_if_unmet(request, f"order W1/{round(1 / width)}", lambda: _order_figures(study))
    values = [m.dW1 for m in study.meshes]
    assert None not in values and len(values) >= 3, values
    steps = [b - a for a, b in zip(values, values[1:])]
    assert all(s < 0 for s in steps) or all(s > 0 for s in steps), values
    assert study.dW1.order is not None and LOWEST_ORDER <= study.dW1.order <= HIGHEST_ORDER, study.dW1


@pytest.mark.parametrize("width", [1 / 6, 1 / 2], ids=["W1/6", "W1/2"])
def test_coarse_midedge_meshes_are_within_the_issues_bounds_of_the_fem(request, width):
    fem, study = _study("fem", 0.5, width), _study("plate-midedge", 0.5, width)
    _xfail_if_unmet(request, f"coarse W1/{round(1 / width)}", lambda: _coarse_figures(study, fem))
    coarse, middle = study.meshes[0], study.meshes[1]
    assert abs(coarse.dW1 - fem.dW1.value) <= COARSE_DW1, (coarse.label, coarse.dW1, fem.dW1)
    assert abs(middle.dW1 - fem.dW1.value) <= MIDDLE_DW1, (middle.label, middle.dW1, fem.dW1)
    assert middle.dW2 is not None and abs(middle.dW2 - fem.dW2.value) <= MIDDLE_DW2, (middle.label, middle.dW2, fem.dW2)


def path_transitions(folder: Path) -> tuple[list[str], list[float], float]:
    """(phases of the shear stage up to the last resolved state, without sign, each run of equal
    phases once; folds; the resolved dW/L)."""
    summary = json.loads((folder / "summary.json").read_text())
    resolved = float(summary.get("resolved_up_to_dW_over_L") or summary["dW_max_over_L"])
    phases = []
    with open(folder / "path.csv") as fh:
        for row in csv.DictReader(fh):
            if row["stage"] == "shear" and row["phase"] and abs(float(row["dW_over_L"])) <= resolved:
                phase = row["phase"].rstrip("+-")
                if not phases or phases[-1] != phase:
                    phases.append(phase)
    return phases, list(summary.get("folds_dW_over_L") or []), resolved


#: Folds beyond the snap to S that are physics (the issue's condition: the shell shows them and the
#: finer meshes keep them): {scene: [dW/L of the fold]}. Each is checked below against the shell's
#: finest run, whose H_mid/L must drop there by more than twice each neighbouring recorded step.
PHYSICAL_FOLDS = {
    # the shell (216 x 28): H_mid/L 0.2415 -> 0.1925 from dW/L 0.3737 to 0.3802; the plate (18 rows)
    # 0.2428 -> 0.1937 over the same step; 12 and 18 rows both fold at 0.379
    "dL0.5_W1/12": [0.379],
}


def shell_drops_at(folder: Path, dw: float) -> bool:
    """Whether the shell's recorded H_mid/L jumps across the recorded step that contains dW/L = dw
    (within 0.01 L): the step's change more than twice each neighbouring step's."""
    with open(folder / "path.csv") as fh:
        rows = [(float(r["dW_over_L"]), float(r["H_mid_over_L"])) for r in csv.DictReader(fh) if r["stage"] == "shear"]
    steps = [abs(b[1] - a[1]) for a, b in zip(rows, rows[1:])]
    for i in range(1, len(steps) - 1):
        a, b = rows[i][0], rows[i + 1][0]
        if a - 0.01 <= dw <= b + 0.01 and steps[i] > 2 * max(steps[i - 1], steps[i + 1]):
            return True
    return False


@pytest.mark.parametrize("scene", SCENES, ids=[_id(*s) for s in SCENES])
def test_midedge_path_leaves_U_continuously_and_reaches_S_through_one_transition(request, scene):
    """At most one fold (the snap to S) up to the last resolved state on the two finer meshes,
    besides the folds of PHYSICAL_FOLDS, which the shell's finest run must show as well."""
    _xfail_if_not_run(request, f"path {_id(*scene)}")
    study = _study("plate-midedge", *scene)
    assert len(study.meshes) >= 3
    _xfail_if_unmet(request, f"path {_id(*scene)}", lambda: _path_figures(study))
    physical = PHYSICAL_FOLDS.get(_id(*scene), [])
    if physical:
        shell = _study("fem", *scene).meshes[-1].folder
        assert all(shell_drops_at(shell, f) for f in physical), (physical, shell)
    for mesh in study.meshes[1:]:
        phases, folds, resolved = path_transitions(mesh.folder)
        first_asymmetric = mesh.dW1 if mesh.dW1 is not None else 0.0
        early = [f for f in folds if f < first_asymmetric]
        assert not early, (mesh.label, "folds before the pitchfork", early)
        assert phases == ["U", "US", "S"], (mesh.label, phases, resolved)
        other = [f for f in folds if f <= resolved and not any(abs(f - g) <= 0.005 for g in physical)]
        assert len(other) <= 1, (mesh.label, folds, resolved)


# ---------------------------------------------------------------------------- locking (data/midedge_locking)
#: The membrane-locking study (validation/locking.py, docs/findings/benchmark.md "Membrane locking of
#: the mid-edge plate"): its committed runs, checked against each other and against this code.
LOCKING = ROOT / "data" / "midedge_locking"


def _locking_runs() -> dict:
    summary = json.loads((LOCKING / "summary.json").read_text())
    return {(r["slenderness"], r["membrane"], r["rows"]): r for r in summary["runs"]}


def test_the_psri_membrane_removes_the_thickness_dependence_of_the_coarse_pitchfork():
    """The locking diagnosis (validation/locking.py, stored runs): on 8 rows the constant-strain
    membrane's dW1/L moves from 0.2774 (L/b = 300) to 0.3056 (1181), 0.028 L, where the converged
    shell moves by -0.004 (0.2692 on 96 x 12 at 300; 0.2654 +- 0.0031 at 1181): spurious membrane
    energy growing as (L/b)^2. With the PSRI membrane: 0.2773 and 0.2777. Bounds: the locked shift
    above 0.02 L; the PSRI shift below 0.002 L (a tenth of the locked one; the 8-row discretisation
    error, 0.012, is what remains and is not locking)."""
    runs = _locking_runs()
    full = [runs[(s, "full", 8)]["dW1_over_L"] for s in (300.0, 1181.1)]
    psri = [runs[(s, "psri", 8)]["dW1_over_L"] for s in (300.0, 1181.1)]
    assert full[1] - full[0] > 0.02, full
    assert abs(psri[1] - psri[0]) < 0.002, psri


def _rerun_locking(tmp_path, slenderness, membrane, rows=8):
    """A committed locking run rerun as validation.locking runs it: the same dW1 to its bisection
    tolerance (1e-4 L) and the same stretching shares along U to 1e-6 (a hundredth of the last digit
    locking.md and the findings quote). Measured with this code against the runs stored before issue
    31 changed the path's substeps: dW1 within 2e-12 (L/b = 300) and 7e-11 (1181), shares within
    1.1e-11."""
    from validation import locking

    stored = _locking_runs()[(slenderness, membrane, rows)]
    summary = locking.run_plate(slenderness, rows, membrane, tmp_path / "run")
    assert summary["status"] == stored["status"] == "complete", summary["message"]
    assert summary["dW1_over_L"] == pytest.approx(stored["dW1_over_L"], abs=1e-4)
    rerun = locking.tabulate_run(tmp_path / "run")
    assert rerun.keys() == stored["stretching_share"].keys()
    for dw, share in stored["stretching_share"].items():
        assert rerun[dw] == pytest.approx(share, abs=1e-6), dw


def test_the_stored_locking_run_is_what_the_code_computes(tmp_path):
    """The committed 8-row PSRI run at L/b = 300 (about 6 s): _rerun_locking."""
    _rerun_locking(tmp_path, 300.0, "psri")


@pytest.mark.slow
@pytest.mark.parametrize("membrane", ["psri", "full"])
def test_the_stored_locking_runs_at_the_papers_slenderness_are_what_the_code_computes(tmp_path, membrane):
    """The two 8-row runs at L/b = 1181 whose dW1 the findings quote (0.2777 with PSRI, 0.3056 with
    the full membrane; 11-12 s each): _rerun_locking. Run with `pytest -m slow -k locking`."""
    _rerun_locking(tmp_path, 1181.1, membrane)


#: Issue 29's speed targets as the stored benchmarks measured them (benchmarks/results/: midedge_path.json,
#: warm calls of benchmarks/plate_path.py --model plate-midedge --rows 8 12, idle machine, OpenBLAS on one
#: thread; speed_accuracy.json, benchmarks/speed_accuracy.py). The tests read the stored benchmarks; they
#: time nothing. Both targets are unmet: strict expected failures whose reasons are computed from them.
def _speed_targets_figures(stored: dict) -> str:
    """The stored benchmark's wall times and iterations per recorded step against the targets, and
    where the 8-row run's iterations go."""
    runs = "; ".join(f"{t['rows']} rows {t['wall_time_s']:.2f} s (target {t['wall_target_s']:g} s), "
                     f"{t['iterations_per_step']:.2f} Newton iterations per recorded step "
                     f"(target {t['iterations_per_step_target']:g})" for t in _issue_29_targets(stored))
    first = min(stored["results"], key=lambda r: r["rows_target"])
    phases = first["newton_iterations_by_phase"]
    return (f"W/L = 1/6, dL/L = 1/2, full path with thresholds (benchmarks/results/midedge_path.json): {runs}; of "
            f"the {first['newton_iterations']} iterations on {first['rows_target']} rows, "
            f"{phases['rejected steps']} are in failed solves, {phases['fold snaps']} in fold snaps and "
            f"{phases['branch switching']} in branch switching ({len(first['branch_switches_dW_over_L'])} "
            f"recorded steps with a branch switch)")


def _issue_29_targets(stored: dict) -> list[dict]:
    """The stored runs issue 29 set a wall time for (8 and 12 rows); a run of other rows (the 18-row
    one of issue 50's breakdown) has none."""
    return [t for t in stored["targets"] if t["wall_target_s"] is not None]


def _speedup_figures(stored: dict) -> str:
    """The speed-accuracy benchmark's verdict on the 10x target, with its figures."""
    verdict, reference = stored["verdict"], stored["reference"]["dW1"]
    cheapest = verdict["cheapest_within_target"]

    def entry(model):
        e = cheapest.get(model)
        return "none" if e is None else f"{e['entry']}, {e['wall_time_s']:.1f} s (error {e['dW1_error']:.4f})"
    ratio = "none" if verdict.get("ratio") is None else f"{verdict['ratio']:.2f}"
    return (f"(benchmarks/results/speed_accuracy.json, W/L = 1/6, dL/L = 1/2): the cheapest mid-edge run within "
            f"{verdict['target_dW1_error_over_L']:g} L of the FEM's converged dW1/L ({reference['value']:.4f} +- "
            f"{reference['error_bar']:.4f}) is {entry('plate-midedge')}; the FEM's is {entry('fem')}: FEM time / "
            f"mid-edge time {ratio} against the {verdict['target_speedup']:g} asked; the benchmark's rule says "
            f"'{verdict['verdict']}': {verdict['reason']}")


def _stored_benchmark(name: str) -> dict:
    return json.loads((ROOT / "benchmarks" / "results" / f"{name}.json").read_text())


def test_midedge_plate_meets_the_issues_speed_targets_in_the_stored_benchmark(request):
    stored = _stored_benchmark("midedge_path")
    _xfail_if_unmet(request, "speed targets", lambda: _speed_targets_figures(stored))
    targets = {t["rows"]: t for t in _issue_29_targets(stored)}
    assert set(targets) == {8, 12}, sorted(targets)
    for rows, t in targets.items():
        assert t["completed"], (rows, t)
        assert t["wall_time_s"] <= t["wall_target_s"] == {8: 8.0, 12: 20.0}[rows], (rows, t)
        assert t["iterations_per_step"] <= t["iterations_per_step_target"] == 6.0, (rows, t)


def test_midedge_plate_is_ten_times_faster_than_the_fem_at_equal_dW1_error_in_the_stored_benchmark(request):
    stored = _stored_benchmark("speed_accuracy")
    _xfail_if_unmet(request, "speedup", lambda: _speedup_figures(stored))
    rule = stored["rule"]
    assert rule["target_dW1_error_over_L"] == 0.003 and rule["target_speedup"] == 10.0, rule
    assert stored["verdict"]["verdict"] == "met", stored["verdict"]
