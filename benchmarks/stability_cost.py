"""What stability costs: the full path with thresholds located and every branch traced.

    .venv/bin/python -m benchmarks.stability_cost [--cases rod:100 plate:2000] [--width-ratio ...]
        [--out benchmarks/results]

For each case (model:resolution) it runs, in a fresh process,

    ddg.simulate(ddg.Strip.from_ratios(W/L, 0.5), ddg.LoadingProtocol(0.5, compression_steps=40,
                 shear_steps=120), model=..., resolution=..., thresholds=True, branches=True)

and splits the wall time into the recorded path, the threshold location (dW1, dW2, dW2_S_stable,
summary key threshold_wall_time_s) and the branch tracing (branches_wall_time_s), with the time
spent in eigenvalue computations (SymmetricBanded.lowest_eigenpairs, wrapped with a timer in the
child process only) within each. Writes OUT/stability_cost.json and OUT/stability_cost.md
(atomically). Not part of the test run.
"""
from __future__ import annotations

import argparse
import json
import multiprocessing as mp
import os
import time
from pathlib import Path

from ddg.output.io import atomic_write_text

DEFAULT_CASES = ("rod:100", "plate:2000")


def _run(model: str, resolution: int, width_ratio: float, branches=None) -> dict:
    import ddg
    from ddg.solve import banded

    eigen = {"calls": 0, "time_s": 0.0, "marks": []}
    original = banded.SymmetricBanded.lowest_eigenpairs

    def timed(self, *args, **kwargs):
        t0 = time.perf_counter()
        try:
            return original(self, *args, **kwargs)
        finally:
            eigen["calls"] += 1
            eigen["time_s"] += time.perf_counter() - t0

    banded.SymmetricBanded.lowest_eigenpairs = timed
    # mark the eigenvalue time at the start of the threshold and branch phases
    import ddg.api as api

    for name in ("fill_thresholds", "trace_all_branches"):
        inner = getattr(api, name)

        def marked(*args, _inner=inner, _name=name, **kwargs):
            eigen["marks"].append((_name, eigen["time_s"], eigen["calls"]))
            return _inner(*args, **kwargs)

        setattr(api, name, marked)
    strip = ddg.Strip.from_ratios(width_ratio, 0.5)
    protocol = ddg.LoadingProtocol(0.5, compression_steps=40, shear_steps=120)
    t0, c0 = time.perf_counter(), time.process_time()
    result = ddg.simulate(strip, protocol, model=model, resolution=resolution, branches=branches)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    s = result.summary
    marks = dict((n, (t, c)) for n, t, c in eigen["marks"])
    eig_path = marks.get("fill_thresholds", (eigen["time_s"], eigen["calls"]))
    eig_thr_end = marks.get("trace_all_branches", (eigen["time_s"], eigen["calls"]))
    threshold_s = s.get("threshold_wall_time_s") or 0.0
    branches_s = s.get("branches_wall_time_s") or 0.0
    return {
        "model": model, "resolution": resolution, "width_ratio": width_ratio,
        "n_free_dof": s["n_free_dof"], "converged": s["converged"], "message": s["message"],
        "wall_time_s": wall, "cpu_time_s": cpu,
        "path_time_s": wall - threshold_s - branches_s, "threshold_time_s": threshold_s, "branches_time_s": branches_s,
        "eigen_time_s": eigen["time_s"], "eigen_calls": eigen["calls"],
        "eigen_time_path_s": eig_path[0], "eigen_time_thresholds_s": eig_thr_end[0] - eig_path[0],
        "eigen_time_branches_s": eigen["time_s"] - eig_thr_end[0],
        "newton_iterations_path_and_thresholds": s["newton_iterations"],
        "newton_iterations_branches": s.get("branches_newton_iterations"),
        "dW1_over_L": s["dW1_over_L"], "dW2_over_L": s["dW2_over_L"], "dW2_S_stable_over_L": s["dW2_S_stable_over_L"],
        "folds_dW_over_L": s.get("folds_dW_over_L"),
        "branch_points": {k: v["points"] for k, v in (s.get("branches") or {}).items()},
        "load_average": os.getloadavg()[0],
    }


def _child(queue, *args):
    queue.put(_run(*args))


def run_case(model: str, resolution: int, width_ratio: float, branches=None) -> dict:
    ctx = mp.get_context("spawn")
    queue = ctx.Queue()
    proc = ctx.Process(target=_child, args=(queue, model, resolution, width_ratio, branches))
    proc.start()
    record = queue.get()
    proc.join()
    return record


def markdown(records: list[dict]) -> str:
    lines = ["# Cost of stability: path, thresholds, branches, eigenvalues", "",
             "`python -m benchmarks.stability_cost`: dL/L = 1/2, 40 + 120 recorded steps to dW_max; "
             "thresholds (dW1 to 1e-4 L, dW2 and dW2_S_stable to 1e-3 L) located after the path; every branch "
             "(U, US+, US-, S) traced by pseudo-arclength. eig = time in SymmetricBanded.lowest_eigenpairs "
             "(shift-invert Lanczos, its own factorisations included).", "",
             "| model | W/L | resolution | free DOF | total s | path s | thresholds s | branches s | eig s (share) "
             "| eig in path | eig in thresholds | eig in branches | Newton its (path+thr / branches) | dW1/L | dW2/L | load |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in records:
        share = r["eigen_time_s"] / r["wall_time_s"]
        lines.append(
            f"| {r['model']} | {r['width_ratio']:.4g} | {r['resolution']} | {r['n_free_dof']} | {r['wall_time_s']:.1f} "
            f"| {r['path_time_s']:.1f} | {r['threshold_time_s']:.1f} | {r['branches_time_s']:.1f} "
            f"| {r['eigen_time_s']:.2f} ({100 * share:.0f} %) | {r['eigen_time_path_s']:.2f} "
            f"| {r['eigen_time_thresholds_s']:.2f} | {r['eigen_time_branches_s']:.2f} "
            f"| {r['newton_iterations_path_and_thresholds']} / {r['newton_iterations_branches']} "
            f"| {r['dW1_over_L'] if r['dW1_over_L'] is None else round(r['dW1_over_L'], 4)} "
            f"| {r['dW2_over_L'] if r['dW2_over_L'] is None else round(r['dW2_over_L'], 4)} | {r['load_average']:.2f} |")
    lines += ["", "load = 1-minute load average at the end of the run (above 2 on this 2-core machine, other "
              "processes shared the cores and the times are inflated).", ""]
    for r in records:
        folds = ", ".join(f"{f:.4f}" for f in (r.get("folds_dW_over_L") or []))
        lines.append(f"- {r['model']} {r['resolution']}: {r['message']}; branch points {r['branch_points'] or 'not traced'}; "
                     f"snaps of the path (folds) at dW/L = [{folds}]" + (f". {r['note']}" if r.get("note") else ""))
    return "\n".join(lines) + "\n"


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", nargs="+", default=list(DEFAULT_CASES), help="model:resolution, e.g. rod:100")
    parser.add_argument("--width-ratio", type=float, nargs="+", default=[0.05, 1 / 6],
                        help="W/L for the rod (first) and the plate (last)")
    parser.add_argument("--branches", choices=("default", "on", "off"), default="default",
                        help="trace the branches (library default: rod yes, plate no)")
    parser.add_argument("--append", action="store_true", help="add to the existing results instead of replacing them")
    parser.add_argument("--out", default="benchmarks/results")
    args = parser.parse_args(argv)
    branches = {"default": None, "on": True, "off": False}[args.branches]
    out = Path(args.out)
    records = json.loads((out / "stability_cost.json").read_text()) if args.append and (out / "stability_cost.json").exists() else []
    for case in args.cases:
        model, resolution = case.split(":")
        width = args.width_ratio[0] if model == "rod" else args.width_ratio[-1]
        record = run_case(model, int(resolution), width, branches)
        print(json.dumps(record), flush=True)
        records.append(record)
    atomic_write_text(out / "stability_cost.json", json.dumps(records, indent=2) + "\n")
    atomic_write_text(out / "stability_cost.md", markdown(records))


if __name__ == "__main__":
    main()
