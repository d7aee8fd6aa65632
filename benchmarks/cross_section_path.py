"""Wall time of the 1D model with its cross-section against the rod's (issue 30's speed target: at
most 2x the rod's at the same M on the same scene).

    .venv/bin/python -m benchmarks.cross_section_path [--nodes 101 201] [--repeat 2] [--out benchmarks/results]

On the four narrow scenes of issue 30 (dL/L = 1/2 and 1/4, W/L = 1/20 and 1/12, the paper's strip),
for each node count M: ddg.simulate(strip, LoadingProtocol(dL/L), model, resolution=M,
branches=False) for model = rod and ribbon-cross-section, alternately in this process, best of
--repeat (after one warm-up call of each model, so compilation is not timed), with the CPU time,
Newton iterations and status of the best run. Writes OUT/cross_section_path.json and .md
atomically. Not part of the test run; tests/validation/test_cross_section_targets.py reads the JSON.
"""
from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path

SCENES = ((0.5, 1 / 20), (0.5, 1 / 12), (0.25, 1 / 20), (0.25, 1 / 12))
MODELS = ("rod", "ribbon-cross-section")
FILE = "cross_section_path.json"


def one_run(model: str, compression: float, width: float, nodes: int) -> dict:
    import ddg

    strip = ddg.Strip.from_ratios(width, compression)
    wall, cpu = time.perf_counter(), time.process_time()
    result = ddg.simulate(strip, ddg.LoadingProtocol(compression), model=model, resolution=nodes, branches=False)
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    s = result.summary
    return {"wall_time_s": wall, "cpu_time_s": cpu, "newton_iterations": s.get("newton_iterations"),
            "status": s.get("status"), "dW1_over_L": s.get("dW1_over_L"), "dW2_over_L": s.get("dW2_over_L")}


def measure(nodes_list, repeat: int) -> list[dict]:
    import warnings

    warnings.simplefilter("ignore")
    for model in MODELS:   # compile once
        one_run(model, 0.5, 1 / 20, 21)
    rows = []
    for compression, width in SCENES:
        for nodes in nodes_list:
            best = {}
            for _ in range(repeat):
                for model in MODELS:
                    run = one_run(model, compression, width, nodes)
                    if model not in best or run["wall_time_s"] < best[model]["wall_time_s"]:
                        best[model] = run
            rows.append({"compression_ratio": compression, "width_ratio": width, "nodes": nodes,
                         **{f"{m}_{k}": v for m in MODELS for k, v in best[m].items()},
                         "wall_time_ratio": best["ribbon-cross-section"]["wall_time_s"] / best["rod"]["wall_time_s"]})
    return rows


def markdown(report: dict) -> str:
    lines = ["# ribbon-cross-section against the rod: wall time at the same M "
             "(benchmarks/cross_section_path.py)", "",
             "| dL/L | W/L | M | rod s | rod its | cross-section s | cross-section its | cross-section status "
             "| ratio |",
             "|---:|---:|---:|---:|---:|---:|---:|---|---:|"]
    for r in report["rows"]:
        lines.append(f"| {r['compression_ratio']:g} | {r['width_ratio']:.4g} | {r['nodes']} | "
                     f"{r['rod_wall_time_s']:.2f} | {r['rod_newton_iterations']} | "
                     f"{r['ribbon-cross-section_wall_time_s']:.2f} | {r['ribbon-cross-section_newton_iterations']} | "
                     f"{r['ribbon-cross-section_status']} | {r['wall_time_ratio']:.1f} |")
    lines += ["", f"Best of {report['repeat']} per model, the two models alternating; load average (1 min) before / "
              f"after: {report['load_average'][0]:.2f} / {report['load_average'][1]:.2f}; {report['date']}."]
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    from ddg.output.io import atomic_write_text

    parser = argparse.ArgumentParser(prog="python -m benchmarks.cross_section_path",
                                     description=__doc__.split("\n")[0])
    parser.add_argument("--nodes", type=int, nargs="+", default=[101, 201])
    parser.add_argument("--repeat", type=int, default=2)
    parser.add_argument("--out", default="benchmarks/results")
    args = parser.parse_args(argv)
    bad = [m for m in args.nodes if not 11 <= m <= 2001]
    if bad or not 1 <= args.repeat <= 10:
        parser.exit(2, f"--nodes {bad[0] if bad else ''} outside [11, 2001] or --repeat {args.repeat} "
                       "outside [1, 10]\n")
    load_before = os.getloadavg()[0]
    rows = measure(args.nodes, args.repeat)
    report = {"rows": rows, "repeat": args.repeat, "load_average": [load_before, os.getloadavg()[0]],
              "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())}
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    atomic_write_text(out / FILE, json.dumps(report, indent=2) + "\n")
    atomic_write_text(out / "cross_section_path.md", markdown(report))
    print(markdown(report), end="")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
