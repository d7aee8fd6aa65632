"""`python -m ddg sweep`: a grid of runs (model x dL/L x W/L x L/b x resolution) as Dask tasks,
cached by content hash in DIR/runs/<key>/; one tidy table DIR/sweep.csv (DIR/sweep.parquet with
pyarrow) and the phase diagram DIR/phase_diagram.png/.pdf (paper Fig. 8).

Exit codes as `simulate`: 0 every run complete; 2 bad input (one line, before any work; also a
missing dask install or an unreachable --scheduler); 3 some runs did not complete (their status is
in the table); 130/143 interrupted (the finished runs are kept and tabled); 1 an internal error.
"""
from __future__ import annotations

import sys

from ..models.names import ROD
from . import cluster
from .run import PAPER_WIDTHS

#: The paper's widths (the FEM gold scenes): W/L = 1/20, 1/12, 1/6, 1/3, 1/2.
DEFAULT_WIDTHS = ",".join(repr(w) for w in PAPER_WIDTHS)
#: The names the checks of ddg.sweep.run give each argument here: the options.
OPTION_NAMES = {"models": "--model", "width_ratios": "--width-ratios W/L",
                "compression_ratios": "--compression-ratios dL/L", "slendernesses": "--slenderness L/b",
                "resolutions": "--resolutions", "out": "--out"}


def add_arguments(parser) -> None:
    """The sweep command's options (lists: comma- or space-separated)."""
    parser.add_argument("--model", nargs="+", default=[ROD], metavar="MODEL",
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
    """Run the sweep (ddg.sweep.run.sweep, the function run_sweep calls); returns the exit code."""
    from ..output.interrupts import exit_code_of, signal_name_of
    from .run import sweep

    result = sweep(args.model, args.width_ratios, args.compression_ratios, args.slenderness, args.resolutions,
                   out=args.out, compression_steps=args.compression_steps, shear_steps=args.shear_steps,
                   workers=args.workers, scheduler=args.scheduler, retries=args.retries, progress=not args.quiet,
                   names=OPTION_NAMES)
    outcome, out, rows = result.outcome, result.out, result.rows
    total = result.runs
    for note in result.notes:
        sys.stderr.write(f"note: {note}\n")
    if not args.quiet:
        where = f" on {outcome.where}" if outcome.where else ""
        runs = f"{total} run{'s' * (total != 1)}"
        files = ", ".join(str(p) for p in result.files)
        print(f"sweep: {runs}: {len(outcome.computed)} computed{where}, {len(outcome.cached)} cached, "
              f"{len(outcome.errors)} failed, in {outcome.wall_time_s:.1f} s; wrote {files}")
    if result.interrupted is not None:
        done = len(outcome.results)
        sys.stderr.write(f"error: interrupted by {signal_name_of(result.interrupted)}: {done} of {total} runs "
                         f"finished and tabled in {out / 'sweep.csv'}; a rerun computes only the other "
                         f"{total - done}\n")
        return exit_code_of(result.interrupted)
    if result.incomplete:
        first = result.incomplete[0]
        sys.stderr.write(f"error: {len(result.incomplete)} of {len(rows)} runs did not complete (status in "
                         f"{out / 'sweep.csv'}); first: {first['model']} W/L={first['W_over_L']:.4g} "
                         f"dL/L={first['dL_over_L']:.4g}: {first['status']}: {first['message']}\n")
        return 3
    return 0
