"""The scorecard of `python -m validation score` (validation/score.py, issue 33 items 3 and 6): the
benchmark read from data/fem_gold, another code's results scored against it (this project's own models
from the committed error map as "another code", hand-made results at and 3 error bars off the
benchmark, the template filled in), malformed results refused with one line before anything is
written, and `report --out FILE` refused the same way. Reads committed data only: no model is run."""
from __future__ import annotations

import csv
import importlib.util
import math
import os
import stat
import time

import numpy as np
import pytest

import ddg
from ddg.output.io import StoredRun
from validation.__main__ import main
from validation.reference import ROOT

from fuzz_cases import at_most
from validation.score import (BENCHMARK_RELEASES, BENCHMARK_VERSION, H_MID_ERROR_BAR_FLOOR, REQUIRED_COLUMNS,
                              load_benchmark, read_results, score_results, write_benchmark_files)

ERROR_MAP = ROOT / "data" / "error_map" / "error_map.csv"
HEADER = ("kind",) + REQUIRED_COLUMNS + ("dW_over_L", "H_mid_over_L")


@pytest.fixture(scope="module")
def scenes():
    return load_benchmark()


def write_csv(path, rows, header=HEADER):
    """rows: dicts (missing keys empty) or lists of cells."""
    with open(path, "w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(header)
        for row in rows:
            writer.writerow([row.get(c, "") for c in header] if isinstance(row, dict) else row)
    return path


def scene_cells(scene):
    return {"compression_ratio": repr(scene.compression_ratio), "width_ratio": repr(scene.width_ratio),
            "slenderness": repr(scene.slenderness), "poisson_ratio": "0"}


def results_at(scenes, offset_bars=0.0):
    """A thresholds row and the whole H_mid curve of every benchmark scene, each value the benchmark's
    plus offset_bars times its error bar."""
    rows = []
    for scene in scenes:
        row = {"kind": "thresholds", **scene_cells(scene)}
        for key in ("dW1", "dW2"):
            e = scene.study.threshold(key)
            row[f"{key}_over_L"] = "" if e is None else repr(e.value + offset_bars * e.error_bar)
        rows.append(row)
        curve = scene.study.curve
        for dw, h, bar in zip(curve.dw, curve.value, curve.error_bar):
            rows.append({"kind": "H_mid", **scene_cells(scene), "dW_over_L": repr(float(dw)),
                         "H_mid_over_L": repr(float(h + offset_bars * bar))})
    return rows


def read_results_of(folder, rows):
    return read_results(write_csv(folder / "results.csv", rows))


def score_cli(capsys, results, out):
    code = main(["score", str(results), "--out", str(out)])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def expected_scored(scenes):
    """Quantities with a benchmark value and error bar (a study may lack dW2: its runs stopped short)."""
    return sum(1 for s in scenes for key in ("dW1", "dW2") if s.study.threshold(key) is not None
               and s.study.threshold(key).error_bar) + sum(s.study.curve is not None for s in scenes)


def score_rows(out):
    with open(out / "score.csv", newline="") as fh:
        return list(csv.DictReader(fh))


def test_the_benchmark_is_every_finished_fem_study(scenes, tmp_path):
    names = [s.name for s in scenes]
    for name in ("dL0.5_W0.05", "dL0.25_W0.5", "dL0.5_W0.05_Lb300", "dL0.3333_W0.1667"):
        assert name in names
    assert all(len(s.study.meshes) >= 2 for s in scenes)
    assert len(names) == len(set(names)) >= 20
    paper = scenes[names.index("dL0.5_W0.05")]
    assert paper.slenderness == pytest.approx(ddg.Strip.from_ratios(0.05, 0.5).slenderness, rel=1e-12)
    assert paper.label == "dL1/2 W1/20 Lb1181"
    assert scenes[names.index("dL0.5_W0.05_Lb300")].slenderness == 300.0
    # a study whose runs stop before the snap has no dW2 (dL/L = 1/2, W/L = 1/6, L/b = 4000 when written)
    without = [k for k, s in enumerate(scenes) for key in ("dW1", "dW2") if s.study.threshold(key) is None]

    written = write_benchmark_files(tmp_path, scenes)
    assert [p.name for p in written] == ["benchmark.csv", "benchmark_H_mid.csv", "README.md"]
    with open(tmp_path / "benchmark.csv", newline="") as fh:
        table = list(csv.DictReader(fh))
    assert [r["scene"] for r in table] == names and {r["version"] for r in table} == {BENCHMARK_VERSION}
    row = table[names.index("dL0.5_W0.05")]
    assert float(row["dW1_over_L"]) == paper.study.dW1.value
    assert float(row["dW1_error_bar"]) == paper.study.dW1.error_bar
    assert row["poisson_ratio"] == "0.0" and row["dW1_basis"].startswith("Richardson")
    assert all(table[k]["dW2_over_L"] == "" or table[k]["dW1_over_L"] == "" for k in without)
    with open(tmp_path / "benchmark_H_mid.csv", newline="") as fh:
        points = list(csv.DictReader(fh))
    assert len(points) == sum(len(s.study.curve.dw) for s in scenes)
    readme = (tmp_path / "README.md").read_text()
    assert BENCHMARK_VERSION in readme and "benchmark_H_mid.csv" in readme and "data digest" in readme


def map_rows(model, pick):
    with open(ERROR_MAP, newline="") as fh:
        rows = [r for r in csv.DictReader(fh) if r["model"] == model]
    by_scene = {}
    for r in rows:
        by_scene.setdefault(r["scene"], []).append(r)
    return [pick(group) for group in by_scene.values()]


@pytest.mark.parametrize("model, pick", [
    ("rod", lambda group: next(r for r in group if r["resolution_label"] == "M100")),
    ("plate", lambda group: max(group, key=lambda r: int(r["resolution"]))),   # the plate's finest mesh
], ids=["rod M100", "plate finest"])
def test_the_error_map_models_score_as_the_map_measures_them(model, pick, tmp_path, capsys):
    """This project's models as another code: their committed error-map rows scored against the
    benchmark give |model - reference| / error bar as the map's own columns do (dW1_error /
    dW1_ref_error_bar), and the plate's stored curves the map's H_mid_error."""
    rows = map_rows(model, pick)
    submitted = []
    for r in rows:
        cells = {"compression_ratio": r["compression_ratio"], "width_ratio": r["width_ratio"],
                 "slenderness": r["slenderness"], "poisson_ratio": "0"}
        submitted.append({"kind": "thresholds", **cells, "dW1_over_L": r["dW1"], "dW2_over_L": r["dW2"]})
        if model == "plate":   # its stored runs' H_mid curves too (the rod's runs are not stored)
            submitted += [{"kind": "H_mid", **cells, "dW_over_L": repr(p["dW_over_L"]),
                           "H_mid_over_L": repr(p["H_mid_over_L"])}
                          for p in StoredRun(ROOT / r["run_source"]).rows if p["stage"] == "shear"]
    results = write_csv(tmp_path / "results.csv", submitted)
    code, out, err = score_cli(capsys, results, tmp_path / "score")
    assert code == 0 and err == ""
    scored = {(s["scene"], s["quantity"]): s for s in score_rows(tmp_path / "score")}
    compared = 0
    for r in rows:
        fem = r["reference"].split("/")
        if fem[:2] != ["data", "fem_gold"]:   # the narrow strip's two-mesh FEM (data/narrow_limit): not benchmark
            assert f"no benchmark scene at dL/L = {float(r['compression_ratio']):g}" in out
            continue
        for key in ("dW1", "dW2"):
            s = scored[(fem[2], f"{key}_over_L")]
            if r[f"{key}_error"] == "":
                assert s["in_error_bars"] == ""
                continue
            error, bar = float(r[f"{key}_error"]), float(r[f"{key}_ref_error_bar"])
            assert float(s["benchmark"]) == pytest.approx(float(r[f"ref_{key}"]), rel=1e-12)
            assert float(s["difference"]) == pytest.approx(float(r[key]) - float(r[f"ref_{key}"]), rel=1e-9)
            assert float(s["in_error_bars"]) == pytest.approx(error / bar, rel=1e-9)
            assert s["within"] == str(error <= bar)
            compared += 1
        s = scored[(fem[2], "H_mid_over_L")]
        if model == "plate" and r["H_mid_error"] != "":   # the map's rule: away from both curves' thresholds
            assert abs(float(s["difference"])) == pytest.approx(float(r["H_mid_error"]), rel=1e-9)
            assert int(s["points"]) == int(r["H_mid_points"]) and float(s["in_error_bars"]) > 1
            compared += 1
    assert compared >= (60 if model == "plate" else 40)
    assert len([line for line in out.splitlines() if line.startswith("dL")]) == len(
        [r for r in rows if r["reference"].startswith("data/fem_gold")])
    assert (tmp_path / "score" / "score.md").read_text().count(" | dW1/L | ") == len(load_benchmark())


def test_results_at_the_benchmark_score_zero_and_within(scenes, tmp_path, capsys):
    results = write_csv(tmp_path / "exact.csv", results_at(scenes))
    code, out, err = score_cli(capsys, results, tmp_path / "score")
    assert code == 0 and err == ""
    rows = score_rows(tmp_path / "score")
    scored = [r for r in rows if r["in_error_bars"] != ""]
    assert len(scored) == expected_scored(scenes) > 2 * len(scenes)
    assert all(float(r["in_error_bars"]) == 0.0 and r["within"] == "True" for r in scored)
    assert all(float(r["points"]) > 10 for r in scored if r["quantity"] == "H_mid_over_L")
    assert all(r["note"] == "no benchmark value: the FEM study has none" for r in rows
               if r["quantity"] != "H_mid_over_L" and r["benchmark"] == "")
    first = out.splitlines()[0]
    assert first.startswith(f"{scenes[0].label}: dW1 ") and "(0.0 bars) within" in first
    if importlib.util.find_spec("matplotlib") is not None:
        assert (tmp_path / "score" / "score.png").stat().st_size > 10_000


def test_results_three_error_bars_off_score_three(scenes, tmp_path):
    card = score_results(scenes, read_results_of(tmp_path, results_at(scenes, offset_bars=3.0)))
    scored = [s for s in card.scores if s.scored]
    assert len(scored) == expected_scored(scenes)
    for s in scored:   # H_mid: the largest |difference| is where the bar is largest, 3 bars there too
        assert s.in_error_bars == pytest.approx(3.0, rel=1e-9) and s.within is False
        assert s.difference == pytest.approx(3.0 * s.error_bar, rel=1e-9)


def h_mid_score(scene, folder, rows):
    """The H_mid score of the submitted rows on one benchmark scene."""
    return score_results([scene], read_results_of(folder, rows)).of(scene)[-1]


def test_h_mid_is_compared_away_from_the_thresholds_and_inside_the_submitted_range(scenes, tmp_path):
    """A submitted curve wrong only within 0.02 of a threshold scores 0; one that stops at dW/L = 0.2
    is compared up to there; a difference below the round-off floor of the bars scores in the floor."""
    scene = next(s for s in scenes if s.name == "dL0.5_W0.05")
    curve, thresholds = scene.study.curve, scene.study.thresholds()
    near = np.min([np.abs(curve.dw - t) for t in thresholds], axis=0) <= 0.02
    assert near.any()
    cells = scene_cells(scene)
    wrong_near = [{"kind": "H_mid", **cells, "dW_over_L": repr(float(d)), "H_mid_over_L": repr(float(h + 0.1 * n))}
                  for d, h, n in zip(curve.dw, curve.value, near)]
    score = h_mid_score(scene, tmp_path, wrong_near)
    assert score.in_error_bars == 0.0 and score.points == int((~near).sum())

    short = [r for r in wrong_near if float(r["dW_over_L"]) <= 0.2]
    score = h_mid_score(scene, tmp_path, short)
    assert score.points == int(np.sum(curve.dw <= 0.2)) and "compared up to dW/L = " in score.note

    # past the snap H_mid is zero by symmetry and the bars are round-off: 5e-8 L there is half the floor
    after = curve.dw > thresholds[-1] + 0.02
    assert curve.error_bar[after].min() < 1e-12
    shifted = [{"kind": "H_mid", **cells, "dW_over_L": repr(float(d)), "H_mid_over_L": repr(float(h + 5e-8 * a))}
               for d, h, a in zip(curve.dw, curve.value, after)]
    score = h_mid_score(scene, tmp_path, shifted)
    assert score.in_error_bars == pytest.approx(5e-8 / H_MID_ERROR_BAR_FLOOR) and score.within is True


def test_the_template_round_trips(scenes, tmp_path, capsys):
    template = tmp_path / "template.csv"
    assert main(["score", "--template", str(template)]) == 0
    assert BENCHMARK_VERSION in capsys.readouterr().out
    lines = template.read_text().splitlines()
    assert lines[0].startswith("#") and BENCHMARK_VERSION in lines[0]
    body = [line for line in lines if not line.startswith("#")]
    rows = list(csv.DictReader(body))
    assert len(rows) == len(scenes) and all(r["kind"] == "thresholds" for r in rows)
    for row, scene in zip(rows, scenes):   # fill it in with the benchmark's values
        for key in ("dW1", "dW2"):
            e = scene.study.threshold(key)
            row[f"{key}_over_L"] = "" if e is None else repr(e.value)
    filled = write_csv(tmp_path / "filled.csv", rows, header=tuple(rows[0]))
    code, out, err = score_cli(capsys, filled, tmp_path / "score")
    assert code == 0 and err == ""
    thresholds = [r for r in score_rows(tmp_path / "score") if r["quantity"] != "H_mid_over_L"]
    assert all(r["in_error_bars"] == "0.0" and r["within"] == "True" for r in thresholds if r["benchmark"] != "")
    assert all(r["note"] == "not submitted" for r in score_rows(tmp_path / "score")
               if r["quantity"] == "H_mid_over_L")
    assert "no benchmark scene" not in out and "not submitted:" not in out


def test_a_row_off_the_benchmark_is_reported_not_refused(scenes, tmp_path, capsys):
    cells = scene_cells(scenes[0])
    rows = [{**cells, "dW1_over_L": "0.3"},
            {**cells, "poisson_ratio": "0.3", "dW1_over_L": "0.3"},   # the benchmark is at nu = 0
            {**cells, "width_ratio": repr(scenes[0].width_ratio * 1.002), "dW1_over_L": "0.3"}]   # 0.2 % off
    code, out, err = score_cli(capsys, write_csv(tmp_path / "r.csv", rows), tmp_path / "score")
    assert code == 0 and err == ""
    assert out.count("no benchmark scene at") == 2 and "nu = 0.3 (line 3)" in out
    assert f"not submitted: {len(scenes) - 1} of {len(scenes)}" in out


GOOD = ["thresholds", "0.5", "0.05", "1181.1", "0", "0.35", "0.47", "", ""]


def with_cell(column, value, line=GOOD):
    row = list(line)
    row[HEADER.index(column)] = value
    return row


MALFORMED = {
    "not a number": ([GOOD, with_cell("width_ratio", "abc")], "line 3, column width_ratio: 'abc' is not a number"),
    "infinite": ([with_cell("dW1_over_L", "inf")], "line 2, column dW1_over_L: 'inf' is not a finite number"),
    "nan": ([GOOD, with_cell("width_ratio", "0.1"), with_cell("dW2_over_L", "nan", with_cell("width_ratio", "0.2"))],
            "line 4, column dW2_over_L: 'nan' is not a finite number"),
    "W/L 1": ([with_cell("width_ratio", "1")], "line 2, column width_ratio: 1 outside (0, 1)"),
    "W/L 0": ([with_cell("width_ratio", "0")], "line 2, column width_ratio: 0 outside (0, 1)"),
    "dL/L 1.5": ([with_cell("compression_ratio", "1.5")], "line 2, column compression_ratio: 1.5 outside (0, 1)"),
    "dL/L -0.5": ([with_cell("compression_ratio", "-0.5")], "line 2, column compression_ratio: -0.5 outside"),
    "L/b 0": ([with_cell("slenderness", "0")], "line 2, column slenderness: 0 outside [10, 100000]"),
    "L/b negative": ([with_cell("slenderness", "-300")], "line 2, column slenderness: -300 outside [10, 100000]"),
    # issue 47 item 3: values near the float range went through to the figure (an IndexError in matplotlib)
    "L/b 1e308": ([with_cell("slenderness", "1e308")], "line 2, column slenderness: 1e+308 outside [10, 100000]"),
    "dW1 1e308": ([with_cell("dW1_over_L", "1e308")], "line 2, column dW1_over_L: 1e+308 outside [0, 1]"),
    "dW2 1.5": ([with_cell("dW2_over_L", "1.5")], "line 2, column dW2_over_L: 1.5 outside [0, 1]"),
    "dW negative": ([with_cell("dW1_over_L", "-0.1")], "line 2, column dW1_over_L: -0.1 outside [0, 1]"),
    "H_mid 1e308": ([["H_mid", "0.5", "0.05", "1181.1", "0", "", "", "0.1", "1e308"]],
                    "line 2, column H_mid_over_L: 1e+308 outside [-1, 1]"),
    "H_mid point dW 2": ([["H_mid", "0.5", "0.05", "1181.1", "0", "", "", "2", "0.1"]],
                         "line 2, column dW_over_L: 2 outside [0, 1]"),
    "nu 0.5": ([with_cell("poisson_ratio", "0.5")], "line 2, column poisson_ratio: 0.5 outside [0, 0.5)"),
    "nu negative": ([with_cell("poisson_ratio", "-0.1")], "line 2, column poisson_ratio: -0.1 outside [0, 0.5)"),
    "empty scene cell": ([with_cell("slenderness", "")], "line 2, column slenderness: empty"),
    "duplicate scene": ([GOOD, with_cell("width_ratio", "0.1"), with_cell("slenderness", "1181.5")],
                        "line 4, columns compression_ratio, width_ratio, slenderness, poisson_ratio: a second "
                        "thresholds row of the scene of line 2"),
    "too few cells": ([GOOD, GOOD[:5]], "line 3: 5 cells, the header has 9 columns"),
    "unknown kind": ([with_cell("kind", "curve")], "line 2, column kind: 'curve' is not one of thresholds, H_mid"),
    "H_mid row without its point": ([GOOD, with_cell("kind", "H_mid", with_cell("dW1_over_L", "",
                                                     with_cell("dW2_over_L", "")))],
                                    "line 3, column dW_over_L: empty"),
    "H_mid point twice": ([["H_mid", "0.5", "0.05", "1181.1", "0", "", "", "0.1", "0.3"],
                           ["H_mid", "0.5", "0.05", "1181.1", "0", "", "", "0.1", "0.31"]],
                          "line 3, column dW_over_L: dW/L = 0.1 is already on line 2"),
}


def check_refused(capsys, tmp_path, argv, fragment):
    code = main(argv)
    captured = capsys.readouterr()
    assert code == 2
    assert captured.out == ""
    assert captured.err.startswith("error: ") and captured.err.count("\n") == 1, captured.err
    assert fragment in captured.err
    assert "Traceback" not in captured.err


@pytest.mark.parametrize("case", sorted(MALFORMED))
def test_malformed_results_are_one_line_naming_row_and_column(case, tmp_path, capsys):
    rows, fragment = MALFORMED[case]
    results = write_csv(tmp_path / "results.csv", rows)
    check_refused(capsys, tmp_path, ["score", str(results), "--out", str(tmp_path / "score")], fragment)
    assert not (tmp_path / "score").exists()   # nothing written


@pytest.mark.parametrize("content, fragment", [
    (None, "does not exist"),
    (b"", "is empty: expected a header line"),
    (b"# only a comment\n\n", "is empty"),
    (b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR", "is not a CSV file: it holds NUL bytes"),
    (b"compression_ratio,width_ratio\n\xff\xfe0.5,0.1\n", "is not a CSV file: line 2 is not UTF-8 text"),
    (b'{"compression_ratio": 0.5}\n', "line 1: column compression_ratio is missing from the header"),
    ("\n".join([",".join(c for c in REQUIRED_COLUMNS if c != "poisson_ratio"), "0.5,0.05,1181,0.3,0.4"]).encode(),
     "line 1: column poisson_ratio is missing"),
    (b"# a comment\ncompression_ratio,width_ratio,slenderness,poisson_ratio,dW1_over_L,dW2_over_L,"
     b"dW1_over_L\n", "line 2: column dW1_over_L appears twice"),
    (b"compression_ratio,width_ratio,slenderness,poisson_ratio,dW1_over_L,dW2_over_L\n"
     b"0.5,0.05,1181,0,0.3,0.4\n0.5,0.05,1181,0,0.3,0.4,,\n", "line 3: 8 cells, the header has 6"),
    (b"compression_ratio,width_ratio,slenderness,poisson_ratio,dW1_over_L,dW2_over_L,kind\n"
     b"0.5,0.05,1181,0,,,H_mid\n", "line 2, column dW_over_L: missing from the header"),
], ids=["missing", "empty", "comments only", "binary", "not utf-8", "json", "column missing", "column twice",
        "too many cells", "no curve columns"])
def test_unreadable_results_are_one_line(content, fragment, tmp_path, capsys):
    results = tmp_path / "results.csv"
    if content is not None:
        results.write_bytes(content)
    check_refused(capsys, tmp_path, ["score", str(results), "--out", str(tmp_path / "score")], fragment)
    assert not (tmp_path / "score").exists()


def test_a_results_directory_and_an_out_file_are_refused(tmp_path, capsys):
    check_refused(capsys, tmp_path, ["score", str(tmp_path), "--out", str(tmp_path / "score")], "is a directory")
    results = write_csv(tmp_path / "results.csv", [GOOD])
    taken = tmp_path / "taken"
    taken.write_text("a file\n")
    check_refused(capsys, tmp_path, ["score", str(results), "--out", str(taken)],
                  f"--out = {str(taken)!r} exists and is not a directory")
    assert taken.read_text() == "a file\n"
    check_refused(capsys, tmp_path, ["score"], "give one of RESULTS")
    check_refused(capsys, tmp_path, ["score", str(results), "--template", str(tmp_path / "t.csv")], "give one of")
    check_refused(capsys, tmp_path, ["score", "--template", str(tmp_path)], "is a directory")
    check_refused(capsys, tmp_path, ["score", "--benchmark", str(taken)], "--benchmark")


def test_a_fifo_a_device_and_a_huge_file_are_refused_before_they_are_read(tmp_path, capsys):
    """Issue 47 item 3: a FIFO hung the read, /dev/zero read until MemoryError. RESULTS must be a
    regular file of at most MAX_RESULTS_BYTES, checked (os.stat) before it is opened."""
    from validation.score import MAX_RESULTS_BYTES

    fifo = tmp_path / "results.fifo"
    os.mkfifo(fifo)
    with at_most(5):
        check_refused(capsys, tmp_path, ["score", str(fifo), "--out", str(tmp_path / "score")],
                      f"RESULTS {str(fifo)!r} is a FIFO, not a regular file")
        check_refused(capsys, tmp_path, ["score", "/dev/zero", "--out", str(tmp_path / "score")],
                      "RESULTS '/dev/zero' is a device, not a regular file")
    huge = tmp_path / "huge.csv"
    with open(huge, "wb") as fh:   # sparse: 9 MiB that take no disk
        fh.truncate(MAX_RESULTS_BYTES + 2**20)
    check_refused(capsys, tmp_path, ["score", str(huge), "--out", str(tmp_path / "score")],
                  f"RESULTS {str(huge)!r} is 9.0 MiB; a results file may weigh at most 8 MiB")
    assert MAX_RESULTS_BYTES >= 10 * len(write_csv(tmp_path / "all.csv", results_at(load_benchmark())).read_bytes())
    assert not (tmp_path / "score").exists()


def test_a_template_never_replaces_a_fifo_or_a_device(tmp_path, capsys):
    """--template writes by an atomic rename onto its target: onto a FIFO (or /dev/null, as root) it would
    replace the special file by a regular one. Refused in one line instead."""
    fifo = tmp_path / "template.fifo"
    os.mkfifo(fifo)
    check_refused(capsys, tmp_path, ["score", "--template", str(fifo)], "exists and is not a regular file")
    assert stat.S_ISFIFO(os.stat(fifo).st_mode)


def test_a_long_curve_and_many_scenes_are_read_in_linear_time(tmp_path):
    """Each row finds its scene and checks its dW/L against the curve in constant time (was a scan of
    every scene and every point: minutes for a file well under MAX_RESULTS_BYTES)."""
    curve = [["H_mid", "0.5", "0.05", "1181.1", "0", "", "", repr(i * 2e-5), "0.1"] for i in range(40000)]
    scenes = [["thresholds", "0.5", repr(0.01 * 1.002**i), repr(lb), "0", "0.3", "0.4", "", ""]   # 0.2 % apart
              for lb in (100.0, 200.0, 400.0, 800.0, 1600.0) for i in range(1000)]
    results = write_csv(tmp_path / "results.csv", curve + scenes)
    t0 = time.perf_counter()
    read = read_results(results)
    assert time.perf_counter() - t0 < 10.0
    assert len(read) == 5001 and len(read[0].curve) == 40000 and read[1].width_ratio == 0.01


def test_report_out_file_is_one_line(tmp_path, capsys, monkeypatch):
    """Item 6: `report --out FILE` was a NotADirectoryError traceback; --out is now checked first."""
    import validation.report

    def no_report(*args, **kwargs):
        raise AssertionError("the report was started with a bad --out")

    monkeypatch.setattr(validation.report, "build_report", no_report)
    taken = tmp_path / "report.html"
    taken.write_text("not a directory\n")
    check_refused(capsys, tmp_path, ["report", "--out", str(taken)],
                  f"--out = {str(taken)!r} exists and is not a directory")
    assert taken.read_text() == "not a directory\n"


def test_without_matplotlib_the_figure_is_skipped_with_one_line(scenes, tmp_path, capsys, monkeypatch):
    import sys

    monkeypatch.setitem(sys.modules, "matplotlib", None)   # import matplotlib raises ImportError
    results = write_csv(tmp_path / "r.csv", [{**scene_cells(scenes[0]), "dW1_over_L": "0.3"}])
    code, out, err = score_cli(capsys, results, tmp_path / "score")
    assert code == 0 and err == "figure skipped: matplotlib is missing (pip install 'ddg-strips[plot]')\n"
    assert sorted(p.name for p in (tmp_path / "score").iterdir()) == ["score.csv", "score.md"]
    assert math.isclose(float(score_rows(tmp_path / "score")[0]["submitted"]), 0.3)


def test_the_committed_studies_are_the_benchmark_version_they_are_released_as():
    """A changed or added study in data/fem_gold changes the digest; it must come with a new release
    (BENCHMARK_RELEASES), so no scorecard calls changed reference values by an old version."""
    from validation.score import benchmark_digest

    assert BENCHMARK_RELEASES[BENCHMARK_VERSION] == benchmark_digest(load_benchmark()), (
        "data/fem_gold changed: add a release to validation.score.BENCHMARK_RELEASES with the new digest and "
        "say what changed in docs/reference/benchmark.rst")
    assert len(set(BENCHMARK_RELEASES.values())) == len(BENCHMARK_RELEASES)
