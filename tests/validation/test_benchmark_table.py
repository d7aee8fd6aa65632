"""The published benchmark table (validation/benchmark.py): its figures from the FEM and plate
studies, missing data as None and "–", and the resumable store of the rod's thresholds. The
studies here are built by hand (a fake `load`), and no rod is run."""
import json

import pytest

import ddg
from validation import benchmark
from validation.benchmark import benchmark_rows, markdown_table, rod_thresholds, write_benchmark
from validation.estimates import Estimate, MeshResult, Study, load_study
from validation.reference import gold_name


def study(model, compression, width, dw1, dw2, labels=("A", "B", "C")):
    """A hand-made study: dw1, dw2 are (value, error bar) or None."""
    meshes = [MeshResult(label, 10 * (k + 1), "elements along L", dw1 and dw1[0], dw2 and dw2[0])
              for k, label in enumerate(labels)]
    return Study(model, compression, width, meshes,
                 None if dw1 is None else Estimate(dw1[0], dw1[1], 1.5, True, "Richardson"),
                 None if dw2 is None else Estimate(dw2[0], dw2[1], None, False, "not asymptotic: the finest value"),
                 None, "hand-made")


FEM = {(0.5, 0.05): ((0.35, 0.004), (0.47, 0.001))}
PLATE = {(0.5, 0.05): ((0.345, 0.0002), (0.464, 0.001)), (0.25, 0.05): ((0.21, 0.0004), (0.32, 0.0008))}


def fake_load(model, compression, width):
    table = FEM if model == "fem" else PLATE
    for (c, w), (dw1, dw2) in table.items():
        if abs(c - compression) < 1e-12 and abs(w - width) < 1e-12:
            return study(model, c, w, dw1, dw2, ("N1", "N2", "N3") if model == "fem" else ("R8", "R12", "R18"))
    return None


def row_of(rows, compression, width):
    return next(r for r in rows if r["compression_ratio"] == compression and abs(r["width_ratio"] - width) < 1e-12)


def test_ten_scenes_in_order_with_the_slenderness_column():
    rows = benchmark_rows(load=fake_load)
    assert [(r["compression_ratio"], r["width_ratio"]) for r in rows] == [
        (c, w) for c in (0.5, 0.25) for w in (1 / 20, 1 / 12, 1 / 6, 1 / 3, 1 / 2)]
    assert row_of(rows, 0.5, 0.05)["width_squared_over_thickness_length"] == pytest.approx(
        0.05**2 * 1181.1023622047244, rel=1e-9)


def test_difference_and_error_bar_ratio_are_the_hand_computed_ones():
    row = row_of(benchmark_rows(load=fake_load), 0.5, 0.05)
    assert row["fem_dW1"] == 0.35 and row["fem_dW1_error_bar"] == 0.004 and row["plate_dW1"] == 0.345
    assert row["dW1_difference"] == pytest.approx(0.345 - 0.35)            # plate minus FEM, signed
    assert row["dW1_in_error_bars"] == pytest.approx(0.005 / (0.004 + 0.0002))
    assert row["dW2_difference"] == pytest.approx(0.464 - 0.47)
    assert row["dW2_in_error_bars"] == pytest.approx(0.006 / 0.002)
    assert row["fem_dW1_basis"] == "Richardson, order 1.50"
    assert row["fem_dW2_basis"] == "not asymptotic: the finest value"
    assert row["fem_dW1_meshes"] == "N1/N2/N3" and row["plate_dW2_meshes"] == "R8/R12/R18"
    assert row["paper_dW1"] == 0.36 and row["paper_dW2"] == 0.52
    assert row["rod_dW1"] is None and row["rod_dW1_error_bar"] is None


def test_a_scene_without_fem_study_keeps_plate_and_paper_values():
    row = row_of(benchmark_rows(load=fake_load), 0.25, 0.05)
    for key in ("dW1", "dW2"):
        assert row[f"fem_{key}"] is None and row[f"fem_{key}_error_bar"] is None
        assert row[f"fem_{key}_basis"] is None and row[f"fem_{key}_meshes"] is None
        assert row[f"{key}_difference"] is None and row[f"{key}_in_error_bars"] is None
    assert row["plate_dW1"] == 0.21 and row["plate_dW2_error_bar"] == 0.0008
    assert row["paper_dW1"] == 0.23 and row["paper_dW2"] == 0.37


def test_no_comparison_without_error_bar_and_a_failing_load_is_no_data():
    def load(model, compression, width):
        if compression == 0.5 and width == 0.05:
            return study(model, compression, width, (0.35, None if model == "fem" else 0.001), None)
        raise OSError("unreadable study")

    rows = benchmark_rows(load=load)
    row = row_of(rows, 0.5, 0.05)
    assert row["dW1_difference"] == pytest.approx(0.0) and row["dW1_in_error_bars"] is None
    assert row["fem_dW2"] is None and row["dW2_difference"] is None
    assert row_of(rows, 0.5, 1 / 6)["plate_dW1"] is None


def test_rod_values_come_from_the_stored_rod_thresholds():
    rods = {gold_name(0.5, 0.05): {"dW1": 0.361, "dW1_error_bar": 0.001, "dW2": 0.52, "dW2_error_bar": None}}
    rows = benchmark_rows(rods, load=fake_load)
    row = row_of(rows, 0.5, 0.05)
    assert (row["rod_dW1"], row["rod_dW1_error_bar"], row["rod_dW2"], row["rod_dW2_error_bar"]) == (
        0.361, 0.001, 0.52, None)
    assert row_of(rows, 0.25, 0.5)["rod_dW1"] is None


def table_lines(text):
    return [line for line in text.splitlines() if line.startswith("|")]


def test_markdown_table_has_ten_scene_rows_and_dashes_for_missing_values(tmp_path):
    rods = {gold_name(0.5, 0.05): {"dW1": 0.361, "dW1_error_bar": 0.001, "dW2": 0.52, "dW2_error_bar": None}}
    rows = benchmark_rows(rods, load=fake_load)
    lines = table_lines(markdown_table(rows))
    assert len(lines) == 2 + 10 and set(lines[1]) <= set("|-: ")
    header = [c.strip() for c in lines[0].strip().strip("|").split(" | ")]
    assert len(header) == 19 and header[6] == "mid-edge dW1/L" and header[11] == "mid-edge dW2/L"
    assert header[17:] == ["cross-section dW1/L", "cross-section dW2/L"]
    cells = [[c.strip() for c in line.strip().strip("|").split(" | ")] for line in lines[2:]]
    assert all(len(c) == 19 for c in cells)
    first = cells[0]
    assert first[:3] == ["1/2", "1/20", "3.0"]
    assert first[3] == "0.3500 ± 0.0040" and first[4] == "0.3450 ± 0.0002"
    assert first[5] == f"{0.005 / 0.0042:.1f}"
    assert first[6:8] == first[4:6]  # fake_load gives the mid-edge plate the plate's studies
    assert first[13:] == ["0.3600", "0.5200", "0.3610 ± 0.0010", "0.5200", "–", "–"]
    no_fem = cells[5]   # dL/L = 1/4, W/L = 1/20
    assert no_fem[:2] == ["1/4", "1/20"]
    assert no_fem[3] == "–" and no_fem[5] == "–" and no_fem[4] == "0.2100 ± 0.0004" and no_fem[13] == "0.2300"
    assert no_fem[7] == "–"
    assert cells[-1][3:13] == ["–"] * 10

    write_benchmark(tmp_path, rows)
    md = (tmp_path / "benchmark.md").read_text()
    assert table_lines(md) == lines and "combined error bar" in md
    csv_lines = (tmp_path / "benchmark.csv").read_text().splitlines()
    assert len(csv_lines) == 11 and csv_lines[0].split(",")[:3] == [
        "compression_ratio", "width_ratio", "width_squared_over_thickness_length"]


class FakeRun:
    def __init__(self, resolution):
        self.summary = {"converged": True, "dW1_over_L": 0.36, "dW2_over_L": 0.52,
                        "scene": {"compression_ratio": 0.5, "width_ratio": 0.05, "resolution": resolution}}
        self.rows = []


def test_rod_thresholds_resume_and_store_after_each_scene(tmp_path, monkeypatch):
    simulated = []

    def fake_simulate(strip, protocol, model="rod", resolution=None, branches=None, **kwargs):
        assert model == "rod" and branches is False
        simulated.append((round(strip.width / strip.length, 6), protocol.compression_ratio, resolution))
        return FakeRun(resolution)

    def fake_study(model, runs, resolutions):
        assert model == "rod" and list(resolutions) == [50, 100, 200] and len(runs) == 3
        return study("rod", 0.5, 0.05, (0.361, 0.002), (0.52, 0.003), ("R50", "R100", "R200"))

    monkeypatch.setattr(ddg, "simulate", fake_simulate)
    monkeypatch.setattr(benchmark, "study_from_runs", fake_study)
    done = {gold_name(0.5, 0.05): {"dW1": 0.1, "dW1_error_bar": 0.01, "dW2": 0.2, "dW2_error_bar": 0.02,
                                   "wall_time_s": 15.0}}
    (tmp_path / "rod_thresholds.json").write_text(json.dumps(done))

    result = rod_thresholds(tmp_path, scenes=[(0.5, 0.05), (0.25, 1 / 6)])
    assert [s[:2] for s in simulated] == [(round(1 / 6, 6), 0.25)] * 3      # the stored scene is not rerun
    assert [s[2] for s in simulated] == [50, 100, 200]
    assert result[gold_name(0.5, 0.05)] == done[gold_name(0.5, 0.05)]
    new = result[gold_name(0.25, 1 / 6)]
    assert (new["dW1"], new["dW1_error_bar"], new["dW2"], new["dW2_error_bar"]) == (0.361, 0.002, 0.52, 0.003)
    assert new["wall_time_s"] >= 0
    assert json.loads((tmp_path / "rod_thresholds.json").read_text()) == result

    simulated.clear()
    assert rod_thresholds(tmp_path, scenes=[(0.5, 0.05), (0.25, 1 / 6)]) == result
    assert simulated == []


def test_on_the_committed_studies_the_narrow_half_compression_scene_has_fem_and_plate_dW1():
    if load_study("fem", 0.5, 1 / 20) is None or load_study("plate", 0.5, 1 / 20) is None:
        pytest.skip("no FEM or plate study of dL0.5_W0.05 in data/")
    row = row_of(benchmark_rows(rod_thresholds=None), 0.5, 1 / 20)
    for model in ("fem", "plate"):
        assert row[f"{model}_dW1"] is not None and row[f"{model}_dW1_error_bar"] is not None
    assert row["dW1_in_error_bars"] is not None and row["paper_dW1"] == 0.36


def test_the_meshes_column_names_the_meshes_a_value_rests_on():
    """The finest three meshes that have the threshold (fem_reference.convergence.estimate): a
    fourth mesh drops the coarsest, a mesh without the value (a run stopped short) is skipped."""
    meshes = [MeshResult("N64x8", 64, "elements along L", 0.26, None), MeshResult("N96x12", 96, "", 0.262, 0.43),
              MeshResult("N144x18", 144, "", 0.264, 0.431), MeshResult("N216x28", 216, "", 0.265, 0.4308)]
    s = Study("fem", 0.5, 1 / 6, meshes, Estimate(0.265, 0.003), Estimate(0.4308, 0.01), None, "hand-made")
    assert benchmark.basis_meshes(s, "dW1") == ["N96x12", "N144x18", "N216x28"]
    meshes[2] = MeshResult("N144x18", 144, "", 0.264, None)
    assert benchmark.basis_meshes(s, "dW2") == ["N96x12", "N216x28"]


def test_the_readme_table_and_count_are_the_committed_benchmark():
    """README.md's benchmark table and its sentence on the bases are data/benchmark/benchmark.md's
    (issue 28: the README's table and sentences match the CSV)."""
    from pathlib import Path

    root = Path(__file__).resolve().parents[2]
    bench = (root / "data" / "benchmark" / "benchmark.md").read_text().splitlines()
    readme = (root / "README.md").read_text()
    table = [line for line in bench if line.startswith("|")]
    assert "\n".join(table) in readme
    sentence = next(line for line in bench if "rest on three meshes" in line)
    assert sentence in " ".join(readme.split())
    rows = list(__import__("csv").DictReader(open(root / "data" / "benchmark" / "benchmark.csv")))
    assert sentence == benchmark.basis_sentence([{k: (None if v == "" else v) for k, v in r.items()} for r in rows])
