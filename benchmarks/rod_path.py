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
(b) linear algebra (SymmetricBanded.cholesky / .solve) and (c) eigenvalue work
(SymmetricBanded.lowest_eigenpairs), the growth exponent d log(time) / d log(M), and the
accuracy of H_mid/L at the end of compression against the exact clamped elastica.

The split is measured by wrapping those methods with timers at run time, in the child process
only (restored afterwards); the library is not modified. A call made from inside another timed
method is counted once, by the outermost one (the Cholesky factorisations and solves of the
Lanczos iteration inside lowest_eigenpairs are eigenvalue work, not linear algebra); "other" is
the rest of the wall time (Newton/continuation bookkeeping, band restriction and copies,
observables, model set-up).

Writes OUT/rod_path.json (all numbers and machine info) and OUT/rod_path.md (the table), both
atomically. Not part of the test run.
"""
from __future__ import annotations

import argparse
import functools
import math
import sys
import time
from collections import defaultdict

from benchmarks.common import (PathInstrument, Provenance, best_of, eigen_paths_text, finish_path_report, fit_slope,
                               fmt, load_line, machine_section, markdown_table, newton_by_caller, newton_notes,
                               path_slopes, path_timing, run_in_child, run_notes, section, slopes_markdown,
                               slopes_text, source_fingerprint, stage_summary, text_table, timed_simulate)

WIDTH_RATIO = 0.05
COMPRESSION_RATIO = 0.5
COMPRESSION_STEPS = 40
SHEAR_STEPS = 120
CATEGORIES = ("evaluate", "linalg", "eigen")
CATEGORY_LABELS = {
    "evaluate": "energy/gradient/Hessian (RodModel.evaluate)",
    "linalg": "linear algebra (SymmetricBanded.cholesky, .solve)",
    "eigen": "eigenvalues (SymmetricBanded.lowest_eigenpairs)",
    "other": "everything else (continuation/Newton bookkeeping, band copies, observables)",
}


# ---------------------------------------------------------------------------- instrumentation
class _Instrument(PathInstrument):
    """Timing wrappers on the rod's library methods, installed and removed around one run."""

    def __init__(self):
        super().__init__()
        self.stack: list[str] = []
        self.top_time = defaultdict(float)     # method -> time in calls made outside other timed calls
        self.top_calls = defaultdict(int)
        self.nested_time = defaultdict(float)  # method -> time in calls made inside another timed call
        self.nested_calls = defaultdict(int)
        self.category_time = defaultdict(float)
        self.factorisations = 0                # cholesky calls that actually factorised (not cached)
        self.eigen_paths = defaultdict(int)    # lowest_eigenpairs: "lanczos" (PD) or "banded" (dsbevx)
        self.eigen_path_time = defaultdict(float)

    # -- generic timed wrapper
    def _timed(self, key: str, category: str, original):
        inst = self

        @functools.wraps(original)
        def wrapper(*args, **kwargs):
            nested = bool(inst.stack)
            inst.stack.append(key)
            t0 = time.perf_counter()
            try:
                return original(*args, **kwargs)
            finally:
                dt = time.perf_counter() - t0
                inst.stack.pop()
                if nested:
                    inst.nested_time[key] += dt
                    inst.nested_calls[key] += 1
                else:
                    inst.top_time[key] += dt
                    inst.top_calls[key] += 1
                    inst.category_time[category] += dt

        return wrapper

    def install(self) -> None:
        from ddg.models.rod import RodModel
        from ddg.solve.banded import SymmetricBanded

        inst = self
        self._set(RodModel, "evaluate", self._timed("RodModel.evaluate", "evaluate", RodModel.__dict__["evaluate"]))

        chol = SymmetricBanded.__dict__["cholesky"]

        def cholesky_counting(self_, *a, **k):
            if not getattr(self_, "_cholesky_tried", True):
                inst.factorisations += 1
            return chol(self_, *a, **k)

        self._set(SymmetricBanded, "cholesky", self._timed("SymmetricBanded.cholesky", "linalg",
                                                           functools.wraps(chol)(cholesky_counting)))
        self._set(SymmetricBanded, "solve", self._timed("SymmetricBanded.solve", "linalg",
                                                        SymmetricBanded.__dict__["solve"]))
        eig = SymmetricBanded.__dict__["lowest_eigenpairs"]

        def eig_counting(self_, count=1, vectors=False):
            t0 = time.perf_counter()
            out = eig(self_, count, vectors)
            dt = time.perf_counter() - t0
            # same test as the library: Lanczos on the inverse when the factorisation exists
            lanczos = chol(self_) and self_.n > 4 * min(count, self_.n) + 20
            path = ("lanczos" if lanczos else "banded (dsbevx)") + (", vectors" if vectors else "")
            inst.eigen_paths[path] += 1
            inst.eigen_path_time[path] += dt
            return out

        self._set(SymmetricBanded, "lowest_eigenpairs",
                  self._timed("SymmetricBanded.lowest_eigenpairs", "eigen", functools.wraps(eig)(eig_counting)))

        # Newton solves (who called them, iterations, converged or not) and the recorded steps
        self.install_path_counters(branch_callers=("_jump", "_ensure_stable"), required=True)


# ---------------------------------------------------------------------------- one run (child)
def _run_once(nodes: int) -> dict:
    import ddg
    from ddg.analysis.analytic import clamped_elastica_midpoint_height

    fingerprint = source_fingerprint()
    inst = _Instrument()
    strip = ddg.Strip.from_ratios(WIDTH_RATIO, COMPRESSION_RATIO)
    protocol = ddg.LoadingProtocol(COMPRESSION_RATIO, compression_steps=COMPRESSION_STEPS, shear_steps=SHEAR_STEPS)
    result, wall, cpu = timed_simulate(inst, strip, protocol, "rod", nodes)

    s = result.summary
    exact = clamped_elastica_midpoint_height(COMPRESSION_RATIO)
    h = s.get("H_mid_over_L_compressed")
    shear_rows = [r for r in result.rows if r["stage"] == "shear"]
    split = {c: inst.category_time.get(c, 0.0) for c in CATEGORIES}
    split["other"] = wall - sum(split.values())
    stable_flips = [
        {"dW_over_L": b["dW_over_L"], "stable_before": a["stable"], "stable_after": b["stable"]}
        for a, b in zip(shear_rows, shear_rows[1:]) if a["stable"] != b["stable"]
    ]
    switches = [r["dW_over_L"] for r in shear_rows if r["branch_switched"]]
    return {
        "nodes": nodes,
        "ddg_source_sha256": fingerprint,
        "n_dof": s.get("n_dof"),
        "n_free_dof": s.get("n_free_dof"),
        **path_timing(result, wall, cpu),
        "converged": bool(s["converged"]),
        "message": s.get("message", ""),
        "split_s": split,
        "split_fraction": {k: v / wall for k, v in split.items()},
        "calls": {
            "top_level": {k: {"calls": inst.top_calls[k], "time_s": inst.top_time[k]} for k in inst.top_calls},
            "nested": {k: {"calls": inst.nested_calls[k], "time_s": inst.nested_time[k]} for k in inst.nested_calls},
            "cholesky_factorisations": inst.factorisations,
            "lowest_eigenpairs_paths": {k: {"calls": v, "time_s": inst.eigen_path_time[k]}
                                        for k, v in inst.eigen_paths.items()},
        },
        "evaluations": inst.top_calls.get("RodModel.evaluate", 0),
        "time_per_evaluation_ms": (1e3 * inst.top_time["RodModel.evaluate"] / inst.top_calls["RodModel.evaluate"]
                                   if inst.top_calls.get("RodModel.evaluate") else None),
        "newton_by_caller": newton_by_caller(inst.newton_calls),
        "stage": stage_summary(inst.steps),
        "steps": inst.steps,
        "stability_changes_during_shear": stable_flips,
        "branch_switches_dW_over_L": switches,
        "dW1_over_L": s.get("dW1_over_L"),
        "dW2_over_L": s.get("dW2_over_L"),
        "dW_max_over_L": s.get("dW_max_over_L"),
        "H_mid_over_L_compressed": h,
        "H_mid_over_L_exact": exact,
        "H_mid_rel_error": (h - exact) / exact if h is not None else None,
    }


# ---------------------------------------------------------------------------- reporting
HEADER = ("M", "free DOF", "first call s", "wall s", "cpu s", "Newton its", "ms/it", "steps", "conv", "evals", "ms/eval", "eval %",
          "linalg %", "eig %", "other %", "H_mid/L", "rel err vs elastica")


def table_rows(results: list[dict]) -> list[tuple]:
    out = []
    for r in results:
        if r["status"] != "ok":
            out.append((str(r["nodes"]), "", "", r["status"]) + ("",) * (len(HEADER) - 4))
            continue
        f = r["split_fraction"]
        err = r["H_mid_rel_error"]
        out.append((
            str(r["nodes"]), str(r["n_free_dof"]), f"{r.get('first_call_wall_s', float('nan')):.2f}", f"{r['wall_time_s']:.2f}", f"{r['cpu_time_s']:.2f}", str(r["newton_iterations"]),
            f"{r['time_per_newton_iteration_ms']:.2f}", str(r["recorded_steps"]), "yes" if r["converged"] else "NO",
            str(r["evaluations"]), f"{r['time_per_evaluation_ms']:.2f}" if r["time_per_evaluation_ms"] else "",
            f"{100 * f['evaluate']:.0f}", f"{100 * f['linalg']:.0f}", f"{100 * f['eigen']:.0f}", f"{100 * f['other']:.0f}",
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
        "h_error_slope": fit_slope(ms, [abs(r["H_mid_rel_error"]) for r in ok]) if ok and all(r["H_mid_rel_error"] for r in ok) else None,
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
    worst, failed, caller = newton_notes(r)
    flips = ", ".join(f"{f['dW_over_L']:.4f} ({'stable' if f['stable_after'] else 'unstable'})"
                      for f in r["stability_changes_during_shear"]) or "none"
    return (
        f"M = {r['nodes']}: compression {st['compression']['iterations']} its / {st['compression']['time_s']:.2f} s, "
        f"shear {st['shear']['iterations']} its / {st['shear']['time_s']:.2f} s; iterations in failed Newton solves "
        f"{failed}; by caller: {caller}; most expensive recorded steps: {worst}; stability changes in shear at "
        f"dW/L = {flips}; branch switches at dW/L = "
        f"{', '.join(f'{x:.4f}' for x in r['branch_switches_dW_over_L']) or 'none'}; "
        "eigenvalue calls: " + eigen_paths_text(r) + "."
    )


def observations(results: list[dict]) -> list[str]:
    return run_notes(results, lambda r: f"M = {r['nodes']}", _run_note)


def _verdict(flag) -> str:
    return "not measured" if flag is None else ("met" if flag else "NOT met")


def markdown_report(report: dict) -> str:
    sc = report["scaling"]
    lines = [
        "# Rod solver, full path: speed and accuracy",
        "",
        f"Scene: W/L = {WIDTH_RATIO}, dL/L = {COMPRESSION_RATIO} in {COMPRESSION_STEPS} recorded steps, then shear to "
        f"dW_max in {SHEAR_STEPS} recorded steps (`python -m benchmarks.rod_path`). Wall time is the best of "
        f"{report['repeat']} run(s) per M, each in a fresh process.",
        "",
        markdown_table(HEADER, table_rows(report["results"])),
        "",
        "first call s = the first simulate call in a fresh process (it loads the compiled kernels from numba's cache; compiling them costs the one-off `python -m ddg warmup`); wall s = the second, warm call, instrumented. cpu s = CPU time of the benchmark process during the same run (wall time above it means the process "
        "waited for a core, or for BLAS threads). evals = calls of RodModel.evaluate (Newton iterations plus line-search trials and the first evaluation "
        "of each solve); ms/eval = their mean time. "
        "Time split columns (share of the wall time): eval = " + CATEGORY_LABELS["evaluate"] + "; linalg = "
        + CATEGORY_LABELS["linalg"] + "; eig = " + CATEGORY_LABELS["eigen"] + " (including its own factorisations "
        "and Lanczos solves); other = " + CATEGORY_LABELS["other"] + ". The relative error compares H_mid/L at the "
        "end of compression with `ddg.analysis.analytic.clamped_elastica_midpoint_height(0.5)` = "
        f"{report['H_mid_over_L_exact']:.8f}.",
        "",
        f"- growth exponent d log(wall time) / d log(M) over M = {sc['nodes_fitted']}: " + slopes_markdown(sc)
        + "; between consecutive M: " + ", ".join(f"{k}: {v:.2f}" for k, v in sc["local_wall_time_slopes"].items()),
        f"- target linear growth (slope ~ 1, taken as <= 1.2): {_verdict(sc['linear_met'])}; "
        f"target M = 100 within 0.3 s (warm): {_verdict(sc['target_M100_under_1s'])}; "
        f"M = 400 within 1 s: {_verdict(sc.get('target_M400_under_1s'))}",
        load_line(report),
        f"- accuracy: |rel err| slope against M: {fmt(sc['h_error_slope'], '.2f')} (O(h^2) expects -2)",
    ]
    lines += section("Where the Newton iterations go", report["observations"])
    lines += machine_section(report)
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.rod_path", description=__doc__.split("\n")[0])
    parser.add_argument("--nodes", type=int, nargs="+", default=[50, 100, 200, 400], help="rod node counts M")
    parser.add_argument("--repeat", type=int, default=1, help="runs per M; the best wall time is reported")
    parser.add_argument("--out", default="benchmarks/results", help="directory for rod_path.json and rod_path.md")
    parser.add_argument("--timeout", type=float, default=300.0,
                        help="seconds allowed for one run of one M (0: no limit); a run over it is stopped and reported")
    args = parser.parse_args(argv)
    if args.repeat < 1 or any(m < 5 for m in args.nodes):
        parser.error("--repeat must be >= 1 and every M >= 5")
    timeout = args.timeout if args.timeout > 0 else None

    from ddg.analysis.analytic import clamped_elastica_midpoint_height

    provenance = Provenance()
    results = [
        best_of(functools.partial(run_in_child, _run_once, (m,), timeout), args.repeat, f"M = {m}", {"nodes": m},
                lambda p: f"{p['wall_time_s']:.2f} s, {p['newton_iterations']} Newton its, converged {p['converged']}",
                args.timeout)
        for m in args.nodes
    ]

    report = {
        "benchmark": "rod_path",
        "scene": {"width_ratio": WIDTH_RATIO, "compression_ratio": COMPRESSION_RATIO,
                  "compression_steps": COMPRESSION_STEPS, "shear_steps": SHEAR_STEPS, "shear_ratio": "dW_max/L",
                  "model": "rod"},
        "repeat": args.repeat,
        "timeout_s": timeout,
        "H_mid_over_L_exact": clamped_elastica_midpoint_height(COMPRESSION_RATIO),
        "split_categories": CATEGORY_LABELS,
        "results": results,
    }
    wrote = finish_path_report(report, provenance, scaling, observations, markdown_report, args.out)

    sc = report["scaling"]
    print(text_table(HEADER, table_rows(results)))
    print()
    print(f"growth exponent d log(time)/d log(M) over M = {sc['nodes_fitted']}: {slopes_text(sc)}; "
          f"target slope ~1 (<= 1.2): {_verdict(sc['linear_met'])}; M = 100 within 0.3 s: "
          f"{_verdict(sc['target_M100_under_1s'])}")
    print("split: eval = RodModel.evaluate, linalg = cholesky+solve, eig = lowest_eigenpairs, other = the rest")
    for n in report["observations"]:
        print("-", n)
    print(wrote)
    return 0


if __name__ == "__main__":
    sys.exit(main())
