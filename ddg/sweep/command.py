"""`python -m ddg sweep`: a grid of runs (model x dL/L x W/L x L/b x resolution) as Dask tasks,
cached by content hash in DIR/runs/<key>/; one tidy table DIR/sweep.csv (DIR/sweep.parquet with
pyarrow) and the phase diagram DIR/phase_diagram.png/.pdf (paper Fig. 8).

Exit codes as `simulate`: 0 every run complete; 2 bad input (one line, before any work; also a
missing dask install or an unreachable --scheduler); 3 some runs did not complete (their status is
in the table); 130/143 interrupted (the finished runs are kept and tabled); 1 an internal error.
"""
from __future__ import annotations

import sys
from pathlib import Path

from ..geometry.strip import InputError
from . import cluster

#: The paper's widths (the FEM gold scenes): W/L = 1/20, 1/12, 1/6, 1/3, 1/2.
DEFAULT_WIDTHS = "0.05,0.08333333333333333,0.16666666666666666,0.3333333333333333,0.5"
#: Most values a list option takes (as the other commands' list options).
MAX_LIST_VALUES = 50


def add_arguments(parser) -> None:
    """The sweep command's options (lists: comma- or space-separated)."""
    parser.add_argument("--model", nargs="+", default=["rod"], metavar="MODEL",
                        help="rod (default), plate, ribbon; several allowed")
    parser.add_argument("--width-ratios", nargs="+", default=[DEFAULT_WIDTHS], metavar="W/L",
                        help="W/L values, comma- or space-separated as every list here (default 1/20, 1/12, 1/6, "
                             "1/3, 1/2)")
    parser.add_argument("--compression-ratios", nargs="+", default=["0.5,0.25"], metavar="dL/L",
                        help="dL/L values (default 0.5, 0.25)")
    parser.add_argument("--slenderness", nargs="+", default=None, metavar="L/b",
                        help="L/b values (default: b = 0.127 mm with the clamps 75 mm apart after compression, "
                             "i.e. 1181 at dL/L = 1/2, 787 at 1/4)")
    parser.add_argument("--resolutions", nargs="+", default=None, metavar="N",
                        help="rod/ribbon node counts M, plate target triangle counts (default: the model's, "
                             "100 / 101 / 2000)")
    parser.add_argument("--compression-steps", type=int, default=40, help="recorded compression steps (default 40)")
    parser.add_argument("--shear-steps", type=int, default=120, help="recorded shear steps (default 120)")
    parser.add_argument("--out", default="out/sweep",
                        help="output directory: runs/<key>/, sweep.csv, phase_diagram.png/.pdf (default out/sweep)")
    cluster.add_options(parser)
    parser.add_argument("--quiet", action="store_true", help="no progress bar or summary line")


def main(args) -> int:
    """Run the sweep; returns the exit code."""
    from ..output.interrupts import deferred_signals, exit_code_of, signal_name_of
    from ..output.io import check_output_directory
    from .cache import run_cached
    from .grid import grid
    from .table import sweep_rows, write_table

    specs = grid(_models(args.model), _floats("--width-ratios W/L", args.width_ratios, 1.0),
                 _floats("--compression-ratios dL/L", args.compression_ratios, 1.0),
                 [None] if args.slenderness is None else _floats("--slenderness L/b", args.slenderness, float("inf")),
                 [None] if args.resolutions is None else _integers("--resolutions", args.resolutions),
                 args.compression_steps, args.shear_steps)
    scheduler, workers, retries = cluster.checked_options(args.scheduler, args.workers, args.retries)
    scheduler = cluster.ready(scheduler, workers)
    out = check_output_directory(args.out, "--out")

    outcome = run_cached(specs, out / "runs", workers=workers, scheduler=scheduler, retries=retries,
                         progress=not args.quiet)
    with deferred_signals():  # a second Ctrl-C does not cut the table in half
        rows = sweep_rows(specs, outcome, out)
        written = write_table(out, rows)
        try:
            figures, _ = _figure(out, rows)
        except ImportError:
            figures = []
            sys.stderr.write("note: matplotlib is not installed: the phase diagram was skipped "
                             "(install the 'plot' extra: pip install ddg-strips[plot])\n")
    for spec in outcome.retried:
        sys.stderr.write(f"note: {spec.label}: an earlier attempt did not finish (its worker was killed or "
                         "stopped); the run was redone\n")
    files = ", ".join(str(p) for p in written + figures)
    if not args.quiet:
        where = f" on {outcome.where}" if outcome.where else ""
        runs = f"{len(specs)} run{'s' * (len(specs) != 1)}"
        print(f"sweep: {runs}: {len(outcome.computed)} computed{where}, {len(outcome.cached)} cached, "
              f"{len(outcome.errors)} failed, in {outcome.wall_time_s:.1f} s; wrote {files}")
    if outcome.interrupted is not None:
        done = len(outcome.results)
        sys.stderr.write(f"error: interrupted by {signal_name_of(outcome.interrupted)}: {done} of {len(specs)} runs "
                         f"finished and tabled in {out / 'sweep.csv'}; a rerun computes only the other "
                         f"{len(specs) - done}\n")
        return exit_code_of(outcome.interrupted)
    incomplete = [r for r in rows if r["status"] != "complete"]
    if incomplete:
        first = incomplete[0]
        sys.stderr.write(f"error: {len(incomplete)} of {len(rows)} runs did not complete (status in "
                         f"{out / 'sweep.csv'}); first: {first['model']} W/L={first['W_over_L']:.4g} "
                         f"dL/L={first['dL_over_L']:.4g}: {first['status']}: {first['message']}\n")
        return 3
    return 0


def _figure(out: Path, rows):
    from .figure import write_phase_diagram

    return write_phase_diagram(out, rows)


def _values(texts) -> list[str]:
    if isinstance(texts, str):
        texts = [texts]
    return [v.strip() for text in texts for v in str(text).split(",") if v.strip()]


def _count(name: str, values: list) -> list:
    if not 1 <= len(values) <= MAX_LIST_VALUES:
        raise InputError(f"{name} has {len(values)} values; allowed 1 to {MAX_LIST_VALUES}")
    return values


def _models(texts) -> list[str]:
    from .grid import MODELS

    values = _count("--model", _values(texts))
    for v in values:
        if v not in MODELS:
            raise InputError(f"--model {v!r} is not available; choose from {', '.join(MODELS)}")
    return values


def _floats(name: str, texts, high: float) -> list[float]:
    from ..analysis.centerline_approx import check_ratios

    return check_ratios(name, _count(name.split()[0], _values(texts)), 0.0, high)


def _integers(name: str, texts) -> list[int]:
    from ..api import MAX_NODES, MAX_TRIANGLES
    from ..geometry.centerline import MIN_NODES

    out = []
    for v in _count(name, _values(texts)):
        try:
            out.append(int(v))
        except ValueError:
            raise InputError(f"{name} {v!r} is not an integer; allowed: rod/ribbon M in [{MIN_NODES}, {MAX_NODES}], "
                             f"plate triangles in [16, {MAX_TRIANGLES}]") from None
    return out
