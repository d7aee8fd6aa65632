"""python -m fem_reference simulate | convergence | gold: the FEM reference from the shell.

Exit codes as `python -m ddg`: 0 complete, 2 bad input (one-line message), 3 the path stopped
converging (the converged part is written, the message says where).
"""
from __future__ import annotations

import argparse
import json
import sys


def _add_scene(p: argparse.ArgumentParser) -> None:
    p.add_argument("--width-ratio", type=float, required=True, help="W/L")
    p.add_argument("--compression-ratio", type=float, required=True, help="dL/L")
    p.add_argument("--shear-ratio", type=float, default=None, help="largest dW/L (default dW_max/L, Eq. B.1)")
    p.add_argument("--slenderness", type=float, default=None, help="L/b (default b = 0.127 mm)")
    p.add_argument("--poisson-ratio", type=float, default=0.0)
    p.add_argument("--compression-steps", type=int, default=40)
    p.add_argument("--shear-steps", type=int, default=120)
    p.add_argument("--shear-sign", type=int, default=1, choices=(1, -1))


def _scene(args):
    from ddg.geometry.strip import LoadingProtocol, Strip

    strip = Strip.from_ratios(args.width_ratio, args.compression_ratio, args.slenderness,
                              poisson_ratio=args.poisson_ratio)
    protocol = LoadingProtocol(args.compression_ratio, args.shear_ratio, args.compression_steps,
                               args.shear_steps, args.shear_sign)
    protocol.resolved_shear_ratio(strip)
    return strip, protocol


def cmd_simulate(args) -> int:
    from .continuation import ContinuationOptions

    strip, protocol = _scene(args)
    if args.perturbation <= 0:
        from ddg.geometry.strip import InputError

        raise InputError(f"perturbation = {args.perturbation!r} must be > 0")
    from .api import simulate

    options = ContinuationOptions(perturbation=args.perturbation, branch_switching=not args.no_branch_switching,
                                  thresholds=not args.no_thresholds)
    result = simulate(strip, protocol, args.resolution, out=args.out, options=options, across=args.across,
                      fields=not args.no_fields, progress=not args.quiet, material=args.material)
    s = result.summary
    if not args.quiet:
        keys = ("H_mid_over_L_compressed", "dW_max_over_L", "dW1_over_L", "dW2_over_L", "n_dof",
                "newton_iterations", "wall_time_s", "converged", "message")
        print(json.dumps({k: s[k] for k in keys}, indent=1))
    if not result.converged:
        print(f"error: {s['message']}", file=sys.stderr)
        return 3
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
    parser = argparse.ArgumentParser(prog="python -m fem_reference", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("simulate", help="one run: path.csv, summary.json, centerline.csv, fields.xdmf")
    _add_scene(p)
    p.add_argument("--resolution", type=int, default=60, help="elements along L (default 60)")
    p.add_argument("--across", type=int, default=None, help="elements across W (default: near-isotropic)")
    p.add_argument("--perturbation", type=float, default=1e-3, help="branch-switch start amplitude / L")
    p.add_argument("--no-branch-switching", action="store_true")
    p.add_argument("--material", choices=("isotropic", "dep"), default="isotropic",
                   help="isotropic (the strip's Poisson ratio, default) or dep: the DDG plate's continuum limit "
                        "(nu = 1/3 membrane, nu_b = -1/3 bending, D = E b^3/12)")
    p.add_argument("--no-thresholds", action="store_true")
    p.add_argument("--no-fields", action="store_true", help="skip fields.xdmf")
    p.add_argument("--out", default=None)
    p.add_argument("--quiet", action="store_true")
    p.set_defaults(func=cmd_simulate)
    p = sub.add_parser("convergence", help="3-4 meshes, Richardson extrapolation, CSV + markdown table")
    _add_scene(p)
    p.add_argument("--resolutions", type=int, nargs="+", default=[60, 90, 120])
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
    p.add_argument("--resolution", type=int, default=None, help="elements along L (default: per scene)")
    p.add_argument("--quiet", action="store_true")
    p.set_defaults(func=cmd_gold)
    return parser


def main(argv=None) -> int:
    from ddg.geometry.strip import InputError

    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return args.func(args)
    except InputError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
