"""What stability costs: the full path with thresholds located and every branch traced.

    .venv/bin/python -m benchmarks.stability_cost [--cases rod:100 plate:2000] [--width-ratio ...]
        [--branches default|on|off] [--no-profile] [--append] [--out benchmarks/results]

For each case (model:resolution) it runs, in a fresh process,

    ddg.simulate(ddg.Strip.from_ratios(W/L, 0.5), ddg.LoadingProtocol(0.5, compression_steps=40,
                 shear_steps=120), model=..., resolution=..., thresholds=True, branches=...)

with a ddg.solve.probe.Probe, and splits its wall time into the recorded path, the threshold
location (dW1, dW2, dW2_S_stable; summary key threshold_wall_time_s) and the branch tracing
(branches_wall_time_s); the path's recorded steps are timed by the probe. A second call of the same
run under cProfile gives the time spent in eigenvalue computations (the outermost calls of
stability.lowest_modes and SymmetricBanded.lowest_eigenpairs) within each of them: the calls made
inside ddg.protocol.after.ThresholdStep.run, inside BranchStep.run, and the rest (the path), each
as a share of the profiled call's wall time, scaled to the un-profiled one. Nothing in the library
is patched. Writes OUT/stability_cost.json and OUT/stability_cost.md (atomically). Not part of the
test run.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

from benchmarks.common import PathProbe, function_key, profiled, ratio, run_in_child
from ddg.output.io import atomic_write_text

DEFAULT_CASES = ("rod:100", "plate:2000")
COMPRESSION_STEPS = 40
SHEAR_STEPS = 120
PHASES = ("path", "thresholds", "branches")


def _eigen_split(graph, eigen_functions) -> dict:
    """Outermost time (s under cProfile) and calls of eigen_functions per phase of the run."""
    from ddg.protocol.after import BranchStep, ThresholdStep

    phases = {function_key(ThresholdStep.run): "thresholds", function_key(BranchStep.run): "branches"}
    attr = graph.attribute([phases, {function_key(f): "eigen" for f in eigen_functions}])
    out = {}
    for phase in PHASES:
        where = None if phase == "path" else phase  # the path: every call outside the steps after it
        out[phase] = {
            "time_s": attr.outermost("eigen", level=1, where={0: where}),
            "calls": round(sum(n for f in eigen_functions for ctx, n in attr.calls(f).items()
                               if ctx == (where, None))),
        }
    return out


def measure(model: str, resolution: int, width_ratio: float, branches=None, profile: bool = True,
            compression_steps: int = COMPRESSION_STEPS, shear_steps: int = SHEAR_STEPS) -> dict:
    """The record of one case, in this process."""
    import ddg
    from ddg.solve.banded import SymmetricBanded
    from ddg.solve.stability import lowest_modes

    strip = ddg.Strip.from_ratios(width_ratio, 0.5)
    protocol = ddg.LoadingProtocol(0.5, compression_steps=compression_steps, shear_steps=shear_steps)
    probe = PathProbe()
    t0, c0 = time.perf_counter(), time.process_time()
    result = ddg.simulate(strip, protocol, model=model, resolution=resolution, branches=branches, probe=probe)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    s = result.summary
    threshold_s = s.get("threshold_wall_time_s") or 0.0
    branches_s = s.get("branches_wall_time_s") or 0.0
    record = {
        "model": model, "resolution": resolution, "width_ratio": width_ratio,
        "n_free_dof": s["n_free_dof"], "converged": s["converged"], "message": s["message"],
        "wall_time_s": wall, "cpu_time_s": cpu,
        "path_time_s": wall - threshold_s - branches_s, "threshold_time_s": threshold_s, "branches_time_s": branches_s,
        "path_steps_time_s": sum(st["time_s"] for st in probe.steps),
        "recorded_steps": len(probe.steps),
        "newton_iterations_path": s["newton_iterations"],
        "newton_iterations_by_phase": s.get("newton_iterations_by_phase"),
        "newton_iterations_thresholds": s.get("threshold_newton_iterations"),
        "newton_iterations_path_and_thresholds": s["newton_iterations"] + (s.get("threshold_newton_iterations") or 0),
        "newton_iterations_branches": s.get("branches_newton_iterations"),
        "probe_matches_summary": probe.matches(s),
        "dW1_over_L": s["dW1_over_L"], "dW2_over_L": s["dW2_over_L"], "dW2_S_stable_over_L": s["dW2_S_stable_over_L"],
        "folds_dW_over_L": s.get("folds_dW_over_L"),
        "branch_points": {k: v["points"] for k, v in (s.get("branches") or {}).items()},
        "eigen_functions": "stability.lowest_modes, SymmetricBanded.lowest_eigenpairs (outermost calls)",
    }
    if profile:
        again, graph, profiled_wall = profiled(ddg.simulate, strip, protocol, model=model, resolution=resolution,
                                               branches=branches)
        scale = wall / profiled_wall
        eig = _eigen_split(graph, (lowest_modes, SymmetricBanded.lowest_eigenpairs))
        only = _eigen_split(graph, (SymmetricBanded.lowest_eigenpairs,))
        record.update({
            "profiled_wall_time_s": profiled_wall,
            "profiled_run_newton_iterations": again.summary["newton_iterations"],
            "eigen_profiled": eig,
            "eigen_time_s": scale * sum(v["time_s"] for v in eig.values()),
            "eigen_calls": sum(v["calls"] for v in eig.values()),
            **{f"eigen_time_{phase}_s": scale * eig[phase]["time_s"] for phase in PHASES},
            "lowest_eigenpairs_only_time_s": {phase: scale * only[phase]["time_s"] for phase in PHASES},
        })
    record["load_average"] = os.getloadavg()[0]
    return record


def run_case(model: str, resolution: int, width_ratio: float, branches=None, profile: bool = True) -> dict:
    """measure(...) in a fresh (spawned) process; raises with the child's traceback if it failed."""
    status, payload, elapsed = run_in_child(measure, (model, resolution, width_ratio, branches, profile), None)
    if status != "ok":
        raise RuntimeError(f"{model}:{resolution} {status} after {elapsed:.0f} s:\n{payload}")
    return payload


def _s(r: dict, key: str, spec: str = ".2f") -> str:
    v = r.get(key)
    return "n/a" if v is None else format(v, spec)


def markdown(records: list[dict]) -> str:
    lines = ["# Cost of stability: path, thresholds, branches, eigenvalues", "",
             "`python -m benchmarks.stability_cost`: dL/L = 1/2, 40 + 120 recorded steps to dW_max; "
             "thresholds (dW1 to 1e-4 L, dW2 and dW2_S_stable to 1e-3 L) located after the path; every branch "
             "(U, US+, US-, S) traced by pseudo-arclength where asked. total s = one simulate call in a fresh process "
             "(it includes loading the compiled kernels from numba's cache), with a `ddg.solve.probe.Probe`; "
             "thresholds s and branches s = summary.json's `threshold_wall_time_s` and `branches_wall_time_s`; "
             "path s = the rest (the probe's recorded steps and model set-up; the JSON has the steps alone, "
             "`path_steps_time_s`). eig = time in the outermost calls of `stability.lowest_modes` and "
             "`SymmetricBanded.lowest_eigenpairs` (shift-invert Lanczos or the compiled Lanczos on the Cholesky "
             "factor, their own factorisations included), **measured under cProfile** in a second, separate call of "
             "the same run and **scaled to the un-profiled wall time**; eig in thresholds / branches = the calls made "
             "inside `ThresholdStep.run` / `BranchStep.run` (the latter also computes the eigenvalues of the rows of "
             "branches.csv, after `branches_wall_time_s` is taken), eig in path = all others. Until issue 15 eig "
             "counted `lowest_eigenpairs` only, marked by patching the library (rows measured that way say so "
             "below); the JSON has that definition too (`lowest_eigenpairs_only_time_s`). Newton its = "
             "`newton_iterations` + `threshold_newton_iterations` / `branches_newton_iterations` of summary.json.",
             "",
             "| model | W/L | resolution | free DOF | total s | path s | thresholds s | branches s | eig s (share) "
             "| eig in path | eig in thresholds | eig in branches | Newton its (path+thr / branches) | dW1/L | dW2/L "
             "| load |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in records:
        eig = r.get("eigen_time_s")
        share = f"{eig:.2f} ({100 * eig / r['wall_time_s']:.0f} %)" if eig is not None else "n/a"
        lines.append(
            f"| {r['model']} | {r['width_ratio']:.4g} | {r['resolution']} | {r['n_free_dof']} | {r['wall_time_s']:.1f} "
            f"| {r['path_time_s']:.1f} | {r['threshold_time_s']:.1f} | {r['branches_time_s']:.1f} "
            f"| {share} | {_s(r, 'eigen_time_path_s')} | {_s(r, 'eigen_time_thresholds_s')} "
            f"| {_s(r, 'eigen_time_branches_s')} "
            f"| {r['newton_iterations_path_and_thresholds']} / {r['newton_iterations_branches']} "
            f"| {r['dW1_over_L'] if r['dW1_over_L'] is None else round(r['dW1_over_L'], 4)} "
            f"| {r['dW2_over_L'] if r['dW2_over_L'] is None else round(r['dW2_over_L'], 4)} "
            f"| {r['load_average']:.2f} |")
    lines += ["", "load = 1-minute load average at the end of the run (above 2 on this 2-core machine, other "
              "processes shared the cores and the times are inflated).", ""]
    for r in records:
        folds = ", ".join(f"{f:.4f}" for f in (r.get("folds_dW_over_L") or []))
        how = ("" if "eigen_functions" in r else
               " Measured before issue 15 (eig = lowest_eigenpairs only, timed by patching the library).")
        lines.append(f"- {r['model']} {r['resolution']}: {r['message']}; branch points "
                     f"{r['branch_points'] or 'not traced'}; snaps of the path (folds) at dW/L = [{folds}]"
                     + (f". {r['note']}" if r.get("note") else "") + how)
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.stability_cost", description=__doc__.splitlines()[0])
    parser.add_argument("--cases", nargs="+", default=list(DEFAULT_CASES), help="model:resolution, e.g. rod:100")
    parser.add_argument("--width-ratio", type=ratio, nargs="+", default=[0.05, 1 / 6],
                        help="W/L for the rod (first) and the plate (last); decimals or fractions")
    parser.add_argument("--branches", choices=("default", "on", "off"), default="default",
                        help="trace the branches (library default: rod yes, plate no)")
    parser.add_argument("--no-profile", action="store_true",
                        help="skip the profiled call (halves the time; the eig columns are then n/a)")
    parser.add_argument("--append", action="store_true", help="add to the existing results instead of replacing them")
    parser.add_argument("--out", default="benchmarks/results")
    args = parser.parse_args(argv)
    branches = {"default": None, "on": True, "off": False}[args.branches]
    out = Path(args.out)
    existing = out / "stability_cost.json"
    records = json.loads(existing.read_text()) if args.append and existing.exists() else []
    for case in args.cases:
        model, resolution = case.split(":")
        width = args.width_ratio[0] if model == "rod" else args.width_ratio[-1]
        record = run_case(model, int(resolution), width, branches, not args.no_profile)
        print(json.dumps(record), flush=True)
        records.append(record)
    atomic_write_text(out / "stability_cost.json", json.dumps(records, indent=2) + "\n")
    atomic_write_text(out / "stability_cost.md", markdown(records))
    print(f"wrote {out / 'stability_cost.json'} and {out / 'stability_cost.md'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
