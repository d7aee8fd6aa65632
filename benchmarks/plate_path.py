"""Speed benchmark of the plate solver's full path (compression to dL/L = 1/2, then shear to dW_max).

    .venv/bin/python -m benchmarks.plate_path [--triangles 500 1000 2000 4000] [--width-ratio 1/6]
        [--shear-steps 120] [--shear-ratio R] [--compression-steps 40] [--repeat 1]
        [--out benchmarks/results] [--timeout 1800]

For each target triangle count N it runs

    ddg.simulate(ddg.Strip.from_ratios(W/L, 0.5),
                 ddg.LoadingProtocol(0.5, None, compression_steps=40, shear_steps=120),
                 model="plate", resolution=N)

in a fresh child process (so a run that exceeds --timeout can be stopped) and reports the actual
triangle count and free DOFs, the Hessian bandwidth, the wall and CPU time (best of --repeat),
Newton iterations, whether the path completed (and the library's message), the dW/L reached,
the evaluations per Newton iteration (full Hessian, gradient only, energy only) and the split of
the time per Newton iteration between

  (a) element evaluation + assembly: PlateModel.evaluate (compiled kernels that write straight
      into the gradient and the band; not split further since issue 14);
  (b) factorisation and solves: SymmetricBanded.cholesky / .solve and any direct call of
      scipy.linalg.cholesky_banded / cho_solve_banded / solve_banded (and scipy.sparse.linalg
      splu / spsolve / factorized, in case the library starts using them);
  (c) eigenvalue work: ddg.solve.stability.lowest_modes, SymmetricBanded.lowest_eigenpairs
      (and scipy.sparse.linalg.eigsh / scipy.linalg.eig_banded called directly);
  (d) other: the rest of the wall time (Newton and continuation bookkeeping, predictors, band
      restriction and copies, observables, model and mesh set-up).

Method: those functions are wrapped with timers at run time (time.perf_counter around each
call), in the child process only, and restored afterwards; the library is not modified. A
call made inside another timed call of categories (a)-(c) is counted once, by the outermost
one: the Cholesky factorisations and Lanczos solves inside lowest_eigenpairs are eigenvalue
work, a kernel call is counted inside (a). The kernels/assembly sub-split is taken the same
way one level down (the outermost kernel or assembly call inside evaluate). Per-function
inclusive times, split by the category of the enclosing call, are kept in the JSON
("calls.by_function"). The wrappers cost ~1 us per call, negligible against the ms-scale
calls they time.

Writes OUT/plate_path.json (all numbers, per-step detail and machine info) and OUT/plate_path.md
(the tables), both atomically (ddg.output.io.atomic_write_text). Not part of the test run.
"""
from __future__ import annotations

import argparse
import functools
import importlib
import inspect
import sys
import time
from collections import defaultdict

from benchmarks.common import (PathInstrument, Provenance, best_of, eigen_paths_text, finish_path_report, fit_slope,
                               fmt, load_line, machine_section, newton_by_caller, newton_notes, path_slopes,
                               path_timing, ratio, run_in_child, run_notes, section, slopes_markdown, slopes_text,
                               source_fingerprint, stage_summary, table_section, text_table, timed_simulate)

WIDTH_RATIO = 1.0 / 6.0
COMPRESSION_RATIO = 0.5
COMPRESSION_STEPS = 40
SHEAR_STEPS = 120
TRIANGLES = [500, 1000, 2000, 4000]

#: level 1: where the wall time goes; level 2: inside PlateModel.evaluate
LEVEL1 = ("evaluate", "linalg", "eigen")
LEVEL2 = ("kernels", "assembly")
CATEGORY_LABELS = {
    "evaluate": "(a) element evaluation + assembly (PlateModel.evaluate)",
    "kernels": "(a1) energy/gradient/Hessian kernels (ddg.energies.* called by PlateModel.evaluate)",
    "assembly": "(a2) band assembly (BandAssembler.assemble)",
    "evaluate_rest": "(a3) rest of PlateModel.evaluate (gathers, edge vectors, gradient bincounts)",
    "linalg": "(b) factorisation and solves (SymmetricBanded.cholesky, .solve; scipy cholesky_banded, "
              "cho_solve_banded, solve_banded called directly)",
    "eigen": "(c) eigenvalue work (stability.lowest_modes, SymmetricBanded.lowest_eigenpairs, with their own "
             "factorisations and Lanczos solves)",
    "other": "(d) everything else (Newton/continuation bookkeeping, predictors, band restriction and copies, "
             "observables, model set-up)",
}


# ---------------------------------------------------------------------------- instrumentation
class _Instrument(PathInstrument):
    """Timing wrappers on the plate's library functions, installed and removed around one run."""

    def __init__(self):
        super().__init__()
        self.stack: list[tuple[str, str]] = []             # (key, category) of the timed calls in progress
        self.level1 = defaultdict(float)                    # category -> time of outermost level-1 calls
        self.level1_calls = defaultdict(int)
        self.level2 = defaultdict(float)                    # (category, enclosing level-1 or "outside") -> time
        self.level2_calls = defaultdict(int)
        self.by_function = defaultdict(lambda: defaultdict(lambda: [0, 0.0]))  # key -> context -> [calls, s]
        self.eval_kinds = defaultdict(lambda: [0, 0.0])     # "full" / "gradient" / "energy" -> [calls, s]
        self.factorisations = defaultdict(lambda: defaultdict(int))  # context -> "ok"/"not PD" -> count
        self.eigen_paths = defaultdict(lambda: [0, 0.0])
        self.notes: list[str] = []

    # -- the timer
    def _timed(self, key: str, category: str, original, after=None):
        inst = self

        @functools.wraps(original)
        def wrapper(*args, **kwargs):
            stack = inst.stack
            outer1 = next((c for _, c in stack if c in LEVEL1), None)
            inside2 = any(c in LEVEL2 for _, c in stack)
            recursive = any(k == key for k, _ in stack)
            stack.append((key, category))
            t0 = time.perf_counter()
            try:
                result = original(*args, **kwargs)
            finally:
                dt = time.perf_counter() - t0
                stack.pop()
                if not recursive:
                    slot = inst.by_function[key][outer1 or "top"]
                    slot[0] += 1
                    slot[1] += dt
                if category in LEVEL1 and outer1 is None:
                    inst.level1[category] += dt
                    inst.level1_calls[category] += 1
                if category in LEVEL2 and not inside2:
                    inst.level2[(category, outer1 or "outside")] += dt
                    inst.level2_calls[(category, outer1 or "outside")] += 1
            if after is not None:
                after(args, kwargs, result, dt, outer1)
            return result

        wrapper.__wrapped_by_benchmark__ = True
        return wrapper

    def _patch_method(self, cls, name: str, key: str, category: str, after=None, required=False) -> bool:
        if name not in cls.__dict__:
            if required:
                raise RuntimeError(f"{cls.__name__}.{name} not found: the benchmark needs updating")
            self.notes.append(f"{cls.__name__}.{name} not found; not timed")
            return False
        self._set(cls, name, self._timed(key, category, cls.__dict__[name], after))
        return True

    def _patch_function(self, module, name: str, key: str, category: str) -> bool:
        """Wrap module.name and every reference to the same function object in loaded ddg modules
        (they import functions by name, e.g. `from .stability import lowest_modes`)."""
        original = getattr(module, name, None)
        if original is None or getattr(original, "__wrapped_by_benchmark__", False):
            if original is None:
                self.notes.append(f"{module.__name__}.{name} not found; not timed")
            return False
        wrapper = self._timed(key, category, original)
        self._set(module, name, wrapper)
        for mod_name, mod in list(sys.modules.items()):
            if mod is module or mod is None or not (mod_name == "ddg" or mod_name.startswith("ddg.")):
                continue
            for attr, value in list(vars(mod).items()):
                if value is original:
                    self._set(mod, attr, wrapper)
        return True

    def install(self) -> None:
        import scipy.linalg
        import scipy.sparse.linalg

        importlib.import_module("ddg.api")  # loads every module whose references are rebound below
        from ddg.models import plate
        from ddg.solve import banded, stability
        from ddg.solve.banded import SymmetricBanded

        inst = self

        # (a) evaluate, with the kind of evaluation
        evaluate = plate.PlateModel.__dict__["evaluate"]
        signature = inspect.signature(evaluate)

        def classify(args, kwargs, result, dt, outer1):
            if outer1 is not None:
                return
            try:
                bound = signature.bind(*args, **kwargs)
                bound.apply_defaults()
                grad, hess = bool(bound.arguments.get("gradient", True)), bool(bound.arguments.get("hessian", True))
                kind = "full" if (grad and hess) else ("gradient" if grad else "energy")
            except TypeError:
                kind = "unknown"
            inst.eval_kinds[kind][0] += 1
            inst.eval_kinds[kind][1] += dt

        self._patch_method(plate.PlateModel, "evaluate", "PlateModel.evaluate", "evaluate", classify, required=True)
        # (a1) kernels: the ddg.energies functions the plate module calls
        kernels = [name for name, value in vars(plate).items()
                   if inspect.isfunction(value) and (value.__module__ or "").startswith("ddg.energies")]
        for name in kernels:
            self._patch_function(plate, name, f"{plate.__dict__[name].__module__}.{name}", "kernels")
        if not kernels:
            self.notes.append("no ddg.energies functions found in ddg.models.plate; kernel time not separated")
        # (a2) assembly: since issue 14 the compiled kernels write straight into the band (no separate
        # assembly step); the kernels are numba dispatchers, timed as a whole inside evaluate

        # (b) factorisation and solves
        chol = SymmetricBanded.__dict__["cholesky"]

        @functools.wraps(chol)
        def cholesky_counting(self_, *a, **k):
            fresh = not getattr(self_, "_cholesky_tried", True)
            out = chol(self_, *a, **k)
            if fresh:
                context = next((c for _, c in inst.stack[:-1] if c in LEVEL1), None) or "top"
                inst.factorisations[context]["positive definite" if out else "not PD"] += 1
            return out

        self._set(SymmetricBanded, "cholesky", self._timed("SymmetricBanded.cholesky", "linalg", cholesky_counting))
        self._patch_method(SymmetricBanded, "solve", "SymmetricBanded.solve", "linalg")
        for name in ("cholesky_banded", "cho_solve_banded", "solve_banded"):
            self._patch_function(scipy.linalg, name, f"scipy.linalg.{name}", "linalg")
        for name in ("splu", "spsolve", "factorized"):
            self._patch_function(scipy.sparse.linalg, name, f"scipy.sparse.linalg.{name}", "linalg")

        # (c) eigenvalue work
        self._patch_function(stability, "lowest_modes", "stability.lowest_modes", "eigen")

        def eig_path(args, kwargs, result, dt, outer1):
            self_ = args[0]
            count = kwargs.get("count", args[1] if len(args) > 1 else 1)
            vectors = kwargs.get("vectors", args[2] if len(args) > 2 else False)
            if self_.n <= 4 * min(count, self_.n) + 20:
                path = "dense eigh"
            elif getattr(self_, "_cholesky", None) is not None:
                path = "Lanczos on A^-1 (A positive definite)"
            else:
                path = "Lanczos on (A + sigma I)^-1 (A indefinite, shift search)"
            path += ", with vectors" if vectors else ""
            inst.eigen_paths[path][0] += 1
            inst.eigen_paths[path][1] += dt

        self._patch_method(SymmetricBanded, "lowest_eigenpairs", "SymmetricBanded.lowest_eigenpairs", "eigen", eig_path)
        self._patch_function(scipy.sparse.linalg, "eigsh", "scipy.sparse.linalg.eigsh", "eigen")
        self._patch_function(scipy.linalg, "eig_banded", "scipy.linalg.eig_banded", "eigen")
        self._patch_function(scipy.linalg, "eigvals_banded", "scipy.linalg.eigvals_banded", "eigen")
        del banded  # imported so its `sla` module attribute lookups see the patched scipy functions

        # Newton solves (who called them, iterations, converged or not) and the recorded steps
        self.install_path_counters()


# ---------------------------------------------------------------------------- one run (child)
def _run_once(triangles: int, config: dict) -> dict:
    import ddg

    fingerprint = source_fingerprint()
    inst = _Instrument()
    strip = ddg.Strip.from_ratios(config["width_ratio"], COMPRESSION_RATIO)
    protocol = ddg.LoadingProtocol(COMPRESSION_RATIO, config["shear_ratio"],
                                   compression_steps=config["compression_steps"],
                                   shear_steps=config["shear_steps"])
    result, wall, cpu = timed_simulate(inst, strip, protocol, "plate", triangles)

    s = result.summary
    model = result.model
    rows = result.rows
    its = int(s["newton_iterations"])

    # level-1 split and the sub-split of evaluate
    split = {c: inst.level1.get(c, 0.0) for c in LEVEL1}
    split["other"] = wall - sum(split.values())
    sub = {c: inst.level2.get((c, "evaluate"), 0.0) for c in LEVEL2}
    sub["evaluate_rest"] = split["evaluate"] - sum(sub.values())
    outside = {f"{c} outside evaluate": inst.level2[(c, ctx)] for (c, ctx) in inst.level2 if ctx != "evaluate"}
    per_it = {k: (1e3 * v / its if its else None) for k, v in {**split, **sub}.items()}
    # linear algebra: factorisation vs solves (outermost calls only)
    fx = inst.by_function
    linalg_detail = {
        "cholesky_s": fx["SymmetricBanded.cholesky"]["top"][1] if "SymmetricBanded.cholesky" in fx else 0.0,
        "solve_s": fx["SymmetricBanded.solve"]["top"][1] if "SymmetricBanded.solve" in fx else 0.0,
        "lu_solve_banded_inside_solve_s": fx["scipy.linalg.solve_banded"]["linalg"][1]
        if "scipy.linalg.solve_banded" in fx else 0.0,
    }
    evals = {k: {"calls": v[0], "time_s": v[1], "per_newton_iteration": v[0] / its if its else None,
                 "ms_per_call": 1e3 * v[1] / v[0] if v[0] else None} for k, v in inst.eval_kinds.items()}
    K = model.free_matrix(result.final_state.evaluation.hessian) if result.final_state is not None else None
    return {
        "triangles_target": triangles,
        "ddg_source_sha256": fingerprint,
        "triangles": int(model.mesh.triangle_count),
        "nodes": int(model.mesh.node_count),
        "n_dof": s.get("n_dof"),
        "n_free_dof": s.get("n_free_dof"),
        "bandwidth": int(K.band.shape[0] - 1) if K is not None else getattr(model, "bandwidth", None),
        **path_timing(result, wall, cpu),
        "completed": bool(s["converged"]),
        "message": s.get("message", ""),
        "dW_over_L_reached": float(rows[-1]["dW_over_L"]) if rows else None,
        "dW_max_over_L": s.get("dW_max_over_L"),
        "dW1_over_L": s.get("dW1_over_L"),
        "dW2_over_L": s.get("dW2_over_L"),
        "H_mid_over_L_compressed": s.get("H_mid_over_L_compressed"),
        "split_s": {**split, **sub, **outside},
        "split_fraction": {k: v / wall for k, v in {**split, **sub}.items()},
        "split_ms_per_newton_iteration": per_it,
        "linalg_detail": linalg_detail,
        "evaluations": evals,
        "evaluations_total": sum(v[0] for v in inst.eval_kinds.values()),
        "calls": {
            "level1": {c: {"calls": inst.level1_calls[c], "time_s": inst.level1[c]} for c in LEVEL1},
            "by_function": {k: {ctx: {"calls": v[0], "time_s": v[1]} for ctx, v in d.items()} for k, d in fx.items()},
            "cholesky_factorisations": {ctx: dict(d) for ctx, d in inst.factorisations.items()},
            "lowest_eigenpairs_paths": {k: {"calls": v[0], "time_s": v[1]} for k, v in inst.eigen_paths.items()},
        },
        "newton_by_caller": newton_by_caller(
            inst.newton_calls, lambda rec: rec["caller"] + (" (minimize)" if rec["minimize"] else "")),
        "stage": stage_summary(inst.steps),
        "steps": inst.steps,
        "branch_switches_dW_over_L": [r["dW_over_L"] for r in rows if r["stage"] == "shear" and r.get("branch_switched")],
        "instrumentation_notes": inst.notes,
    }


# ---------------------------------------------------------------------------- reporting
RUN_HEADER = ("N target", "triangles", "free DOF", "band", "wall s", "cpu s", "Newton its", "ms/it", "complete",
              "dW/L reached", "steps", "full evals/it", "grad evals/it", "energy evals/it", "ms/full eval")
SPLIT_HEADER = ("triangles", "eval ms/it", "kernels", "assembly", "eval rest", "factor+solve ms/it",
                "eigen ms/it", "other ms/it", "eval %", "kernels %", "assembly %", "linalg %", "eig %", "other %")


def _run_rows(results: list[dict]) -> list[tuple]:
    out = []
    for r in results:
        if r["status"] != "ok":
            out.append((str(r["triangles_target"]), "", r["status"]) + ("",) * (len(RUN_HEADER) - 3))
            continue
        ev = r["evaluations"]

        def per_it(kind):
            v = ev.get(kind, {}).get("per_newton_iteration")
            return f"{v:.2f}" if v is not None else "0"

        full_ms = ev.get("full", {}).get("ms_per_call")
        out.append((
            str(r["triangles_target"]), str(r["triangles"]), str(r["n_free_dof"]), str(r["bandwidth"]),
            f"{r['wall_time_s']:.2f}", f"{r['cpu_time_s']:.2f}", str(r["newton_iterations"]),
            fmt(r["time_per_newton_iteration_ms"], ".2f"), "yes" if r["completed"] else "NO",
            fmt(r["dW_over_L_reached"], ".4f") + (f" / {r['dW_max_over_L']:.4f}" if r.get("dW_max_over_L") else ""),
            str(r["recorded_steps"]), per_it("full"), per_it("gradient"), per_it("energy"), fmt(full_ms, ".2f"),
        ))
    return out


def _split_rows(results: list[dict]) -> list[tuple]:
    out = []
    for r in results:
        if r["status"] != "ok":
            continue
        p, f = r["split_ms_per_newton_iteration"], r["split_fraction"]
        out.append((
            str(r["triangles"]), fmt(p["evaluate"], ".2f"), fmt(p["kernels"], ".2f"), fmt(p["assembly"], ".2f"),
            fmt(p["evaluate_rest"], ".2f"), fmt(p["linalg"], ".2f"), fmt(p["eigen"], ".2f"), fmt(p["other"], ".2f"),
            f"{100 * f['evaluate']:.0f}", f"{100 * f['kernels']:.0f}", f"{100 * f['assembly']:.0f}",
            f"{100 * f['linalg']:.0f}", f"{100 * f['eigen']:.0f}", f"{100 * f['other']:.0f}",
        ))
    return out


def _slope(xs, ys):
    """fit_slope, or None with fewer than two distinct x (targets that round to the same mesh)."""
    return fit_slope(xs, ys) if len(set(xs)) >= 2 else None


def scaling(results: list[dict]) -> dict:
    ok = [r for r in results if r["status"] == "ok" and r["completed"]]
    ts = [r["triangles"] for r in ok]
    return {"triangles_fitted": ts, **path_slopes(ts, ok, (*LEVEL1, *LEVEL2, "other"), _slope)}


def _run_note(r: dict) -> str:
    st = r["stage"]
    worst, failed, caller = newton_notes(r)
    fac = r["calls"]["cholesky_factorisations"]
    fac_txt = "; ".join(f"{ctx}: " + ", ".join(f"{n} {k}" for k, n in d.items()) for ctx, d in fac.items())
    ld = r["linalg_detail"]
    return (
        f"N = {r['triangles_target']} ({r['triangles']} triangles): {r['message']!r}. Compression "
        f"{st['compression']['iterations']} its / {st['compression']['time_s']:.2f} s, shear "
        f"{st['shear']['iterations']} its / {st['shear']['time_s']:.2f} s; iterations in failed Newton solves "
        f"{failed}; by caller: {caller}; most expensive recorded steps: {worst or 'none'}; branch switches at dW/L = "
        f"{', '.join(f'{x:.4f}' for x in r['branch_switches_dW_over_L']) or 'none'}. Linear algebra: Cholesky "
        f"{ld['cholesky_s']:.2f} s, solves {ld['solve_s']:.2f} s (of which banded LU on indefinite matrices "
        f"{ld['lu_solve_banded_inside_solve_s']:.2f} s); Cholesky factorisations by context: {fac_txt or 'none'}. "
        "Eigenvalue calls: " + (eigen_paths_text(r) or "none")
        + "." + (f" Instrumentation notes: {'; '.join(r['instrumentation_notes'])}." if r["instrumentation_notes"] else "")
    )


def observations(results: list[dict]) -> list[str]:
    return run_notes(results, lambda r: f"N = {r['triangles_target']}", _run_note)


def markdown_report(report: dict) -> str:
    sc, scene = report["scaling"], report["scene"]
    results = report["results"]
    lines = [
        "# Plate solver, full path: speed",
        "",
        f"Scene: W/L = {scene['width_ratio']:.6g}, dL/L = {COMPRESSION_RATIO} in {scene['compression_steps']} recorded "
        f"steps, then shear to dW/L = {scene['shear_ratio']} in {scene['shear_steps']} recorded steps, model "
        f"\"plate\" on the structured mesh with about N triangles (`python -m benchmarks.plate_path`). Wall time is "
        f"the best of {report['repeat']} run(s) per N, each in a fresh process.",
    ]
    lines += table_section(
        "Runs", RUN_HEADER, _run_rows(results),
        "triangles = `result.model.mesh.triangle_count`; free DOF = `summary['n_free_dof']`; band = bandwidth of the "
        "free-DOF Hessian (lower band storage rows - 1); cpu s = CPU time of the child process during the run (above "
        "the wall time when BLAS uses a second thread, below it when the process waited for a core); Newton its = "
        "`summary['newton_iterations']` (including failed and branch-switching solves); complete = the path reached "
        "its last load (the message is below); dW/L reached = the last recorded row / the largest asked. Evaluations "
        "per Newton iteration: full = energy + gradient + Hessian (one per accepted step and one at the start of "
        "each solve), grad = energy + gradient (line-search trials on indefinite Hessians), energy = energy only "
        "(line-search trials after a rejected full step).")
    lines += table_section(
        "Time per Newton iteration", SPLIT_HEADER, _split_rows(results),
        "Milliseconds per Newton iteration (category time / Newton iterations; the evaluations, factorisations and "
        "eigen-solves outside the iterations proper are spread over them) and share of the wall time:")
    lines += [""] + [f"- {CATEGORY_LABELS[k]}" for k in ("evaluate", "kernels", "assembly", "evaluate_rest", "linalg",
                                                  "eigen", "other")]
    lines += [
        "",
        "Method: the functions named above are wrapped with `time.perf_counter` timers at run time in the child "
        "process (the library is not modified; the wrappers are removed afterwards). A call nested inside another "
        "timed call is counted once, for the outermost one: the factorisations and Lanczos solves inside "
        "`lowest_eigenpairs` are eigenvalue work, not (b); kernels and assembly are counted inside (a). Per-function "
        "inclusive times by enclosing category are in the JSON (`calls.by_function`).",
        "",
        f"- growth exponent d log(wall time) / d log(triangles) over {sc['triangles_fitted']}: " + slopes_markdown(sc),
        load_line(report),
    ]
    lines += section("Per run", report["observations"])
    lines += machine_section(report)
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.plate_path", description=__doc__.split("\n")[0])
    parser.add_argument("--triangles", type=int, nargs="+", default=TRIANGLES, help="target triangle counts N")
    parser.add_argument("--width-ratio", type=ratio, default=WIDTH_RATIO, help="W/L (decimal or fraction; default 1/6)")
    parser.add_argument("--compression-steps", type=int, default=COMPRESSION_STEPS)
    parser.add_argument("--shear-steps", type=int, default=SHEAR_STEPS)
    parser.add_argument("--shear-ratio", type=ratio, default=None,
                        help="largest dW/L (default dW_max/L); a small value gives a short smoke run")
    parser.add_argument("--repeat", type=int, default=1, help="runs per N; the best wall time is reported")
    parser.add_argument("--out", default="benchmarks/results", help="directory for plate_path.json and plate_path.md")
    parser.add_argument("--timeout", type=float, default=1800.0,
                        help="seconds allowed for one run of one N (0: no limit); a run over it is stopped and reported")
    args = parser.parse_args(argv)
    if args.repeat < 1 or any(t < 16 for t in args.triangles) or args.shear_steps < 1 or args.compression_steps < 1:
        parser.error("--repeat, --shear-steps, --compression-steps must be >= 1 and every N >= 16")
    timeout = args.timeout if args.timeout > 0 else None
    config = {"width_ratio": args.width_ratio, "shear_ratio": args.shear_ratio,
              "compression_steps": args.compression_steps, "shear_steps": args.shear_steps}

    provenance = Provenance()
    results = [
        best_of(functools.partial(run_in_child, _run_once, (n, config), timeout), args.repeat, f"N = {n}",
                {"triangles_target": n},
                lambda p: (f"{p['triangles']} triangles, {p['wall_time_s']:.2f} s, {p['newton_iterations']} Newton "
                           f"its, complete {p['completed']}"),
                args.timeout)
        for n in args.triangles
    ]

    report = {
        "benchmark": "plate_path",
        "scene": {"width_ratio": args.width_ratio, "compression_ratio": COMPRESSION_RATIO,
                  "compression_steps": args.compression_steps, "shear_steps": args.shear_steps,
                  "shear_ratio": "dW_max/L" if args.shear_ratio is None else args.shear_ratio, "model": "plate"},
        "repeat": args.repeat,
        "timeout_s": timeout,
        "split_categories": CATEGORY_LABELS,
        "method": "run-time timer wrappers; nested timed calls counted once, by the outermost (see module docstring)",
        "results": results,
    }
    wrote = finish_path_report(report, provenance, scaling, observations, markdown_report, args.out, blas=True)

    sc = report["scaling"]
    print(text_table(RUN_HEADER, _run_rows(results)))
    print()
    print(text_table(SPLIT_HEADER, _split_rows(results)))
    print()
    print(f"growth exponent d log(time)/d log(triangles) over {sc['triangles_fitted']}: {slopes_text(sc)}")
    for n in report["observations"]:
        print("-", n)
    print(wrote)
    return 0


if __name__ == "__main__":
    sys.exit(main())
