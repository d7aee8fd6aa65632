"""One Newton iteration of a plate, piece by piece, against another source tree.

    .venv/bin/python -m benchmarks.plate_iteration [--against DIR] [--rounds 3] [--rows 8 12 18 28]
        [--model plate-midedge|plate] [--out benchmarks/results]

--model plate times the paper's plate instead, `--rows` then giving its triangle counts (issue 50:
2100 triangles <= 3 ms); it writes plate_iteration_paper.json and .md.

Issue 50's per-iteration targets (mid-edge 12 rows <= 6 ms, 28 rows <= 50 ms) split into what an
iteration of ddg.solve.newton does on a positive definite Hessian: `model.evaluate` with gradient
and Hessian (the accumulators zeroed, the three kernels), `model.free_matrix` (the free block, a
copy of the band), `SymmetricBanded.cholesky` (LAPACK's dpbtrf on a copy) and one `solve`
(dpbtrs). The state is the flat strip's rest state with a seeded 1e-7 L perturbation: its Hessian
is positive definite and has the band's full pattern, and the work of every piece depends on the
mesh only, not on the values. Each piece is timed over `calls` repetitions of the whole iteration
(as many as fit in 2 s, 3 to 200, each iteration's arrays freed before the next, as in Newton),
median per piece; each round runs in a fresh child process per configuration, the configurations
alternating round by round; the figure is the minimum over the rounds of the medians.

Configurations: this tree; this tree with DDG_MALLOC=default (glibc's own thresholds: what
ddg.solve.allocation saves); with --against DIR, another checkout (its kernels compiled).
Writes OUT/plate_iteration.json and .md atomically. Not part of the test run; nothing asserts on it.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

from benchmarks.common import load_average, machine_info, markdown_table, source_fingerprint, write_report

REPO = Path(__file__).resolve().parents[1]
ROWS = (8, 12, 18, 28)
PIECES = ("evaluate", "free block", "Cholesky", "solve")
#: issue 50's targets per Newton iteration (ms), per model and mesh (rows; triangles for the paper's plate)
TARGET_MS = {"plate-midedge": {12: 6.0, 28: 50.0}, "plate": {2100: 3.0}}
MESH_WORD = {"plate-midedge": "rows", "plate": "triangles"}
REPORT_NAME = {"plate-midedge": "plate_iteration", "plate": "plate_iteration_paper"}

CHILD = r"""
import json, statistics, sys, time
import numpy as np
import ddg
from ddg.models.midedge_plate import MidedgePlateModel
from ddg.models.plate import PlateModel

out = []
for rows in json.loads(sys.argv[1]):
    strip = ddg.Strip.from_ratios(1 / 6, 0.5)
    model = PlateModel(strip, rows) if sys.argv[2] == "plate" else MidedgePlateModel(strip, rows=rows)
    rng = np.random.default_rng(rows)
    q = model.rest_state() + 1e-7 * strip.length * rng.standard_normal(model.n_dof)
    times = {k: [] for k in ("evaluate", "free block", "Cholesky", "solve")}
    start = time.perf_counter()
    calls = 0
    while calls < 200 and (calls < 3 or time.perf_counter() - start < 2.0):
        t0 = time.perf_counter()
        ev = model.evaluate(q)
        t1 = time.perf_counter()
        block = model.free_matrix(ev.hessian)
        t2 = time.perf_counter()
        assert block.cholesky()
        t3 = time.perf_counter()
        block.solve(ev.gradient[model.free])
        t4 = time.perf_counter()
        for k, dt in zip(times, (t1 - t0, t2 - t1, t3 - t2, t4 - t3)):
            times[k].append(1e3 * dt)
        del ev, block
        calls += 1
    out.append({"rows": rows, "n_free": model.free.stop - model.free.start, "bandwidth": model.bandwidth,
                "calls": calls, **{k: statistics.median(v) for k, v in times.items()}})
print(json.dumps(out))
"""


def one_round(tree: Path, rows, env: dict, model: str = "plate-midedge") -> list[dict]:
    done = subprocess.run([sys.executable, "-c", CHILD, json.dumps(list(rows)), model], cwd=tree, capture_output=True,
                          text=True, check=True, timeout=1800,
                          env={**os.environ, "PYTHONPATH": str(tree), "OPENBLAS_NUM_THREADS": "1", **env})
    return json.loads(done.stdout.splitlines()[-1])


def markdown(report: dict) -> str:
    configs = list(report["results"])
    model = report.get("model", "plate-midedge")
    title = {"plate-midedge": "Mid-edge plate", "plate": "The paper's plate"}[model]
    lines = [f"# {title}: one Newton iteration, piece by piece", "",
             "`python -m benchmarks.plate_iteration` (the module docstring gives the method); W/L = 1/6, dL/L = 1/2, "
             "L/b = 1181; ms, minimum over rounds of the median over calls; one BLAS thread.", ""]
    header = [MESH_WORD[model], "free DOF", "bandwidth", "tree"] + list(PIECES) + ["total"]
    rows = []
    for i, r in enumerate(report["results"][configs[0]]):
        for c in configs:
            x = report["results"][c][i]
            rows.append([str(r["rows"]), str(r["n_free"]), str(r["bandwidth"]), c]
                        + [f"{x[p]:.2f}" for p in PIECES] + [f"{sum(x[p] for p in PIECES):.2f}"])
    lines += markdown_table(header, rows).splitlines()
    lines += ["", "Targets (issue 50, per Newton iteration): "
              + "; ".join(f"{r} {MESH_WORD[model]} <= {t:g} ms" for r, t in TARGET_MS[model].items())
              + ". An iteration of the path does "
              "more than one evaluation with the Hessian (mid-edge: about 1.35, benchmarks/results/midedge_path.md) "
              "and, at the accepted states, the stability test's eigen-solves: the pieces above are its floor.", "",
              f"Configurations: {json.dumps(report['configurations'])}; rounds {report['rounds']}; load average "
              f"{report['load_before']} before, {report['load_after']} after; ddg sources sha256 "
              f"`{report['sources']}`; {report['machine'].get('cpu', '')}."]
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.plate_iteration", description=__doc__.split("\n")[0])
    parser.add_argument("--against", type=Path, default=None)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--rows", type=int, nargs="+", default=list(ROWS))
    parser.add_argument("--model", choices=sorted(MESH_WORD), default="plate-midedge")
    parser.add_argument("--out", type=Path, default=REPO / "benchmarks" / "results")
    args = parser.parse_args(argv)
    configs = {"this": (REPO, {}), "this, DDG_MALLOC=default": (REPO, {"DDG_MALLOC": "default"})}
    if args.against is not None:
        configs["other"] = (args.against.resolve(), {"DDG_MALLOC": "default"})
    load_before = load_average()
    best: dict = {}
    for _ in range(args.rounds):
        for name, (tree, env) in configs.items():
            new = one_round(tree, args.rows, env, args.model)
            if name not in best:
                best[name] = new
            else:
                for old, fresh in zip(best[name], new):
                    for p in PIECES:
                        old[p] = min(old[p], fresh[p])
            print(name, [(r["rows"], round(sum(r[p] for p in PIECES), 2)) for r in new], flush=True)
    report = {"model": args.model, "results": best, "rounds": args.rounds,
              "configurations": {k: [str(t), e] for k, (t, e) in configs.items()},
              "load_before": load_before, "load_after": load_average(), "sources": source_fingerprint(),
              "machine": machine_info(blas=True)}
    print(write_report(args.out, REPORT_NAME[args.model], report, markdown(report)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
