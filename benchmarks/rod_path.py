"""Speed benchmark of the rod solver's full path (compression to dL/L = 1/2, then shear to dW_max).

    .venv/bin/python -m benchmarks.rod_path [--nodes 50 100 200 400] [--repeat 1]
        [--out benchmarks/results] [--timeout 300]

For each node count M it runs

    ddg.simulate(ddg.Strip.from_ratios(0.05, 0.5),
                 ddg.LoadingProtocol(0.5, compression_steps=40, shear_steps=120),
                 model="rod", resolution=M)

in a fresh child process (so a run that exceeds --timeout can be stopped) and reports the wall
time (best of --repeat), Newton iterations, time per iteration, recorded steps, convergence,
the split of the time between (a) energy/gradient/Hessian evaluation (RodModel.evaluate),
(b) linear algebra (SymmetricBanded.cholesky / .solve / .ldlt) and (c) eigenvalue work
(stability.lowest_modes, SymmetricBanded.lowest_eigenpairs), the growth exponent
d log(time) / d log(M), and the accuracy of H_mid/L at the end of compression against the exact
clamped elastica.

Everything is measured through the library's public hooks (benchmarks.common.measure_path): the
child calls simulate three times. The first call is timed as the first call; the second, warm,
carries a ddg.solve.probe.Probe (every Newton solve of the path with its phase, every recorded
step with its wall time) and is the wall time reported; the third runs under cProfile, and the
split is each category's outermost time there (a call made inside another category's call counts
once, for the outer one: the factorisations and solves of the Lanczos iteration inside
lowest_eigenpairs are eigenvalue work, not linear algebra) as a share of that call's wall time,
scaled to the un-profiled wall time. "other" is the rest (Newton/continuation bookkeeping, band
restriction and copies, observables, model set-up).

Writes OUT/rod_path.json (all numbers and machine info) and OUT/rod_path.md (the table), both
atomically. Not part of the test run.
"""
from __future__ import annotations

import argparse
import functools
import math
import sys

from benchmarks.common import (PROBE_METHOD, Provenance, after_path_text, best_of, category_split, eigen_calls,
                               eigen_paths_text,
                               shared_machine_note,
                               finish_path_report, fit_slope, fmt, load_line, machine_section, markdown_table,
                               measure_path, newton_notes, path_slopes, path_timing, run_in_child, run_notes, section,
                               slopes_markdown, slopes_text, source_fingerprint, targets_markdown, text_table,
                               iterations_target, wall_target)

WIDTH_RATIO = 0.05
COMPRESSION_RATIO = 0.5
COMPRESSION_STEPS = 40
SHEAR_STEPS = 120
CATEGORIES = ("compiled", "evaluate", "linalg", "eigen")
CATEGORY_LABELS = {
    "compiled": "the compiled Newton load steps and pseudo-arclength corrections (ddg.solve.compiled_newton: "
                "their evaluations, factorisations and solves inside one call each)",
    "evaluate": "energy/gradient/Hessian (RodModel.evaluate)",
    "linalg": "linear algebra (SymmetricBanded.cholesky, .solve, .ldlt)",
    "eigen": "eigenvalues (stability.lowest_modes, SymmetricBanded.lowest_eigenpairs)",
    "other": "everything else (continuation/Newton bookkeeping, band copies, observables)",
}


#: Issue 31's targets (best of --repeat, warm cache, idle machine): the solver's wall time of the
#: full default path (summary wall_time_s, thresholds and branch tracing included) at M = 100 and
#: 400, the whole process of the command line at M = 100, Newton iterations per recorded step.
TARGET_SOLVER_S = {100: 0.15, 400: 0.5}
TARGET_PROCESS_S = 0.8
TARGET_PROCESS_NODES = 100
TARGET_ITERATIONS_PER_STEP = 4.0


# ---------------------------------------------------------------------------- what is timed
def category_functions(previous: bool = False) -> dict:
    """The entry points of each category: {category: functions}. previous=True: the definition of
    the reports up to issue 14 (eigen = lowest_eigenpairs only, so lowest_modes' compiled Lanczos
    counted as other and its Cholesky as linear algebra; no ldlt entry)."""
    from ddg.models.rod import RodModel
    from ddg.solve import newton
    from ddg.solve.arclength import ArclengthTracer
    from ddg.solve.banded import SymmetricBanded as SB
    from ddg.solve.stability import lowest_modes

    compiled = [newton._compiled, ArclengthTracer._correct_compiled]
    if previous:
        return {"compiled": compiled, "evaluate": [RodModel.evaluate], "linalg": [SB.cholesky, SB.solve],
                "eigen": [SB.lowest_eigenpairs]}
    return {"compiled": compiled, "evaluate": [RodModel.evaluate], "linalg": [SB.cholesky, SB.solve, SB.ldlt],
            "eigen": [lowest_modes, SB.lowest_eigenpairs]}


def _eigen_functions() -> dict:
    import numpy as np
    from scipy.sparse.linalg import eigsh

    from ddg.solve.banded import SymmetricBanded as SB
    from ddg.solve.lanczos import lowest_eigenvalue
    from ddg.solve.stability import lowest_modes

    return {"lowest_modes": lowest_modes, "compiled Lanczos on the Cholesky factor": lowest_eigenvalue,
            "lowest_eigenpairs": SB.lowest_eigenpairs, "ARPACK eigsh": eigsh, "dense eigh": np.linalg.eigh}


# ---------------------------------------------------------------------------- one run (child)
def measure(nodes: int, compression_steps: int = COMPRESSION_STEPS, shear_steps: int = SHEAR_STEPS) -> dict:
    """The record of one M: the benchmark's scene through measure_path, in this process."""
    import scipy.linalg

    import ddg
    from ddg.analysis.analytic import clamped_elastica_midpoint_height
    from ddg.solve.band_ldlt import BandLDLT

    fingerprint = source_fingerprint()
    strip = ddg.Strip.from_ratios(WIDTH_RATIO, COMPRESSION_RATIO)
    protocol = ddg.LoadingProtocol(COMPRESSION_RATIO, compression_steps=compression_steps, shear_steps=shear_steps)
    m = measure_path(strip, protocol, "rod", nodes)
    result = m.result
    fns = category_functions()
    split, attr = category_split(m, fns)
    previous, _ = category_split(m, category_functions(previous=True))

    s = result.summary
    exact = clamped_elastica_midpoint_height(COMPRESSION_RATIO)
    h = s.get("H_mid_over_L_compressed")
    shear_rows = [r for r in result.rows if r["stage"] == "shear"]
    stable_flips = [
        {"dW_over_L": b["dW_over_L"], "stable_before": a["stable"], "stable_after": b["stable"]}
        for a, b in zip(shear_rows, shear_rows[1:]) if a["stable"] != b["stable"]
    ]
    switches = [r["dW_over_L"] for r in shear_rows if r["branch_switched"]]
    evaluations = round(sum(attr.calls(fns["evaluate"][0]).values()))
    return {
        "nodes": nodes,
        "ddg_source_sha256": fingerprint,
        "n_dof": s.get("n_dof"),
        "n_free_dof": s.get("n_free_dof"),
        **path_timing(m),
        "converged": bool(s["converged"]),
        "message": s.get("message", ""),
        **split,
        "split_fraction_issue14_definition": previous["split_fraction"],
        "calls": {
            "by_function": {f"{fn.__qualname__}": attr.by_context(fn) for fns_ in fns.values() for fn in fns_},
            "cholesky_factorisations": round(sum(attr.calls(scipy.linalg.cholesky_banded).values())),
            "eigen_calls": eigen_calls(attr, _eigen_functions()),
            "ldlt_factorisations": round(sum(attr.calls(BandLDLT.__init__).values())),
        },
        "evaluations": evaluations,
        "time_per_evaluation_ms": 1e3 * split["split_s"]["evaluate"] / evaluations if evaluations else None,
        "stability_changes_during_shear": stable_flips,
        "branch_switches_dW_over_L": switches,
        "dW1_over_L": s.get("dW1_over_L"),
        "dW2_over_L": s.get("dW2_over_L"),
        "dW_max_over_L": s.get("dW_max_over_L"),
        "H_mid_over_L_compressed": h,
        "H_mid_over_L_exact": exact,
        "H_mid_rel_error": (h - exact) / exact if h is not None else None,
    }


def measure_process(nodes: int, repeat: int, timeout: float | None) -> dict:
    """The whole command-line process of the default rod run at M = nodes, as a user types it
    (`python -m ddg simulate --model rod --width-ratio 0.05 --compression-ratio 0.5`), timed by
    this process: best of `repeat`; and `python -c "import ddg.cli"` alone (interpreter start and
    imports), so that process = imports + the run (numba's cache loads, the solver, the files)."""
    import subprocess
    import tempfile
    import time

    def timed(args) -> float:
        t0 = time.perf_counter()
        subprocess.run([sys.executable, *args], check=True, capture_output=True, timeout=timeout)
        return time.perf_counter() - t0

    with tempfile.TemporaryDirectory() as tmp:
        run = ["-m", "ddg", "simulate", "--model", "rod", "--width-ratio", str(WIDTH_RATIO), "--compression-ratio",
               str(COMPRESSION_RATIO), "--resolution", str(nodes), "--out", f"{tmp}/run"]
        timed(run)  # numba's cache index read once before the timed runs
        process = [timed(run) for _ in range(repeat)]
        imports = [timed(["-c", "import ddg.cli"]) for _ in range(repeat)]
    return {"nodes": nodes, "command": "python " + " ".join(run[:-2]), "process_wall_s": min(process),
            "all_process_wall_s": process, "imports_wall_s": min(imports), "all_imports_wall_s": imports}


def issue31_targets(results: list[dict], process: dict | None) -> list[dict]:
    """Issue 31's targets against the runs, each with what its figure is made of (the same run's
    record), so that an unmet one says where the rest goes."""
    ok = {r["nodes"]: r for r in results if r["status"] == "ok" and r["converged"]}
    kinds = (*CATEGORIES, "other")
    out = [wall_target(f"M = {m} full default path, solver wall time", bound, ok[m], kinds)
           for m, bound in TARGET_SOLVER_S.items() if m in ok]
    if process is not None:
        r = ok.get(process["nodes"])
        made_of = {"interpreter start and imports (python -c 'import ddg.cli')": process["imports_wall_s"]}
        if r is not None:
            made_of["first simulate call in a fresh process (numba's cache loads, the run)"] = r["first_call_wall_s"]
            made_of["rest (arguments, files, exit)"] = (process["process_wall_s"] - process["imports_wall_s"]
                                                        - r["first_call_wall_s"])
        out.append({"target": f"M = {process['nodes']} whole process ({process['command']})",
                    "bound": TARGET_PROCESS_S, "measured": process["process_wall_s"], "unit": "s",
                    "met": process["process_wall_s"] <= TARGET_PROCESS_S, "made_of": made_of})
    out += [iterations_target(f"M = {m} Newton iterations per recorded step", TARGET_ITERATIONS_PER_STEP, r)
            for m, r in sorted(ok.items())]
    return out


# ---------------------------------------------------------------------------- reporting
HEADER = ("M", "free DOF", "first call s", "wall s", "cpu s", "Newton its", "ms/it", "steps", "conv", "evals",
          "ms/eval", "loop %", "eval %", "linalg %", "eig %", "other %", "H_mid/L", "rel err vs elastica")


def table_rows(results: list[dict]) -> list[tuple]:
    out = []
    for r in results:
        if r["status"] != "ok":
            out.append((str(r["nodes"]), "", "", r["status"]) + ("",) * (len(HEADER) - 4))
            continue
        f = r["split_fraction"]
        err = r["H_mid_rel_error"]
        out.append((
            str(r["nodes"]), str(r["n_free_dof"]), fmt(r.get("first_call_wall_s"), ".2f"), f"{r['wall_time_s']:.2f}",
            f"{r['cpu_time_s']:.2f}", str(r["newton_iterations"]), f"{r['time_per_newton_iteration_ms']:.2f}",
            str(r["recorded_steps"]), "yes" if r["converged"] else "NO",
            str(r["evaluations"]), f"{r['time_per_evaluation_ms']:.2f}" if r["time_per_evaluation_ms"] else "",
            f"{100 * f['compiled']:.0f}", f"{100 * f['evaluate']:.0f}", f"{100 * f['linalg']:.0f}",
            f"{100 * f['eigen']:.0f}",
            f"{100 * f['other']:.0f}",
            f"{r['H_mid_over_L_compressed']:.6f}" if r["H_mid_over_L_compressed"] is not None else "",
            f"{err:+.2e}" if err is not None else "",
        ))
    return out


def scaling(results: list[dict]) -> dict:
    ok = [r for r in results if r["status"] == "ok" and r["converged"]]
    ms = [r["nodes"] for r in ok]
    out = {
        "nodes_fitted": ms,
        **path_slopes(ms, ok, (*CATEGORIES, "other")),
        "h_error_slope": (fit_slope(ms, [abs(r["H_mid_rel_error"]) for r in ok])
                          if ok and all(r["H_mid_rel_error"] for r in ok) else None),
    }
    out["local_wall_time_slopes"] = {
        f"{a['nodes']}-{b['nodes']}": math.log(b["wall_time_s"] / a["wall_time_s"]) / math.log(b["nodes"] / a["nodes"])
        for a, b in zip(ok, ok[1:])
    }
    m100 = [r for r in ok if r["nodes"] == 100]
    out["target_linear"] = "slope ~ 1"
    m400 = [r for r in ok if r["nodes"] == 400]
    out["target_M100_under_1s"] = (m100[0]["wall_time_s"] <= 0.3) if m100 else None  # issue 14: 0.3 s
    out["target_M400_under_1s"] = (m400[0]["wall_time_s"] <= 1.0) if m400 else None
    out["linear_met"] = None if out["wall_time_slope"] is None else bool(out["wall_time_slope"] <= 1.2)
    return out


def _run_note(r: dict) -> str:
    st = r["stage"]
    worst, failed, phase = newton_notes(r)
    flips = ", ".join(f"{f['dW_over_L']:.4f} ({'stable' if f['stable_after'] else 'unstable'})"
                      for f in r["stability_changes_during_shear"]) or "none"
    return (
        f"M = {r['nodes']}: compression {st['compression']['iterations']} its / {st['compression']['time_s']:.2f} s, "
        f"shear {st['shear']['iterations']} its / {st['shear']['time_s']:.2f} s; iterations in failed Newton solves "
        f"{failed}; by phase: {phase}; after the path: {after_path_text(r)}; most expensive recorded steps: {worst}; "
        f"stability changes in shear at dW/L = {flips}; branch switches at dW/L = "
        f"{', '.join(f'{x:.4f}' for x in r['branch_switches_dW_over_L']) or 'none'}; "
        "eigenvalue calls (s under cProfile): " + (eigen_paths_text(r) or "none") + "."
    )


def observations(results: list[dict]) -> list[str]:
    return run_notes(results, lambda r: f"M = {r['nodes']}", _run_note)


def _verdict(flag) -> str:
    return "not measured" if flag is None else ("met" if flag else "NOT met")


def _overhead(results: list[dict]) -> str:
    """The range of profiled / un-profiled wall time over the runs."""
    ratios = [r["profiled_wall_time_s"] / r["wall_time_s"] for r in results if r.get("status") == "ok"]
    return f"{min(ratios):.2f}-{max(ratios):.2f}" if ratios else "n/a"


def _previous_split(results: list[dict]) -> str:
    return "; ".join(f"M = {r['nodes']}: " + ", ".join(f"{k} {100 * v:.0f} %"
                                                       for k, v in r["split_fraction_issue14_definition"].items())
                     for r in results if r.get("status") == "ok")



def markdown_report(report: dict) -> str:
    sc = report["scaling"]
    results = report["results"]
    lines = [
        "# Rod solver, full path: speed and accuracy",
        "",
        f"Scene: W/L = {WIDTH_RATIO}, dL/L = {COMPRESSION_RATIO} in {COMPRESSION_STEPS} recorded steps, then shear to "
        f"dW_max in {SHEAR_STEPS} recorded steps (`python -m benchmarks.rod_path`). Wall time is the best of "
        f"{report['repeat']} run(s) per M, each in a fresh process.",
        "",
        markdown_table(HEADER, table_rows(results)),
        "",
        "first call s = the first simulate call in a fresh process (it loads the compiled kernels from numba's cache; "
        "compiling them costs the one-off `python -m ddg warmup`); wall s = the second, warm call, with a "
        "`ddg.solve.probe.Probe` (every Newton solve and recorded step; no profiler, no patching). cpu s = CPU time of "
        "the benchmark process during the same call (wall time above it means the process waited for a core, or for "
        "BLAS threads). Newton its = `summary['newton_iterations']` (the path; threshold location and branch "
        "tracing are counted apart, below). evals = calls of RodModel.evaluate from Python (since issue 31 the "
        "Newton load steps and arclength corrections evaluate inside their compiled loop, uncounted: these are "
        "the rest, e.g. threshold location's descents and the recorded states' re-evaluations), counted by "
        "cProfile in the profiled call (the same, deterministic path); ms/eval = their mean time (scaled as the "
        "split). "
        "Time split columns (share of the wall time), **measured under cProfile** in a third, separate warm call "
        "of the same run and **scaled to the un-profiled wall time**: each category's outermost calls (a category's "
        "call inside another category's call counts once, for the outer one) as a share of the profiled call's wall "
        f"time (which cProfile's per-call overhead makes {_overhead(results)} times the un-profiled one; the "
        "overhead falls on Python calls, so the shares lean a little towards the Python-heavy categories). "
        "loop = " + CATEGORY_LABELS["compiled"] + "; eval = " + CATEGORY_LABELS["evaluate"] + "; linalg = "
        + CATEGORY_LABELS["linalg"] + "; eig = "
        + CATEGORY_LABELS["eigen"] + " (including their own factorisations, the compiled Lanczos on the Cholesky "
        "factor and ARPACK's solves); other = " + CATEGORY_LABELS["other"] + ". Until issue 15 the eig column "
        "counted lowest_eigenpairs only (lowest_modes' compiled Lanczos was in other, its Cholesky in linalg); "
        "that definition's split of the same runs: " + _previous_split(results) + " (JSON: "
        "`split_fraction_issue14_definition`). The relative error compares H_mid/L at the end of compression with "
        f"`ddg.analysis.analytic.clamped_elastica_midpoint_height(0.5)` = {report['H_mid_over_L_exact']:.8f}.",
        "",
        f"- growth exponent d log(wall time) / d log(M) over M = {sc['nodes_fitted']}: " + slopes_markdown(sc)
        + "; between consecutive M: " + ", ".join(f"{k}: {v:.2f}" for k, v in sc["local_wall_time_slopes"].items()),
        f"- target linear growth (slope ~ 1, taken as <= 1.2): {_verdict(sc['linear_met'])}; "
        f"target M = 100 within 0.3 s (warm): {_verdict(sc['target_M100_under_1s'])}; "
        f"M = 400 within 1 s: {_verdict(sc.get('target_M400_under_1s'))}",
        load_line(report),
        *shared_machine_note(report),
        f"- accuracy: |rel err| slope against M: {fmt(sc['h_error_slope'], '.2f')} (O(h^2) expects -2)",
    ]
    lines += targets_markdown("Targets (issue 31)", report.get("issue31_targets", []))
    lines += section("Where the Newton iterations go", report["observations"])
    lines += ["", "Per stage, per phase (`ddg.solve.continuation.PHASES`) and per recorded step: from the probe of "
              "the warm call (a step's time is the wall time from the previous recorded row to this one). The "
              "phases add up to `summary['newton_iterations']` (checked: "
              + ("yes" if all(r.get("probe_matches_summary") for r in results if r.get("status") == "ok") else "NO")
              + "). Until issue 15 this section counted solves by the name of the calling function, summing every "
              "call of `continuation.newton` made during a recorded step (1281 iterations at M = 100 against the "
              "summary's 977). Threshold location and branch tracing come from summary.json "
              "(`threshold_newton_iterations`, `threshold_wall_time_s`, `branches_newton_iterations`, "
              "`branches_wall_time_s`); they are part of the wall time."]
    lines += machine_section(report)
    return "\n".join(lines)


def build_report(results: list[dict], repeat: int, timeout: float | None) -> dict:
    """The report's data before finish_path_report adds the scaling, provenance and notes."""
    from ddg.analysis.analytic import clamped_elastica_midpoint_height

    return {
        "benchmark": "rod_path",
        "scene": {"width_ratio": WIDTH_RATIO, "compression_ratio": COMPRESSION_RATIO,
                  "compression_steps": COMPRESSION_STEPS, "shear_steps": SHEAR_STEPS, "shear_ratio": "dW_max/L",
                  "model": "rod"},
        "repeat": repeat,
        "timeout_s": timeout,
        "H_mid_over_L_exact": clamped_elastica_midpoint_height(COMPRESSION_RATIO),
        "split_categories": CATEGORY_LABELS,
        "method": PROBE_METHOD,
        "results": results,
    }


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.rod_path", description=__doc__.split("\n")[0])
    parser.add_argument("--nodes", type=int, nargs="+", default=[50, 100, 200, 400], help="rod node counts M")
    parser.add_argument("--repeat", type=int, default=1, help="runs per M; the best wall time is reported")
    parser.add_argument("--out", default="benchmarks/results", help="directory for rod_path.json and rod_path.md")
    parser.add_argument("--timeout", type=float, default=300.0,
                        help="seconds allowed for one run of one M (0: no limit); a run over it is stopped, reported")
    parser.add_argument("--no-process", action="store_true",
                        help=f"skip timing the whole command-line process at M = {TARGET_PROCESS_NODES}")
    args = parser.parse_args(argv)
    if args.repeat < 1 or any(m < 5 for m in args.nodes):
        parser.error("--repeat must be >= 1 and every M >= 5")
    timeout = args.timeout if args.timeout > 0 else None

    provenance = Provenance()
    results = [
        best_of(functools.partial(run_in_child, measure, (m,), timeout), args.repeat, f"M = {m}", {"nodes": m},
                lambda p: f"{p['wall_time_s']:.2f} s, {p['newton_iterations']} Newton its, converged {p['converged']}",
                args.timeout)
        for m in args.nodes
    ]

    report = build_report(results, args.repeat, timeout)
    report["process"] = (measure_process(TARGET_PROCESS_NODES, args.repeat, timeout)
                         if TARGET_PROCESS_NODES in args.nodes and not args.no_process else None)
    report["issue31_targets"] = issue31_targets(results, report["process"])
    wrote = finish_path_report(report, provenance, scaling, observations, markdown_report, args.out)

    sc = report["scaling"]
    print(text_table(HEADER, table_rows(results)))
    print()
    print(f"growth exponent d log(time)/d log(M) over M = {sc['nodes_fitted']}: {slopes_text(sc)}; "
          f"target slope ~1 (<= 1.2): {_verdict(sc['linear_met'])}; M = 100 within 0.3 s: "
          f"{_verdict(sc['target_M100_under_1s'])}")
    print("split (under cProfile, scaled to the wall time): loop = the compiled Newton and corrector, "
          "eval = RodModel.evaluate, linalg = cholesky+solve+ldlt, "
          "eig = lowest_modes+lowest_eigenpairs, other = the rest")
    for n in report["observations"]:
        print("-", n)
    print(wrote)
    return 0


if __name__ == "__main__":
    sys.exit(main())
