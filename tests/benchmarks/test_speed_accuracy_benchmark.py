"""The pure parts of benchmarks/speed_accuracy.py (issue 29's speed-accuracy benchmark): the
entries and their bad-input errors, the reference as the benchmark table reads it, the verdict
rule on constructed entries, the report built from a constructed result. No simulation runs."""
from __future__ import annotations

import json

import pytest

from benchmarks import speed_accuracy as sa
from benchmarks.common import Provenance
from ddg.geometry.strip import InputError

ALL = ["plate:8", "plate:12", "plate:18", "plate-midedge:8", "plate-midedge:12", "plate-midedge:18",
       "plate-midedge:28", "fem:64x8", "fem:96x12", "fem:144x18"]


# ---------------------------------------------------------------------------- entries and the command line
def test_the_entries_are_the_study_meshes_plus_28_midedge_rows():
    assert sa.entry_names() == ALL
    folders = {e.name: e.folder for e in sa.entries()}
    assert folders["plate:12"] == "R12" and folders["plate-midedge:28"] == "R28" and folders["fem:96x12"] == "N96x12"
    assert sa.scene() == "dL0.5_W0.1667"


def test_only_selects_in_the_report_order_each_once():
    assert [e.name for e in sa.parse_entries(None)] == ALL
    chosen = sa.parse_entries(["fem:96x12", "plate:8", "fem:96x12"])
    assert [e.name for e in chosen] == ["plate:8", "fem:96x12"]
    assert (chosen[1].along, chosen[1].across, chosen[0].rows) == (96, 12, 8)


@pytest.mark.parametrize("bad", ["plate:9", "fem:96X12", "midedge:8", "plate"])
def test_an_unknown_entry_is_refused_naming_it_and_the_allowed_ones(bad):
    with pytest.raises(InputError) as err:
        sa.parse_entries(["plate:8", bad])
    text = str(err.value)
    assert repr(bad) in text and all(name in text for name in ALL)


@pytest.mark.parametrize("argv, named", [
    (["--only", "plate:9"], "'plate:9'"),
    (["--only", "fem:60x12", "plate:8"], "'fem:60x12'"),
    (["--timeout", "-5"], "--timeout = -5"),
    (["--timeout", "nan"], "--timeout = nan"),
    (["--timeout", "abc"], "'abc'"),
    (["--only"], "--only"),
    (["--frobnicate"], "--frobnicate"),
])
def test_bad_input_exits_2_with_one_line_before_any_work(argv, named, tmp_path, capsys, monkeypatch):
    def no_run(*args, **kwargs):
        raise AssertionError("a run was started")

    monkeypatch.setattr(sa, "run_in_child", no_run)
    out = tmp_path / "never"
    assert sa.main([*argv, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("error:") and named in err
    assert not out.exists()


def test_an_unwritable_out_exits_2(tmp_path, capsys):
    afile = tmp_path / "file"
    afile.write_text("x")
    assert sa.main(["--only", "plate:8", "--out", str(afile)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and str(afile) in err


# ---------------------------------------------------------------------------- the reference
def test_the_reference_is_the_benchmark_tables_fem_value_with_its_rule_2_bar():
    from validation.estimates import load_study

    ref = sa.reference()
    study = load_study("fem", 0.5, 1 / 6)
    assert ref["source"].endswith("data/fem_gold/dL0.5_W0.1667/richardson.json")
    for key in ("dW1", "dW2"):
        assert ref[key]["value"] == study.threshold(key).value
        assert ref[key]["error_bar"] == study.threshold(key).error_bar
        assert ref[key]["rule"] == 2
    assert ref["dW1"]["value"] == pytest.approx(0.2654, abs=5e-5)
    assert ref["dW1"]["error_bar"] == pytest.approx(0.0031, abs=5e-5)


def _fake_fem_study(root, dw1, bar1):
    folder = root / "dL0.5_W0.1667"
    folder.mkdir(parents=True)
    study = {"scene": {"width_ratio": 1 / 6, "compression_ratio": 0.5, "slenderness": 1181.1},
             "meshes": [{"along": n, "across": c, "folder": f"N{n}x{c}", "dW1_over_L": dw1, "dW2_over_L": None}
                        for n, c in ((64, 8), (96, 12), (144, 18))],
             "dW1": {"value": dw1, "error_bar": bar1, "order": 2.0, "asymptotic": True, "meshes": [64, 96, 144],
                     "basis": "Richardson", "rule": 2},
             "dW2": None}
    (folder / "richardson.json").write_text(json.dumps(study))
    return folder


def test_the_reference_from_another_root(tmp_path):
    _fake_fem_study(tmp_path, 0.25, 0.001)
    ref = sa.reference(tmp_path)
    assert ref["dW1"]["value"] == 0.25 and ref["dW1"]["error_bar"] == 0.001 and ref["dW1"]["meshes"] == [64, 96, 144]
    assert ref["dW2"] is None
    assert sa.threshold_error({"dW1_over_L": 0.2535}, ref, "dW1") == pytest.approx(0.0035)
    assert sa.threshold_error({"dW1_over_L": None}, ref, "dW1") is None
    assert sa.threshold_error({"dW2_over_L": 0.4}, ref, "dW2") is None


# ---------------------------------------------------------------------------- the verdict
def _ref(bar=0.001, value=0.2654):
    return {"source": "fake", "dW1": {"value": value, "error_bar": bar, "basis": "b", "order": 2.0,
                                      "asymptotic": True, "meshes": [64, 96, 144], "rule": 2},
            "dW2": {"value": 0.43, "error_bar": 0.01, "basis": "b", "order": None, "asymptotic": False,
                    "meshes": [96, 144, 216], "rule": 2}}


def _rec(name, wall, dw1, status="ok"):
    model = name.split(":")[0]
    return {"entry": name, "model": model, "status": status, "wall_time_s": wall, "cpu_time_s": wall,
            "dW1_over_L": dw1, "dW2_over_L": 0.43}


def _records(mid, fem, plate=None):
    """mid, fem, plate: {mesh: (wall, dW1)}; every other entry of those models measured far off."""
    out = {}
    for model, given in (("plate-midedge", mid), ("fem", fem), ("plate", plate or {})):
        for name in ALL:
            if name.startswith(model + ":"):
                mesh = name.split(":", 1)[1]
                wall, dw1 = given.get(mesh, (1000.0, 0.30))
                out[name] = _rec(name, wall, dw1)
    return out


def test_met_when_the_fem_is_ten_times_slower_at_the_target_error():
    recs = _records(mid={"8": (5.0, 0.2700), "12": (12.0, 0.2660)}, fem={"96x12": (120.0, 0.2640)})
    v = sa.verdict(recs, _ref())
    assert v["verdict"] == "met" and v["step"] == 5
    assert v["cheapest_within_target"]["plate-midedge"]["entry"] == "plate-midedge:12"   # 8 rows: error 0.0046
    assert v["cheapest_within_target"]["fem"]["entry"] == "fem:96x12"
    assert v["ratio"] == pytest.approx(10.0)


def test_the_cheapest_entry_within_the_target_is_taken():
    recs = _records(mid={"8": (5.0, 0.2660), "12": (3.0, 0.2650), "18": (1.0, 0.2600)}, fem={"64x8": (40.0, 0.2680)})
    v = sa.verdict(recs, _ref())
    assert v["cheapest_within_target"]["plate-midedge"]["entry"] == "plate-midedge:12"
    assert v["ratio"] == pytest.approx(40.0 / 3.0) and v["verdict"] == "met"


def test_not_met_when_the_ratio_is_below_ten():
    recs = _records(mid={"12": (30.0, 0.2660)}, fem={"96x12": (200.0, 0.2640)})
    v = sa.verdict(recs, _ref())
    assert v["verdict"] == "not met" and v["step"] == 5 and v["ratio"] == pytest.approx(200 / 30)
    assert "6.67 < 10" in v["reason"]


def test_not_met_when_no_midedge_entry_reaches_the_target():
    recs = _records(mid={}, fem={"96x12": (200.0, 0.2640)})
    v = sa.verdict(recs, _ref())
    assert v["verdict"] == "not met" and v["step"] == 3 and v["ratio"] is None


def test_undecided_when_the_references_bar_exceeds_the_target_whatever_the_times():
    recs = _records(mid={"12": (1.0, 0.2654)}, fem={"96x12": (1000.0, 0.2654)})
    v = sa.verdict(recs, _ref(bar=0.0031))
    assert v["verdict"] == "undecided" and v["step"] == 1 and "0.00310 exceeds the target 0.003" in v["reason"]
    assert v["ratio"] == pytest.approx(1000.0)      # the figures are still given


def test_undecided_when_a_midedge_or_fem_entry_is_missing_or_failed():
    recs = _records(mid={"12": (1.0, 0.2654)}, fem={"96x12": (1000.0, 0.2654)})
    del recs["plate-midedge:28"]
    recs["fem:144x18"] = _rec("fem:144x18", 3600.0, None, status="timeout")
    v = sa.verdict(recs, _ref())
    assert v["verdict"] == "undecided" and v["step"] == 2
    assert v["unmeasured"] == ["plate-midedge:28", "fem:144x18"]
    del recs["plate:8"]                              # the paper's plate does not enter the ratio
    assert sa.verdict({k: r for k, r in recs.items() if k.startswith("plate:")}, _ref())["step"] == 2


def test_undecided_when_no_fem_entry_reaches_the_target():
    recs = _records(mid={"12": (1.0, 0.2654)}, fem={})
    v = sa.verdict(recs, _ref())
    assert v["verdict"] == "undecided" and v["step"] == 4


def test_an_entry_exactly_at_the_target_counts():
    recs = _records(mid={"12": (1.0, 0.2654 + 0.003 - 1e-12)}, fem={"64x8": (10.0, 0.2654 - 0.003 + 1e-12)})
    assert sa.verdict(recs, _ref())["verdict"] == "met"


# ---------------------------------------------------------------------------- records and the report
def test_newton_counts_put_threshold_location_in_the_total_for_both_kinds():
    assert sa._newton_counts("plate", {"newton_iterations": 100, "threshold_newton_iterations": 6}) == (106, 100, 6)
    assert sa._newton_counts("fem", {"newton_iterations": 1246, "threshold_newton_iterations": 219}) == \
        (1246, 1027, 219)


def test_study_comparison_reads_the_stored_run_and_its_bracket(tmp_path):
    run = tmp_path / "dL0.5_W0.1667" / "R8"
    run.mkdir(parents=True)
    (run / "summary.json").write_text(json.dumps({"status": "complete", "wall_time_s": 11.0, "dW1_over_L": 0.25,
                                                  "dW2_over_L": None}))
    roots = {"plate": tmp_path, "plate-midedge": tmp_path / "none"}
    got = sa.study_comparison(sa.Entry("plate", rows=8), {"status": "ok", "dW1_over_L": 0.25005,
                                                          "dW2_over_L": 0.44}, roots)
    assert got["study_run_found"] and got["study_dW1_over_L"] == 0.25
    assert got["dW1_difference_from_study"] == pytest.approx(5e-5) and got["dW1_within_bracket_of_study"]
    assert got["dW2_difference_from_study"] is None and got["dW2_within_bracket_of_study"] is None
    missing = sa.study_comparison(sa.Entry("plate-midedge", rows=28), {"status": "ok", "dW1_over_L": 0.27}, roots)
    assert not missing["study_run_found"] and missing["study_dW1_over_L"] is None
    assert missing["dW1_difference_from_study"] is None


def test_a_stored_entry_is_kept_only_when_measured_with_the_same_sources():
    plate, fem = sa.Entry("plate", rows=8), sa.Entry("fem", along=64, across=8)
    ok = {"status": "ok", "ddg_source_sha256": "a", "fem_reference_source_sha256": "f"}
    assert sa.kept(ok, plate, "a", "f") and sa.kept(ok, fem, "a", "f")
    assert not sa.kept(ok, plate, "b", "f") and not sa.kept(ok, fem, "a", "g") and sa.kept(ok, plate, "a", "g")
    assert not sa.kept({**ok, "status": "timeout"}, plate, "a", "f") and not sa.kept(None, plate, "a", "f")


def _report(records, ref, chart=None):
    report = sa.build_report(records, 3600.0, Provenance(), ref)
    report["chart"] = chart
    report["chart_note"] = None if chart else "matplotlib is not importable: no chart (plotting is an optional extra)."
    return report


def test_the_markdown_is_built_from_the_result():
    recs = _records(mid={"12": (12.0, 0.2660)}, fem={"96x12": (120.0, 0.2640)})
    recs["plate:8"].update(run_status="complete", triangles=952, n_free_dof=1509, newton_iterations=2873,
                           path_iterations_per_recorded_step=17.81, study_dW1_over_L=0.2517,
                           dW1_difference_from_study=2e-11, dW1_bisection_bracket=1e-4, study_run_found=True,
                           dW1_over_L=0.2517, load_average_before=1.1, load_average_after=1.3)
    del recs["plate:18"]
    recs["fem:144x18"] = {**_rec("fem:144x18", None, None, status="timeout"), "error": "stopped after 3600 s"}
    report = _report(recs, _ref())
    md = sa.markdown_report(report)
    assert md.startswith("# Speed against accuracy")
    assert "W/L = 1/6, dL/L = 0.5" in md and "0.26540 \u00b1 0.00100" in md
    table = [line for line in md.splitlines() if line.startswith("| ")]
    assert len(table) == 1 + len(ALL) and len({line.count("|") for line in table}) == 1   # no stray pipes
    row8 = next(line for line in table if line.startswith("| plate (paper) | 8 |"))
    cells = [c.strip() for c in row8.strip("|").split("|")]
    assert cells[2:6] == ["complete", "952", "1509", "1000.0"] and cells[9:11] == ["0.2517", "0.0137"]
    assert cells[-2:] == ["0.2517", "+2.0e-11"]
    assert "| plate (paper) | 18 | not run |" in md and "| FEM shell | 144x18 | timeout |" in md
    assert "**Verdict: undecided** (rule step 2)" in md and "Not measured: fem:144x18." in md
    assert "mid-edge plate: plate-midedge:12, 12.0 s wall" in md and "FEM time / mid-edge time: 10.00" in md
    assert "matplotlib is not importable" in md and "![" not in md
    assert "plate:8 1.1 / 1.3" in md


def test_the_markdown_states_a_met_verdict_with_its_figures_and_the_chart():
    recs = _records(mid={"12": (12.0, 0.2660)}, fem={"96x12": (240.0, 0.2640)})
    md = sa.markdown_report(_report(recs, _ref(), chart="speed_accuracy.png"))
    assert "**Verdict: met** (rule step 5): FEM time / mid-edge time = 20.00 >= 10" in md
    assert "![wall time against dW1 error](speed_accuracy.png)" in md


def test_the_chart_is_written_when_matplotlib_is_there(tmp_path):
    pytest.importorskip("matplotlib")
    recs = _records(mid={"12": (12.0, 0.2660)}, fem={"96x12": (240.0, 0.2640)})
    report = _report(recs, _ref())
    assert sa.chart(report, tmp_path / "c.png") == "c.png"
    assert (tmp_path / "c.png").read_bytes()[:4] == b"\x89PNG"
