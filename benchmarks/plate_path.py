"""Speed benchmark of the plate solvers' full path (compression to dL/L = 1/2, then shear to dW_max).

    .venv/bin/python -m benchmarks.plate_path [--model plate|plate-midedge]
        [--triangles 500 1000 2000 4000 | --rows 8 12] [--width-ratio 1/6]
        [--shear-steps 120] [--shear-ratio R] [--compression-steps 40] [--repeat 1]
        [--out benchmarks/results] [--timeout 1800]

--model plate (default) is the paper's plate; --model plate-midedge the mid-edge plate
(ddg.models.midedge_plate.MidedgePlateModel), sized by --rows R (rows of triangles across W: the
mesh is ddg.geometry.plate_mesh.ghost_clamp_mesh(L, W, rows=R), passed as simulate's mesh; default
8 and 12, issue 29's speed targets) or by --triangles N (resolution=N). Its outputs are
OUT/midedge_path.json and OUT/midedge_path.md, with a "Targets (issue 29)" table: wall time
(best of --repeat) <= 8 s on 8 rows and <= 20 s on 12 rows, at most 6 Newton iterations per
recorded step (summary newton_iterations / recorded steps).

For each target triangle count N it runs

    ddg.simulate(ddg.Strip.from_ratios(W/L, 0.5),
                 ddg.LoadingProtocol(0.5, None, compression_steps=40, shear_steps=120),
                 model="plate", resolution=N)

in a fresh child process (so a run that exceeds --timeout can be stopped) and reports the actual
triangle count and free DOFs, the Hessian bandwidth, the wall and CPU time (best of --repeat),
Newton iterations, whether the path completed (and the library's message), the dW/L reached,
the evaluations per Newton iteration and the split of the time per Newton iteration between

  (a) element evaluation + assembly: PlateModel.evaluate (MidedgePlateModel.evaluate for the
      mid-edge plate; compiled kernels that write straight into the gradient and the band), with
      (a1) the kernels and (a3) the rest of evaluate;
  (b) factorisation and solves: SymmetricBanded.cholesky / .solve / .ldlt and any direct call of
      scipy.linalg.cholesky_banded / cho_solve_banded / solve_banded (and scipy.sparse.linalg
      splu / spsolve / factorized, in case the library starts using them);
  (c) eigenvalue work: ddg.solve.stability.lowest_modes, SymmetricBanded.lowest_eigenpairs
      (and scipy.sparse.linalg.eigsh / scipy.linalg.eig_banded called directly);
  (d) other: the rest of the wall time (Newton and continuation bookkeeping, predictors, band
      restriction and copies, observables, model and mesh set-up).

Method (benchmarks.common.measure_path; the library's public hooks only, nothing patched): the
child calls simulate three times. The first call is timed as the first call; the second, warm,
carries a ddg.solve.probe.Probe (every Newton solve of the path with its phase, every recorded
step with its wall time) and is the wall time reported; the third runs under cProfile. A
category's time is the time of its entry points' outermost calls there (a call made inside
another category's call counts once, for the outer one: the Cholesky factorisations and Lanczos
solves inside lowest_eigenpairs are eigenvalue work), as a share of the profiled call's wall time,
scaled to the un-profiled wall time. The compiled kernels are not Python calls for cProfile: their
time is the model's evaluate's own time, reported as (a1). Per-function times by enclosing category
are kept in the JSON ("calls.by_function", seconds under cProfile).

Writes OUT/plate_path.json (OUT/midedge_path.json for plate-midedge: all numbers, per-step detail
and machine info) and OUT/plate_path.md (OUT/midedge_path.md: the tables), both atomically
(ddg.output.io.atomic_write_text). Not part of the test run.
"""
from __future__ import annotations

import argparse
import functools
import sys

from benchmarks.common import (PROBE_METHOD, Provenance, after_path_text, best_of, category_split, eigen_calls,
                               eigen_paths_text,
                               shared_machine_note,
                               finish_path_report, fit_slope, fmt, function_key, load_line, machine_section,
                               measure_path, newton_notes, path_slopes, path_timing, ratio, run_in_child, run_notes,
                               section, slopes_markdown, slopes_text, source_fingerprint, table_section, text_table,
                               iterations_target, targets_markdown, wall_target)

WIDTH_RATIO = 1.0 / 6.0
COMPRESSION_RATIO = 0.5
COMPRESSION_STEPS = 40
SHEAR_STEPS = 120
TRIANGLES = [500, 1000, 2000, 4000]
MODELS = ("plate", "plate-midedge")
#: the report's name (OUT/<name>.json, OUT/<name>.md) per model
OUTPUT_NAME = {"plate": "plate_path", "plate-midedge": "midedge_path"}
#: default rows across W of the mid-edge plate (issue 29's speed targets)
MIDEDGE_ROWS = [8, 12]
#: issue 29: wall time (s, best of --repeat, warm, full path with thresholds) by rows across W
WALL_TARGET_S = {8: 8.0, 12: 20.0}
#: issue 29: Newton iterations per recorded step (summary newton_iterations / recorded steps)
ITERATIONS_PER_STEP_TARGET = 6.0
#: issue 31 (the paper's plate at W/L = 1/6, full default path with thresholds, best of 3, warm):
#: wall time by triangles, Newton iterations per recorded step
ISSUE31_WALL_TARGET_S = {2100: 6.0, 5740: 25.0}
ISSUE31_ITERATIONS_PER_STEP = 6.0
#: the compiled kernels each model's evaluate calls (dotted names)
KERNELS = {
    "plate": ("ddg.energies.stretch.add_edge_terms", "ddg.energies.hinge_bending.add_hinge_terms"),
    "plate-midedge": ("ddg.energies.membrane.add_membrane_terms",
                      "ddg.energies.smoothed_membrane.add_smoothed_membrane_terms",
                      "ddg.energies.midedge_bending.add_midedge_terms"),
}
EVALUATE_NAME = {"plate": "PlateModel.evaluate", "plate-midedge": "MidedgePlateModel.evaluate"}

#: level 1: where the wall time goes; level 2: inside the model's evaluate
LEVEL1 = ("evaluate", "linalg", "eigen")
LEVEL2 = ("kernels",)


def category_labels(model: str = "plate") -> dict:
    """The split's labels, naming the model's evaluate and its compiled kernels."""
    ev = EVALUATE_NAME[model]
    if model == "plate":
        kernels = ("(a1) energy/gradient/Hessian kernels: the compiled passes evaluate calls (ddg.energies "
                   "add_edge_terms, add_hinge_terms); cProfile does not see compiled calls, so this is evaluate's own "
                   "time (its few lines of Python included)")
        rest = f"(a3) rest of {ev} (the Python calls it makes: accumulators, reshapes, the Evaluation)"
    else:
        kernels = ("(a1) energy/gradient/Hessian kernels: the compiled passes evaluate calls "
                   "(ddg.energies.membrane.add_membrane_terms, ddg.energies.smoothed_membrane."
                   "add_smoothed_membrane_terms (the node-smoothed part of the PSRI membrane, when alpha < 1), "
                   "ddg.energies.midedge_bending.add_midedge_terms); cProfile does not see compiled calls, so this is "
                   "evaluate's own time (its lines of Python included: the gather of q into node positions and edge "
                   "angles, the membrane matrices scaled by alpha)")
        rest = (f"(a3) rest of {ev} (the Python and builtin calls it makes: ascontiguousarray, accumulators, the "
                "Evaluation)")
    return {
        "evaluate": f"(a) element evaluation + assembly ({ev})",
        "kernels": kernels,
        "assembly": "(a2) band assembly: not a separate step since issue 14 (the kernels write into the band): n/a",
        "evaluate_rest": rest,
        **_COMMON_LABELS,
    }


_COMMON_LABELS = {
    "linalg": "(b) factorisation and solves (SymmetricBanded.cholesky, .solve, .ldlt; scipy cholesky_banded, "
              "cho_solve_banded, solve_banded called directly)",
    "eigen": "(c) eigenvalue work (stability.lowest_modes, SymmetricBanded.lowest_eigenpairs, with their own "
             "factorisations and Lanczos solves)",
    "other": "(d) everything else (Newton/continuation bookkeeping, predictors, band restriction and copies, "
             "observables, model set-up)",
}
CATEGORY_LABELS = category_labels("plate")


# ---------------------------------------------------------------------------- what is timed
def model_class(model: str = "plate"):
    """PlateModel or MidedgePlateModel (which overrides evaluate)."""
    if model == "plate-midedge":
        from ddg.models.midedge_plate import MidedgePlateModel

        return MidedgePlateModel
    from ddg.models.plate import PlateModel

    return PlateModel


def category_functions(model: str = "plate") -> dict:
    """The entry points of each level-1 category: {category: functions}."""
    import scipy.linalg
    import scipy.sparse.linalg

    from ddg.solve.banded import SymmetricBanded as SB
    from ddg.solve.stability import lowest_modes

    sl, ssl = scipy.linalg, scipy.sparse.linalg
    return {
        "evaluate": [model_class(model).evaluate],
        "linalg": [SB.cholesky, SB.solve, SB.ldlt, sl.cholesky_banded, sl.cho_solve_banded, sl.solve_banded,
                   ssl.splu, ssl.spsolve, ssl.factorized],
        "eigen": [lowest_modes, SB.lowest_eigenpairs, ssl.eigsh, sl.eig_banded, sl.eigvals_banded],
    }


def _eigen_functions() -> dict:
    import numpy as np
    from scipy.sparse.linalg import eigsh

    from ddg.solve.banded import SymmetricBanded as SB
    from ddg.solve.lanczos import lowest_eigenvalue
    from ddg.solve.stability import lowest_modes

    return {"lowest_modes": lowest_modes, "compiled Lanczos on the Cholesky factor": lowest_eigenvalue,
            "lowest_eigenpairs": SB.lowest_eigenpairs, "ARPACK eigsh": eigsh, "dense eigh": np.linalg.eigh}


# ---------------------------------------------------------------------------- one run (child)
def measure(target: int, config: dict) -> dict:
    """The record of one size (config["by"]: "triangles", target N, or "rows", target R rows across W
    of the mid-edge plate's ghost_clamp_mesh): the scene of config through measure_path, in this process."""
    import scipy.linalg

    import ddg
    from ddg.geometry.plate_mesh import ghost_clamp_mesh, structured_size
    from ddg.solve.band_ldlt import BandLDLT
    from ddg.solve.banded import SymmetricBanded as SB

    name = config.get("model", "plate")
    by = config.get("by", "triangles")
    fingerprint = source_fingerprint()
    strip = ddg.Strip.from_ratios(config["width_ratio"], COMPRESSION_RATIO)
    protocol = ddg.LoadingProtocol(COMPRESSION_RATIO, config["shear_ratio"],
                                   compression_steps=config["compression_steps"],
                                   shear_steps=config["shear_steps"])
    if by == "rows":
        m = measure_path(strip, protocol, name, None, mesh=ghost_clamp_mesh(strip.length, strip.width, rows=target))
        rows_across = target
    else:
        m = measure_path(strip, protocol, name, target)
        rows_across = structured_size(strip.length, strip.width, target)[1] if name == "plate-midedge" else None
    result, wall = m.result, m.wall_s
    s = result.summary
    model = result.model
    rows = result.rows
    its = int(s["newton_iterations"])
    fns = category_functions(name)
    evaluate = model_class(name).evaluate
    # compiled kernels that cProfile saw as Python calls (only without numba's JIT: then (a1) misses them)
    kernel_names = {k.rsplit(".", 1)[1] for k in KERNELS[name]}
    kernels_seen = sorted({key[2] for key in m.graph.stats if key[2] in kernel_names})

    def kernels(attr):
        # the compiled kernels are evaluate's own time; its share of the calls made outside other categories
        own, cumulative = m.graph.row(evaluate)[2], m.graph.row(evaluate)[3]
        outer = attr.outermost("evaluate")
        return {"kernels": own * (outer / cumulative if cumulative else 0.0)}

    rec, attr = category_split(m, fns, kernels)
    split = rec["split_s"]
    split["evaluate_rest"] = split["evaluate"] - split["kernels"]
    rec["split_fraction"] = {k: v / wall for k, v in split.items()}
    scale = wall / m.profiled_wall_s
    per_it = {k: (1e3 * v / its if its else None) for k, v in split.items()}

    # factorisation vs solves (outermost calls), and the banded LU inside the solves
    def outer(fn):
        return scale * attr.time(fn).get((None,), 0.0)

    linalg_detail = {
        "cholesky_s": outer(SB.cholesky),
        "solve_s": outer(SB.solve),
        "ldlt_s": outer(SB.ldlt),
        "lu_solve_banded_inside_solve_s": scale * attr.time(scipy.linalg.solve_banded).get(("linalg",), 0.0),
    }
    # factorisations by the category enclosing the SymmetricBanded.cholesky call that made them
    no_cholesky = {function_key(f): c for c, fs in fns.items() for f in fs if f is not SB.cholesky}
    around = m.graph.attribute([no_cholesky])
    factorisations = {ctx: v["calls"] for ctx, v in around.by_context(scipy.linalg.cholesky_banded).items()}
    total = round(sum(attr.calls(evaluate).values()))
    with_hessian = round(sum(v for ctx, v in attr.calls(SB.__init__).items() if ctx == ("evaluate",)))
    evals = {"total": total, "with_hessian": with_hessian, "without_hessian": total - with_hessian,
             "per_newton_iteration": total / its if its else None,
             "with_hessian_per_newton_iteration": with_hessian / its if its else None,
             "without_hessian_per_newton_iteration": (total - with_hessian) / its if its else None,
             "ms_per_call_all_kinds": 1e3 * split["evaluate"] / total if total else None}
    K = model.free_matrix(result.final_state.evaluation.hessian) if result.final_state is not None else None
    threshold_its = s.get("threshold_newton_iterations")
    n_rows = len(rows)
    return {
        "model": name,
        "triangles_target": target if by == "triangles" else None,
        "rows_target": target if by == "rows" else None,
        "rows_across": rows_across,
        "membrane": getattr(model, "membrane", None),
        "membrane_alpha": getattr(model, "membrane_alpha", None),
        "ddg_source_sha256": fingerprint,
        "triangles": int(model.mesh.triangle_count),
        "nodes": int(model.mesh.node_count),
        "n_dof": s.get("n_dof"),
        "n_free_dof": s.get("n_free_dof"),
        "bandwidth": int(K.band.shape[0] - 1) if K is not None else getattr(model, "bandwidth", None),
        **path_timing(m),
        "newton_iterations_per_recorded_step": its / n_rows if n_rows else None,
        "newton_iterations_per_recorded_step_with_threshold_location":
            (its + (threshold_its or 0)) / n_rows if n_rows else None,
        "completed": bool(s["converged"]),
        "message": s.get("message", ""),
        "dW_over_L_reached": float(rows[-1]["dW_over_L"]) if rows else None,
        "dW_max_over_L": s.get("dW_max_over_L"),
        "dW1_over_L": s.get("dW1_over_L"),
        "dW2_over_L": s.get("dW2_over_L"),
        "H_mid_over_L_compressed": s.get("H_mid_over_L_compressed"),
        **rec,
        "compiled_kernels": list(KERNELS[name]),
        "compiled_kernels_seen_by_cprofile": kernels_seen,
        "split_ms_per_newton_iteration": per_it,
        "linalg_detail": linalg_detail,
        "evaluations": evals,
        "calls": {
            "by_function": {f"{fn.__module__}.{fn.__qualname__}": attr.by_context(fn)
                            for fs in fns.values() for fn in fs if sum(attr.calls(fn).values())},
            "cholesky_factorisations": factorisations,
            "ldlt_factorisations": round(sum(attr.calls(BandLDLT.__init__).values())),
            "eigen_calls": eigen_calls(attr, _eigen_functions()),
        },
        "branch_switches_dW_over_L": [r["dW_over_L"] for r in rows
                                      if r["stage"] == "shear" and r.get("branch_switched")],
    }


# ---------------------------------------------------------------------------- reporting
RUN_HEADER = ("N target", "triangles", "free DOF", "band", "wall s", "cpu s", "Newton its", "ms/it", "complete",
              "dW/L reached", "steps", "its/step", "its/step + threshold", "full evals/it", "grad evals/it",
              "energy evals/it", "ms/full eval")
TARGET_HEADER = ("rows", "triangles", "wall s", "target s", "met", "its/step", "target its/step", "met")
SPLIT_HEADER = ("triangles", "eval ms/it", "kernels", "assembly", "eval rest", "factor+solve ms/it",
                "eigen ms/it", "other ms/it", "eval %", "kernels %", "assembly %", "linalg %", "eig %", "other %")
NA = "n/a"


def asked(r: dict) -> str:
    """The size a run was asked for: "N" (target triangles) or "R rows"."""
    return f"{r['rows_target']} rows" if r.get("rows_target") is not None else str(r["triangles_target"])


def label(r: dict) -> str:
    return f"R = {r['rows_target']} rows" if r.get("rows_target") is not None else f"N = {r['triangles_target']}"


def run_header(model: str = "plate") -> tuple:
    return RUN_HEADER if model == "plate" else ("asked",) + RUN_HEADER[1:]


def _run_rows(results: list[dict]) -> list[tuple]:
    out = []
    for r in results:
        if r["status"] != "ok":
            out.append((asked(r), "", r["status"]) + ("",) * (len(RUN_HEADER) - 3))
            continue
        ev = r["evaluations"]
        out.append((
            asked(r), str(r["triangles"]), str(r["n_free_dof"]), str(r["bandwidth"]),
            f"{r['wall_time_s']:.2f}", f"{r['cpu_time_s']:.2f}", str(r["newton_iterations"]),
            fmt(r["time_per_newton_iteration_ms"], ".2f"), "yes" if r["completed"] else "NO",
            fmt(r["dW_over_L_reached"], ".4f") + (f" / {r['dW_max_over_L']:.4f}" if r.get("dW_max_over_L") else ""),
            str(r["recorded_steps"]), fmt(r["newton_iterations_per_recorded_step"], ".2f"),
            fmt(r["newton_iterations_per_recorded_step_with_threshold_location"], ".2f"),
            fmt(ev["with_hessian_per_newton_iteration"], ".2f"), NA, NA, NA,
        ))
    return out


def _yes_no(ok) -> str:
    return NA if ok is None else ("yes" if ok else "no")


def targets(results: list[dict]) -> list[dict]:
    """Issue 29's targets per run: wall time (best of --repeat) against WALL_TARGET_S by rows across W,
    Newton iterations per recorded step against ITERATIONS_PER_STEP_TARGET; a target counts as met
    only on a completed path."""
    out = []
    for r in results:
        rows = r.get("rows_target") if r.get("rows_target") is not None else r.get("rows_across")
        if r["status"] != "ok":
            out.append({"asked": asked(r), "rows": rows, "status": r["status"]})
            continue
        wall_target = WALL_TARGET_S.get(rows)
        per_step = r["newton_iterations_per_recorded_step"]
        out.append({
            "asked": asked(r), "rows": rows, "status": "ok", "triangles": r["triangles"], "completed": r["completed"],
            "wall_time_s": r["wall_time_s"], "wall_target_s": wall_target,
            "wall_met": None if wall_target is None else bool(r["completed"] and r["wall_time_s"] <= wall_target),
            "iterations_per_step": per_step, "iterations_per_step_target": ITERATIONS_PER_STEP_TARGET,
            "iterations_met": None if per_step is None else bool(r["completed"]
                                                                 and per_step <= ITERATIONS_PER_STEP_TARGET),
        })
    return out


def issue31_targets(results: list[dict]) -> list[dict]:
    """Issue 31's targets for the paper's plate (completed paths only), each with what its figure
    is made of (benchmarks.common.wall_target, iterations_target)."""
    ok = [r for r in results if r["status"] == "ok" and r["completed"]]
    out = [wall_target(f"{r['triangles']} triangles, full default path", ISSUE31_WALL_TARGET_S[r["triangles"]], r,
                       (*LEVEL1, "other"))
           for r in ok if r["triangles"] in ISSUE31_WALL_TARGET_S]
    out += [iterations_target(f"{r['triangles']} triangles, Newton iterations per recorded step",
                              ISSUE31_ITERATIONS_PER_STEP, r) for r in ok]
    return out


def _target_rows(rows: list[dict]) -> list[tuple]:
    out = []
    for t in rows:
        if t["status"] != "ok":
            out.append((fmt(t["rows"], "d"), "", t["status"]) + ("",) * (len(TARGET_HEADER) - 3))
            continue
        out.append((fmt(t["rows"], "d"), str(t["triangles"]), f"{t['wall_time_s']:.2f}", fmt(t["wall_target_s"], "g"),
                    _yes_no(t["wall_met"]), fmt(t["iterations_per_step"], ".2f"),
                    f"{t['iterations_per_step_target']:g}", _yes_no(t["iterations_met"])))
    return out


def _split_rows(results: list[dict]) -> list[tuple]:
    out = []
    for r in results:
        if r["status"] != "ok":
            continue
        p, f = r["split_ms_per_newton_iteration"], r["split_fraction"]
        out.append((
            str(r["triangles"]), fmt(p["evaluate"], ".2f"), fmt(p["kernels"], ".2f"), NA,
            fmt(p["evaluate_rest"], ".2f"), fmt(p["linalg"], ".2f"), fmt(p["eigen"], ".2f"), fmt(p["other"], ".2f"),
            f"{100 * f['evaluate']:.0f}", f"{100 * f['kernels']:.0f}", NA,
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
    worst, failed, phase = newton_notes(r)
    fac = r["calls"]["cholesky_factorisations"]
    fac_txt = ", ".join(f"{ctx}: {n}" for ctx, n in fac.items())
    ld, ev = r["linalg_detail"], r["evaluations"]
    return (
        f"{label(r)} ({r['triangles']} triangles): {r['message']!r}. Compression "
        f"{st['compression']['iterations']} its / {st['compression']['time_s']:.2f} s, shear "
        f"{st['shear']['iterations']} its / {st['shear']['time_s']:.2f} s; iterations in failed Newton solves "
        f"{failed}; by phase: {phase}; after the path: {after_path_text(r)}; most expensive recorded steps: "
        f"{worst or 'none'}; branch switches at dW/L = "
        f"{', '.join(f'{x:.4f}' for x in r['branch_switches_dW_over_L']) or 'none'}. Evaluations: "
        f"{fmt(ev['per_newton_iteration'], '.2f')} per Newton iteration, "
        f"{fmt(ev['with_hessian_per_newton_iteration'], '.2f')} with the Hessian and "
        f"{fmt(ev['without_hessian_per_newton_iteration'], '.2f')} without (gradient or energy only), "
        f"{fmt(ev['ms_per_call_all_kinds'], '.2f')} ms each on average over all kinds. Linear algebra "
        f"(outermost calls, scaled): Cholesky {ld['cholesky_s']:.2f} s, solves {ld['solve_s']:.2f} s (of which "
        f"banded LU on indefinite matrices {ld['lu_solve_banded_inside_solve_s']:.2f} s), LDL^T {ld['ldlt_s']:.2f} s; "
        f"Cholesky factorisations by enclosing category: {fac_txt or 'none'}; LDL^T factorisations "
        f"{r['calls']['ldlt_factorisations']}. Eigenvalue calls (s under cProfile): "
        + (eigen_paths_text(r) or "none") + "."
    )


def observations(results: list[dict]) -> list[str]:
    return run_notes(results, label, _run_note)


def _overhead(results: list[dict]) -> str:
    """The profiled call's wall time against the un-profiled one's, and what it means for the split."""
    ratios = [r["profiled_wall_time_s"] / r["wall_time_s"] for r in results if r.get("status") == "ok"]
    if not ratios:
        return "no run to compare"
    text = f"the profiled call took {min(ratios):.2f}-{max(ratios):.2f} times as long as the un-profiled one; "
    if max(abs(x - 1.0) for x in ratios) <= 0.15:
        return text + ("within 15 %: cProfile's per-call overhead is small against the compiled and LAPACK work, and "
                       "the two calls differ as much by the machine's load and BLAS threads as by it")
    return text + ("cProfile's overhead is per Python call, so the shares lean a little towards the Python-heavy "
                   "categories")



def markdown_report(report: dict) -> str:
    sc, scene = report["scaling"], report["scene"]
    results = report["results"]
    model = scene.get("model", "plate")
    ev = EVALUATE_NAME[model]
    labels = report.get("split_categories") or category_labels(model)
    if model == "plate":
        lines = [
            "# Plate solver, full path: speed",
            "",
            f"Scene: W/L = {scene['width_ratio']:.6g}, dL/L = {COMPRESSION_RATIO} in {scene['compression_steps']} "
            f"recorded steps, then shear to dW/L = {scene['shear_ratio']} in {scene['shear_steps']} recorded steps, "
            f"model \"plate\" on the structured mesh with about N triangles (`python -m benchmarks.plate_path`). Wall "
            f"time is the best of {report['repeat']} run(s) per N, each in a fresh process.",
        ]
    else:
        lines = [
            "# Mid-edge plate solver, full path: speed",
            "",
            f"Scene: W/L = {scene['width_ratio']:.6g}, dL/L = {COMPRESSION_RATIO} in {scene['compression_steps']} "
            f"recorded steps, then shear to dW/L = {scene['shear_ratio']} in {scene['shear_steps']} recorded steps, "
            "thresholds located, model \"plate-midedge\" (`MidedgePlateModel`, default membrane) on "
            "`ghost_clamp_mesh(L, W, rows=R)` (asked \"R rows\") or with resolution N (asked \"N\") "
            "(`python -m benchmarks.plate_path --model plate-midedge`). Wall time is the best of "
            f"{report['repeat']} run(s) per size, each in a fresh process.",
        ]
        lines += table_section(
            "Targets (issue 29)", TARGET_HEADER, _target_rows(report.get("targets", [])),
            "rows = rows of triangles across W; wall s = the warm call's wall time, best of "
            f"{report['repeat']} (all of them: `all_wall_times_s` in the JSON); target s = issue 29's "
            + ", ".join(f"{v:g} s on {k} rows" for k, v in WALL_TARGET_S.items())
            + " (n/a for other rows); its/step = `summary['newton_iterations']` / recorded steps (rows of path.csv, "
            "the flat start included), threshold location not counted; met = the path completed and the figure is at "
            "or below the target.")
    lines += targets_markdown("Targets (issue 31)", report.get("issue31_targets", []))
    lines += table_section(
        "Runs", run_header(model), _run_rows(results),
        "triangles = `result.model.mesh.triangle_count`; free DOF = `summary['n_free_dof']`; band = bandwidth of the "
        "free-DOF Hessian (lower band storage rows - 1); wall s = the second, warm simulate call of the child, with a "
        "`ddg.solve.probe.Probe` (no profiler, no patching; the first call, which loads the compiled kernels from "
        "numba's cache, is `first_call_wall_s` in the JSON); cpu s = CPU time of the child process during the run "
        "(above the wall time when BLAS uses a second thread, below it when the process waited for a core); Newton "
        "its = `summary['newton_iterations']` (the path, including failed and branch-switching solves; threshold "
        "location is counted apart, in the notes below); complete = the path reached its last load (the message is "
        "below); dW/L reached = the last recorded row / the largest asked; its/step = Newton its / steps (recorded "
        "steps: rows of path.csv, the flat start included); its/step + threshold = (Newton its + "
        "`summary['threshold_newton_iterations']`) / steps. full evals/it = evaluations with the "
        "Hessian (energy + gradient + Hessian: one per accepted step and one at the start of each solve) per Newton "
        f"iteration, counted by cProfile as the SymmetricBanded Hessians built inside {ev} in the "
        "profiled call (the same, deterministic path). **grad evals/it, energy evals/it and ms/full eval are n/a**: "
        "the line search's trials without Hessian (energy + gradient on indefinite Hessians, energy only after a "
        "rejected full step) differ from a full evaluation only in evaluate's arguments, which neither cProfile "
        "nor the probe sees; their sum per iteration and the mean time of an evaluation over all kinds are in the "
        "notes below.")
    lines += table_section(
        "Time per Newton iteration", SPLIT_HEADER, _split_rows(results),
        "Milliseconds per Newton iteration (category time / Newton iterations; the evaluations, factorisations and "
        "eigen-solves outside the iterations proper are spread over them) and share of the wall time, **measured "
        "under cProfile** in a third, separate warm call of the same run and **scaled to the un-profiled wall time** "
        f"({_overhead(results)}). **assembly is n/a**: since issue 14 the "
        "compiled kernels write straight into the band, there is no assembly step to time.")
    lines += [""] + [f"- {labels[k]}" for k in ("evaluate", "kernels", "assembly", "evaluate_rest", "linalg",
                                                          "eigen", "other")]
    lines += [
        "",
        "Method: cProfile's caller data of the profiled call (`benchmarks.common.CallGraph`); a category's time is "
        "the time of its entry points' calls made outside any other category's call, so a call nested inside another "
        "category's call counts once, for the outermost one: the factorisations and Lanczos solves inside "
        "`lowest_eigenpairs` are eigenvalue work, not (b). Nothing in the library is patched. Per-function times by "
        "enclosing category are in the JSON (`calls.by_function`, seconds under cProfile). Until issue 15 the "
        "functions were wrapped with timers at run time; (a1) then read 0 (the compiled kernels were not found "
        "as Python functions) and the evaluations were split by kind from evaluate's arguments. Compiled kernels "
        "cProfile saw as Python calls (then missing from (a1)): "
        + (", ".join(sorted({k for r in results if r.get("status") == "ok"
                             for k in r.get("compiled_kernels_seen_by_cprofile", [])})) or "none") + ".",
        "",
        f"- growth exponent d log(wall time) / d log(triangles) over {sc['triangles_fitted']}: " + slopes_markdown(sc),
        load_line(report),
        *shared_machine_note(report),
    ]
    lines += section("Per run", report["observations"])
    lines += ["", "Newton iterations per stage, per phase (`ddg.solve.continuation.PHASES`) and per recorded step come "
              "from the probe of the warm call and add up to `summary['newton_iterations']` (checked: "
              + ("yes" if all(r.get("probe_matches_summary") for r in results if r.get("status") == "ok") else "NO")
              + "); until issue 15 they were counted per calling function (by caller). Threshold location and branch "
              "tracing come from summary.json and are part of the wall time."]
    lines += machine_section(report)
    return "\n".join(lines)


def build_report(results: list[dict], args, timeout) -> dict:
    model = getattr(args, "model", "plate")
    report = {
        "benchmark": OUTPUT_NAME[model],
        "scene": {"width_ratio": args.width_ratio, "compression_ratio": COMPRESSION_RATIO,
                  "compression_steps": args.compression_steps, "shear_steps": args.shear_steps,
                  "shear_ratio": "dW_max/L" if args.shear_ratio is None else args.shear_ratio, "model": model},
        "repeat": args.repeat,
        "timeout_s": timeout,
        "split_categories": category_labels(model),
        "method": PROBE_METHOD,
        "results": results,
    }
    if model == "plate":
        report["issue31_targets"] = issue31_targets(results)
    if model == "plate-midedge":
        report["targets"] = targets(results)
        report["targets_definition"] = {
            "wall_time_s_by_rows": WALL_TARGET_S, "newton_iterations_per_recorded_step": ITERATIONS_PER_STEP_TARGET,
            "source": "issue 29: W/L = 1/6, dL/L = 1/2, full path with thresholds, best of 3, warm"}
    return report


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.plate_path", description=__doc__.split("\n")[0])
    parser.add_argument("--model", choices=MODELS, default="plate",
                        help="plate (default; writes OUT/plate_path.*) or plate-midedge (writes OUT/midedge_path.*)")
    size = parser.add_mutually_exclusive_group()
    size.add_argument("--triangles", type=int, nargs="+", default=None,
                      help=f"target triangle counts N (default for plate: {' '.join(map(str, TRIANGLES))})")
    size.add_argument("--rows", type=int, nargs="+", default=None,
                      help="plate-midedge only: rows of triangles across W (even), the mesh ghost_clamp_mesh(L, W, "
                           f"rows=R) (default for plate-midedge: {' '.join(map(str, MIDEDGE_ROWS))})")
    parser.add_argument("--width-ratio", type=ratio, default=WIDTH_RATIO, help="W/L (decimal or fraction; default 1/6)")
    parser.add_argument("--compression-steps", type=int, default=COMPRESSION_STEPS)
    parser.add_argument("--shear-steps", type=int, default=SHEAR_STEPS)
    parser.add_argument("--shear-ratio", type=ratio, default=None,
                        help="largest dW/L (default dW_max/L); a small value gives a short smoke run")
    parser.add_argument("--repeat", type=int, default=1, help="runs per size; the best wall time is reported")
    parser.add_argument("--out", default="benchmarks/results",
                        help="directory for plate_path.json and .md (midedge_path.json and .md for plate-midedge)")
    parser.add_argument("--timeout", type=float, default=1800.0,
                        help="seconds allowed for one run of one size (0: no limit); a run over it is stopped, "
                             "reported")
    args = parser.parse_args(argv)
    if args.rows is not None and args.model != "plate-midedge":
        parser.error("--rows applies to --model plate-midedge only; give the plate --triangles")
    if args.rows is not None:
        by, sizes = "rows", args.rows
    elif args.triangles is not None or args.model == "plate":
        by, sizes = "triangles", args.triangles or TRIANGLES
    else:
        by, sizes = "rows", MIDEDGE_ROWS
    if args.repeat < 1 or args.shear_steps < 1 or args.compression_steps < 1:
        parser.error("--repeat, --shear-steps, --compression-steps must be >= 1")
    if by == "triangles" and any(t < 16 for t in sizes):
        parser.error("every N must be >= 16")
    if by == "rows" and any(r < 2 or r % 2 for r in sizes):
        parser.error("every R must be even and >= 2 (the centre y = 0 is a row of nodes)")
    timeout = args.timeout if args.timeout > 0 else None
    config = {"width_ratio": args.width_ratio, "shear_ratio": args.shear_ratio,
              "compression_steps": args.compression_steps, "shear_steps": args.shear_steps,
              "model": args.model, "by": by}

    def ident(n):
        return {"triangles_target": n, "rows_target": None} if by == "triangles" else \
            {"triangles_target": None, "rows_target": n}

    provenance = Provenance()
    results = [
        best_of(functools.partial(run_in_child, measure, (n, config), timeout), args.repeat, label(ident(n)),
                ident(n),
                lambda p: (f"{p['triangles']} triangles, {p['wall_time_s']:.2f} s, {p['newton_iterations']} Newton "
                           f"its, complete {p['completed']}"),
                args.timeout)
        for n in sizes
    ]

    report = build_report(results, args, timeout)
    wrote = finish_path_report(report, provenance, scaling, observations, markdown_report, args.out, blas=True)

    sc = report["scaling"]
    if "targets" in report:
        print(text_table(TARGET_HEADER, _target_rows(report["targets"])))
        print()
    print(text_table(run_header(args.model), _run_rows(results)))
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
