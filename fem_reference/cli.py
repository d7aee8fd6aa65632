"""python -m fem_reference simulate | convergence | convergence-table | gold: the FEM reference from the shell.

Exit codes as `python -m ddg`: 0 complete, 2 bad input (a one-line message, before any mesh or
solve and before dolfinx is imported), 3 the path stopped converging (the converged part is
written, the message says where), 130 / 143 interrupted by SIGINT / SIGTERM (every converged step
written, summary.json status "interrupted"), 1 any other failure (one line: a missing FEM
package, out of memory, a file that cannot be written, an internal error; FEM_REFERENCE_TRACEBACK=1
shows the traceback of the last).
"""
from __future__ import annotations

import argparse
import json
import os
import sys

from ddg.cli_parser import EXIT_BAD_INPUT, OneLineParser
from ddg.sweep.cluster import add_options as cluster_options

from .elements import DEFAULT_ELEMENT, ELEMENTS
from .scene import add_scene_options, scene_from_args

EXIT_FAILURE = 1
EXIT_NOT_CONVERGED = 3


#: Option names of the command line, for api.check_inputs' messages.
OPTION_NAMES = {"resolution": "--resolution", "across": "--across", "out": "--out", "perturbation": "--perturbation",
                "element": "--element"}


def _thresholds_note(s: dict) -> str:
    found = [f"{label} = {s[key]:.4f}" for key, label in (("dW1_over_L", "dW1/L"), ("dW2_over_L", "dW2/L"))
             if s.get(key) is not None]
    return f"; located before it: {', '.join(found)}" if found else "; no threshold located"


def cmd_simulate(args) -> int:
    from .api import check_inputs

    strip, protocol = scene_from_args(args)
    # every input checked before dolfinx is imported (api.simulate checks them again, cheaply)
    check_inputs(strip, protocol, args.resolution, args.across, args.material, args.out, args.perturbation,
                 names=OPTION_NAMES, element=args.element)
    from .api import simulate
    from .continuation import ContinuationOptions

    options = ContinuationOptions(perturbation=args.perturbation, branch_switching=not args.no_branch_switching,
                                  thresholds=not args.no_thresholds)
    result = simulate(strip, protocol, args.resolution, out=args.out, options=options, across=args.across,
                      fields=not args.no_fields, progress=not args.quiet, material=args.material,
                      centerline=not args.no_centerline, element=args.element)
    args.finished_in = args.out or ""  # for the message of a Ctrl-C from here on
    s = result.summary
    if not args.quiet:
        keys = ("H_mid_over_L_compressed", "dW_max_over_L", "dW1_over_L", "dW2_over_L", "n_dof",
                "newton_iterations", "wall_time_s", "converged", "status", "message")
        print(json.dumps({k: s.get(k) for k in keys}, indent=1))
    if not result.converged:
        where = f"; the converged part is written to {args.out}" if args.out is not None else ""
        print(f"error: run did not complete: {s['message']}{_thresholds_note(s)}{where}", file=sys.stderr)
        return EXIT_NOT_CONVERGED
    return 0


def cmd_convergence(args) -> int:
    from .convergence import run_convergence

    return run_convergence(args)


def cmd_convergence_table(args) -> int:
    from .convergence import table_from_runs

    return table_from_runs(args)


def cmd_gold(args) -> int:
    from .gold import run_gold

    return run_gold(args)


def build_parser() -> argparse.ArgumentParser:
    # parse errors: one line, exit 2 (ddg.cli_parser, the one parser of every command line)
    parser = OneLineParser(prog="python -m fem_reference", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True, parser_class=OneLineParser)
    p = sub.add_parser("simulate", help="one run: path.csv, summary.json, centerline.csv, fields.xdmf")
    add_scene_options(p)
    p.add_argument("--resolution", type=int, default=60,
                   help="elements along L, 4..400, odd rounded up to even (default 60)")
    p.add_argument("--across", type=int, default=None,
                   help="elements across W, 2..400, odd rounded up to even (default: near-isotropic)")
    p.add_argument("--perturbation", type=float, default=1e-3,
                   help="branch-switch start amplitude / L, in [1e-6, 0.1] (default 1e-3)")
    p.add_argument("--no-branch-switching", action="store_true")
    p.add_argument("--material", choices=("isotropic", "dep"), default="isotropic",
                   help="isotropic (the strip's Poisson ratio, default) or dep: the DDG plate's continuum limit "
                        "(nu = 1/3 membrane, nu_b = -1/3 bending, D = E b^3/12)")
    p.add_argument("--element", choices=tuple(ELEMENTS), default=DEFAULT_ELEMENT,
                   help="the shell's finite element: P2B3 (u in [P2 + B3]^3, theta in [P2]^2, default) or P3 "
                        "(u in [P3]^3, theta in [P3]^2)")
    p.add_argument("--no-thresholds", action="store_true")
    p.add_argument("--no-fields", action="store_true", help="skip fields.xdmf")
    p.add_argument("--no-centerline", action="store_true", help="skip centerline.csv")
    p.add_argument("--out", default=None, help="output directory (default: nothing written)")
    p.add_argument("--quiet", action="store_true")
    p.set_defaults(func=cmd_simulate)
    p = sub.add_parser("convergence", help="2-6 meshes, Richardson extrapolation, CSV + markdown table")
    add_scene_options(p)
    p.add_argument("--resolutions", type=int, nargs="+", default=[60, 90, 120],
                   help="elements along L of each mesh, 4..400 each (default 60 90 120)")
    p.add_argument("--out", required=True)
    p.add_argument("--quiet", action="store_true")
    p.set_defaults(func=cmd_convergence)
    p = sub.add_parser("convergence-table", help="the convergence table of finished runs (simulate/gold folders)")
    p.add_argument("--runs", nargs="+", required=True, help="output folders of one scene on 2 or more meshes")
    p.add_argument("--out", required=True)
    p.set_defaults(func=cmd_convergence_table)
    p = sub.add_parser("gold", help="reference runs of the paper's scenes into a data folder")
    p.add_argument("--out", required=True)
    p.add_argument("--only", nargs="*", default=None,
                   help="scene names to run (e.g. dL0.5_W0.1667); default all")
    p.add_argument("--resolution", type=int, default=None,
                   help="elements along L of the coarsest mesh of each scene's study, 4..400 (default 64)")
    p.add_argument("--levels", type=int, default=None, help="meshes per scene, each 1.5 times finer, 1..4 (default 3)")
    p.add_argument("--studies-only", action="store_true",
                   help="no run: rewrite each selected scene's study (richardson.json, convergence.*) and the index "
                        "from its finished runs")
    cluster_options(p)  # --workers, --scheduler, --retries: the runs are Dask tasks, as the DDG sweep's
    p.add_argument("--quiet", action="store_true")
    p.set_defaults(func=cmd_gold)
    return parser


def _one_line(text) -> str:
    return " ".join(str(text).split())


def _interrupted(exc: BaseException, args) -> int:
    """One line for a run stopped by SIGINT/SIGTERM; the exit code 128 + the signal number."""
    from ddg.output.interrupts import exit_code_of, signal_name_of

    message = getattr(exc, "run_message", None)
    if message is None:
        message = f"interrupted by {signal_name_of(exc)}"
        if getattr(args, "command", None) == "simulate":
            done = getattr(args, "finished_in", None)
            message += (f" after the run; its files are complete in {done}" if done
                        else " after the run" if done is not None else " before the run started; nothing computed")
    folder = getattr(exc, "run_folder", None)
    if folder is not None:
        message += f"; written to {folder} (summary.json status 'interrupted')"
    elif getattr(exc, "result", None) is not None:
        message += "; nothing written (no --out)"
    sys.stderr.write(f"error: {_one_line(message)}\n")
    return exit_code_of(exc)


def main(argv=None) -> int:
    from ddg.geometry.strip import InputError
    from ddg.output.interrupts import terminate_as_interrupt

    terminate_as_interrupt()  # SIGTERM raises an interrupt too: every converged step is written
    args = None
    try:
        args = build_parser().parse_args(argv)
        return args.func(args)
    except SystemExit as exc:  # --help (0) or a bad option (2, its line already written)
        return exc.code if isinstance(exc.code, int) else EXIT_BAD_INPUT
    except InputError as exc:
        sys.stderr.write(f"error: {_one_line(exc)}\n")
        return EXIT_BAD_INPUT
    except KeyboardInterrupt as exc:
        return _interrupted(exc, args)
    except Exception as exc:
        from ddg.output.interrupts import interrupt_behind

        interrupt = interrupt_behind(exc)
        if interrupt is not None:
            return _interrupted(interrupt, args)
        folder = getattr(exc, "run_folder", None)
        kept = f"; the converged part is written to {folder} (summary.json status 'error')" if folder else ""
        if isinstance(exc, ImportError):
            sys.stderr.write(f"error: the FEM reference needs dolfinx 0.5, petsc4py, slepc4py, mpi4py and gmsh "
                             f"(scripts/setup.sh installs them): {_one_line(exc)}\n")
        elif isinstance(exc, MemoryError):
            sys.stderr.write(f"error: out of memory; use a coarser mesh (--resolution, --across){kept}\n")
        elif isinstance(exc, OSError):
            name = f"{exc.filename}: " if getattr(exc, "filename", None) else ""
            sys.stderr.write(f"error: {name}{_one_line(exc.strerror or exc)}{kept}\n")
        else:  # a bug: one line (FEM_REFERENCE_TRACEBACK=1 for the traceback)
            if os.environ.get("FEM_REFERENCE_TRACEBACK"):
                raise
            sys.stderr.write(f"error: internal error: {type(exc).__name__}: {_one_line(exc)}{kept} "
                             "(FEM_REFERENCE_TRACEBACK=1 shows the traceback)\n")
        return EXIT_FAILURE
