"""The compiled kernels' evaluation time, model by model, and against another source tree.

    .venv/bin/python -m benchmarks.kernel_evaluation [--against DIR] [--rounds 5] [--calls 200]
        [--out benchmarks/results]

For each model at its default resolution (ddg.api.DEFAULT_RESOLUTION; the rod also at M = 400)
it builds the model, takes its buckled guess at dL/L = 1/3 with a seeded random perturbation of
1e-3 L (a deformed state: no term vanishes), commits it and times `model.evaluate` with the
gradient and Hessian, with the gradient only, and the energy only: `calls` calls per round, the
round's median per call, and the minimum of the rounds' medians (the least disturbed by other
processes). Each round runs in a fresh child process whose working directory is the source tree
(the repository, or --against DIR: another checkout with its kernels compiled), the trees
alternating round by round so that a change of load falls on both. The kernels must be compiled
(`python -m ddg warmup` in each tree): a first untimed call loads them.

Writes OUT/kernel_evaluation.json and .md atomically (with --against: the ratio this / other per
row). Not part of the test run; nothing asserts on it.
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

from benchmarks.common import load_average, machine_info, markdown_table, source_fingerprint, write_report

REPO = Path(__file__).resolve().parents[1]

#: (model, resolution): every model at its default resolution, the rod also at M = 400.
CASES = (("rod", 100), ("rod", 400), ("ribbon", 101), ("ribbon-sano-wada", 101), ("ribbon-trapeze", 101),
         ("ribbon-cross-section", 101), ("ribbon-wunderlich", 101), ("plate", 2000), ("plate-midedge", 2000))
#: Issue 47's bound on a kernel's evaluation time against the tree before a change: within 5 %.
BOUND = 0.05
MODES = (("gradient and Hessian", True, True), ("gradient", True, False), ("energy", False, False))

CHILD = r"""
import json, statistics, sys, time
import numpy as np
import ddg
from ddg.api import make_model
cases, calls = json.loads(sys.argv[1]), int(sys.argv[2])
modes = ((True, True), (True, False), (False, False))
out = []
for name, resolution in cases:
    strip = ddg.Strip.from_ratios(1 / 20, 1 / 3)
    model = make_model(name, strip, resolution)
    compression = strip.length / 3
    q = model.apply_clamps(model.buckled_guess(compression), compression, 0.0)
    q = q + 1e-3 * strip.length * np.random.default_rng(1).standard_normal(q.shape)
    model.commit(q)
    row = []
    for gradient, hessian in modes:
        model.evaluate(q, gradient=gradient, hessian=hessian)   # loads the kernels
        times = []
        for _ in range(calls):
            start = time.perf_counter()
            model.evaluate(q, gradient=gradient, hessian=hessian)
            times.append(time.perf_counter() - start)
        row.append(statistics.median(times))
    out.append(row)
print(json.dumps(out))
"""


def one_round(tree: Path, calls: int, timeout: float) -> list[list[float]]:
    done = subprocess.run([sys.executable, "-c", CHILD, json.dumps(CASES), str(calls)], cwd=tree,
                          capture_output=True, text=True, timeout=timeout)
    if done.returncode:
        raise SystemExit(f"{tree}: {done.stderr.strip().splitlines()[-1:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--against", type=Path, default=None, help="another source tree, its kernels compiled")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--calls", type=int, default=200)
    parser.add_argument("--timeout", type=float, default=900.0)
    parser.add_argument("--out", default="benchmarks/results")
    args = parser.parse_args(argv)
    trees = {"this": REPO} | ({"other": args.against.resolve()} if args.against else {})
    best = {label: None for label in trees}
    load_before = load_average()
    for _ in range(args.rounds):
        for label, tree in trees.items():
            medians = one_round(tree, args.calls, args.timeout)
            best[label] = medians if best[label] is None else [[min(a, b) for a, b in zip(x, y)]
                                                              for x, y in zip(best[label], medians)]
    report = {"machine": machine_info(), "source": source_fingerprint(), "date": time.strftime("%Y-%m-%d %H:%M"),
              "load_before": load_before, "load_after": load_average(), "rounds": args.rounds, "calls": args.calls,
              "trees": {k: str(v) for k, v in trees.items()}, "cases": CASES, "modes": [m[0] for m in MODES],
              "seconds": best}
    header = ["model", "resolution"] + [f"{m[0]} us" for m in MODES]
    rows = []
    for i, (name, resolution) in enumerate(CASES):
        cells = [name, str(resolution)]
        for j in range(len(MODES)):
            cell = f"{1e6 * best['this'][i][j]:.1f}"
            if args.against:
                other = best["other"][i][j]
                cell += f" ({1e6 * other:.1f}, x{best['this'][i][j] / other:.3f})"
            cells.append(cell)
        rows.append(cells)
    summary = []
    if args.against:
        ratios = [(best["this"][i][j] / best["other"][i][j], f"{name} at {resolution}, {MODES[j][0]}")
                  for i, (name, resolution) in enumerate(CASES) for j in range(len(MODES))]
        worst = max(ratios)
        beyond = [label for ratio, label in ratios if ratio > 1.0 + BOUND]
        summary = [f"Largest ratio this / other: x{worst[0]:.3f} ({worst[1]}); "
                   + (f"beyond x{1 + BOUND:.2f}: {'; '.join(beyond)}." if beyond else
                      f"every evaluation within x{1 + BOUND:.2f} of the other tree's."), ""]
    caption = ("Minimum over rounds of the per-round median time of one `model.evaluate` call, microseconds"
               + ("; in brackets the other tree's time and the ratio this / other" if args.against else "") + ".")
    markdown = "\n".join(["# Kernel evaluation times", "", caption, "", markdown_table(header, rows), "",
                          f"Trees: {report['trees']}; {args.rounds} rounds of {args.calls} calls; load average "
                          f"{load_before} before, {report['load_after']} after; "
                          f"{report['machine'].get('cpu_model', '?')}.", ""] + summary)
    print(markdown)
    print(write_report(args.out, "kernel_evaluation", report, markdown))
    return 0


if __name__ == "__main__":
    sys.exit(main())
