"""benchmarks/path_iterations.py (issue 49's path iterations): the run's record from a short rod path
in this process (the probe's counts against the summary's), the targets and reports from records,
the compare mode on synthetic records, and a failing child recorded as an error. No timing and no
exact iteration count is asserted."""
from __future__ import annotations

import copy
import json

import pytest

from benchmarks import path_iterations as pi

ROD = {"model": "rod", "resolution": 100, "rows": None, "width_ratio": 0.05, "compression_ratio": 0.5,
       "scene": "1/20:1/2"}


@pytest.fixture(scope="module")
def rod_record():
    """The rod at W/L = 1/20, dL/L = 1/2 on a short protocol (8 compression, 24 shear steps), twice."""
    return pi.measure(ROD, repeat=2, compression_steps=8, shear_steps=24, warmup=False)


def test_the_rod_record_adds_up(rod_record):
    r = rod_record
    assert r["status"] == "complete" and r["probe_matches_summary"]
    assert r["recorded_steps"] == 1 + 8 + 24 and r["recorded_shear_steps"] == 24
    assert sum(r["iterations_by_phase"].values()) == r["path_iterations"] > 0
    assert r["iterations_per_step"] == pytest.approx(r["path_iterations"] / r["recorded_steps"])
    assert r["whole_run_iterations"] == r["path_iterations"] + r["threshold_iterations"] + r["branch_iterations"]
    assert r["branches_traced"] and r["branch_iterations"] > 0  # the rod's default
    assert 0 <= r["thresholds_located"] <= 3 and r["thresholds_located"] == len(r["thresholds_located_keys"])
    assert r["fold_snaps"] <= r["recorded_steps"]
    if r["fold_snaps"]:
        assert r["iterations_per_snap"] == pytest.approx(r["iterations_by_phase"]["fold snaps"] / r["fold_snaps"])
    else:
        assert r["iterations_by_phase"]["fold snaps"] == 0
    assert r["branch_sequence"][0] == "U"
    assert all(a != b for a, b in zip(r["branch_sequence"], r["branch_sequence"][1:]))
    assert r["rejected_solves"] == r["solves_by_phase"]["rejected steps"]
    assert len(r["all_wall_times_s"]) == 2 and isinstance(r["repeats_same_counts"], bool)
    assert r["size"] == "M=100" and pi.run_key(r) == "rod|M=100|1/20:1/2"


def test_the_report_renders_every_target_from_the_records(rod_record, tmp_path):
    stopped = dict(copy.deepcopy(rod_record), scene="1/6:1/4", status="stopped")
    failed = {**ROD, "size": "M=100", "scene": "1/2:1/2", "status": "timeout", "error": "stopped after 9 s"}
    records = {pi.run_key(r): r for r in (rod_record, stopped, failed)}
    config = {"models": ["rod"], "scenes": ["1/20:1/2"], "rows": [], "timeout_s": 9.0, "repeat": 2, "jobs": 1,
              "compression_steps": 8, "shear_steps": 24}
    report = pi.build_report(records, "test", config, pi.Provenance(), None)
    kinds = [t["kind"] for t in report["targets"]]
    assert kinds.count("per step") == 1 and kinds.count("rod whole run") == 1
    per_step = report["targets"][0]
    assert per_step["scenes"] == 3 and per_step["met"] is False  # a stopped path and a timeout never meet it
    text = pi.markdown_report(report)
    for heading in ("## Targets (issue 49)", "## Rod and 1D ribbons: iterations by phase", "## Definitions",
                    "## Method", "## Machine"):
        assert heading in text
    assert "timeout" in text and "(stopped)" in text
    pi.write_outputs(tmp_path, "path_iterations_test", report, text)
    stored = json.loads((tmp_path / "path_iterations_test.json").read_text())
    assert pi.markdown_report(stored) == text


def test_compare_flags_what_changed(rod_record, tmp_path):
    before = {"results": [rod_record], "targets": pi.compute_targets([rod_record]), "ddg_source_sha256": "a" * 64}
    moved = copy.deepcopy(rod_record)
    moved["path_iterations"] //= 2
    moved["iterations_per_step"] /= 2
    if moved["dW1_over_L"] is not None:
        moved["dW1_over_L"] += 2 * pi.DW1_FLAG
    moved["branch_sequence"] = ["U", "S+"]
    after = {"results": [moved], "targets": pi.compute_targets([moved]), "ddg_source_sha256": "b" * 64}
    (row,) = pi.compare_runs(before, after)
    assert row["same_sequence"] is False and row["dW1_flag"] == (rod_record["dW1_over_L"] is not None)
    assert row["dW2_flag"] is False and row["folds_same_count"]
    for label, report in (("b", before), ("a", after)):
        (tmp_path / f"path_iterations_{label}.json").write_text(json.dumps(report))
    assert pi.main(["--compare", "b", "a", "--out", str(tmp_path)]) == 0
    text = (tmp_path / "path_iterations.md").read_text()
    assert "## Physics unchanged" in text and "NO: U > US" in text and "flagged: rod|M=100|1/20:1/2" in text
    assert "fewer a in 1" in text


def test_scenes_and_runs():
    assert len(pi.parse_scenes(pi.DEFAULT_SCENES)) == 6
    assert pi.parse_scenes(["1/20:0.5,1/6:1/4", "1/20:1/2"]) == [("1/20", "1/2"), ("1/6", "1/4")]
    with pytest.raises(Exception):
        pi.parse_scenes("1/20")
    specs = pi.run_specs(pi.MODELS, pi.parse_scenes(pi.DEFAULT_SCENES))
    assert len(specs) == (6 + 3 + 1) * 6
    assert {pi.size_label(s) for s in specs if s["model"] == "plate-midedge"} == {"8 rows", "12 rows", "18 rows"}


def test_a_failing_child_is_recorded_and_the_others_go_on():
    done = []
    bad = {**ROD, "model": "no-such-model"}
    pi.run_parallel([bad], 1, 120.0, lambda spec, status, payload, elapsed, load: done.append((status, payload)),
                    (1, 2, 2))
    ((status, payload),) = done
    assert status == "error" and "no-such-model" in payload
