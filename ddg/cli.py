"""Command line: `python -m ddg simulate ...`, a thin layer over ddg.simulate.

Exit codes: 0 path complete; 2 bad arguments (one-line message); 3 the run stopped
converging (the converged part of the path is written, the message says where).
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from .geometry.strip import InputError, LoadingProtocol, Strip

EXIT_BAD_INPUT = 2
EXIT_NOT_CONVERGED = 3


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, exit 2, no usage dump
        sys.stderr.write(f"error: {message}\n")
        raise SystemExit(EXIT_BAD_INPUT)


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="python -m ddg", description="DDG solvers for pre-buckled strips under shear.")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    sim = sub.add_parser("simulate", help="compress by dL, then shear by dW; write path.csv and summary.json")
    sim.add_argument("--model", default="rod", choices=("rod", "plate", "ribbon"),
                     help="rod (DAR, default), plate (DEP on a triangle mesh) or ribbon (Sadowsky, Eq. A.5)")
    sim.add_argument("--zeta", type=float, default=None,
                     help="ribbon: regularisation length zeta of Eq. (A.5) in metres (default 1e4 L)")
    sim.add_argument("--ribbon-init", choices=("direct", "rod"), default=None,
                     help="ribbon: 'direct' from the flat strip (default) or 'rod': relax each rod equilibrium")
    sim.add_argument("--width-ratio", type=float, default=0.05, help="W/L (default 0.05)")
    sim.add_argument("--compression-ratio", type=float, default=0.5, help="dL/L (default 0.5)")
    sim.add_argument("--shear-ratio", type=float, default=None, help="largest dW/L (default dW_max/L, Eq. B.1)")
    sim.add_argument("--slenderness", type=float, default=None,
                     help="L/b (default: b = 0.127 mm with clamps 75 mm apart, i.e. 1181 at dL/L = 1/2)")
    sim.add_argument("--poisson-ratio", type=float, default=0.0, help="nu in [0, 0.5) (default 0)")
    sim.add_argument("--young-modulus", type=float, default=100e9, help="E in Pa (default 100 GPa)")
    sim.add_argument("--resolution", type=int, default=None,
                     help="rod: node count M (default 100); plate: target triangle count N_mesh (default 2000)")
    sim.add_argument("--mesh", default=None,
                     help="plate: a mesh file meshio reads (e.g. gmsh .msh) spanning L + 2c by W, or 'gmsh' for an "
                          "unstructured gmsh mesh of --resolution triangles (default: structured near-equilateral)")
    sim.add_argument("--frames", action="store_true",
                     help="also write OUT/frames/frame_NNNNN.vtu per recorded step and OUT/frames/frames.pvd (ParaView)")
    sim.add_argument("--compression-steps", type=int, default=40, help="recorded compression steps (default 40)")
    sim.add_argument("--shear-steps", type=int, default=120, help="recorded shear steps (default 120)")
    sim.add_argument("--shear-direction", type=int, choices=(1, -1), default=1, help="+1 or -1 (default +1)")
    sim.add_argument("--branch", choices=("+", "-"), default="+",
                     help="at the pitchfork follow US+ and then S+ (default) or US- and S-")
    sim.add_argument("--no-thresholds", action="store_true",
                     help="skip locating dW1 and dW2 from stability after the path (summary keys stay null)")
    sim.add_argument("--no-branches", action="store_true",
                     help="skip tracing every branch (U, US+, US-, S) by pseudo-arclength after the path "
                          "(OUT/branches.csv)")
    sim.add_argument("--no-branch-switching", action="store_true",
                     help="stay on the branch the path starts on, even where it is unstable")
    sim.add_argument("--solver", choices=("static", "dynamic"), default="static",
                     help="static Newton continuation (default) or the paper's implicit-Euler time marching (rod)")
    sim.add_argument("--clamp-speed", type=float, default=1e-3, help="dynamic solver: clamp speed in m/s (default 1e-3)")
    sim.add_argument("--max-newton-iterations", type=int, default=15, help="per load step (default 15)")
    sim.add_argument("--out", default="out", help="output directory (default ./out)")
    sim.add_argument("--quiet", action="store_true", help="no progress bar or result print-out")
    return parser


def cmd_simulate(args) -> int:
    from .api import simulate
    from .solve.continuation import ContinuationOptions
    from .solve.newton import NewtonOptions

    strip = Strip.from_ratios(args.width_ratio, args.compression_ratio, args.slenderness,
                              young_modulus=args.young_modulus, poisson_ratio=args.poisson_ratio)
    protocol = LoadingProtocol(args.compression_ratio, args.shear_ratio, args.compression_steps, args.shear_steps,
                               args.shear_direction)
    if args.max_newton_iterations < 1:
        raise InputError(f"--max-newton-iterations = {args.max_newton_iterations} must be >= 1")
    options = ContinuationOptions(newton=NewtonOptions(max_iterations=args.max_newton_iterations),
                                  branch_switching=not args.no_branch_switching,
                                  branch_sign=1 if args.branch == "+" else -1)
    dynamic_options = None
    if args.solver == "dynamic":
        from .solve.dynamics import DynamicOptions

        if not args.clamp_speed > 0:
            raise InputError(f"--clamp-speed = {args.clamp_speed} must be a positive speed in m/s")
        dynamic_options = DynamicOptions(clamp_speed=args.clamp_speed)
    if args.model == "ribbon":
        from .ribbon_runs import run_ribbon

        if args.solver != "static" or args.mesh is not None or args.frames:
            raise InputError("--model ribbon runs the static solver only, without --mesh or --frames")
        result = run_ribbon(strip, protocol, args.ribbon_init or "direct", args.zeta, args.resolution, out=args.out,
                            options=options, thresholds=not args.no_thresholds, progress=not args.quiet)
    elif args.zeta is not None or args.ribbon_init is not None:
        raise InputError(f"--zeta and --ribbon-init apply to --model ribbon only, not {args.model!r}")
    else:
        result = simulate(strip, protocol, args.model, args.resolution, out=args.out, options=options,
                          progress=not args.quiet, solver=args.solver, dynamic_options=dynamic_options,
                          mesh=args.mesh, frames=args.frames, thresholds=not args.no_thresholds,
                          branches=not args.no_branches)
    s = result.summary
    if not args.quiet:
        keys = ("model", "H_mid_over_L_compressed", "dW_max_over_L", "dW1_over_L", "dW2_over_L", "n_dof",
                "newton_iterations", "wall_time_s", "converged", "message")
        print(json.dumps({k: s[k] for k in keys}, indent=2))
        print(f"wrote {Path(args.out) / 'path.csv'} and {Path(args.out) / 'summary.json'}")
    if not result.converged:
        sys.stderr.write(f"error: run did not complete: {s['message']}; converged part kept in {args.out}\n")
        return EXIT_NOT_CONVERGED
    return 0


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        if args.command == "simulate":
            return cmd_simulate(args)
    except InputError as exc:
        sys.stderr.write(f"error: {exc}\n")
        return EXIT_BAD_INPUT
    return EXIT_BAD_INPUT
