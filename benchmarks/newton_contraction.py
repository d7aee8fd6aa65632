"""Newton's optional fail-fast on contraction (NewtonOptions.contraction_limit, issue 31 item 2):
what it saves and what it changes, model by model.

    .venv/bin/python -m benchmarks.newton_contraction [--limit 0.5] [--out benchmarks/results]
        [--timeout 900] [--quick]

For each case (model, W/L, resolution) it runs the full default path with thresholds,

    ddg.simulate(Strip.from_ratios(W/L, 1/2), LoadingProtocol(1/2), model=..., resolution=...,
                 options=ContinuationOptions(newton=NewtonOptions(contraction_limit=...)),
                 branches=False)

once with the test off (None) and once with it on (--limit; 0.5 is the default), each in a fresh
child process after `python -m ddg warmup` and an untimed short run of the same model (which loads
or compiles every kernel it uses: the warm-up does not cover every model's), and reports the
path's Newton iterations (with the failed solves' and the fold snaps'), the threshold location's,
the wall time (summary wall_time_s), the status, dW1/L, dW2/L, dW2_S_stable/L and the folds met.
Writes OUT/newton_contraction.json and .md atomically. Not part of the test run; no timing is asserted anywhere.
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

from benchmarks.common import load_average, loads_line, machine_info, source_fingerprint, write_report

#: (model, W/L, resolution): the rod and the 1D models at M ~ 100, both plates at ~2000 triangles
CASES = (("rod", 1 / 20, 100), ("rod", 1 / 20, 400), ("ribbon", 1 / 20, 101), ("ribbon-sano-wada", 1 / 20, 101),
         ("ribbon-trapeze", 1 / 20, 101), ("ribbon-wunderlich", 1 / 20, 101), ("ribbon-cross-section", 1 / 20, 101),
         ("ribbon-cross-section", 1 / 12, 101), ("plate", 1 / 20, 2000), ("plate", 1 / 6, 2000),
         ("plate-midedge", 1 / 20, 2000))
QUICK = CASES[:1] + CASES[4:5]

CHILD = """
import json, sys, warnings
warnings.simplefilter("ignore")
import ddg
model, w, n = sys.argv[1], float(sys.argv[2]), int(sys.argv[3])
limit = None if sys.argv[4] == "none" else float(sys.argv[4])
options = ddg.ContinuationOptions(newton=ddg.NewtonOptions(contraction_limit=limit))
strip = ddg.Strip.from_ratios(w, 0.5)
# untimed: loads (or compiles) every kernel the model uses, which `ddg warmup` may not cover
ddg.simulate(strip, ddg.LoadingProtocol(0.5, 0.05, compression_steps=4, shear_steps=2), model=model, resolution=n,
             branches=False)
r = ddg.simulate(strip, ddg.LoadingProtocol(0.5), model=model, resolution=n, options=options, branches=False)
s = r.summary
keys = ("status", "wall_time_s", "newton_iterations", "newton_iterations_by_phase", "threshold_newton_iterations",
        "dW1_over_L", "dW2_over_L", "dW2_S_stable_over_L", "folds_dW_over_L", "resolved_up_to_dW_over_L")
print(json.dumps({k: s.get(k) for k in keys}))
"""


def one_run(model: str, width: float, resolution: int, limit: float | None, timeout: float) -> dict:
    load = load_average()
    done = subprocess.run([sys.executable, "-c", CHILD, model, repr(width), str(resolution),
                           "none" if limit is None else repr(limit)], capture_output=True, text=True, timeout=timeout)
    if done.returncode != 0:
        tail = done.stderr.strip().splitlines()
        return {"error": tail[-1] if tail else f"exit {done.returncode}", "load_average": load}
    return {**json.loads(done.stdout.strip().splitlines()[-1]), "load_average": load}


def _its(run: dict, key: str) -> str:
    return str(run.get(key, "-")) if "error" not in run else "error"


def _value(x) -> str:
    return "-" if x is None else f"{x:.6f}"


def _difference(off: dict, on: dict, key: str) -> str:
    a, b = off.get(key), on.get(key)
    if a is None and b is None:
        return "-"
    if a is None or b is None:
        return "one missing"
    return f"{abs(a - b):.1e}"


def markdown(report: dict) -> str:
    limit = report["limit"]
    lines = ["# Newton's fail-fast on contraction (benchmarks/newton_contraction.py)", "",
             f"Full default path with thresholds, dL/L = 1/2, no branch tracing; each run in a fresh process after an "
             f"untimed short run of the same model. off = `NewtonOptions(contraction_limit=None)`, on = "
             f"`contraction_limit={limit}` (0.5 is the default). Path its = "
             f"`summary['newton_iterations']` (failed solves and fold snaps included); threshold its = "
             f"`threshold_newton_iterations`; wall = `wall_time_s` (one run each: a guide, not a benchmark of speed).",
             "", "| model | W/L | M or N | status off / on | path its off / on | failed-solve its off / on | "
             "fold-snap its off / on | threshold its off / on | wall s off / on | dW1 off | dW1 diff | dW2 off | "
             "dW2 diff | folds off / on |",
             "|---|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in report["rows"]:
        off, on = r["off"], r["on"]

        def pair(key, phase=None):
            def get(run):
                if "error" in run:
                    return "error"
                if phase is not None:
                    return str((run.get("newton_iterations_by_phase") or {}).get(phase, "-"))
                return _its(run, key)
            return f"{get(off)} / {get(on)}"

        def wall(run):
            return f"{run['wall_time_s']:.2f}" if run.get("wall_time_s") is not None else "-"

        folds = f"{len(off.get('folds_dW_over_L') or [])} / {len(on.get('folds_dW_over_L') or [])}"
        lines.append(f"| {r['model']} | {r['width_ratio']:.4g} | {r['resolution']} | {off.get('status', 'error')} / "
                     f"{on.get('status', 'error')} | {pair('newton_iterations')} | "
                     f"{pair(None, 'rejected steps')} | {pair(None, 'fold snaps')} | "
                     f"{pair('threshold_newton_iterations')} | {wall(off)} / {wall(on)} | "
                     f"{_value(off.get('dW1_over_L'))} | {_difference(off, on, 'dW1_over_L')} | "
                     f"{_value(off.get('dW2_over_L'))} | {_difference(off, on, 'dW2_over_L')} | {folds} |")
    saved = [(r["off"]["newton_iterations"], r["on"]["newton_iterations"]) for r in report["rows"]
             if "error" not in r["off"] and "error" not in r["on"]]
    complete_changed = [f"{r['model']} W/L = {r['width_ratio']:.4g}" for r in report["rows"]
                        if r["off"].get("status") != r["on"].get("status")]
    fewer = sum(1 for a, b in saved if b < a)
    lines += ["", f"Path iterations fewer with the test on in {fewer} of {len(saved)} cases; "
                  f"status changed in: {', '.join(complete_changed) if complete_changed else 'none'}."]
    loads = [r[k].get("load_average") for r in report["rows"] for k in ("off", "on")]
    lines += ["", loads_line(report, loads)]
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.newton_contraction",
                                     description=__doc__.split("\n")[0])
    parser.add_argument("--limit", type=float, default=0.5)
    parser.add_argument("--timeout", type=float, default=900.0)
    parser.add_argument("--out", default="benchmarks/results")
    parser.add_argument("--quick", action="store_true", help="two cheap cases only (a smoke run)")
    args = parser.parse_args(argv)
    if not 0.0 < args.limit <= 1.0 or args.timeout <= 0:
        print(f"error: --limit {args.limit} must be in (0, 1] and --timeout positive", file=sys.stderr)
        return 2
    subprocess.run([sys.executable, "-m", "ddg", "warmup"], capture_output=True, timeout=args.timeout, check=True)
    rows = []
    for model, width, resolution in (QUICK if args.quick else CASES):
        rows.append({"model": model, "width_ratio": width, "resolution": resolution,
                     "off": one_run(model, width, resolution, None, args.timeout),
                     "on": one_run(model, width, resolution, args.limit, args.timeout)})
        print(json.dumps(rows[-1]), flush=True)
    report = {"limit": args.limit, "rows": rows, "machine": machine_info(blas=True), "source": source_fingerprint()}
    print(write_report(Path(args.out), "newton_contraction", report, markdown(report)))
    print(markdown(report))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
