"""Command line: `python -m ddg simulate ...`, a thin layer over ddg.simulate; `python -m ddg
curvatures ...` and `python -m ddg centerline-error ...` (ddg.analysis.curvatures, ddg.analysis.centerline_approx).

Exit codes: 0 path complete; 2 bad arguments (one-line message, before any work); 3 the run
stopped converging (the converged part of the path is written, the message says where); 130 or
143 interrupted by SIGINT or SIGTERM (every converged step written); 1 an internal error (one
line; DDG_TRACEBACK=1 shows the traceback).
"""
from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

from .cli_parser import EXIT_BAD_INPUT, OneLineParser
from .limits import InputError
from .geometry.strip import LoadingProtocol, Strip
from .models import registry

EXIT_NOT_CONVERGED = 3
EXIT_INTERNAL = 1


#: --model choices of simulate: every model of the registry (ddg.models.registry).
MODEL_CHOICES = registry.NAMES


def build_parser() -> argparse.ArgumentParser:
    # parse errors are one line and exit 2 (ddg.cli_parser), as every command line of the project
    parser = OneLineParser(prog="python -m ddg", description="DDG solvers for pre-buckled strips under shear.")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=OneLineParser)
    sim = sub.add_parser("simulate", help="compress by dL, then shear by dW; write path.csv and summary.json")
    sim.add_argument("--model", default="rod", choices=MODEL_CHOICES + ("auto",),
                     help="rod (DAR, default), plate (DEP on a triangle mesh), plate-midedge (mid-edge "
                          "Kirchhoff plate with the material's Poisson ratio), ribbon (Sadowsky, Eq. A.5), "
                          "ribbon-sano-wada (Eq. A.5 with zeta^2 = (1 - nu) W^4 / (60 b^2)), ribbon-trapeze "
                          "(the rod plus the edges' stretching under twist), ribbon-cross-section (the rod plus its "
                          "cross-section as a field of two modes, which bends to relieve that stretching; after "
                          "Audoly and Neukirch 2021) or ribbon-wunderlich (Eq. A.2)")
    sim.add_argument("--zeta", type=float, default=None,
                     help="ribbon: regularisation length zeta of Eq. (A.5) in metres (default 1e4 L); "
                          "ribbon-wunderlich: the same for its ruling slope (default the Sano-Wada value)")
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
                     help="also write OUT/frames/frame_NNNNN.vtu per recorded step and OUT/frames/frames.pvd "
                          "(ParaView)")
    sim.add_argument("--no-centerline", action="store_true",
                     help="do not write OUT/centerline.csv (the deformed centerline per recorded step); "
                          "path.csv and summary.json as always")
    sim.add_argument("--compression-steps", type=int, default=40, help="recorded compression steps (default 40)")
    sim.add_argument("--shear-steps", type=int, default=120, help="recorded shear steps (default 120)")
    sim.add_argument("--shear-direction", type=int, choices=(1, -1), default=1, help="+1 or -1 (default +1)")
    sim.add_argument("--branch", choices=("+", "-"), default="+",
                     help="at the pitchfork follow US+ and then S+ (default) or US- and S-")
    sim.add_argument("--no-thresholds", action="store_true",
                     help="skip locating dW1 and dW2 from stability after the path (summary keys stay null)")
    branch_group = sim.add_mutually_exclusive_group()
    branch_group.add_argument("--branches", dest="branches", action="store_true", default=None,
                              help="trace every branch (U, US+, US-, S) by pseudo-arclength after the path into "
                                   "OUT/branches.csv (default for the rod; the plate's costs more "
                                   "than its path)")
    branch_group.add_argument("--no-branches", dest="branches", action="store_false", help="do not trace the branches")
    sim.add_argument("--no-branch-switching", action="store_true",
                     help="stay on the branch the path starts on, even where it is unstable")
    sim.add_argument("--solver", choices=("static", "dynamic"), default="static",
                     help="static Newton continuation (default) or the paper's implicit-Euler time marching (rod)")
    sim.add_argument("--clamp-speed", type=float, default=None,
                     help="dynamic solver: clamp speed in m/s (default 1e-3)")
    sim.add_argument("--max-newton-iterations", type=int, default=15, help="per load step (default 15)")
    sim.add_argument("--out", default="out", help="output directory (default ./out)")
    sim.add_argument("--quiet", action="store_true", help="no progress bar or result print-out")
    _add_auto_arguments(sim, "--model auto: ")

    cur = sub.add_parser("curvatures", help="centerline curvatures k1, k2, tau along s (Figs. A.12-A.14): CSV and PNG")
    cur.add_argument("--model", default="rod", choices=("rod", "plate", "ribbon"),
                     help="rod (default), plate or ribbon")
    cur.add_argument("--width-ratio", type=float, default=0.05, help="W/L (default 0.05)")
    cur.add_argument("--compression-ratio", type=float, default=0.5, help="dL/L (default 0.5)")
    cur.add_argument("--shear-ratios", default="0,0.3,0.45", help="comma-separated dW/L to report (default 0,0.3,0.45)")
    cur.add_argument("--slenderness", type=float, default=None, help="L/b (default: b = 0.127 mm)")
    cur.add_argument("--resolution", type=int, default=None,
                     help="rod/ribbon: node count (default 100 / 101); plate: target triangles (default 2000)")
    cur.add_argument("--zeta", type=float, default=None, help="ribbon: zeta of Eq. (A.5) in metres (default 1e4 L)")
    cur.add_argument("--ribbon-init", choices=("direct", "rod"), default="direct",
                     help="ribbon: direct (default) or rod")
    cur.add_argument("--stations", type=int, default=None, help="plate: centerline stations (default ~ columns / 2)")
    cur.add_argument("--out", default="out", help="output directory: curvatures.csv, curvatures.png (default ./out)")

    adv = sub.add_parser("advise", help="the model and resolution the error map predicts within a tolerance on a "
                                        "scene, with the predicted errors and cost, without running (ddg.advise)")
    adv.add_argument("--width-ratio", type=float, required=True, help="W/L")
    adv.add_argument("--compression-ratio", type=float, required=True, help="dL/L")
    adv.add_argument("--slenderness", type=float, default=None, help="L/b (default: b = 0.127 mm)")
    adv.add_argument("--poisson-ratio", type=float, default=0.0,
                     help="nu (default 0, the error map's; another value is refused: the map is at nu = 0)")
    _add_auto_arguments(adv, "")
    warm = sub.add_parser("warmup", help="compile and cache the numba kernels once (scripts/setup.sh runs it), "
                                         "so the first run pays no JIT cost")
    warm.add_argument("parts", nargs="*", metavar="PART",
                      help="models (rod, plate, plate-midedge, the ribbons) or 'arrays'; default all")
    warm.add_argument("--jobs", type=int, default=None,
                      help="worker processes (default: the machine's cores, at most 4)")
    err = sub.add_parser("centerline-error",
                         help="plate centerline approximation error (Eqs. 12-13) against L/W (Fig. 10): CSV and PNG")
    err.add_argument("--width-ratios", default="0.5,0.3333333333333333,0.16666666666666666,0.08333333333333333,0.05",
                     help="comma-separated W/L (default 1/2, 1/3, 1/6, 1/12, 1/20)")
    err.add_argument("--shear-ratios", default="0.1,0.3,0.5", help="comma-separated dW/L (default 0.1,0.3,0.5)")
    err.add_argument("--compression-ratio", type=float, default=0.5, help="dL/L (default 0.5)")
    err.add_argument("--slenderness", type=float, default=None, help="L/b (default: b = 0.127 mm)")
    err.add_argument("--resolution", type=int, default=800, help="target triangle count (default 800)")
    err.add_argument("--out", default="out", help="output directory: centerline_error.csv, .png (default ./out)")
    from .output import render_command
    from .sweep import command as sweep_command

    sweep_command.add_arguments(sub.add_parser(
        "sweep",
        help="a grid of runs (W/L, dL/L, L/b, resolution, model) as Dask tasks: one table and a phase diagram"))
    render_command.add_arguments(sub.add_parser("render", help="draw a run's frames (PNG, HTML scene) with pyvista"))
    return parser


#: Most values a comma-separated list option takes (each is a run or a recorded state).
MAX_LIST_VALUES = 50


def _ratios(name: str, text: str, low: float, high: float, low_inclusive: bool = False) -> list[float]:
    from .limits import check_ratios

    values = [v for v in str(text).split(",") if v.strip()] or [text]
    if len(values) > MAX_LIST_VALUES:
        raise InputError(f"{name} has {len(values)} values; allowed 1 to {MAX_LIST_VALUES}")
    return check_ratios(name, values, low, high, low_inclusive)


#: Most centerline stations a plate profile may ask for (a profile finer than the mesh columns
#: only interpolates; 10000 is far beyond any mesh the machine can run).
MAX_STATIONS = 10000


def _within_shear_limit(name: str, shears: list[float], strip: Strip, compression_ratio: float) -> None:
    limit = strip.shear_limit(compression_ratio * strip.length) / strip.length
    for shear in shears:
        if shear > limit * (1.0 + 1e-12):
            raise InputError(f"{name} dW/L = {shear:g} beyond the shear limit dW_max/L = {limit:.6g} (Eq. B.1) for "
                             f"W/L = {strip.width_ratio:.4g}, dL/L = {compression_ratio:g}; allowed [0, {limit:.6g}]")


def _check_zeta(zeta) -> None:
    if zeta is not None:
        from .energies.sadowsky import check_zeta

        check_zeta(zeta)


def _output_directory(out) -> Path:
    from .output.io import check_output_directory

    return check_output_directory(out, "--out")


#: The files a run folder may hold, in the order the final line lists them (docs/reference/output_contract.rst).
RUN_FILES = ("path.csv", "summary.json", "centerline.csv", "branches.csv", "rod_path.csv", "frames/")


def written_files(out: Path) -> list[str]:
    """The run's files that exist in `out` (frames/ as a folder with its frame count), as paths."""
    found = []
    for name in RUN_FILES:
        path = out / name.rstrip("/")
        if name.endswith("/") and path.is_dir():
            found.append(f"{path}/ ({len(list(path.glob('*.vtu')))} frames, frames.pvd)")
        elif path.is_file():
            found.append(str(path))
    return found


def _require_extra(module: str, extra: str) -> None:
    import importlib.util

    if importlib.util.find_spec(module) is None:
        raise InputError(f"this command needs {module}: pip install 'ddg-strips[{extra}]' (or Debian's "
                         f"python3-{module})")


def cmd_curvatures(args) -> int:
    """Curvature profiles at the requested shears: OUT/curvatures.csv and OUT/curvatures.png."""
    from .analysis.curvatures import centerline_curvatures, inflection_jumps
    from .studies.curvature_studies import states_at_shears, write_curvatures_csv
    from .output.io import save_figure

    from .api import check_resolution
    from .limits import check_integer

    strip = Strip.from_ratios(args.width_ratio, args.compression_ratio, args.slenderness)
    shears = _ratios("--shear-ratios dW/L", args.shear_ratios, 0.0, 1.0, low_inclusive=True)
    _within_shear_limit("--shear-ratios", shears, strip, args.compression_ratio)
    if args.model != "ribbon" and args.zeta is not None:
        raise InputError(f"--zeta applies to --model ribbon only, not {args.model!r}")
    if args.stations is not None and args.model != "plate":
        raise InputError(f"--stations applies to --model plate only, not {args.model!r}")
    if args.stations is not None:
        check_integer("--stations", args.stations, 3, MAX_STATIONS)
    _check_zeta(args.zeta)
    check_resolution(args.model, args.resolution, strip)
    out = _output_directory(args.out)
    _require_extra("matplotlib", "plot")
    records = []
    states = states_at_shears(args.model, strip, args.compression_ratio, shears, args.resolution,
                              ribbon_init=args.ribbon_init, zeta=args.zeta)
    for step, (model, state) in enumerate(states):
        profile = centerline_curvatures(model, state.q, args.stations) if args.model == "plate" \
            else centerline_curvatures(model, state.q)
        records.append({"model": args.model, "step": step, "dL_over_L": state.compression / strip.length,
                        "dW_over_L": state.shear / strip.length, "profile": profile,
                        "inflections": inflection_jumps(profile)})
    write_curvatures_csv(out / "curvatures.csv", records)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(len(records), 1, figsize=(6.4, 2.4 * len(records)), sharex=True, squeeze=False)
    for ax, rec in zip(axes[:, 0], records):
        p = rec["profile"]
        ax.plot(p["s_over_L"], p["k2_L"], "s", ms=3, color="green", label=r"$\kappa^{(2)}L$")
        ax.plot(p["s_over_L"], p["tau_L"], "o", ms=3, color="red", label=r"$\tau L$")
        ax.plot(p["s_over_L"], p["k1_L"], "^", ms=3, color="black", label=r"$\kappa^{(1)}L$")
        ax.axhline(0.0, color="0.7", lw=0.5)
        ax.set_title(f"{args.model}, W/L = {strip.width_ratio:.4g}, dW/L = {rec['dW_over_L']:.3g}", fontsize=9)
    axes[0, 0].legend(fontsize=8)
    axes[-1, 0].set_xlabel("s / L")
    fig.tight_layout()
    save_figure(fig, out / "curvatures.png", dpi=120)
    plt.close(fig)
    for rec in records:
        jumps = ", ".join(f"s/L={j['s_over_L']:.3f}: k2 jump x{j['k2_jump_ratio']:.3g}, tau "
                          f"L={j['tau_at_inflection_L']:.3g}"
                          for j in rec["inflections"])
        print(f"dW/L = {rec['dW_over_L']:.4g}: inflections {jumps or 'none'}")
    print(f"wrote {out / 'curvatures.csv'} and {out / 'curvatures.png'}")
    return 0


def centerline_error_figure(rows: list[dict], shears):
    """Fig. 10 of `ddg centerline-error`: mean (solid) and largest (dotted) delta of Eq. (13) in %
    of L against L/W, one colour per dW/L, on log axes (a linear one hides L/W = 20 and the
    narrow strips' errors); the y axis stays linear if an error is zero. The report draws its Fig. 10
    with it too (validation.figures.centerline_error)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5.4, 3.8))
    positive = True
    for k, shear in enumerate(shears):   # Fig. 10: mean (solid) and largest (dotted) delta, log axes
        mine = sorted((r for r in rows if abs(r["dW_over_L"] - shear) < 1e-9 and isinstance(r["mean_error"], float)
                       and math.isfinite(r["mean_error"])), key=lambda r: r["L_over_W"])   # unreached: NaN/empty
        lw = [r["L_over_W"] for r in mine]
        ax.plot(lw, [100 * r["mean_error"] for r in mine], "o-", color=f"C{k}", label=f"dW/L = {shear:g}, mean")
        ax.plot(lw, [100 * r["max_error"] for r in mine], "s:", color=f"C{k}", ms=3, label=f"dW/L = {shear:g}, max")
        positive &= all(r["mean_error"] > 0 for r in mine)
    ax.set_xscale("log")
    ticks = sorted({r["L_over_W"] for r in rows})
    ax.set_xticks(ticks, [f"{t:.3g}" for t in ticks])
    ax.xaxis.set_minor_formatter(plt.NullFormatter())
    if positive:
        ax.set_yscale("log")
    ax.set_xlabel("L / W (log)")
    ax.set_ylabel(r"$\delta$ (% of L), Eq. (13)")
    ax.legend(fontsize=7)
    fig.tight_layout()
    return fig


def cmd_centerline_error(args) -> int:
    """Fig. 10: OUT/centerline_error.csv (mean and max of Eq. 13 per W/L and dW/L) and a PNG."""
    import csv
    import io as _io

    from .studies.centerline_error import centerline_error_study
    from .output.io import atomic_write_text, save_figure

    from .api import check_resolution

    widths = _ratios("--width-ratios W/L", args.width_ratios, 0.0, 1.0)
    shears = _ratios("--shear-ratios dW/L", args.shear_ratios, 0.0, 1.0)
    for width in widths:
        strip = Strip.from_ratios(width, args.compression_ratio, args.slenderness)
        _within_shear_limit("--shear-ratios", shears, strip, args.compression_ratio)
        check_resolution("plate", args.resolution, strip)
    out = _output_directory(args.out)
    _require_extra("matplotlib", "plot")
    from .protocol.progress import ProgressBar

    bar = ProgressBar(len(widths) * len(shears), True, what="centerline-error study", unit="states")
    rows = centerline_error_study(widths, shears, args.compression_ratio, args.resolution, args.slenderness,
                                  progress=bar.update)
    bar.close()
    columns = ("L_over_W", "W_over_L", "dW_over_L", "mean_error", "max_error", "rod_edge_mean_error",
               "ribbon_edge_mean_error", "phase", "triangles", "message")
    buf = _io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=columns, lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    atomic_write_text(out / "centerline_error.csv", buf.getvalue())
    fig = centerline_error_figure(rows, shears)
    save_figure(fig, out / "centerline_error.png", dpi=120)
    import matplotlib.pyplot as plt

    plt.close(fig)
    for r in rows:
        print(f"L/W = {r['L_over_W']:.3g}  dW/L = {r['dW_over_L']:.3g}  mean {r['mean_error']:.3e}  max "
              f"{r['max_error']:.3e}"
              f"  {r['phase']} {r['message']}")
    print(f"wrote {out / 'centerline_error.csv'} and {out / 'centerline_error.png'}")
    failed = [r for r in rows if r["message"]]
    if failed:
        sys.stderr.write(f"error: {len(failed)} of {len(rows)} rows did not converge (their errors are empty): "
                         f"{failed[0]['message']}\n")
        return EXIT_NOT_CONVERGED
    return 0


def cmd_simulate(args) -> int:
    from .api import simulate
    from .solve.continuation import ContinuationOptions
    from .solve.newton import NewtonOptions

    from .api import check_resolution
    from .limits import check_integer

    strip = Strip.from_ratios(args.width_ratio, args.compression_ratio, args.slenderness,
                              young_modulus=args.young_modulus, poisson_ratio=args.poisson_ratio)
    protocol = LoadingProtocol(args.compression_ratio, args.shear_ratio, args.compression_steps, args.shear_steps,
                               args.shear_direction)
    protocol.resolved_shear_ratio(strip)
    check_integer("--max-newton-iterations", args.max_newton_iterations, 1, 1000)
    if args.model == "auto" or any(v is not None for v in (args.tolerance, args.quantities, args.error_map)):
        return cmd_simulate_auto(args, strip, protocol)
    check_resolution(args.model, args.resolution, strip, args.mesh)
    _check_zeta(args.zeta)
    if args.mesh is not None and args.model != "plate":
        raise InputError(f"--mesh applies to --model plate only, not {args.model!r}")
    if args.solver == "dynamic" and args.model != "rod":
        raise InputError(f"--solver dynamic is available for --model rod only, not {args.model!r}")
    if args.solver != "dynamic" and args.clamp_speed is not None:
        raise InputError("--clamp-speed applies to --solver dynamic only")
    _output_directory(args.out)
    options = ContinuationOptions(newton=NewtonOptions(max_iterations=args.max_newton_iterations),
                                  branch_switching=not args.no_branch_switching,
                                  branch_sign=1 if args.branch == "+" else -1)
    dynamic_options = None
    if args.solver == "dynamic":
        from .solve.dynamics import DynamicOptions

        dynamic_options = DynamicOptions(clamp_speed=1e-3 if args.clamp_speed is None else args.clamp_speed)
        dynamic_options.check_scene(strip, protocol)
    if args.model == "ribbon":
        from .api import run_ribbon

        if args.solver != "static" or args.mesh is not None or args.frames:
            raise InputError("--model ribbon runs the static solver only, without --mesh or --frames")
        result = run_ribbon(strip, protocol, args.ribbon_init or "direct", args.zeta, args.resolution, out=args.out,
                            options=options, thresholds=not args.no_thresholds, progress=not args.quiet,
                            centerline=not args.no_centerline)
    elif args.ribbon_init is not None or (args.zeta is not None and args.model != "ribbon-wunderlich"):
        raise InputError(f"--zeta applies to --model ribbon and ribbon-wunderlich, --ribbon-init to --model "
                         f"ribbon only, not {args.model!r}")
    else:
        result = simulate(strip, protocol, args.model, args.resolution, out=args.out, options=options,
                          progress=not args.quiet, solver=args.solver, dynamic_options=dynamic_options,
                          mesh=args.mesh, frames=args.frames, thresholds=not args.no_thresholds,
                          branches=args.branches, zeta=args.zeta, centerline=not args.no_centerline)
    return _finish_simulate(args, result)


#: summary.json keys `simulate` prints (and, with --model auto, the `auto` block).
PRINTED_KEYS = ("model", "H_mid_over_L_compressed", "dW_max_over_L", "dW1_over_L", "dW2_over_L", "n_dof",
                "newton_iterations", "wall_time_s", "converged", "message")


def _finish_simulate(args, result, auto: bool = False) -> int:
    """Print the run's summary (unless --quiet), its warnings and, if it did not complete, the
    error line; the exit code (0 or EXIT_NOT_CONVERGED)."""
    s = result.summary
    if not args.quiet:
        keys = PRINTED_KEYS + (("auto",) if auto else ())
        print(json.dumps({k: s.get(k) for k in keys}, indent=2))
        print(f"wrote {', '.join(written_files(Path(args.out)))}")
    if auto:
        block = s.get("auto") or {}
        sys.stderr.write(f"auto: {block.get('chosen_model')} {block.get('resolution_label')}, {block.get('verdict')}: "
                         f"{block.get('reason')}\n")
    for warning in s.get("warnings") or ():
        sys.stderr.write(f"warning: {warning}\n")
    if not result.converged:
        sys.stderr.write(f"error: run did not complete: {s['message']}; converged part kept in {args.out}\n")
        return EXIT_NOT_CONVERGED
    return 0


def _add_auto_arguments(parser, prefix: str) -> None:
    parser.add_argument("--tolerance", default=None,
                        help=f"{prefix}largest acceptable error of each quantity in units of L, in (0, 1] "
                             "(error + the reference's error bar, from the error map)")
    parser.add_argument("--quantities", default=None,
                        help=f"{prefix}comma-separated quantities the tolerance applies to: dW1, dW2, H_mid "
                             "(default all three)")
    parser.add_argument("--error-map", default=None,
                        help=f"{prefix}the error map CSV (default $DDG_ERROR_MAP or data/error_map/error_map.csv)")


def cmd_advise(args) -> int:
    """`python -m ddg advise`: ddg.advise.choose on the scene, printed; nothing is run."""
    from .advise import check_quantities, check_tolerance, choose, format_choice, map_file
    from .api import DEFAULT_RESOLUTION

    if args.tolerance is None:
        raise InputError("--tolerance is required: the largest acceptable error in units of L, in (0, 1]")
    tolerance = check_tolerance(args.tolerance)
    quantities = check_quantities(args.quantities)
    map_file(args.error_map)
    choice = choose(args.width_ratio, args.compression_ratio, args.slenderness, tolerance, quantities,
                    path=args.error_map, runnable=set(DEFAULT_RESOLUTION), poisson_ratio=args.poisson_ratio)
    print(format_choice(choice))
    return 0


def cmd_simulate_auto(args, strip: Strip, protocol: LoadingProtocol) -> int:
    """`simulate --model auto --tolerance T`: the choice of ddg.advise run by ddg.simulate; every
    option is checked before any work (exit 2)."""
    from .advise import check_mapped_poisson_ratio, check_quantities, check_tolerance, map_file
    from .api import simulate
    from .solve.continuation import ContinuationOptions
    from .solve.newton import NewtonOptions

    if args.model != "auto":
        given = next(f"{flag} {v!r}" for flag, v in (("--tolerance", args.tolerance), ("--quantities", args.quantities),
                                                    ("--error-map", args.error_map)) if v is not None)
        raise InputError(f"{given} applies to --model auto only, not --model {args.model}")
    if args.tolerance is None:
        raise InputError("--model auto needs --tolerance, the largest acceptable error in units of L, in (0, 1]")
    tolerance = check_tolerance(args.tolerance)
    quantities = check_quantities(args.quantities)
    map_file(args.error_map)
    check_mapped_poisson_ratio(strip.poisson_ratio)
    for flag, value in (("--resolution", args.resolution), ("--mesh", args.mesh), ("--zeta", args.zeta),
                        ("--ribbon-init", args.ribbon_init), ("--clamp-speed", args.clamp_speed)):
        if value is not None:
            raise InputError(f"{flag} {value!r} does not apply to --model auto (the model and resolution are chosen)")
    if args.frames or args.solver != "static":
        raise InputError("--model auto runs the static solver without --frames")
    _output_directory(args.out)
    options = ContinuationOptions(newton=NewtonOptions(max_iterations=args.max_newton_iterations),
                                  branch_switching=not args.no_branch_switching,
                                  branch_sign=1 if args.branch == "+" else -1)
    result = simulate(strip, protocol, "auto", out=args.out, options=options, progress=not args.quiet,
                      thresholds=not args.no_thresholds, branches=args.branches, tolerance=tolerance,
                      quantities=quantities, error_map=args.error_map, centerline=not args.no_centerline)
    return _finish_simulate(args, result, auto=True)


def main(argv=None) -> int:
    """The command line; returns the exit code (0 complete, 2 bad input, 3 not converged,
    130/143 interrupted by SIGINT/SIGTERM with every converged step written, 1 internal error).
    The commands print summary.json's warnings themselves ("warning: ..."), so the API's
    ValidityWarnings are silenced here, to say each once."""
    import warnings

    from .protocol.validity import ValidityWarning

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ValidityWarning)
        return _main(argv)


def _main(argv=None) -> int:
    import os
    import signal as _signal

    from .output.interrupts import exit_code_of, interrupt_behind, signal_name_of, terminate_as_interrupt
    from .solve.continuation import ContinuationFailure

    previous = {sig: _signal.getsignal(sig) for sig in (_signal.SIGINT, _signal.SIGTERM)}
    terminate_as_interrupt()
    try:
        parser = build_parser()
        args = parser.parse_args(argv)
        from .solve.blas_threads import requested_threads

        requested_threads()   # a bad DDG_BLAS_THREADS is refused before any command does work
        if args.command == "simulate":
            return cmd_simulate(args)
        if args.command == "curvatures":
            return cmd_curvatures(args)
        if args.command == "advise":
            return cmd_advise(args)
        if args.command == "centerline-error":
            return cmd_centerline_error(args)
        if args.command == "sweep":
            from .sweep.command import main as sweep

            return sweep(args)
        if args.command == "render":
            from .output.render_command import main as render

            return render(args)
        if args.command == "warmup":
            from .warmup import PARTS, main as warmup

            for part in args.parts:
                if part not in PARTS:
                    raise InputError(f"warm-up part {part!r} is not one of {', '.join(PARTS)}")
            if args.jobs is not None and not 1 <= args.jobs <= 64:
                raise InputError(f"--jobs = {args.jobs} is outside 1..64")
            return warmup(args.parts or None, args.jobs)
        return EXIT_BAD_INPUT
    except InputError as exc:
        sys.stderr.write(f"error: {_one_line(exc)}\n")
        return EXIT_BAD_INPUT
    except ContinuationFailure as exc:
        sys.stderr.write(f"error: run did not complete: {_one_line(exc)}\n")
        return EXIT_NOT_CONVERGED
    except KeyboardInterrupt as exc:
        result = getattr(exc, "result", None)
        kept = f": {result.summary['message']}" if result is not None else ""
        sys.stderr.write(f"error: interrupted by {signal_name_of(exc)}{kept}\n")
        return exit_code_of(exc)
    except MemoryError:
        sys.stderr.write("error: out of memory; lower --resolution\n")
        return EXIT_INTERNAL
    except Exception as exc:  # noqa: BLE001  (one line, never a traceback; DDG_TRACEBACK=1 shows it)
        interrupt = interrupt_behind(exc)
        if interrupt is not None:  # a signal that arrived inside compiled code
            sys.stderr.write(f"error: interrupted by {signal_name_of(interrupt)}\n")
            return exit_code_of(interrupt)
        if os.environ.get("DDG_TRACEBACK"):
            raise
        sys.stderr.write(f"error: internal error: {type(exc).__name__}: {_one_line(exc)} "
                         "(set DDG_TRACEBACK=1 for the traceback)\n")
        return EXIT_INTERNAL
    finally:
        import threading

        if threading.current_thread() is threading.main_thread():
            for sig, handler in previous.items():
                if handler is not None:
                    _signal.signal(sig, handler)


def _one_line(exc: BaseException) -> str:
    return " ".join(str(exc).split())
