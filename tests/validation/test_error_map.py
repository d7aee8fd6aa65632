"""validation.error_map: the error columns against a reference study, the resumable table, the
held-out (leave-one-scene-out) check of ddg.advise's prediction, and the committed map."""
import csv

import numpy as np
import pytest

from validation import error_map as em
from validation.error_map import command as map_command
from validation.error_map import compute as map_compute
from validation.error_map import rows as map_rows
from validation.estimates import Curve, Estimate, MeshResult, Study

ROOT = em.ROOT
COMMITTED = ROOT / "data" / "error_map"


def reference(dw1=0.30, dw2=0.45):
    dw = np.linspace(0.0, 0.6, 61)
    return Study("fem", 0.5, 0.05, [MeshResult("N96x12", 96, "elements along L", dw1, dw2)],
                 Estimate(dw1, 0.002), Estimate(dw2, 0.003), Curve(dw, 0.4 - 0.5 * dw, np.full_like(dw, 0.001)),
                 "synthetic")


def run_rows(shift=0.0, bump_at=None, upto=0.6):
    rows = [{"stage": "compression", "dW_over_L": 0.0, "H_mid_over_L": 0.0}]
    for x in np.linspace(0.0, upto, 121):
        h = 0.4 - 0.5 * x + shift + (0.2 if bump_at is not None and abs(x - bump_at) < 0.011 else 0.0)
        rows.append({"stage": "shear", "dW_over_L": float(x), "H_mid_over_L": float(h)})
    return rows


def test_errors_against_the_reference_and_its_error_bars():
    summary = {"status": "complete", "dW1_over_L": 0.31, "dW2_over_L": 0.44}
    e = em.row_errors(reference(), summary, run_rows(shift=0.004))
    assert e["dW1_error"] == pytest.approx(0.01) and e["dW1_bound"] == pytest.approx(0.012)
    assert e["dW2_error"] == pytest.approx(0.01) and e["dW2_bound"] == pytest.approx(0.013)
    assert e["H_mid_error"] == pytest.approx(0.004) and e["H_mid_bound"] == pytest.approx(0.005)
    assert e["H_mid_ref_error_bar"] == pytest.approx(0.001) and e["reason"] == ""


def test_the_band_about_the_reference_thresholds_is_left_out():
    summary = {"status": "complete", "dW1_over_L": 0.30, "dW2_over_L": 0.45}
    near = em.row_errors(reference(), summary, run_rows(bump_at=0.305))   # within 0.02 of dW1: ignored
    far = em.row_errors(reference(), summary, run_rows(bump_at=0.20))
    assert near["H_mid_error"] < 1e-12 and far["H_mid_error"] == pytest.approx(0.2)
    assert em.THRESHOLD_BAND == 0.02


def test_missing_thresholds_and_incomplete_runs_say_why_and_have_no_bound():
    summary = {"status": "complete", "dW1_over_L": 0.30, "dW2_over_L": None,
               "unresolved_thresholds": {"dW2_over_L": {"value": 0.5, "reason": "the strain reaches 0.03"}}}
    e = em.row_errors(reference(), summary, run_rows())
    assert "dW2_bound" not in e and "dW2 null: located at 0.5000 but unresolved" in e["reason"]
    stopped = em.row_errors(reference(), {"status": "stopped", "message": "Newton failed", "dW1_over_L": 0.3,
                                          "dW2_over_L": 0.45}, run_rows(upto=0.4))
    assert not any(f"{q}_bound" in stopped for q in em.QUANTITIES)
    assert "compared up to dW/L = 0.4000 only" in stopped["reason"] and "no bounds" in stopped["reason"]


def test_table_is_resumable_by_key_and_hashes(tmp_path):
    path = tmp_path / "map.csv"
    table = em.open_table(path)
    row = {"scene": "dL0.5_W0.05_Lb1181", "model": "rod", "resolution": 50, "resolution_label": "M50",
           "source_hash": "a", "reference_hash": "r", "dW1_bound": 0.01}
    em.put_row(table, row)
    em.put_row(table, {**row, "model": "ribbon", "resolution_label": "M51"})
    again = em.open_table(path)
    assert em.is_current(again, ("rod", "M50", "dL0.5_W0.05_Lb1181"), "a", "r")
    assert not em.is_current(again, ("rod", "M50", "dL0.5_W0.05_Lb1181"), "b", "r")     # other sources: recompute
    assert not em.is_current(again, ("rod", "M50", "dL0.5_W0.05_Lb1181"), "a", "s")     # other reference: recompute
    em.put_row(again, {**row, "source_hash": "b", "dW1_bound": 0.02})                    # replaces, never duplicates
    with open(path) as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 2 and [r["dW1_bound"] for r in rows if r["model"] == "rod"] == ["0.02"]
    assert list(rows[0]) == list(em.COLUMNS)
    assert {r["rules_version"] for r in rows} == {em.RULES_VERSION}


def test_a_row_made_under_other_comparison_rules_is_recomputed(tmp_path, monkeypatch):
    """A change of the rules that make a row (RULES_VERSION) makes every row stale, also those whose
    run and reference did not change (the stored plate and FEM runs), and rows from before the
    column existed."""
    path = tmp_path / "map.csv"
    row = {"scene": "dL0.5_W0.05_Lb1181", "model": "plate", "resolution": 8, "resolution_label": "R8",
           "source_hash": "a", "reference_hash": "r"}
    em.put_row(em.open_table(path), row)
    assert em.is_current(em.open_table(path), ("plate", "R8", "dL0.5_W0.05_Lb1181"), "a", "r")
    monkeypatch.setattr(map_rows, "RULES_VERSION", "next")
    assert not em.is_current(em.open_table(path), ("plate", "R8", "dL0.5_W0.05_Lb1181"), "a", "r")
    old = path.read_text().replace(",rules_version", "").replace(",2\n", "\n")
    path.write_text(old)
    monkeypatch.undo()
    assert not em.is_current(em.open_table(path), ("plate", "R8", "dL0.5_W0.05_Lb1181"), "a", "r")


def _map_row(w, lb, model, label, wall, bound):
    row = {c: "" for c in em.COLUMNS}
    row.update(scene=f"dL0.5_W{w:.4g}_Lb{lb:.0f}", compression_ratio="0.5", width_ratio=repr(w), slenderness=repr(lb),
               model=model, resolution=label[1:], resolution_label=label, wall_time_s=repr(wall))
    for q in em.QUANTITIES:   # a reference without error bar: error and bound the same
        row[f"{q}_bound"] = row[f"{q}_error"] = repr(bound)
    return row


def test_held_out_check_leaves_each_scene_out():
    """W/L = 1/12 left out and predicted from 1/20 and 1/6: the rod on 100 nodes (predicted 0.02,
    measured 0.006) holds, the rod on 50 (predicted 0.008, measured 0.03 on dW2) fails on that
    quantity; at 0.01 the choice is the cheap M50, predicted within and measured not."""
    lb = 1181.1023622047244
    rows = [_map_row(w, lb, "rod", "M100", 1.0, b) for w, b in ((0.05, 0.004), (1 / 12, 0.006), (1 / 6, 0.02))]
    rows += [_map_row(w, lb, "rod", "M50", 0.5, b) for w, b in ((0.05, 0.003), (1 / 12, 0.006), (1 / 6, 0.008))]
    rows[4]["dW2_bound"] = rows[4]["dW2_error"] = "0.03"
    out = {e["scene"]: e for e in em.held_out_check(rows, 0.01)}
    edge, middle = out["dL0.5_W0.05_Lb1181"], out["dL0.5_W0.08333_Lb1181"]
    assert not edge["held_out"] and "outside" in edge["why"]
    assert middle["held_out"] and middle["basis"] == ["dL0.5_W0.05_Lb1181", "dL0.5_W0.1667_Lb1181"]
    assert (middle["compared"], middle["held"]) == (6, 5) and middle["violations"] == [
        "rod M50 dW2: measured 0.0300 > predicted 0.0080"]
    assert middle["choice"] == "rod M50" and middle["choice_within"] and middle["choice_holds"] is False
    assert middle["choice_measured"] == pytest.approx(0.03) and middle["choice_measured_wall"] == pytest.approx(0.5)


def test_the_margin_measured_on_the_fitting_scenes_is_carried_to_the_held_out_ones():
    """A held-out W/L = 1/8 measured at 0.016: margin 1 predicts the worse of 1/12 and 1/6 (0.012) and
    fails; rule v3 multiplies by the leave-one-out margin of the fitting scenes (1/12 measured 0.012
    against 0.008 predicted from 1/20 and 1/6: 1.5) and holds. For the fitting scene 1/12 itself
    the margin is measured without it (nested): no other scene is bracketed, margin 1."""
    lb = 1181.1023622047244
    rows = [_map_row(w, lb, "rod", "M100", 100.0, b) for w, b in ((0.05, 0.003), (1 / 12, 0.012), (1 / 6, 0.008))]
    held = _map_row(0.125, lb, "rod", "M100", 100.0, 0.016)
    held["role"] = "held-out"
    v1 = {e["scene"]: e for e in em.held_out_check(rows + [held], 0.05, rule="v1")}
    v3 = {e["scene"]: e for e in em.held_out_check(rows + [held], 0.05)}
    e1, e3 = v1["dL0.5_W0.125_Lb1181"], v3["dL0.5_W0.125_Lb1181"]
    assert (e1["compared"], e1["held"], e1["margin"]) == (3, 0, 1.0)
    assert (e3["compared"], e3["held"]) == (3, 3) and e3["margin"] == pytest.approx(1.5)
    assert v3["dL0.5_W0.08333_Lb1181"]["margin"] == 1.0 and v3["dL0.5_W0.08333_Lb1181"]["held"] == 0


def test_a_prediction_is_checked_against_the_error_not_the_bound():
    """The prediction (from bounds: error + the basis references' error bars) claims the error
    against a converged reference; at the checking scene it meets |q - reference|, its reference's
    own error bar reported, not added (rule v2 added it: the bar counted twice). A held-out rod
    predicted 0.02 with error 0.015 and a reference error bar 0.01 (bound 0.025) holds."""
    lb = 1181.1023622047244
    rows = [_map_row(w, lb, "rod", "M100", 1.0, b) for w, b in ((0.05, 0.004), (1 / 6, 0.02))]
    held = _map_row(0.125, lb, "rod", "M100", 1.0, 0.025)
    held["role"] = "held-out"
    for q in em.QUANTITIES:
        held[f"{q}_error"], held[f"{q}_ref_error_bar"] = "0.015", "0.01"
    e = {e["scene"]: e for e in em.held_out_check(rows + [held], 0.05)}["dL0.5_W0.125_Lb1181"]
    assert (e["compared"], e["held"]) == (3, 3) and e["choice_measured"] == pytest.approx(0.015)
    held["dW1_bound"] = ""      # no bound (e.g. a run that stopped): nothing to check on dW1
    e = {e["scene"]: e for e in em.held_out_check(rows + [held], 0.05)}["dL0.5_W0.125_Lb1181"]
    assert e["compared"] == 2


def test_held_out_targets_count_scenes_choices_and_predictions():
    """Issue 32's targets from the check's entries: scenes inside the map, choices predicted within,
    the median wall time of those (measured where the scene has the chosen run), predictions holding."""
    entries = [
        {"role": "held-out", "held_out": True, "choice_within": True, "choice_measured_wall": 4.0,
         "choice_predicted_wall": 9.0, "held": 9, "compared": 10, "choice_holds": True},
        {"role": "held-out", "held_out": True, "choice_within": True, "choice_measured_wall": None,
         "choice_predicted_wall": 20.0, "held": 10, "compared": 10, "choice_holds": None},
        {"role": "held-out", "held_out": True, "choice_within": False, "choice_measured_wall": 500.0,
         "choice_predicted_wall": 600.0, "held": 10, "compared": 10, "choice_holds": None},
        {"role": "held-out", "held_out": False, "choice_within": None, "choice_measured_wall": None,
         "choice_predicted_wall": None, "held": 0, "compared": 0, "choice_holds": None},
        {"role": "fit", "held_out": True, "choice_within": True, "choice_measured_wall": 1.0,
         "choice_predicted_wall": 1.0, "held": 0, "compared": 5, "choice_holds": False},
    ]
    t = em.held_out_targets(entries, 0.01)
    assert (t["held_out"], t["inside"], t["within"], t["held"], t["compared"]) == (4, 3, 2, 29, 30)
    assert t["median_wall_s"] == pytest.approx(12.0) and (t["choices_measured"], t["choices_holding"]) == (1, 1)


def test_cheapest_within_and_combined_error():
    lb = 1181.1
    rows = [_map_row(0.05, lb, "rod", "M100", 1.0, 0.02), _map_row(0.05, lb, "plate", "R12", 50.0, 0.009),
            _map_row(0.05, lb, "fem", "N64", 40.0, 0.001)]
    assert em.cheapest_within(rows, 0.01)["model"] == "fem"
    assert em.cheapest_within(rows, 0.01, runnable_only=True)["model"] == "plate"
    assert em.cheapest_within(rows, 0.0001) is None
    rows[0]["dW2_bound"] = ""
    assert em.combined_error(rows[0]) is None and em.combined_error(rows[1]) == pytest.approx(0.009)


# ------------------------------------------------------------------------------ the committed map
def committed_rows():
    path = COMMITTED / em.CSV_NAME
    if not path.exists():
        pytest.skip("no committed error map")
    return em.read_table(path)


def test_committed_map_is_small_and_holds_no_run_folders():
    committed_rows()
    files = [p for p in COMMITTED.rglob("*") if p.is_file()]
    assert {p.suffix for p in files} <= {".csv", ".md", ".png"}
    assert sum(p.stat().st_size for p in files) < 2e6
    assert all(p.stat().st_size < 300e3 for p in files if p.suffix == ".png")
    assert len([p for p in files if p.suffix == ".png"]) <= 2


def test_committed_map_covers_every_scene_with_a_reference():
    rows = committed_rows()
    scenes = {r["scene"] for r in rows}
    expected = {s.name for s in em.reference_scenes() if s.reference is not None and s.role == "fit"}
    assert expected <= scenes, sorted(expected - scenes)
    # the ten benchmark scenes, W/L = 1/20 at L/b = 100, 300 and 4000, 1/6 at 300 and 4000, the six
    # earlier held-out scenes (1/8, 1/10, 1/4) and issue 32's four at dL/L = 1/3 (1/20, 1/10, 1/6, 1/3)
    assert len(expected) == 25 and {"dL0.5_W0.05_Lb4000", "dL0.3333_W0.1_Lb886", "dL0.5_W0.1667_Lb4000"} <= expected
    #: the plates' studies the map lacks (listed in its README's "What is missing")
    lacking = {"dL0.5_W0.05_Lb100": {"plate-midedge"}, "dL0.5_W0.1667_Lb4000": {"plate", "plate-midedge"}}
    for s in scenes:
        models = {r["model"] for r in rows if r["scene"] == s}
        assert {"rod", "plate", "plate-midedge", "fem"} - lacking.get(s, set()) <= models, (s, models)
    for r in rows:   # a row without a bound says why
        if any(r[f"{q}_bound"] == "" for q in em.QUANTITIES):
            assert r["reason"], r
    assert {r["rules_version"] for r in rows} == {em.RULES_VERSION}


def test_committed_map_leave_one_out():
    """Leave-one-scene-out on the fitting scenes (rule v3, nested margin): the scenes bracketed by the
    others are the interior ones of the box (dL/L, W/L, relative L/b); every prediction made there
    bounds the error measured (339 of 339 on the map of issue 32; docs/findings/model_choice.md reports them)."""
    entries = [e for e in em.held_out_check(committed_rows(), 0.01) if e["role"] == "fit"]
    inside = {e["scene"] for e in entries if e["held_out"]}
    assert inside == {"dL0.5_W0.05_Lb1181", "dL0.5_W0.08333_Lb1181", "dL0.5_W0.1_Lb1181", "dL0.5_W0.125_Lb1181",
                      "dL0.5_W0.1667_Lb1181", "dL0.5_W0.25_Lb1181", "dL0.5_W0.3333_Lb1181", "dL0.5_W0.05_Lb300",
                      "dL0.25_W0.08333_Lb787", "dL0.25_W0.1_Lb787", "dL0.25_W0.125_Lb787", "dL0.25_W0.1667_Lb787",
                      "dL0.25_W0.25_Lb787", "dL0.25_W0.3333_Lb787", "dL0.3333_W0.1_Lb886", "dL0.3333_W0.1667_Lb886"}
    assert all(e["compared"] > 0 for e in entries if e["held_out"])
    held, compared = sum(e["held"] for e in entries), sum(e["compared"] for e in entries)
    assert held == compared == 339, [v for e in entries for v in e["violations"]]


def test_held_out_scenes_are_predicted_from_the_fitting_set_only():
    """A scene with role held-out is never used to predict (ddg.advise.fitting) and is checked against
    the fitting scenes that bracket it."""
    lb = 1181.1023622047244
    rows = [_map_row(w, lb, "rod", "M100", 1.0, b) for w, b in ((0.05, 0.004), (1 / 6, 0.02))]
    held = _map_row(0.125, lb, "rod", "M100", 1.0, 0.03)
    held["role"] = "held-out"
    out = {e["scene"]: e for e in em.held_out_check(rows + [held], 0.05)}
    e = out["dL0.5_W0.125_Lb1181"]
    assert e["role"] == "held-out" and e["held_out"] and (e["compared"], e["held"]) == (3, 0)
    assert e["choice"] == "rod M100" and e["choice_within"] and e["choice_holds"] is True
    # the held-out row does not change what the fitting scenes predict for each other
    from ddg.advise import choose, parse_rows
    assert choose(0.1, 0.5, None, 0.05, rows=parse_rows(rows + [held])).predicted_errors["dW1"] == 0.02


#: Issue 32's targets on the held-out scenes, fixed by the issue before their references existed: at
#: tolerances 0.01 and 0.02, a model predicted within at >= 80 % of the scenes inside the map, the
#: median wall time of those choices <= 30 s, measured <= predicted in >= 95 % of the predictions.
TARGET_WITHIN, TARGET_MEDIAN_WALL_S, TARGET_HOLDING = 0.80, 30.0, 0.95
HELD_OUT_NAMES = {"dL0.4_W0.05_Lb984", "dL0.3333_W0.125_Lb886", "dL0.5_W0.05_Lb2000", "dL0.3_W0.25_Lb844"}


def _targets(tolerance):
    rows = committed_rows()
    assert {r["scene"] for r in rows if r.get("role") == "held-out"} == HELD_OUT_NAMES
    return em.held_out_targets(em.held_out_check(rows, tolerance), tolerance)


@pytest.mark.parametrize("tolerance", [0.01, 0.02])
def test_issue_32_predictions_hold_on_the_held_out_scenes(tolerance):
    """Measured |q - reference| <= predicted in >= 95 % of (scene, candidate, quantity) predictions on
    the four held-out scenes, all inside the map: 116 of 117 (99.1 %; the miss: ribbon-trapeze M = 51's
    dW1 at dL/L = 0.4, measured 0.0423 against 0.0420 predicted)."""
    t = _targets(tolerance)
    assert t["inside"] == 4 and t["held"] >= TARGET_HOLDING * t["compared"], t


def _choice_text(e) -> str:
    measured = "not measured in the map" if e["choice_measured"] is None else f"measured {e['choice_measured']:.4f}"
    wall = e["choice_measured_wall"] if e["choice_measured_wall"] is not None else e["choice_predicted_wall"]
    kind = "measured" if e["choice_measured_wall"] is not None else "predicted"
    return (f"{e['scene']}: {e['choice']} (predicted {e['choice_predicted']:.4f}, {measured}; {kind} wall "
            f"{'none' if wall is None else f'{wall:.0f} s'})")


def _within_share_figures(entries, t) -> str:
    inside = [e for e in entries if e["role"] == "held-out" and e["held_out"]]
    within = [e for e in inside if e["choice_within"]]
    others = [e for e in inside if not e["choice_within"]]
    share = 100.0 * t["within"] / t["inside"] if t["inside"] else 0.0
    text = (f"issue 32's target not met: a model is predicted within {t['tolerance']:g} at {t['within']} of the "
            f"{t['inside']} held-out scenes inside the map ({share:.0f} %; bound {100 * TARGET_WITHIN:.0f} %)")
    if within:
        text += ": " + "; ".join(_choice_text(e) for e in within)
    if others:
        text += "; elsewhere the best is predicted " + ", ".join(
            f"{'none' if e['choice_predicted'] is None else format(e['choice_predicted'], '.4f')} ({e['scene']})"
            for e in others)
    return text + " (data/error_map/error_map.csv)"


def _median_wall_figures(entries, t) -> str:
    within = [e for e in entries if e["role"] == "held-out" and e["held_out"] and e["choice_within"]]
    median = "none" if t["median_wall_s"] is None else f"{t['median_wall_s']:.0f} s"
    return (f"issue 32's target not met: the median wall of the choices predicted within {t['tolerance']:g} is "
            f"{median} (bound {TARGET_MEDIAN_WALL_S:g} s; each the run's measured wall where the scene has it, "
            f"else the map's prediction): " + "; ".join(_choice_text(e) for e in within)
            + " (data/error_map/error_map.csv)")


def _within_share_met(t):
    return t["within"] >= TARGET_WITHIN * t["inside"]


def _median_wall_met(t):
    return t["median_wall_s"] is not None and t["median_wall_s"] <= TARGET_MEDIAN_WALL_S


#: The two targets, both not met at both tolerances: strict expected failures whose reasons are
#: computed from the held-out check the assertion reads (which targets are unmet is fixed here).
HELD_OUT_TARGETS = {"within-at-80-percent": (_within_share_met, _within_share_figures),
                    "median-wall-under-30-s": (_median_wall_met, _median_wall_figures)}
UNMET_TARGETS = {"within-at-80-percent", "median-wall-under-30-s"}


@pytest.mark.parametrize("target", list(HELD_OUT_TARGETS))
@pytest.mark.parametrize("tolerance", [0.01, 0.02])
def test_issue_32_targets_on_the_held_out_scenes(request, tolerance, target):
    rows = committed_rows()
    assert {r["scene"] for r in rows if r.get("role") == "held-out"} == HELD_OUT_NAMES
    entries = em.held_out_check(rows, tolerance)
    t = em.held_out_targets(entries, tolerance)
    met, figures = HELD_OUT_TARGETS[target]
    if target in UNMET_TARGETS:
        request.applymarker(pytest.mark.xfail(strict=True, raises=AssertionError, reason=figures(entries, t)))
    assert met(t), t


def test_committed_map_held_out_scenes_are_those_with_a_finished_study():
    """The held-out scenes (fem_reference.gold.HELD_OUT_SCENES) are in the map once their FEM study is
    finished, and only then."""
    rows = committed_rows()
    held = {r["scene"] for r in rows if r.get("role") == "held-out"}
    finished = {s.name for s in em.reference_scenes() if s.role == "held-out" and s.reference is not None}
    assert held <= finished
    entries = [e for e in em.held_out_check(rows, 0.01) if e["role"] == "held-out"]
    assert len(entries) == len(held)


# ---------------------------------------------------------------------------- failed runs (issue 47 item 3)
def test_a_failed_run_is_never_written_and_one_of_an_older_table_is_dropped(tmp_path):
    """A row of status "error" (the run raised, or ran past --timeout) is not a measurement: put refuses
    it and leaves the table as it was; one read from an older table is dropped at the next write."""
    path = tmp_path / "map.csv"
    good = {"scene": "dL0.5_W0.05_Lb1181", "model": "rod", "resolution": 50, "resolution_label": "M50",
            "status": "complete", "source_hash": "a", "reference_hash": "r", "dW1_bound": 0.01}
    table = em.open_table(path)
    assert em.put_row(table, good)
    before = path.read_text()
    assert not em.put_row(table, {**good, "status": em.FAILED, "source_hash": "b", "reason": "run failed: _Timeout"})
    assert path.read_text() == before and em.is_current(em.open_table(path), ("rod", "M50", "dL0.5_W0.05_Lb1181"),
                                                        "a", "r")
    old = [{**{c: "" for c in em.COLUMNS}, **good, "model": "ribbon", "resolution_label": "M51",
            "status": em.FAILED}]
    with open(path, "a", newline="") as fh:   # an error row written before this rule
        csv.DictWriter(fh, fieldnames=em.COLUMNS).writerows(old)
    again = em.open_table(path)
    assert [r["model"] for r in again.rows] == ["rod"]
    assert em.put_row(again, {**good, "resolution": 100, "resolution_label": "M100"})
    assert {r["status"] for r in em.read_table(path)} == {"complete"} and len(em.read_table(path)) == 2


def test_a_run_that_fails_is_reported_not_written_and_the_command_exits_1(tmp_path, monkeypatch, capsys):
    """The whole command with the runs made in this process (run_all replaced): the run's error row is
    refused, the older row of its key stays as it was, one line names the failure, exit 1."""
    from ddg.sweep import cluster

    found = [s for s in em.reference_scenes() if s.name == "dL0.25_W0.05_Lb787" and s.reference is not None]
    if not found:
        pytest.skip("the repository's FEM gold data (data/fem_gold) is not here")
    scene = found[0].name

    def in_process(tasks, finished, **options):
        for task in tasks:
            finished(task, task.function(*task.args), None)
        return cluster.Ran(where="this process")

    def failing(at, model, resolution, timeout):
        return {"scene": at.name, "model": model, "resolution": resolution, "resolution_label": f"M{resolution}",
                "status": em.FAILED, "reason": f"run failed: _Timeout: the run took more than {timeout:g} s"}

    monkeypatch.setattr(cluster, "run_all", in_process)
    monkeypatch.setattr(map_compute, "run_row", failing)
    monkeypatch.setattr(map_compute, "rod_family", lambda: [("rod", (24,))])
    monkeypatch.setattr(map_command, "figures", lambda rows, out: [])   # matplotlib: not what is tested here
    out = tmp_path / "map"
    committed = [r for r in committed_rows()
                 if (r["scene"], r["model"], r["resolution_label"]) == (scene, "rod", "M50")]
    older = {**committed[0], "resolution": "24", "resolution_label": "M24", "source_hash": "older sources"}
    em.put_row(em.open_table(out / em.CSV_NAME), older)
    before = (out / em.CSV_NAME).read_text()
    code = em.main(["--out", str(out), "--only", "dL0.25_W0.05", "--models", "rod", "--workers", "1",
                    "--timeout", "5"])
    err = capsys.readouterr().err.splitlines()
    assert code == 1
    assert err[0] == (f"error: {scene} rod M24: run failed: _Timeout: the run took more than 5 s; not written to "
                      "the map (a rerun retries it)"), err
    assert err[-1].startswith("error: 1 run(s) failed and are not in the map (first: "), err
    assert (out / em.CSV_NAME).read_text() == before and (out / "README.md").exists()
