"""The manual in docs/ builds with Sphinx, warnings as errors, and its key pages say what they must.

The build runs as scripts/docs.sh runs it (`python -m sphinx -W --keep-going -b html`), on a copy of
docs/ in a temporary folder (DDG_DOCS_ROOT names this checkout, so the API pages document its
sources and the gallery shows its examples/), the examples shown but not run: about 30 s on the
project's machine with its other core busy. `pytest -m slow` also builds it with the gallery run
(each example inside the build, with --out in the temporary folder). Skipped when Sphinx or one of
its extensions is not installed (scripts/setup.sh installs them from Debian)."""
from __future__ import annotations

import html
import importlib.util
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
NEEDED = ("sphinx", "numpydoc", "sphinx_gallery", "furo")
MISSING = [name for name in NEEDED if importlib.util.find_spec(name) is None]

pytestmark = pytest.mark.skipif(bool(MISSING), reason=f"the manual needs {', '.join(MISSING)} (scripts/setup.sh "
                                                       "installs python3-sphinx python3-numpydoc "
                                                       "python3-sphinx-gallery furo)")


def build_manual(tmp: Path, gallery: bool, timeout: float) -> Path:
    """docs/ copied to tmp/docs and built into tmp/html; the build's output is shown when it fails."""
    source = tmp / "docs"
    shutil.copytree(DOCS, source, ignore=shutil.ignore_patterns("auto_examples", "_build", "__pycache__"))
    out = tmp / "html"
    env = {**os.environ, "DDG_DOCS_ROOT": str(ROOT), "DDG_DOCS_GALLERY": "1" if gallery else "0",
           "DDG_DOCS_GALLERY_OUT": str(tmp / "example_runs")}
    done = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-b", "html", "-d",
                           str(tmp / "doctrees"), str(source), str(out)],
                          cwd=ROOT, env=env, capture_output=True, text=True, timeout=timeout)
    assert done.returncode == 0, f"sphinx exited {done.returncode}\n{done.stdout[-3000:]}\n{done.stderr[-6000:]}"
    return out


INLINE_TAGS = r"</?(?:span|a|em|strong|code|sub|sup|cite)\b[^>]*>"


def text_of(page: Path) -> str:
    """A page's text: inline tags removed (``--model auto`` is split into spans in the HTML), other tags
    made spaces, entities decoded, whitespace collapsed."""
    body = re.sub(r"<script.*?</script>|<style.*?</style>", " ", page.read_text(encoding="utf-8"), flags=re.S)
    body = re.sub(r"<[^>]+>", " ", re.sub(INLINE_TAGS, "", body))
    return " ".join(html.unescape(body).split())


@pytest.fixture(scope="module")
def manual(tmp_path_factory) -> Path:
    return build_manual(tmp_path_factory.mktemp("docs"), gallery=False, timeout=600)


def test_index_and_api_pages_exist(manual):
    for page in ("index.html", "getting_started.html", "api/index.html", "api/ddg.html", "api/advise.html",
                 "reference/output_contract.html", "reference/benchmark.html", "auto_examples/index.html"):
        assert (manual / page).is_file(), page
    index = text_of(manual / "index.html")
    assert "bash scripts/setup.sh" in index and ".venv/bin/python -m pytest -q" in index
    api = text_of(manual / "api/ddg.html")
    for name in ("ddg.simulate", "ddg.read_run", "ddg.Strip", "ddg.LoadingProtocol", "ddg.SimulationResult"):
        assert name in api, name


def test_choosing_a_model_names_auto_and_the_rule(manual):
    page = text_of(manual / "guide/choosing_a_model.html")
    for phrase in ("--model auto", "python -m ddg advise", "--tolerance", "rule v3", "python -m validation.error_map"):
        assert phrase in page, phrase


def test_output_contract_lists_every_column_and_key(manual):
    import ddg
    from ddg.analysis.observables import EXTRA_COLUMNS, PATH_COLUMNS
    from ddg.api import make_model
    from ddg.protocol.results import base_summary

    page = text_of(manual / "reference/output_contract.html")
    strip = ddg.Strip.from_ratios(0.05, 0.5)
    summary = base_summary("rod", strip, ddg.LoadingProtocol(0.5), 20, make_model("rod", strip, 20))
    names = list(PATH_COLUMNS) + list(EXTRA_COLUMNS) + list(summary) + ["recorded_steps", "resolved_up_to_dW_over_L"]
    missing = [name for name in names if name not in page]
    assert not missing, f"the output contract page does not name {missing}"


def test_benchmark_pages_carry_the_rule_and_the_format(manual):
    from validation.score import BENCHMARK_VERSION, REQUIRED_COLUMNS

    page = text_of(manual / "reference/benchmark.html")
    assert f"Benchmark {BENCHMARK_VERSION}" in page
    for phrase in ("grid convergence index", "Richardson", "benchmark_H_mid.csv", *REQUIRED_COLUMNS):
        assert phrase in page, phrase
    scoring = text_of(manual / "guide/scoring.html")
    assert "python -m validation score" in scoring and "--template" in scoring


def test_physics_pages_cite_the_papers_equations(manual):
    for page, tags in (("physics/rod.html", ("6a", "6b", "6c")), ("physics/plate.html", ("11a", "11b")),
                       ("physics/ribbons.html", ("A.2", "A.5")), ("physics/index.html", ("B.1",))):
        source = (manual / page).read_text(encoding="utf-8")
        for tag in tags:
            assert f"\\tag{{{tag}}}" in source, (page, tag)


def test_command_line_page_shows_the_parsers(manual):
    page = text_of(manual / "reference/cli.html")
    for usage in ("usage: python -m ddg simulate", "usage: python -m validation score",
                  "usage: python -m fem_reference gold"):
        assert usage in page, usage


def test_gallery_lists_every_example(manual):
    index = text_of(manual / "auto_examples/index.html")
    for script in sorted((ROOT / "examples").glob("*.py")):
        assert (manual / "auto_examples" / f"{script.stem}.html").is_file(), script.name
        first_line = script.read_text().split('"""')[1].strip().splitlines()[0].rstrip(".")
        assert first_line in index, first_line


@pytest.mark.slow
def test_manual_with_the_gallery_run(tmp_path):
    """The examples run inside the build: their printed output ends in "ok: ", and the pictures they
    save (thresholds.png; the plate renders where pyvista is installed) are in their pages."""
    out = build_manual(tmp_path, gallery=True, timeout=1800)
    for script in sorted((ROOT / "examples").glob("*.py")):
        page = text_of(out / "auto_examples" / f"{script.stem}.html")
        assert "ok: " in page, f"{script.name}: no 'ok: ' line in its page"
    thresholds = (out / "auto_examples/thresholds_against_width.html").read_text()
    assert "sphx_glr_thresholds_against_width_001.png" in thresholds
    if importlib.util.find_spec("pyvista") is not None:
        render = (out / "auto_examples/plate_frames_render.html").read_text()
        assert "sphx_glr_plate_frames_render_003.png" in render
