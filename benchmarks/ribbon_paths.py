"""The 1D models' full default path, compiled end to end against the Python Newton loop (issue
31 item 1: "the rod's and the 1D ribbons' Newton loop compiled end to end").

    .venv/bin/python -m benchmarks.ribbon_paths [--models rod ribbon-trapeze ...] [--repeat 2]
        [--out benchmarks/results] [--timeout 600]

For each 1D model (the rod at M = 100, the ribbons at M = 101, the default resolution) on the
benchmark's scene (W/L = 1/20, dL/L = 1/2, the paper's strip) it runs

    ddg.simulate(ddg.Strip.from_ratios(0.05, 0.5), ddg.LoadingProtocol(0.5), model=..., resolution=M)

(thresholds and branch tracing included) in two configurations, each in a fresh child process
through benchmarks.common.measure_path (a first call that loads numba's cache, a warm call timed,
a third under cProfile for the split):

- `compiled`: the library's default: the Newton load steps and pseudo-arclength corrections in one
  compiled call each (ddg.solve.compiled_newton), which evaluates the model's energy, gradient and
  Hessian in one compiled call (ddg.models.rod_assembly.rod_energy, with the ribbon's width terms);
- `python loop`: NewtonOptions(compiled=False): the same evaluations from the Python Newton loop.

and, at the compiled run's last state, the time of one evaluation (energy, gradient, Hessian;
best of 5 batches of 100) by the one-call assembly (RodModel.evaluate) and by the piecewise
composition of the same compiled pieces (RodModel.evaluate_piecewise: what the wide ribbons
evaluated before issue 31's width terms; the rod and the Sano-Wada ribbon had the one call
already).

It reports the wall time (best of --repeat), Newton iterations (by phase), time per iteration, the
split between the compiled loops, evaluate, linear algebra, eigenvalues and the rest (benchmarks.
rod_path.category_functions), the status and thresholds of both. Writes OUT/ribbon_paths.json and
.md atomically, with the load average. Not part of the test run; no timing is asserted anywhere.
"""
from __future__ import annotations

import argparse
import functools
import sys

from benchmarks.common import (Provenance, best_of, category_split, fmt, markdown_table, measure_path, path_timing,
                               run_in_child, shared_machine_note, source_fingerprint, warn_if_changed, write_report)

WIDTH_RATIO = 0.05
COMPRESSION_RATIO = 0.5
#: (model, resolution): the default resolutions (the rod's 100; the ribbons' 101, not a multiple of 4).
MODELS = {"rod": 100, "ribbon-sano-wada": 101, "ribbon-trapeze": 101, "ribbon-wunderlich": 101,
          "ribbon-cross-section": 101}
CONFIGURATIONS = ("compiled", "python loop")
#: Evaluations per timed batch, and batches (the best is reported).
BATCH, BATCHES = 100, 5
CATEGORIES = ("compiled", "evaluate", "linalg", "eigen", "other")


def evaluation_times(model, q) -> dict:
    """Milliseconds per evaluation (energy, gradient, Hessian) at q: the one-call assembly and the
    piecewise composition, best of BATCHES batches of BATCH."""
    import time

    out = {}
    for name, evaluate in (("one_call", model.evaluate), ("piecewise", model.evaluate_piecewise)):
        evaluate(q)
        best = float("inf")
        for _ in range(BATCHES):
            t0 = time.perf_counter()
            for _ in range(BATCH):
                evaluate(q)
            best = min(best, (time.perf_counter() - t0) / BATCH)
        out[f"evaluation_{name}_ms"] = 1e3 * best
    return out


def measure(model: str, resolution: int, configuration: str) -> dict:
    """One run's record in this (child) process."""
    import ddg
    from ddg.solve.newton import NewtonOptions

    from benchmarks.rod_path import category_functions

    options = {}
    if configuration == "python loop":
        options["options"] = ddg.ContinuationOptions(newton=NewtonOptions(compiled=False))
    strip = ddg.Strip.from_ratios(WIDTH_RATIO, COMPRESSION_RATIO)
    m = measure_path(strip, ddg.LoadingProtocol(COMPRESSION_RATIO), model, resolution, **options)
    split, _ = category_split(m, category_functions())
    s = m.result.summary
    timing = path_timing(m)
    timing.pop("steps")
    evaluations = evaluation_times(m.result.model, m.result.final_state.q) if configuration == "compiled" else {}
    return {"model": model, "resolution": resolution, "configuration": configuration,
            "ddg_source_sha256": source_fingerprint(), **timing, **split, **evaluations,
            "status": s.get("status"), "dW1_over_L": s.get("dW1_over_L"), "dW2_over_L": s.get("dW2_over_L")}


def run_all(models, repeat: int, timeout: float) -> list[dict]:
    results = []
    for model in models:
        for configuration in CONFIGURATIONS:
            ident = {"model": model, "resolution": MODELS[model], "configuration": configuration}
            run = functools.partial(run_in_child, measure, (model, MODELS[model], configuration), timeout)
            results.append(best_of(run, repeat, f"{model} {configuration}", ident,
                                   lambda r: f"{r['wall_time_s']:.2f} s, {r['newton_iterations']} its", timeout))
    return results


def table_rows(results: list[dict]) -> list[tuple]:
    rows = []
    for r in results:
        if r.get("status") in ("timeout", "error"):
            rows.append((r["model"], r["configuration"], r["status"], *["-"] * 10))
            continue
        split = r["split_s"]
        rows.append((r["model"], r["configuration"], r["status"], fmt(r["wall_time_s"], ".2f"),
                     str(r["newton_iterations"]), fmt(r["time_per_newton_iteration_ms"], ".3f"),
                     *(fmt(split[k], ".2f") for k in CATEGORIES), fmt(r["dW1_over_L"], ".6f"),
                     fmt(r["dW2_over_L"], ".6f")))
    return rows


def comparisons(results: list[dict]) -> list[str]:
    """One line per model: the compiled run against the Python loop's, and one evaluation by the one
    call against the piecewise composition, computed."""
    by = {(r["model"], r["configuration"]): r for r in results if "wall_time_s" in r}
    lines = []
    for model in dict.fromkeys(r["model"] for r in results):
        a, b = by.get((model, "compiled")), by.get((model, "python loop"))
        if a is None or b is None:
            continue
        speedup = b["wall_time_s"] / a["wall_time_s"]
        lines.append(f"- {model}: compiled {a['wall_time_s']:.2f} s ({a['newton_iterations']} its) against the "
                     f"Python loop's {b['wall_time_s']:.2f} s ({b['newton_iterations']} its): {speedup:.2f}x; "
                     f"per iteration {a['time_per_newton_iteration_ms']:.3f} against "
                     f"{b['time_per_newton_iteration_ms']:.3f} ms; the compiled run spends "
                     f"{a['split_s']['compiled']:.2f} s in the compiled loops, {a['split_s']['evaluate']:.2f} s in "
                     f"evaluations outside them, {a['split_s']['linalg']:.2f} s in linear algebra outside them; "
                     f"iterations by phase {a['newton_iterations_by_phase']}; one evaluation "
                     f"{a['evaluation_one_call_ms']:.3f} ms in one call against {a['evaluation_piecewise_ms']:.3f} ms "
                     f"piecewise ({a['evaluation_piecewise_ms'] / a['evaluation_one_call_ms']:.2f}x).")
    return lines


def markdown_report(report: dict) -> str:
    header = ("model", "configuration", "status", "wall s", "Newton its", "ms/it", *(f"{k} s" for k in CATEGORIES),
              "dW1/L", "dW2/L")
    intro = (f"W/L = {WIDTH_RATIO}, dL/L = {COMPRESSION_RATIO}, the paper's strip; full default path with "
             f"thresholds and branch tracing; best of {report['repeat']}; each run in a fresh process after a "
             "first call that loads numba's cache.")
    legend = ("compiled: the compiled Newton load steps and corrections (their evaluations and factorisations "
              "inside); evaluate: evaluations outside them (fold snaps, which are Levenberg-Marquardt minimisations "
              "in Python, threshold bisection, branch switching); linalg: factorisations and solves outside them; "
              "eigen: eigenvalue work; other: the rest.")
    loads = report["load_average"]
    lines = ["# The 1D models compiled end to end against the Python loop (benchmarks/ribbon_paths.py)",
             "", intro, "", markdown_table(header, table_rows(report["results"])), "", legend, "",
             "## Compiled against the Python loop, one call against the pieces", "",
             *comparisons(report["results"]), "",
             f"Load average (1 min) at the start / end: {loads[0]} / {loads[1]}.", *shared_machine_note(report), ""]
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.ribbon_paths", description=__doc__.split("\n\n")[0])
    parser.add_argument("--models", nargs="+", choices=list(MODELS), default=list(MODELS))
    parser.add_argument("--repeat", type=int, default=2)
    parser.add_argument("--out", default="benchmarks/results")
    parser.add_argument("--timeout", type=float, default=600.0)
    args = parser.parse_args(argv)
    if not 1 <= args.repeat <= 10:
        print(f"error: --repeat {args.repeat} outside 1..10", file=sys.stderr)
        return 2
    provenance = Provenance()
    results = run_all(args.models, args.repeat, args.timeout)
    report = {"benchmark": "ribbon_paths", "repeat": args.repeat, "results": results,
              **provenance.report(results)}
    print(write_report(args.out, "ribbon_paths", report, markdown_report(report)))
    warn_if_changed(report)
    return 0


if __name__ == "__main__":
    sys.exit(main())
