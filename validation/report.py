"""`python -m validation report`: run the models on the paper's scenes and write the report.

Output in DIR: index.html (self-contained: figures embedded), report.md, figures/<name>.png and
.pdf with figures/<name>.csv (every number behind each figure), tables as CSV, and summary.json
with the headline errors, the claims and the timings. Runs are cached in DIR/cache (validation/runs.py).

The numbers are one ReportData object (validation/report_data/); report.md and index.html are
rendered from it by the Jinja2 templates in validation/templates/ (sentences.j2 words the verdicts
of validation/verdicts.py for both), summary.json and the CSVs are written from it here.
"""
from __future__ import annotations

import argparse
import importlib
import json
import math
import re
import sys
import time
from pathlib import Path

from ddg.output.io import atomic_write_text

from . import figures
from .command_line import standalone
from .report_data import ReportData, collect
from .runs import run_all
from .studies import PROFILES, specs
from .table import FigureData, fraction, write_csv
from .verdicts import ClaimsVerdict, MaterialCheck, MeshTrend, PaperReading

TEMPLATES = Path(__file__).resolve().parent / "templates"
#: The modules the report needs beyond the models' own: pyproject's `report` extra.
REPORT_EXTRAS = ("jinja2", "matplotlib")


class MissingExtra(ImportError):
    """An optional dependency of the report is not installed (the message names the extra)."""


def _missing_extra(modules: list[str]) -> MissingExtra:
    debian = " ".join(f"python3-{m}" for m in modules)
    return MissingExtra(f"the validation report needs {' and '.join(modules)}: pip install 'ddg-strips[report]' "
                        f"(or Debian's {debian})")


def require_report_extras() -> None:
    """Import jinja2 and matplotlib, or raise MissingExtra with one line naming the `report` extra."""
    missing = []
    for module in REPORT_EXTRAS:
        try:
            importlib.import_module(module)
        except ImportError:
            missing.append(module)
    if missing:
        raise _missing_extra(missing)


# ---------------------------------------------------------------------------- rendering
def cell(value) -> str:
    """A table cell: 4 significant digits, '-' for a missing or non-finite number."""
    if value is None:
        return "-"
    if isinstance(value, float):
        return "-" if not math.isfinite(value) else f"{value:.4g}"
    return str(value)


#: What the report folds (layout only): a table cell longer than `cell` characters shows its first
#: `preview` characters and folds the whole text in <details>; a table or list of more than `rows`
#: entries is folded whole (the templates' macros fold, the summary at the top never is).
FOLD = {"cell": 80, "preview": 40, "rows": 12}


_CODE = re.compile(r"`([^`]+)`")
_BOLD = re.compile(r"\*\*(.+?)\*\*")
_LINK = re.compile(r"\[([^\]]+)\]\(([^)\s]+)\)")
_URL = re.compile(r"(?<![\"=>/])\b(https?://[^\s<)]+)")


def inline_markdown(text):
    """The inline Markdown the sentences and captions use (`code`, **bold**, [text](target), bare
    http(s) URLs) as HTML, the text itself escaped first: a Markup for the autoescaped templates."""
    from markupsafe import Markup, escape

    html = str(text) if isinstance(text, Markup) else str(escape(text))
    html = _CODE.sub(r"<code>\1</code>", html)
    html = _BOLD.sub(r"<strong>\1</strong>", html)
    html = _LINK.sub(r'<a href="\2">\1</a>', html)
    html = _URL.sub(r'<a href="\1">\1</a>', html)
    return Markup(html)


def _environment(html: bool):
    """The Jinja2 environment of validation/templates: autoescaped for HTML, plain for Markdown."""
    try:
        import jinja2
    except ImportError as exc:
        raise _missing_extra(["jinja2"]) from exc
    env = jinja2.Environment(loader=jinja2.FileSystemLoader(TEMPLATES), autoescape=html, trim_blocks=True,
                             lstrip_blocks=True, keep_trailing_newline=True, undefined=jinja2.StrictUndefined)
    env.filters.update(cell=cell, frac=fraction, fmt=format, md=inline_markdown if html else (lambda t: t))
    env.globals["FOLD"] = FOLD
    return env


def render_markdown(data: ReportData) -> str:
    return _environment(html=False).get_template("report.md.j2").render(data=data)


def render_html(data: ReportData) -> str:
    return _environment(html=True).get_template("index.html.j2").render(data=data)


def sentence(name: str, *args) -> str:
    """One macro of templates/sentences.j2 rendered as plain text (the report's wording of a verdict)."""
    macro = getattr(_environment(html=False).get_template("sentences.j2").module, name)
    return str(macro(*args)).strip()


def claims_sentence(claims: list[dict]) -> str:
    """All claims hold, or which do not and why (Markdown: the failing ones in bold)."""
    text = sentence("claims", ClaimsVerdict(claims))
    return text if ClaimsVerdict(claims).all_hold else f"**{text}**"


def paper_reading_sentence(table: list[dict], model: str = "fem") -> str:
    return sentence("paper_reading", PaperReading.of(table, model))


def material_sentence(check: MaterialCheck) -> str:
    return sentence("material", check)


def mesh_trend_sentence(points: list[tuple[int, float]], reference: float, name: str = "the FEM gold shell's") -> str:
    return sentence("mesh_trend", MeshTrend(points, reference, name))


# ---------------------------------------------------------------------------- writing
def draw_figures(items: list[FigureData], out: Path) -> None:
    """OUT/figures/<name>.png, .pdf and .csv of every figure; the PNGs kept for the HTML."""
    for item in items:
        item.png = figures.save(figures.draw(item), out / "figures", item.name)
        write_csv(out / "figures" / f"{item.name}.csv", item.columns, item.rows)


def material_summary(check: MaterialCheck | None) -> dict | None:
    if check is None:
        return None
    out = {k: getattr(check, k) for k in ("fem_dep_vs_nu0_dW1", "fem_dep_vs_nu0_curve", "plate_vs_fem_gold_dW1",
                                          "plate_vs_fem_gold_curve", "plate_vs_fem_dep_dW1", "plate_vs_fem_dep_curve",
                                          "fem_dep_resolution", "plate_triangles")}
    out["statement"] = material_sentence(check)
    if check.mesh_trend is not None:
        out["plate_dW1_by_triangles"] = check.mesh_trend.points
        out["mesh_statement"] = sentence("mesh_trend", check.mesh_trend)
    return out


def summary(data: ReportData) -> dict:
    """summary.json: the headline numbers, the claims and the timings."""
    p, t = data.provenance, data.tables
    return {
        "profile": p.profile, "runs": p.runs, "requested_runs": p.specs,
        "fem_gold_scenes": p.fem_gold_names, "missing_fem_gold": p.missing_fem_gold_names,
        "claims": data.claims, "claims_failing": [c["claim"] for c in data.claims_verdict.failing],
        "thresholds": t["thresholds"].rows, "speed_accuracy_reference": data.speed_reference,
        "speed_accuracy": t["speed_accuracy"].rows, "convergence": t["convergence"].rows,
        "poisson": {str(k): v for k, v in data.poisson.items()}, "stability_map": t["stability_map"].rows,
        "plate_material_check": material_summary(data.material),
        "report_wall_time_s": data.timings.report_wall_time_s, "model_wall_time_s": data.timings.model_wall_time_s,
    }


def write_report(data: ReportData, out: Path) -> dict:
    """The tables' CSVs, report.md, index.html and summary.json of `data` in `out`; returns the summary."""
    for table in data.tables.values():
        if table.csv:
            table.write(out / f"{table.name}.csv")
    atomic_write_text(out / "report.md", render_markdown(data))
    atomic_write_text(out / "index.html", render_html(data))
    result = summary(data)
    atomic_write_text(out / "summary.json", json.dumps(result, indent=2, default=str) + "\n")
    return result


def build_report(profile_name: str, out: Path, jobs: int = 1, progress: bool = True,
                 gold_root: Path | None = None, scheduler: str | None = None) -> dict:
    """Run (or take from the cache) the profile's runs, then write the report in `out`; returns
    summary.json's dict. scheduler: an existing Dask scheduler's address for the runs (default: a
    LocalCluster of `jobs` workers, ddg.sweep). Raises MissingExtra before any run if jinja2 or
    matplotlib is missing."""
    require_report_extras()
    t0 = time.perf_counter()
    profile = PROFILES[profile_name]()
    out = Path(out)
    study = specs(profile)
    results = run_all([s for group in study.values() for s in group], out / "cache", jobs=jobs, progress=progress,
                      scheduler=scheduler)
    data = collect(profile, study, results, gold_root)
    draw_figures(data.figures, out)
    data.timings.report_wall_time_s = time.perf_counter() - t0
    return write_report(data, out)


# ---------------------------------------------------------------------------- the command
def add_arguments(parser) -> None:
    """The options of `python -m validation report`."""
    parser.description = "Run the models on the paper's scenes and write DIR/index.html, report.md."
    group = parser.add_mutually_exclusive_group()
    group.add_argument("--quick", dest="profile", action="store_const", const="quick",
                       help="the default scenes with cached FEM gold data (a few minutes on 2 cores; default)")
    group.add_argument("--full", dest="profile", action="store_const", const="full", help="every study (1-2 hours)")
    group.add_argument("--smoke", dest="profile", action="store_const", const="smoke", help=argparse.SUPPRESS)
    parser.add_argument("--out", default="out/validation", help="output directory (default out/validation)")
    parser.add_argument("--jobs", type=int, default=2, help="worker processes for the model runs (default 2)")
    parser.add_argument("--scheduler", default=None,
                        help="an existing Dask scheduler for the runs, e.g. tcp://host:8786 (default: a local cluster)")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")


def check_report_inputs(args) -> None:
    """`report`'s options before any folder is made (a one-line ddg.InputError): --jobs within the
    LocalCluster's bounds (ddg.sweep.cluster), DDG_BLAS_THREADS, and the scheduler the runs would use
    (--scheduler, else DASK_SCHEDULER_ADDRESS) connected to once: an unreachable one leaves no --out.
    Without dask the runs are made in this process (validation.runs.run_all says so), and no
    scheduler is asked."""
    from ddg.geometry.strip import InputError
    from ddg.limits import check_integer
    from ddg.solve.blas_threads import requested_threads
    from ddg.sweep import cluster

    check_integer("--jobs", args.jobs, 1, max(4 * cluster.cores(), 8),
                  "worker processes for the runs; more than the cores share them")
    requested_threads()
    if args.scheduler is not None:
        cluster.checked_options(args.scheduler, None, 0)
    try:
        cluster.require_dask()
    except InputError:
        return
    if args.scheduler is not None:
        cluster.check_scheduler(args.scheduler)
    elif cluster.default_scheduler() is not None:
        cluster.check_scheduler(cluster.default_scheduler(), "DASK_SCHEDULER_ADDRESS")


def run(args) -> int:
    """`python -m validation report`: every option checked, then the report (build_report); a bad
    option or a missing extra is one line on stderr and exit 2."""
    from ddg.geometry.strip import InputError
    from ddg.output.io import check_output_directory

    try:
        check_report_inputs(args)
        check_output_directory(args.out, "--out")   # before any run: an existing file is one line, not a traceback
        summary = build_report(args.profile or "quick", args.out, jobs=args.jobs, progress=not args.quiet,
                               scheduler=args.scheduler)
    except (MissingExtra, InputError) as exc:
        sys.stderr.write(f"error: {exc}\n")
        return 2
    print(f"report: {args.out}/index.html ({summary['runs']} runs, {summary['report_wall_time_s']:.0f} s); "
          f"claims failing: {summary['claims_failing'] or 'none'}")
    return 0


def main(argv=None) -> int:
    """`python -m validation.report [options]`: the same as `python -m validation report [options]`."""
    return standalone("report", add_arguments, run, argv)


if __name__ == "__main__":
    raise SystemExit(main())
