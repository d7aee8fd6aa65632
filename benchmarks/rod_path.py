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
import datetime as _dt
import functools
import hashlib
import inspect
import json
import math
import multiprocessing as mp
import os
import platform
import sys
import time
import traceback
from collections import defaultdict
from pathlib import Path
from ddg.io import atomic_write_text

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
class _Instrument:
    """Timing wrappers on library methods, installed and removed around one run."""

    def __init__(self):
        self.stack: list[str] = []
        self.top_time = defaultdict(float)     # method -> time in calls made outside other timed calls
        self.top_calls = defaultdict(int)
        self.nested_time = defaultdict(float)  # method -> time in calls made inside another timed call
        self.nested_calls = defaultdict(int)
        self.category_time = defaultdict(float)
        self.factorisations = 0                # cholesky calls that actually factorised (not cached)
        self.eigen_paths = defaultdict(int)    # lowest_eigenpairs: "lanczos" (PD) or "banded" (dsbevx)
        self.eigen_path_time = defaultdict(float)
        self.newton_calls: list[dict] = []
        self.steps: list[dict] = []
        self._current_step: dict | None = None
        self._patches: list[tuple[object, str, object]] = []

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

    def _patch(self, owner, name: str, replacement) -> None:
        self._patches.append((owner, name, owner.__dict__[name]))
        setattr(owner, name, replacement)

    def install(self) -> None:
        from ddg.models.rod import RodModel
        from ddg.solve import continuation
        from ddg.solve.banded import SymmetricBanded

        inst = self
        self._patch(RodModel, "evaluate", self._timed("RodModel.evaluate", "evaluate", RodModel.__dict__["evaluate"]))

        chol = SymmetricBanded.__dict__["cholesky"]

        def cholesky_counting(self_, *a, **k):
            if not getattr(self_, "_cholesky_tried", True):
                inst.factorisations += 1
            return chol(self_, *a, **k)

        self._patch(SymmetricBanded, "cholesky", self._timed("SymmetricBanded.cholesky", "linalg",
                                                             functools.wraps(chol)(cholesky_counting)))
        self._patch(SymmetricBanded, "solve", self._timed("SymmetricBanded.solve", "linalg",
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

        self._patch(SymmetricBanded, "lowest_eigenpairs",
                    self._timed("SymmetricBanded.lowest_eigenpairs", "eigen", functools.wraps(eig)(eig_counting)))

        # Newton solves: who called them, how many iterations, converged or not
        newton = continuation.__dict__["newton"]

        def newton_counting(model, q, options=None, **kwargs):
            caller = sys._getframe(1).f_code.co_name
            result = newton(model, q, options, **kwargs)
            rec = {"caller": caller, "iterations": int(result.iterations), "converged": bool(result.converged)}
            inst.newton_calls.append(rec)
            if inst._current_step is not None:
                step = inst._current_step
                step["newton_solves"] += 1
                step["iterations_all"] += rec["iterations"]
                if not rec["converged"]:
                    step["failed_solves"] += 1
                    step["iterations_failed"] += rec["iterations"]
                if caller in ("_jump", "_ensure_stable"):
                    step["branch_solves"] += 1
            return result

        self._patch(continuation, "newton", newton_counting)

        PF = continuation.PathFollower

        def stepper(name):
            original = PF.__dict__[name]

            signature = inspect.signature(original)

            @functools.wraps(original)
            def wrapper(self_, *args, **kwargs):
                L = self_.model.strip.length
                try:
                    bound = signature.bind(self_, *args, **kwargs).arguments
                    compression, shear = float(bound.get("compression", math.nan)), float(bound.get("shear", 0.0))
                except (TypeError, ValueError):
                    compression, shear = math.nan, math.nan
                step = {"dL_over_L": compression / L, "dW_over_L": shear / L, "newton_solves": 0,
                        "iterations_all": 0, "failed_solves": 0, "iterations_failed": 0, "branch_solves": 0}
                inst._current_step = step
                t0 = time.perf_counter()
                try:
                    return original(self_, *args, **kwargs)
                finally:
                    step["time_s"] = time.perf_counter() - t0
                    inst._current_step = None
                    inst.steps.append(step)

            return wrapper

        self._patch(PF, "advance", stepper("advance"))
        self._patch(PF, "start_compression", stepper("start_compression"))

    def restore(self) -> None:
        while self._patches:
            owner, name, original = self._patches.pop()
            setattr(owner, name, original)


# ---------------------------------------------------------------------------- one run (child)
def _run_once(nodes: int) -> dict:
    import ddg
    from ddg.analytic import clamped_elastica_midpoint_height

    fingerprint = source_fingerprint()
    inst = _Instrument()
    inst.install()
    try:
        strip = ddg.Strip.from_ratios(WIDTH_RATIO, COMPRESSION_RATIO)
        protocol = ddg.LoadingProtocol(COMPRESSION_RATIO, compression_steps=COMPRESSION_STEPS, shear_steps=SHEAR_STEPS)
        c0, t0 = time.process_time(), time.perf_counter()
        result = ddg.simulate(strip, protocol, model="rod", resolution=nodes)
        wall = time.perf_counter() - t0
        cpu = time.process_time() - c0
    finally:
        inst.restore()

    s = result.summary
    exact = clamped_elastica_midpoint_height(COMPRESSION_RATIO)
    h = s.get("H_mid_over_L_compressed")
    rows = result.rows
    shear_rows = [r for r in rows if r["stage"] == "shear"]
    comp_steps = [st for st in inst.steps if st["dW_over_L"] == 0.0]
    shear_steps = [st for st in inst.steps if st["dW_over_L"] != 0.0]
    split = {c: inst.category_time.get(c, 0.0) for c in CATEGORIES}
    split["other"] = wall - sum(split.values())
    by_caller = defaultdict(lambda: {"solves": 0, "iterations": 0, "failed": 0, "iterations_failed": 0})
    for rec in inst.newton_calls:
        b = by_caller[rec["caller"]]
        b["solves"] += 1
        b["iterations"] += rec["iterations"]
        if not rec["converged"]:
            b["failed"] += 1
            b["iterations_failed"] += rec["iterations"]
    stable_flips = [
        {"dW_over_L": b["dW_over_L"], "stable_before": a["stable"], "stable_after": b["stable"]}
        for a, b in zip(shear_rows, shear_rows[1:]) if a["stable"] != b["stable"]
    ]
    switches = [r["dW_over_L"] for r in shear_rows if r["branch_switched"]]
    newton_iterations = int(s["newton_iterations"])
    return {
        "nodes": nodes,
        "ddg_source_sha256": fingerprint,
        "n_dof": s.get("n_dof"),
        "n_free_dof": s.get("n_free_dof"),
        "wall_time_s": wall,
        "cpu_time_s": cpu,
        "library_wall_time_s": s.get("wall_time_s"),
        "newton_iterations": newton_iterations,
        "time_per_newton_iteration_ms": 1e3 * wall / newton_iterations if newton_iterations else None,
        "recorded_steps": len(rows),
        "recorded_shear_steps": len(shear_rows),
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
        "newton_by_caller": dict(by_caller),
        "stage": {
            "compression": {"time_s": sum(st["time_s"] for st in comp_steps),
                            "iterations": sum(st["iterations_all"] for st in comp_steps),
                            "failed_solves": sum(st["failed_solves"] for st in comp_steps)},
            "shear": {"time_s": sum(st["time_s"] for st in shear_steps),
                      "iterations": sum(st["iterations_all"] for st in shear_steps),
                      "failed_solves": sum(st["failed_solves"] for st in shear_steps)},
        },
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


def _child(nodes: int, conn) -> None:
    try:
        conn.send(("ok", _run_once(nodes)))
    except BaseException:  # report any failure to the parent instead of dying silently
        conn.send(("error", traceback.format_exc()))
    finally:
        conn.close()


def run_in_child(nodes: int, timeout: float | None) -> tuple[str, object, float]:
    """Run one M in a fresh process; returns (status, payload, elapsed)."""
    ctx = mp.get_context("spawn")
    parent, child = ctx.Pipe(duplex=False)
    proc = ctx.Process(target=_child, args=(nodes, child), daemon=True)
    t0 = time.perf_counter()
    proc.start()
    child.close()
    try:
        if parent.poll(timeout):
            status, payload = parent.recv()
        else:
            status, payload = "timeout", f"no result within {timeout:g} s"
    except EOFError:
        status, payload = "error", f"child exited with code {proc.exitcode} without a result"
    elapsed = time.perf_counter() - t0
    if proc.is_alive():
        proc.terminate()  # only the child this function started
    proc.join(5)
    if proc.is_alive():
        proc.kill()
        proc.join()
    parent.close()
    return status, payload, elapsed


# ---------------------------------------------------------------------------- reporting
def fit_slope(xs, ys):
    """Least-squares slope of log(y) against log(x)."""
    if len(xs) < 2:
        return None
    lx = [math.log(x) for x in xs]
    ly = [math.log(y) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    sxx = sum((a - mx) ** 2 for a in lx)
    return sum((a - mx) * (b - my) for a, b in zip(lx, ly)) / sxx


def source_fingerprint() -> str:
    """sha256 over the ddg package sources, to tie the numbers to one state of the library."""
    import ddg

    root = Path(ddg.__file__).resolve().parent
    digest = hashlib.sha256()
    for path in sorted(root.rglob("*.py")):
        digest.update(str(path.relative_to(root)).encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()


def machine_info() -> dict:
    import numpy
    import scipy

    try:
        import ddg
        ddg_version = ddg.__version__
    except Exception:  # pragma: no cover
        ddg_version = None
    cpu = None
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return {
        "cpu_count": os.cpu_count(),
        "cpu_model": cpu,
        "platform": platform.platform(),
        "python": platform.python_version(),
        "numpy": numpy.__version__,
        "scipy": scipy.__version__,
        "ddg": ddg_version,
        "thread_env": {k: os.environ.get(k) for k in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")},
        "date": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
    }


HEADER = ("M", "free DOF", "wall s", "cpu s", "Newton its", "ms/it", "steps", "conv", "evals", "ms/eval", "eval %",
          "linalg %", "eig %", "other %", "H_mid/L", "rel err vs elastica")


def table_rows(results: list[dict]) -> list[tuple]:
    out = []
    for r in results:
        if r["status"] != "ok":
            out.append((str(r["nodes"]), "", r["status"]) + ("",) * (len(HEADER) - 3))
            continue
        f = r["split_fraction"]
        err = r["H_mid_rel_error"]
        out.append((
            str(r["nodes"]), str(r["n_free_dof"]), f"{r['wall_time_s']:.2f}", f"{r['cpu_time_s']:.2f}", str(r["newton_iterations"]),
            f"{r['time_per_newton_iteration_ms']:.2f}", str(r["recorded_steps"]), "yes" if r["converged"] else "NO",
            str(r["evaluations"]), f"{r['time_per_evaluation_ms']:.2f}" if r["time_per_evaluation_ms"] else "",
            f"{100 * f['evaluate']:.0f}", f"{100 * f['linalg']:.0f}", f"{100 * f['eigen']:.0f}", f"{100 * f['other']:.0f}",
            f"{r['H_mid_over_L_compressed']:.6f}" if r["H_mid_over_L_compressed"] is not None else "",
            f"{err:+.2e}" if err is not None else "",
        ))
    return out


def text_table(results: list[dict]) -> str:
    rows = [HEADER] + table_rows(results)
    widths = [max(len(row[i]) for row in rows) for i in range(len(HEADER))]
    lines = ["  ".join(c.rjust(w) for c, w in zip(row, widths)) for row in rows]
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines)


def markdown_table(results: list[dict]) -> str:
    lines = ["| " + " | ".join(HEADER) + " |", "|" + "|".join("---:" for _ in HEADER) + "|"]
    lines += ["| " + " | ".join(row) + " |" for row in table_rows(results)]
    return "\n".join(lines)


def scaling(results: list[dict]) -> dict:
    ok = [r for r in results if r["status"] == "ok" and r["converged"]]
    ms = [r["nodes"] for r in ok]
    out = {
        "nodes_fitted": ms,
        "wall_time_slope": fit_slope(ms, [r["wall_time_s"] for r in ok]),
        "newton_iterations_slope": fit_slope(ms, [r["newton_iterations"] for r in ok]),
        "time_per_iteration_slope": fit_slope(ms, [r["time_per_newton_iteration_ms"] for r in ok]),
        "category_slopes": {c: fit_slope(ms, [max(r["split_s"][c], 1e-12) for r in ok]) for c in (*CATEGORIES, "other")},
        "h_error_slope": fit_slope(ms, [abs(r["H_mid_rel_error"]) for r in ok]) if ok and all(r["H_mid_rel_error"] for r in ok) else None,
    }
    out["local_wall_time_slopes"] = {
        f"{a['nodes']}-{b['nodes']}": math.log(b["wall_time_s"] / a["wall_time_s"]) / math.log(b["nodes"] / a["nodes"])
        for a, b in zip(ok, ok[1:])
    }
    m100 = [r for r in ok if r["nodes"] == 100]
    out["target_linear"] = "slope ~ 1"
    out["target_M100_under_1s"] = (m100[0]["wall_time_s"] < 1.0) if m100 else None
    out["linear_met"] = None if out["wall_time_slope"] is None else bool(out["wall_time_slope"] <= 1.2)
    return out


def observations(results: list[dict]) -> list[str]:
    notes = []
    for r in results:
        if r["status"] != "ok":
            notes.append(f"M = {r['nodes']}: {r['status']} ({r.get('error', '')})".strip())
            continue
        st = r["stage"]
        nb = r["newton_by_caller"]
        steps = sorted(r["steps"], key=lambda s: -s["iterations_all"])[:3]
        worst = ", ".join(f"dL/L={s['dL_over_L']:.3f} dW/L={s['dW_over_L']:.4f}: {s['iterations_all']} its, "
                          f"{s['time_s']:.2f} s ({s['newton_solves']} solves, {s['failed_solves']} failed)" for s in steps)
        failed = sum(b["iterations_failed"] for b in nb.values())
        caller = ", ".join(f"{k} {v['solves']} solves/{v['iterations']} its" for k, v in sorted(nb.items()))
        flips = ", ".join(f"{f['dW_over_L']:.4f} ({'stable' if f['stable_after'] else 'unstable'})"
                          for f in r["stability_changes_during_shear"]) or "none"
        notes.append(
            f"M = {r['nodes']}: compression {st['compression']['iterations']} its / {st['compression']['time_s']:.2f} s, "
            f"shear {st['shear']['iterations']} its / {st['shear']['time_s']:.2f} s; iterations in failed Newton solves "
            f"{failed}; by caller: {caller}; most expensive recorded steps: {worst}; stability changes in shear at "
            f"dW/L = {flips}; branch switches at dW/L = "
            f"{', '.join(f'{x:.4f}' for x in r['branch_switches_dW_over_L']) or 'none'}; "
            "eigenvalue calls: " + "; ".join(f"{k} {v['calls']} calls/{v['time_s']:.2f} s"
                                             for k, v in r["calls"]["lowest_eigenpairs_paths"].items()) + "."
        )
    return notes


def _verdict(flag) -> str:
    return "not measured" if flag is None else ("met" if flag else "NOT met")


def _load() -> float | None:
    try:
        return round(os.getloadavg()[0], 2)
    except OSError:
        return None


def _fmt(x, spec=".3f"):
    return "n/a" if x is None else format(x, spec)


def markdown_report(report: dict) -> str:
    sc, mi = report["scaling"], report["machine"]
    lines = [
        "# Rod solver, full path: speed and accuracy",
        "",
        f"Scene: W/L = {WIDTH_RATIO}, dL/L = {COMPRESSION_RATIO} in {COMPRESSION_STEPS} recorded steps, then shear to "
        f"dW_max in {SHEAR_STEPS} recorded steps (`python -m benchmarks.rod_path`). Wall time is the best of "
        f"{report['repeat']} run(s) per M, each in a fresh process.",
        "",
        markdown_table(report["results"]),
        "",
        "cpu s = CPU time of the benchmark process during the same run (wall time above it means the process "
        "waited for a core, or for BLAS threads). evals = calls of RodModel.evaluate (Newton iterations plus line-search trials and the first evaluation "
        "of each solve); ms/eval = their mean time. "
        "Time split columns (share of the wall time): eval = " + CATEGORY_LABELS["evaluate"] + "; linalg = "
        + CATEGORY_LABELS["linalg"] + "; eig = " + CATEGORY_LABELS["eigen"] + " (including its own factorisations "
        "and Lanczos solves); other = " + CATEGORY_LABELS["other"] + ". The relative error compares H_mid/L at the "
        "end of compression with `ddg.analytic.clamped_elastica_midpoint_height(0.5)` = "
        f"{report['H_mid_over_L_exact']:.8f}.",
        "",
        f"- growth exponent d log(wall time) / d log(M) over M = {sc['nodes_fitted']}: **{_fmt(sc['wall_time_slope'], '.2f')}** "
        f"(Newton iterations: {_fmt(sc['newton_iterations_slope'], '.2f')}, time per iteration: "
        f"{_fmt(sc['time_per_iteration_slope'], '.2f')}); per category: "
        + ", ".join(f"{k} {_fmt(v, '.2f')}" for k, v in sc["category_slopes"].items())
        + "; between consecutive M: " + ", ".join(f"{k}: {v:.2f}" for k, v in sc["local_wall_time_slopes"].items()),
        f"- target linear growth (slope ~ 1, taken as <= 1.2): {_verdict(sc['linear_met'])}; "
        f"target M = 100 under 1 s: {_verdict(sc['target_M100_under_1s'])}",
        f"- load average (1 min) before / after the runs: {report['load_average'][0]} / {report['load_average'][1]} "
        "(other processes on the machine inflate wall times)",
        f"- accuracy: |rel err| slope against M: {_fmt(sc['h_error_slope'], '.2f')} (O(h^2) expects -2)",
        "",
        "## Where the Newton iterations go",
        "",
    ]
    lines += [f"- {n}" for n in report["observations"]]
    lines += [
        "",
        "## Machine",
        "",
        f"{mi['cpu_count']} CPUs ({mi['cpu_model']}), {mi['platform']}, Python {mi['python']}, numpy {mi['numpy']}, "
        f"scipy {mi['scipy']}, ddg {mi['ddg']}; {mi['date']}. ddg sources sha256 "
        f"`{report['ddg_source_sha256'][:16]}`" + (" (CHANGED during the run: runs may mix library versions)"
                                                   if report["ddg_source_changed_during_run"] else "") + ".",
        "",
    ]
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

    from ddg.analytic import clamped_elastica_midpoint_height

    fingerprint_start = source_fingerprint()
    load_start = _load()
    results = []
    for m in args.nodes:
        best, attempts = None, []
        for k in range(args.repeat):
            status, payload, elapsed = run_in_child(m, timeout)
            if status == "ok":
                attempts.append(payload["wall_time_s"])
                if best is None or payload["wall_time_s"] < best["wall_time_s"]:
                    best = payload
                print(f"M = {m} run {k + 1}/{args.repeat}: {payload['wall_time_s']:.2f} s, "
                      f"{payload['newton_iterations']} Newton its, converged {payload['converged']}", file=sys.stderr)
            else:
                print(f"M = {m} run {k + 1}/{args.repeat}: {status} after {elapsed:.0f} s", file=sys.stderr)
                if best is None:
                    best = {"nodes": m, "status": status, "error": payload if status == "error" else
                            f"stopped after {elapsed:.0f} s (--timeout {args.timeout:g})"}
                    if status == "error":
                        print(payload, file=sys.stderr)
                break  # a timeout or crash will repeat; do not wait again
        if "status" not in best:
            best["status"] = "ok"
            best["all_wall_times_s"] = attempts
        results.append(best)

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
        "scaling": scaling(results),
        "machine": machine_info(),
        "ddg_source_sha256": fingerprint_start,
        "load_average": [load_start, _load()],
        "ddg_source_changed_during_run": source_fingerprint() != fingerprint_start or any(
            r.get("ddg_source_sha256", fingerprint_start) != fingerprint_start for r in results),
    }
    report["observations"] = observations(results)

    out = Path(args.out)
    atomic_write_text(out / "rod_path.json", json.dumps(report, indent=1, default=float) + "\n")
    atomic_write_text(out / "rod_path.md", markdown_report(report))

    sc = report["scaling"]
    if report["ddg_source_changed_during_run"]:
        print("WARNING: the ddg sources changed while the benchmark ran; the runs may mix library versions",
              file=sys.stderr)
    print(text_table(results))
    print()
    print(f"growth exponent d log(time)/d log(M) over M = {sc['nodes_fitted']}: {_fmt(sc['wall_time_slope'], '.2f')} "
          f"(Newton iterations {_fmt(sc['newton_iterations_slope'], '.2f')}, time/iteration "
          f"{_fmt(sc['time_per_iteration_slope'], '.2f')}); target slope ~1 (<= 1.2): {_verdict(sc['linear_met'])}; "
          f"M = 100 under 1 s: {_verdict(sc['target_M100_under_1s'])}")
    print("split: eval = RodModel.evaluate, linalg = cholesky+solve, eig = lowest_eigenpairs, other = the rest")
    for n in report["observations"]:
        print("-", n)
    print(f"wrote {out / 'rod_path.json'} and {out / 'rod_path.md'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
