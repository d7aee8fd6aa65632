"""python -m validation report [--quick | --full] [--out DIR] [--jobs N] [--scheduler ADDRESS] [--quiet]
python -m validation score RESULTS [--out DIR] | --template FILE | --benchmark DIR  (validation/score.py)"""
from __future__ import annotations

import argparse
import sys


def main(argv=None) -> int:
    from ddg.cli_parser import OneLineParser  # one-line parse errors, exit 2

    parser = OneLineParser(prog="python -m validation")
    sub = parser.add_subparsers(dest="command", required=True)
    rep = sub.add_parser("report", help="run the models on the paper's scenes and write DIR/index.html, report.md")
    group = rep.add_mutually_exclusive_group()
    group.add_argument("--quick", dest="profile", action="store_const", const="quick",
                       help="the default scenes with cached FEM gold data (a few minutes on 2 cores; default)")
    group.add_argument("--full", dest="profile", action="store_const", const="full", help="every study (1-2 hours)")
    group.add_argument("--smoke", dest="profile", action="store_const", const="smoke", help=argparse.SUPPRESS)
    rep.add_argument("--out", default="out/validation", help="output directory (default out/validation)")
    rep.add_argument("--jobs", type=int, default=2, help="worker processes for the model runs (default 2)")
    rep.add_argument("--scheduler", default=None,
                     help="an existing Dask scheduler for the runs, e.g. tcp://host:8786 (default: a local cluster)")
    rep.add_argument("--quiet", action="store_true", help="no progress bar")
    score = sub.add_parser("score", help="score another code's thresholds and H_mid curves (a CSV file) against "
                                         "the FEM benchmark: DIR/score.csv, score.md, score.png")
    score.add_argument("results", nargs="?", default=None, metavar="RESULTS",
                       help="the CSV file to score (format: validation/score.py, or write a template with --template)")
    score.add_argument("--out", default="out/score", help="output directory (default out/score)")
    score.add_argument("--template", default=None, metavar="FILE",
                       help="write a RESULTS template with a row per benchmark scene to FILE and exit")
    score.add_argument("--benchmark", default=None, metavar="DIR",
                       help="write the benchmark (benchmark.csv, benchmark_H_mid.csv, README.md) to DIR and exit")
    args = parser.parse_args(argv)
    if args.command == "score":
        from .score import run

        return run(args)
    from ddg.geometry.strip import InputError
    from ddg.output.io import check_output_directory

    from .report import MissingExtra, build_report

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


if __name__ == "__main__":
    raise SystemExit(main())
