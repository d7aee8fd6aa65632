"""The README is what a newcomer reads first (issue 33 item 4): under 150 lines, its two commands the
ones CI runs, every link resolving to a file of the repository, the manual's pages linked, and its
sentence on the benchmark table computed from data/benchmark/benchmark.csv (the table itself:
tests/validation/test_benchmark_table.py)."""
import csv
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text()
LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)\)")


def test_the_readme_fits_two_screens_of_a_newcomer():
    assert len(README.splitlines()) < 150


def test_every_link_of_the_readme_resolves_to_a_file_here():
    targets = LINK.findall(README)
    assert len(targets) >= 20
    for target in targets:
        assert not target.startswith(("http://", "https://")), f"{target}: the README links only into the repository"
        path = ROOT / target.split("#")[0]
        assert path.exists(), f"README links {target!r}, which does not exist"


def test_the_readme_links_every_page_of_the_manual_a_task_needs():
    linked = {t.split("#")[0] for t in LINK.findall(README)}
    for folder in ("guide", "findings", "reference"):
        for page in (ROOT / "docs" / folder).glob("*.*"):
            if page.suffix in (".rst", ".md") and page.stem != "index":
                assert f"docs/{folder}/{page.name}" in linked, f"the README does not link docs/{folder}/{page.name}"
    assert "docs/getting_started.rst" in linked and "docs/physics/index.rst" in linked


def test_the_readme_commands_are_the_setup_and_the_test_command_ci_runs():
    ci = (ROOT / ".ci" / "run").read_text()
    for command in ("bash scripts/setup.sh", ".venv/bin/python -m pytest -q"):
        assert command in ci and f"    {command}\n" in README
    assert "    .venv/bin/python -m ddg simulate --model rod --width-ratio 0.05 --compression-ratio 0.5" in README


def _f(value):
    return float(value) if value not in ("", None) else None


def test_the_readme_sentence_on_the_benchmark_table_is_computed_from_it():
    """"the paper's plate lies A to B combined error bars from the FEM on both thresholds at W/L =
    1/20; the mid-edge plate lies within C of them wherever the error bars decide (a combined error
    bar of at most LIMIT L, the claims' rule): on N of its 20 thresholds, both at S of the ten
    scenes; the other U (combined error bars P-Q L) are undecided; the rod's dW1/L stays at D-E while
    the FEM's falls to F-G at W/L = 1/2": each figure recomputed from benchmark.csv, rounded as the
    table rounds. Decided as tests/validation/test_midedge_studies.py decides (assert_agreement_where_decided):
    the sum of the mid-edge and FEM error bars at most the error-bar limit of the report's threshold
    claims (validation.claims), so an entry whose bars are too wide to tell is not counted as
    agreeing."""
    from validation.claims import CLAIMS

    limit = CLAIMS["plate_vs_fem_narrow_thresholds"].error_bar_limit
    rows = list(csv.DictReader(open(ROOT / "data" / "benchmark" / "benchmark.csv")))
    narrow = [r for r in rows if abs(float(r["width_ratio"]) - 0.05) < 1e-9]
    wide = [r for r in rows if abs(float(r["width_ratio"]) - 0.5) < 1e-9]
    plate = [_f(r[f"{q}_in_error_bars"]) for r in narrow for q in ("dW1", "dW2")]
    midedge = [(_f(r[f"midedge_{q}_in_error_bars"]), _f(r[f"midedge_{q}_error_bar"]), _f(r[f"fem_{q}_error_bar"]))
               for r in rows for q in ("dW1", "dW2")]
    rod = [_f(r["rod_dW1"]) for r in rows]
    fem = [_f(r["fem_dW1"]) for r in wide]
    assert None not in plate + [x for m in midedge for x in m] + rod + fem and len(rows) == 10
    decided = [ratio for ratio, a, b in midedge if a + b <= limit]
    undecided = [a + b for _, a, b in midedge if a + b > limit]
    both = sum(all(_f(r[f"midedge_{q}_error_bar"]) + _f(r[f"fem_{q}_error_bar"]) <= limit for q in ("dW1", "dW2"))
               for r in rows)
    assert decided and undecided, "the sentence names both kinds"
    text = " ".join(README.split())
    assert (f"the paper's plate lies {min(plate):.1f} to {max(plate):.1f} combined error bars from the FEM "
            f"on both thresholds at W/L = 1/20") in text
    assert (f"the mid-edge plate lies within {max(decided):.1f} of them wherever the error bars decide (a combined "
            f"error bar of at most {limit:g} L, the claims' rule): on {len(decided)} of its {len(midedge)} thresholds, "
            f"both at {both} of the ten scenes; the other {len(undecided)} (combined error bars "
            f"{min(undecided):.3f}-{max(undecided):.3f} L) are undecided") in text
    assert (f"the rod's dW1/L stays at {min(rod):.3f}-{max(rod):.3f} while the FEM's falls to "
            f"{min(fem):.4f}-{max(fem):.4f} at W/L = 1/2") in text
