"""`python -m validation error-map`: the error map's command line (old spelling
`python -m validation.error_map`).

Every option is checked before any folder is made or any run starts (exit 2, one line): --only
against the map's scenes, --models against the models it has, --timeout in [1, MAX_TIMEOUT] s, the
cluster options, and a --scheduler connected to first. Then the rows (validation.error_map.compute;
none with --report-only), OUT/README.md and the two figures. A failed run is reported on stderr
and not written, and the command exits 1 after the README and the figures; Ctrl-C (or SIGTERM)
keeps every row written (exit 130 or 143); no rows at all: exit 3.
"""
from __future__ import annotations

import sys

from ddg.output.io import atomic_write_text

from ..command_line import standalone
from .compute import MAX_TIMEOUT, RUN_TIMEOUT, build
from .held_out import TOLERANCES, held_out_check
from .plots import figures
from .readme_writer import readme
from .rows import CSV_NAME, read_table
from .scenes import check_selection, missing_scenes, reference_scenes


def add_arguments(parser) -> None:
    """The error map's options."""
    from ddg.sweep import cluster

    parser.description = ("The error map: the error of every model at every resolution on every scene with a "
                          "converged FEM reference, and its wall time.")
    parser.add_argument("--out", default="data/error_map", help="output directory (default data/error_map)")
    parser.add_argument("--only", nargs="+", default=None,
                        help="scenes to (re)compute, e.g. dL0.5_W0.05 or dL0.5_W0.05_Lb300 (default all)")
    parser.add_argument("--models", nargs="+", default=None, help="models to (re)compute (default all)")
    parser.add_argument("--timeout", type=int, default=RUN_TIMEOUT,
                        help=f"seconds per run made here, 1..{MAX_TIMEOUT} (default {RUN_TIMEOUT}); a run past it "
                             "fails and is not written")
    parser.add_argument("--report-only", action="store_true", help="no runs: README and figures from the CSV")
    cluster.add_options(parser)  # --workers, --scheduler, --retries: the runs are Dask tasks, as the sweep's


def run(args) -> int:
    """The command's work (module docstring); returns the exit code."""
    from ddg.geometry.strip import InputError
    from ddg.limits import check_integer
    from ddg.output.interrupts import exit_code_of, terminate_as_interrupt
    from ddg.output.io import check_output_directory
    from ddg.solve.blas_threads import requested_threads
    from ddg.sweep import cluster

    terminate_as_interrupt()  # SIGTERM too keeps the rows written
    scenes = reference_scenes()
    try:   # every option before any folder or run; the scheduler connected to last
        check_selection(args.only, args.models, scenes)
        check_integer("--timeout", args.timeout, 1, MAX_TIMEOUT, "seconds one run made here may take")
        scheduler, workers, retries = cluster.checked_options(args.scheduler, args.workers, args.retries)
        if not args.report_only:
            requested_threads()   # a bad DDG_BLAS_THREADS would fail every run on its worker
            scheduler = cluster.ready(scheduler, workers)
        out = check_output_directory(args.out, "--out")
    except InputError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    failures: list[str] = []
    try:
        rows = read_table(out / CSV_NAME) if args.report_only else build(
            out, args.only, args.models, timeout=args.timeout, scheduler=scheduler, workers=workers, retries=retries,
            failures=failures)
    except InputError as exc:  # the scheduler at --scheduler went away after it was checked
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as exc:
        print(f"error: {getattr(exc, 'run_message', 'interrupted')}", file=sys.stderr)
        return exit_code_of(exc)
    if not rows:
        print("error: the map has no rows" + (f" ({len(failures)} runs failed)" if failures else ""), file=sys.stderr)
        return 1 if failures else 3
    held = {tol: held_out_check(rows, tol) for tol in TOLERANCES}
    names = figures(rows, out)
    atomic_write_text(out / "README.md", readme(rows, held, names, missing_scenes(scenes)))
    print(f"wrote {out / CSV_NAME} ({len(rows)} rows), {out / 'README.md'}"
          + "".join(f", {out / n}" for n in names))
    if failures:
        print(f"error: {len(failures)} run(s) failed and are not in the map (first: {failures[0]}); a rerun "
              "retries them", file=sys.stderr)
        return 1
    return 0


def main(argv=None) -> int:
    """`python -m validation.error_map [options]`: the same as `python -m validation error-map [options]`."""
    return standalone("error-map", add_arguments, run, argv)
