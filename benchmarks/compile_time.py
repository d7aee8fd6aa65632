"""What a new user pays before the first run: the numba kernels compiled from an empty cache.

    .venv/bin/python -m benchmarks.compile_time [--out benchmarks/results] [--timeout 1800]
        [--groups all models solvers arrays rod plate plate-midedge ...]

For each group it copies the ddg package's sources (no __pycache__) into a fresh scratch folder
and runs, in a child process with that folder first on sys.path, the group's part of
`python -m ddg warmup` (ddg.warmup: `all` is the whole warm-up; a model name warms that model
alone, what a user of one model waits for on first use). numba's compile events
(numba.core.event "numba:compile") give each kernel's seconds per signature: inclusive (with the
kernels it compiles on the way) and exclusive (its own type inference, lowering and LLVM work,
which includes optimising and emitting the code of the kernels linked into it). Reports the
group's wall time, the child's peak resident memory, the kernels by exclusive time, and the
kernels compiled for more than one signature (each signature is a full compile).

Writes OUT/compile_time.json and .md atomically. Not part of the test run; nothing asserts on it.
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from benchmarks.common import load_average, machine_info, markdown_table, source_fingerprint, write_report

REPO = Path(__file__).resolve().parents[1]

CHILD = r"""
import json, resource, sys, time
from numba.core import event

stack, kernels = [], {}

class Listener(event.Listener):
    def on_start(self, ev):
        stack.append([ev.data["dispatcher"], ev.data["args"], time.perf_counter(), 0.0])

    def on_end(self, ev):
        dispatcher, args, start, children = stack.pop()
        seconds = time.perf_counter() - start
        function = getattr(dispatcher, "py_func", None)
        name = f"{getattr(function, '__module__', '?')}.{getattr(function, '__qualname__', '?')}"
        row = kernels.setdefault(name, {"exclusive_s": 0.0, "inclusive_s": 0.0, "signatures": []})
        row["exclusive_s"] += seconds - children
        row["inclusive_s"] += seconds
        row["signatures"].append(str(args)[:400])
        if stack:
            stack[-1][3] += seconds

event.register("numba:compile", Listener())
start = time.perf_counter()
from ddg.warmup import compile_kernels
timings = compile_kernels(sys.argv[1:] or None)
wall = time.perf_counter() - start
peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
print(json.dumps({"wall_s": wall, "groups": timings, "peak_rss_mb": peak_mb, "kernels": kernels}))
"""


PARALLEL = r"""
import json, resource, subprocess, sys, time
start = time.perf_counter()
done = subprocess.run([sys.executable, "-m", "ddg", "warmup"], capture_output=True, text=True)
wall = time.perf_counter() - start
if done.returncode:
    raise SystemExit(done.stderr)
peak_mb = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
print(json.dumps({"wall_s": wall, "peak_rss_mb": peak_mb, "output": done.stdout.strip()}))
"""


def compile_group(parts: list[str], timeout: float) -> dict:
    """The warm-up `parts` (ddg.warmup.compile_kernels' names) from an empty cache in a scratch copy."""
    with tempfile.TemporaryDirectory(prefix="ddg-compile-") as scratch:
        shutil.copytree(REPO / "ddg", Path(scratch) / "ddg", ignore=shutil.ignore_patterns("__pycache__"))
        env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_")}
        env["PYTHONPATH"] = scratch
        load = load_average()
        code = PARALLEL if parts == ["parallel"] else CHILD
        done = subprocess.run([sys.executable, "-c", code, *parts], cwd=scratch, env=env, capture_output=True,
                              text=True, timeout=timeout)
        if done.returncode != 0:
            return {"parts": parts, "error": done.stderr.strip().splitlines()[-1:], "load_before": load}
        result = json.loads(done.stdout.strip().splitlines()[-1])
        result.update(parts=parts, load_before=load, load_after=load_average())
        return result


def markdown(report: dict) -> str:
    lines = ["# Compiling the kernels from an empty cache", "",
             "Each group in a fresh scratch copy of ddg/ (`python -m benchmarks.compile_time`): the warm-up's "
             "parts (ddg.warmup), the child's wall time and peak resident memory. exclusive s = a kernel's own "
             "compile (type inference, lowering, LLVM optimisation and code emission of its module, which "
             "includes the kernels linked into it); inclusive s = with the kernels it compiled on the way.", ""]
    rows = []
    for r in report["groups"]:
        kernels = r.get("kernels", {})
        rows.append((r["label"], f"{r['wall_s']:.1f}" if "wall_s" in r else "error",
                     f"{r['peak_rss_mb']:.0f}" if "peak_rss_mb" in r else "", str(len(kernels)),
                     str(sum(len(k["signatures"]) for k in kernels.values()))))
    lines += [markdown_table(("group", "wall s", "peak MB", "kernels", "compiles"), rows), ""]
    whole = next((r for r in report["groups"] if r["label"] == "all" and "kernels" in r), None)
    if whole:
        top = sorted(whole["kernels"].items(), key=lambda kv: -kv[1]["exclusive_s"])[:25]
        lines += ["## The whole warm-up, kernels by exclusive time", "",
                  markdown_table(("kernel", "exclusive s", "inclusive s", "signatures"),
                                 [(k, f"{v['exclusive_s']:.2f}", f"{v['inclusive_s']:.2f}", str(len(v["signatures"])))
                                  for k, v in top]), ""]
        multi = [(k, len(v["signatures"])) for k, v in whole["kernels"].items() if len(v["signatures"]) > 1]
        lines += ["Kernels compiled for more than one signature: "
                  + (", ".join(f"{k} ({n})" for k, n in sorted(multi)) if multi else "none") + ".", ""]
    m = report["machine"]
    lines += [f"Machine: {m.get('cpu_model', '?')}, {m.get('cpu_count', '?')} cores; ddg sources {report['source']}; "
              f"load average before the runs {report['load_before']}.", ""]
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="benchmarks/results")
    parser.add_argument("--timeout", type=float, default=1800.0)
    parser.add_argument("--groups", nargs="+", default=["warmup", "all", "rod", "plate", "plate-midedge"],
                        help="'warmup' (`python -m ddg warmup` as a user runs it: its parts in parallel "
                             "processes; peak MB is the largest process's), 'all' (the whole warm-up in one "
                             "process, each kernel timed) or warm-up parts / model names, each in its own copy")
    args = parser.parse_args(argv)
    report = {"machine": machine_info(), "source": source_fingerprint(), "load_before": load_average(),
              "started": time.strftime("%Y-%m-%d %H:%M:%S"), "groups": []}
    for group in args.groups:
        result = compile_group({"all": [], "warmup": ["parallel"]}.get(group, [group]), args.timeout)
        result["label"] = group
        report["groups"].append(result)
        print(f"{group}: {result.get('wall_s', float('nan')):.1f} s, {result.get('peak_rss_mb', 0):.0f} MB"
              + (f" ({result['error']})" if "error" in result else ""), flush=True)
    print(write_report(args.out, "compile_time", report, markdown(report)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
