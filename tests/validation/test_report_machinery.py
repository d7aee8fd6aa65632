"""The validation report's machinery, on the smoke profile: the files it writes (every figure with
its data, a self-contained page whose links resolve), the claims its runs allow it to evaluate, its
cache (a rerun computes nothing, an interrupted report resumes with the missing run only, the key
follows the code and the frames), and every module of the package importing without the report's
extras."""
import json

import pytest

from validation import claims as C
from validation import runs as R
from validation.reference import load_gold
from validation.report import build_report


# ---------------------------------------------------------------------------- outputs
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
    assert written["runs"] == summary["runs"] > 0


def test_the_report_html_links_resolve_and_shows_no_markdown_source(smoke_report):
    from test_report_html import check_page

    out, _ = smoke_report
    check_page(out)


def test_smoke_report_evaluates_the_claims_its_runs_allow_and_fails_the_others(smoke_report):
    """The smoke profile runs rods at M = 30 and 40 only (the single-model claims are stated for
    M = 100 and for plates and ribbons), so of those it can evaluate only the FEM shell's elastica,
    from the gold data; the cross-model claims come from the stored studies (and the rod study of
    its M = 30/40 runs) wherever those exist. Every claim without data does not hold and says
    what is missing; the report lists every claim that does not hold."""
    out, summary = smoke_report
    claims = {c["claim"]: c for c in summary["claims"]}
    assert set(claims) == set(C.CLAIMS)
    single = {k for k, c in C.CLAIMS.items() if not c.cross_model}
    evaluable = {"fem_elastica"} if load_gold(1 / 2, 1 / 6) is not None else set()
    assert {k for k in single if claims[k]["measured"] is not None} == evaluable
    for key in evaluable:
        assert claims[key]["holds"] is True, claims[key]
    for key in single - evaluable:
        assert claims[key]["holds"] is False and claims[key]["reason"].startswith("no data: no "), claims[key]
    for key in set(C.CLAIMS) - single:
        c = claims[key]
        assert (c["measured"] is None) == c["reason"].startswith("no data"), c
        assert c["needs"] or c["reason"].startswith("no data"), c
    failing = sorted(k for k, c in claims.items() if not c["holds"])
    assert sorted(summary["claims_failing"]) == failing
    report = (out / "report.md").read_text()
    assert f"{len(failing)} of {len(claims)} claims do not hold" in report
    assert "rod_elastica (fails: no data: no rod run (M = 100, W/L = 1/20, dL/L = 1/2))" in report


# ---------------------------------------------------------------------------- cache
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


# ---------------------------------------------------------------------------- imports
def test_each_validation_module_imports_first_without_the_report_extras():
    """Every module of the package imported first in a fresh interpreter (an import circle would
    fail for one of them), none importing jinja2 or matplotlib: those load where rendering happens."""
    import pathlib
    import subprocess
    import sys

    import validation

    root = pathlib.Path(validation.__file__).parent
    # the package's modules and its sub-packages' (validation.error_map.rows, ...), a sub-package by its name
    names = sorted(".".join(p.relative_to(root).with_suffix("").parts).removesuffix(".__init__")
                   for p in root.rglob("*.py"))
    assert {"report", "report_data", "figures", "verdicts"} <= set(names)
    check = ("import importlib, sys; importlib.import_module(sys.argv[1]); "
             "loaded = [m for m in ('jinja2', 'matplotlib') if m in sys.modules]; assert not loaded, loaded")
    failed = {}
    for start in range(0, len(names), 8):   # eight interpreters at a time
        procs = {name: subprocess.Popen([sys.executable, "-c", check, f"validation.{name}"], stderr=subprocess.PIPE,
                                        text=True) for name in names[start:start + 8]}
        failed.update({name: proc.communicate()[1].strip().splitlines()[-1:] for name, proc in procs.items()
                       if proc.wait() != 0})
    assert not failed
