"""The paper's plate beside a busy process: does a run on a shared machine collapse? (issue 31
item 3: at most 1.3x its idle wall time beside one busy single-threaded process on 2 cores).

    .venv/bin/python -m benchmarks.plate_under_load [--triangles 2000] [--width-ratio 1/6]
        [--repeat 1] [--out benchmarks/results] [--timeout 900]

For each BLAS setting, DDG_BLAS_THREADS=1 (the library's default, ddg.solve.blas_threads) and
DDG_BLAS_THREADS=keep (OpenBLAS's own default: as many threads as cores), it runs the full default
path of ddg.simulate(Strip.from_ratios(W/L, 1/2), LoadingProtocol(1/2), model="plate",
resolution=N, branches=False) in a fresh child process, first on the idle machine, then beside a
busy neighbour (a child process spinning `while True: pass`, started before and stopped after),
the best of --repeat of each (after `python -m ddg warmup`, so no run compiles kernels), and
reports the run's wall time (summary wall_time_s), Newton iterations, the slowdown busy / idle
and the one-minute load average before each run. Writes OUT/plate_under_load.json and .md
atomically. Not part of the test run.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from fractions import Fraction
from pathlib import Path

from benchmarks.common import load_average, loads_line, machine_info, source_fingerprint, write_report

SETTINGS = ("1", "keep")
CHILD = """
import json, sys, warnings
warnings.simplefilter("ignore")
import ddg
w, n = float(sys.argv[1]), int(sys.argv[2])
r = ddg.simulate(ddg.Strip.from_ratios(w, 0.5), ddg.LoadingProtocol(0.5), model="plate", resolution=n,
                 branches=False)
s = r.summary
print(json.dumps({"wall_time_s": s["wall_time_s"], "newton_iterations": s["newton_iterations"],
                  "status": s["status"], "n_free_dof": s["n_free_dof"], "blas_threads": s.get("blas_threads"),
                  "dW1_over_L": s["dW1_over_L"], "dW2_over_L": s["dW2_over_L"]}))
"""


def one_run(setting: str, width: float, triangles: int, busy: bool, timeout: float) -> dict:
    env = {**os.environ, "DDG_BLAS_THREADS": setting}
    for key in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS"):   # the library's setting, not the shell's
        env.pop(key, None)
    neighbour = subprocess.Popen([sys.executable, "-c", "while True: pass"]) if busy else None
    try:
        if neighbour is not None:
            time.sleep(1.0)
        load = load_average()
        start = time.perf_counter()
        done = subprocess.run([sys.executable, "-c", CHILD, repr(width), str(triangles)], env=env,
                              capture_output=True, text=True, timeout=timeout)
        process = time.perf_counter() - start
    finally:
        if neighbour is not None:
            neighbour.kill()
            neighbour.wait()
    if done.returncode != 0:
        return {"error": done.stderr.strip().splitlines()[-1] if done.stderr.strip() else f"exit {done.returncode}",
                "load_average": load}
    out = json.loads(done.stdout.strip().splitlines()[-1])
    return {**out, "process_s": process, "load_average": load}


def measure(width: float, triangles: int, repeat: int, timeout: float) -> list[dict]:
    # compile (or load) the kernels once, so no measured run pays numba's compilation
    subprocess.run([sys.executable, "-m", "ddg", "warmup"], capture_output=True, timeout=timeout, check=True)
    rows = []
    for setting in SETTINGS:
        best = {}
        for busy in (False, True):
            for _ in range(repeat):
                run = one_run(setting, width, triangles, busy, timeout)
                key = "busy" if busy else "idle"
                if key not in best or run.get("wall_time_s", float("inf")) < best[key].get("wall_time_s", float("inf")):
                    best[key] = run
        idle, busy = best["idle"].get("wall_time_s"), best["busy"].get("wall_time_s")
        rows.append({"blas_threads": setting, "idle": best["idle"], "busy": best["busy"],
                     "slowdown": busy / idle if idle and busy else None})
    return rows


def markdown(report: dict) -> str:
    lines = ["# The paper's plate beside a busy process (benchmarks/plate_under_load.py)", "",
             f"W/L = {report['width_ratio']:.4g}, dL/L = 1/2, --resolution {report['triangles']} "
             f"({report['rows'][0]['idle'].get('n_free_dof')} free DOFs), full default path without branches; "
             f"best of {report['repeat']}; the busy neighbour is one process spinning `while True: pass`.", "",
             "| DDG_BLAS_THREADS | idle s | idle its | busy s | busy its | busy / idle | target |",
             "|---|---:|---:|---:|---:|---:|---|"]
    for r in report["rows"]:
        idle, busy = r["idle"], r["busy"]
        target = "<= 1.3" if r["blas_threads"] == "1" else "(before: OpenBLAS's own threads)"
        slow = f"{r['slowdown']:.2f}" if r["slowdown"] is not None else "-"
        lines.append(f"| {r['blas_threads']} | {idle.get('wall_time_s', float('nan')):.1f} | "
                     f"{idle.get('newton_iterations', '-')} | {busy.get('wall_time_s', float('nan')):.1f} | "
                     f"{busy.get('newton_iterations', '-')} | {slow} | {target} |")
    loads = [r[k].get("load_average") for r in report["rows"] for k in ("idle", "busy")]
    lines += ["", loads_line(report, loads)]
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.plate_under_load", description=__doc__.split("\n")[0])
    parser.add_argument("--triangles", type=int, default=2000)
    parser.add_argument("--width-ratio", type=Fraction, default=Fraction(1, 6))
    parser.add_argument("--repeat", type=int, default=1)
    parser.add_argument("--timeout", type=float, default=900.0)
    parser.add_argument("--out", default="benchmarks/results")
    args = parser.parse_args(argv)
    if args.repeat < 1 or args.triangles < 100 or not 0 < args.width_ratio <= 1:
        print("error: --repeat >= 1, --triangles >= 100 and 0 < --width-ratio <= 1", file=sys.stderr)
        return 2
    width = float(args.width_ratio)
    rows = measure(width, args.triangles, args.repeat, args.timeout)
    report = {"width_ratio": width, "triangles": args.triangles, "repeat": args.repeat, "rows": rows,
              "machine": machine_info(blas=True), "source": source_fingerprint()}
    print(write_report(Path(args.out), "plate_under_load", report, markdown(report)))
    print(markdown(report))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
