"""The validation report: its machinery (outputs, cache, resume) and every agreement it claims
(validation/claims.py), asserted here with the same functions and bounds on quick runs."""
import json

import pytest

import ddg
from validation import claims as C
from validation import runs as R
from validation.reference import load_gold
from validation.report import build_report


def simulate(model, width_ratio, compression_ratio, resolution, shear_ratio=None, shear_steps=60, **kw):
    strip = ddg.Strip.from_ratios(width_ratio, compression_ratio)
    protocol = ddg.LoadingProtocol(compression_ratio, shear_ratio=shear_ratio, compression_steps=40,
                                   shear_steps=shear_steps)
    result = ddg.simulate(strip, protocol, model=model, resolution=resolution, branches=False, **kw)
    assert result.converged, result.summary["message"]
    return result


def holds(key, measured):
    verdict = C.evaluate(key, measured)
    assert verdict["holds"], verdict
    return verdict


# ---------------------------------------------------------------------------- machinery
@pytest.fixture(scope="module")
def smoke_report(tmp_path_factory):
    out = tmp_path_factory.mktemp("report")
    summary = build_report("smoke", out, jobs=1, progress=False)
    return out, summary


def test_report_writes_every_figure_with_its_data(smoke_report):
    out, summary = smoke_report
    for name in ("index.html", "report.md", "summary.json", "thresholds.csv", "claims.csv", "stability_map.csv"):
        assert (out / name).stat().st_size > 0, name
    figures = sorted(p.stem for p in (out / "figures").glob("*.png"))
    assert {"elastica", "thresholds_vs_width", "shear_force", "convergence", "poisson", "speed_accuracy",
            "stability_map"} <= set(figures)
    for stem in figures:
        assert (out / "figures" / f"{stem}.pdf").exists() and (out / "figures" / f"{stem}.csv").exists()
        assert len((out / "figures" / f"{stem}.csv").read_text().splitlines()) > 1, stem
    html = (out / "index.html").read_text()
    assert html.count("data:image/png;base64,") == len(figures)  # self-contained
    written = json.loads((out / "summary.json").read_text())
    assert written["claims_failing"] == [] and written["runs"] == summary["runs"] > 0


def test_rerun_takes_every_run_from_the_cache(smoke_report, monkeypatch):
    out, summary = smoke_report

    def refuse(*args, **kwargs):
        raise AssertionError("a cached run was recomputed")

    monkeypatch.setattr(R, "execute_one", refuse)
    again = build_report("smoke", out, jobs=1, progress=False)
    assert again["runs"] == summary["runs"]


def test_an_interrupted_report_resumes_with_the_missing_run_only(smoke_report, monkeypatch):
    out, summary = smoke_report
    finished = sorted((out / "cache").glob("*/spec.json"))
    finished[0].unlink()  # as if the report had been stopped during that run
    computed = []
    original = R.execute_one

    def counting(spec, directory):
        computed.append(spec)
        return original(spec, directory)

    monkeypatch.setattr(R, "execute_one", counting)
    again = build_report("smoke", out, jobs=1, progress=False)
    assert len(computed) == 1 and again["runs"] == summary["runs"]


def test_a_change_of_the_code_changes_the_cache_key():
    spec = R.RunSpec("rod", 0.05, 0.5, 100)
    assert spec.key("version-a") != spec.key("version-b")
    assert spec.key("version-a") == R.RunSpec("rod", 0.05, 0.5, 100).key("version-a")


def test_frames_change_the_cache_key_only_where_asked():
    """Runs without frames keep the key they had before RunSpec.frames existed (cached runs stay valid)."""
    import hashlib
    from dataclasses import asdict

    spec = R.RunSpec("plate", 0.05, 0.5, 2000)
    fields = {k: v for k, v in asdict(spec).items() if k != "frames"}
    before = hashlib.sha256(json.dumps({"spec": fields, "code": "c"}, sort_keys=True).encode()).hexdigest()[:16]
    assert spec.key("c") == before
    assert R.RunSpec("plate", 0.05, 0.5, 2000, frames=True).key("c") != before


# ---------------------------------------------------------------------------- claims
@pytest.fixture(scope="module")
def narrow_rod():
    return simulate("rod", 1 / 20, 1 / 2, 100)


def test_claim_rod_matches_the_elastica(narrow_rod):
    holds("rod_elastica", C.elastica_error(narrow_rod))


def test_claim_plate_matches_the_elastica():
    holds("plate_elastica", C.elastica_error(simulate("plate", 1 / 6, 1 / 2, 1000, shear_ratio=0.0)))


def test_claim_ribbon_matches_the_elastica():
    """Untwisted, the Sadowsky energy is the rod's bending energy: the compressed ribbon is the
    elastica (measured -2.6e-4 at M = 101)."""
    from ddg.ribbon_runs import run_ribbon

    strip = ddg.Strip.from_ratios(1 / 20, 1 / 2)
    protocol = ddg.LoadingProtocol(1 / 2, shear_ratio=0.0, compression_steps=40, shear_steps=1)
    result = run_ribbon(strip, protocol, "direct", None, 101, thresholds=False)
    holds("ribbon_elastica", C.elastica_error(result))


def test_claim_fem_matches_the_elastica():
    gold = load_gold(1 / 2, 1 / 6)
    if gold is None:
        pytest.skip("no FEM gold data for W/L = 1/6, dL/L = 1/2 in data/fem_gold")
    holds("fem_elastica", C.elastica_error(gold))


def test_claim_rod_thresholds_near_the_paper(narrow_rod):
    quarter = simulate("rod", 1 / 20, 1 / 4, 100)
    holds("rod_thresholds_paper", max(C.paper_threshold_error(narrow_rod), C.paper_threshold_error(quarter)))


def test_claim_narrow_plate_and_rod_agree_on_U(narrow_rod):
    plate = simulate("plate", 1 / 20, 1 / 2, 1000, shear_ratio=0.36, shear_steps=36)
    holds("rod_vs_plate_narrow_U", C.u_branch_difference(plate, narrow_rod))


@pytest.fixture(scope="module")
def plate_sixth():
    """The report's quick scene: the plate at its default 2000 triangles."""
    return simulate("plate", 1 / 6, 1 / 2, 2000)


@pytest.mark.slow
def test_claim_plate_dW1_near_the_paper_at_one_sixth(plate_sixth):
    holds("plate_dW1_paper_sixth", plate_sixth.summary["dW1_over_L"] - 0.27)


def _gold_sixth():
    gold = load_gold(1 / 2, 1 / 6)
    if gold is None:
        pytest.skip("no FEM gold data for W/L = 1/6, dL/L = 1/2 in data/fem_gold")
    return gold


def test_claim_plate_and_fem_agree_on_dW1(plate_sixth_fine):
    """Measured 0.2575 (plate, 5740 triangles) vs 0.2640 (FEM, 120 x 20 elements)."""
    holds("plate_vs_fem_dW1", C.threshold_difference(plate_sixth_fine, _gold_sixth()))


def test_claim_plate_and_fem_agree_on_the_H_mid_curve(plate_sixth_fine):
    """Measured 0.0098 L at 5740 triangles (0.013 L at the default 2000)."""
    holds("plate_vs_fem_curve", C.curve_difference_away_from_thresholds(plate_sixth_fine, _gold_sixth()))


def test_claim_plate_and_the_shell_with_its_material_agree(plate_sixth_fine):
    from validation.report import load_dep_material

    dep = load_dep_material()
    if dep is None:
        pytest.skip("no FEM run with the DEP material (data/fem_dep)")
    holds("plate_vs_fem_own_material_curve", C.curve_difference_away_from_thresholds(plate_sixth_fine, dep))


def test_snapshots_show_the_plate_states_from_its_frames(tmp_path):
    """3D snapshots (paper Fig. 1) come from the frames the plate run kept: one panel per phase
    the run passes (a coarse W/L = 1/6 plate passes U and US), the CSV holds the frame's nodes."""
    pytest.importorskip("meshio", reason="the plate frames are VTU files read with meshio (python3-meshio)")
    import csv

    import numpy as np

    from validation import report
    from validation.studies import Profile

    strip = ddg.Strip.from_ratios(1 / 6, 1 / 2)
    protocol = ddg.LoadingProtocol(1 / 2, compression_steps=20, shear_steps=40)
    ddg.simulate(strip, protocol, model="plate", resolution=300, branches=False, frames=True, out=tmp_path / "run")
    spec = R.RunSpec("plate", 1 / 6, 1 / 2, 300, frames=True)
    run = R.load(tmp_path / "run", spec)
    states = report.snapshot_states(run)
    phases = [phase.rstrip("+-") for phase, _, _ in states]
    assert phases[:2] == ["U", "US"]
    dw1 = run.summary["dW1_over_L"]
    assert states[0][1] < dw1 < states[1][1]
    profile = Profile("test", [], {"plate": 300}, [], [], (), {}, {})
    note = report.figure_snapshots(report.Figures(tmp_path / "out"), {spec: run}, profile)
    assert note.startswith(f"{len(states)} shapes")
    for ext in ("png", "pdf", "csv"):
        assert (tmp_path / "out" / "figures" / f"snapshots_3d.{ext}").stat().st_size > 0
    with open(tmp_path / "out" / "figures" / "snapshots_3d.csv") as f:
        rows = [r for r in csv.DictReader(f) if r["phase"] == states[0][0]]
    import meshio

    nodes = meshio.read(states[0][2]).points / strip.length
    assert np.allclose([[float(r[k]) for k in ("x_over_L", "y_over_L", "z_over_L")] for r in rows], nodes)
