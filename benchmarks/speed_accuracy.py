"""Speed against accuracy of the three plate models at one scene: the paper's plate, the mid-edge
plate and the FEM shell, on the meshes of their mesh studies (issue 29).

    .venv/bin/python -m benchmarks.speed_accuracy [--only ENTRY ...] [--out benchmarks/results]
        [--timeout 3600] [--rerun]

Scene (fixed): W/L = 1/6, dL/L = 1/2, the default strip (L/b = 1181, ddg.Strip.from_ratios(1/6,
0.5)), the default path (docs/guide/run_a_scene.rst): compression in 40 recorded steps, shear in
120 to dW_max, dW1 and dW2 located, no branch tracing. The entries are exactly the runs of the mesh
studies of this scene:

- plate:8, plate:12, plate:18: the paper's plate on equilateral meshes of 8/12/18 rows of
  triangles across W (data/plate_gold/dL0.5_W0.1667/R<rows>), run by validation.plate_gold.run_mesh
  (its model_mesh("plate", L, W, rows));
- plate-midedge:8, :12, :18 (data/midedge_gold/dL0.5_W0.1667/R<rows>) and plate-midedge:28 (no
  stored study run): the same function with model "plate-midedge" (ghost-clamp meshes);
- fem:64x8, fem:96x12, fem:144x18: the Naghdi shell on the FEM gold meshes
  (data/fem_gold/dL0.5_W0.1667/N<along>x<across>), run by fem_reference.gold.run_mesh (dW1 and dW2
  bisected to the gold tolerances; dolfinx is imported in the child only).

Method: each entry runs in a fresh child process (benchmarks.common.run_in_child, --timeout
seconds) into a temporary folder. A DDG child first makes an untimed warm-up simulate (the same
model on a ghost-clamp or equilateral mesh of WARMUP_ROWS rows, WARMUP_STEPS recorded steps per
stage, thresholds located), so that loading numba's compiled kernels is not timed; the FEM child has
no warm-up (its form compilation, cached by FFCx on disk, is in summary build_wall_time_s). Timed:
the run_mesh call, wall (perf_counter) and CPU time of the child process (process_time, all its
threads). From the run's summary.json: status, path_complete, Newton iterations (all of them:
the path and the threshold location; DDG summaries count the latter apart, FEM summaries within
newton_iterations), recorded steps, dW1/L, dW2/L, triangles, unknowns (n_free_dof). Each entry
also carries the dW1/dW2 of the stored study run on the same mesh (its summary.json; None where
there is none) and the difference, a reproducibility check against the bisection bracket.
OUT/speed_accuracy.json is rewritten atomically after each entry, with the load average before
and after it; an entry stored with status ok and the same ddg source fingerprint
(benchmarks.common.source_fingerprint; for FEM entries also the fem_reference one) is kept unless
--rerun; Ctrl-C or SIGTERM keeps the finished entries (exit 130/143). Bad input (an unknown entry,
a negative --timeout, an unwritable --out) gives a one-line error and exit 2 before any work.

Reference (fixed before any entry was measured): the FEM shell's converged dW1/L and dW2/L at this
scene with their error bars, exactly as the benchmark table (validation.benchmark) takes them:
validation.estimates.load_study("fem", 1/2, 1/6), i.e. data/fem_gold/dL0.5_W0.1667/richardson.json,
the estimate of fem_reference.convergence.estimate under error-bar rule 2 (when this was written:
dW1/L = 0.2654 +- 0.0031, dW2/L = 0.4308 +- 0.0125). The error of an entry is |dW1/L - reference
value| (and |dW2/L - reference value| for dW2).

Verdict on issue 29's target "At equal dW1 error of 0.003 L the mid-edge plate is at least 10x
faster than the FEM" (TARGET_DW1_ERROR, TARGET_SPEEDUP): for each model, the cheapest measured entry
(least wall time) whose dW1 error is <= 0.003; ratio = the FEM's wall time / the mid-edge plate's.
Decided in this order:
1. "undecided" if the reference's own dW1 error bar exceeds 0.003: errors below the bar cannot be
   resolved;
2. "undecided" if an entry of the mid-edge plate or of the FEM is not measured (not run, failed or
   timed out): a missing run could be the cheapest one within 0.003;
3. "not met" if no mid-edge entry is within 0.003;
4. "undecided" if no FEM entry is within 0.003 (no FEM time at that accuracy to compare with);
5. "met" if the ratio is >= 10, else "not met".
Every verdict is reported with its figures (each model's cheapest entry within 0.003 with its wall
time and error, the ratio where both exist, the reference's bar).

Outputs: OUT/speed_accuracy.json (every number, machine info, provenance), OUT/speed_accuracy.md
(scene, method, reference, the table, the verdict with its figures, the reproducibility check)
and, if matplotlib is importable, OUT/speed_accuracy.png (wall time against dW1 error, log-log).
Not part of the test run.
"""
from __future__ import annotations

import argparse
import math
import sys
import tempfile
import time
import warnings
from dataclasses import dataclass
from pathlib import Path

from benchmarks.common import (Provenance, fmt, load_average, load_line, machine_section, markdown_table,
                               run_in_child, section, shared_machine_note, source_fingerprint, text_table,
                               write_report)

BENCHMARK = "speed_accuracy"
WIDTH_RATIO = 1.0 / 6.0
WIDTH_RATIO_TEXT = "1/6"
COMPRESSION_RATIO = 0.5
COMPRESSION_STEPS = 40
SHEAR_STEPS = 120
MODELS = ("plate", "plate-midedge", "fem")
MODEL_TITLES = {"plate": "plate (paper)", "plate-midedge": "mid-edge plate", "fem": "FEM shell"}
#: rows of the mid-edge plate beyond its study's meshes (no stored study run)
EXTRA_MIDEDGE_ROWS = (28,)
#: issue 29: the dW1 error (units of L) at which the speeds are compared, and the speed-up asked
TARGET_DW1_ERROR = 0.003
TARGET_SPEEDUP = 10.0
#: the DDG warm-up (untimed): rows across W and recorded steps per stage
WARMUP_ROWS = 4
WARMUP_STEPS = 4
TIMEOUT_S = 3600.0
THRESHOLDS = ("dW1", "dW2")
#: floor of the chart's error axis (an error of exactly 0 has no logarithm)
CHART_ERROR_FLOOR = 1e-5


# ---------------------------------------------------------------------------- the entries
@dataclass(frozen=True)
class Entry:
    """One run of the benchmark: a model on one mesh of its study."""
    model: str
    rows: int | None = None      # DDG: rows of triangles across W
    along: int | None = None     # FEM: elements along L
    across: int | None = None    # FEM: elements across W

    @property
    def mesh(self) -> str:
        return f"{self.along}x{self.across}" if self.model == "fem" else str(self.rows)

    @property
    def name(self) -> str:
        return f"{self.model}:{self.mesh}"

    @property
    def folder(self) -> str:
        """The run folder of the mesh study (R<rows>, N<along>x<across>)."""
        return f"N{self.along}x{self.across}" if self.model == "fem" else f"R{self.rows}"


def scene() -> str:
    """The scene folder of the studies (dL0.5_W0.1667)."""
    from fem_reference.gold import scene_name

    return scene_name(COMPRESSION_RATIO, WIDTH_RATIO)


def entries() -> list[Entry]:
    """Every entry, in the report's order: the studies' meshes of the scene (validation.plate_gold
    .rows_sequence, fem_reference.gold.mesh_sequence), plus EXTRA_MIDEDGE_ROWS."""
    from fem_reference.gold import mesh_sequence
    from validation.plate_gold import rows_sequence

    rows = rows_sequence(WIDTH_RATIO)
    return ([Entry("plate", rows=r) for r in rows]
            + [Entry("plate-midedge", rows=r) for r in [*rows, *EXTRA_MIDEDGE_ROWS]]
            + [Entry("fem", along=a, across=c) for a, c in mesh_sequence(WIDTH_RATIO)])


def entry_names() -> list[str]:
    return [e.name for e in entries()]


def parse_entries(values) -> list[Entry]:
    """The entries named (in the report's order, each once); all of them for None. InputError
    naming the value and the allowed ones otherwise."""
    from ddg.geometry.strip import InputError

    known = {e.name: e for e in entries()}
    if values is None:
        return list(known.values())
    unknown = [v for v in dict.fromkeys(values) if v not in known]
    if unknown:
        raise InputError(f"--only: unknown entry {', '.join(map(repr, unknown))}; allowed: {', '.join(known)}")
    return [e for name, e in known.items() if name in values]


# ---------------------------------------------------------------------------- the reference and the errors
def reference(root: Path | None = None) -> dict:
    """The FEM's converged dW1/L and dW2/L at the scene with their error bars, as the benchmark
    table reads them (validation.estimates.load_study("fem", ...)); `root` replaces data/fem_gold.
    {"source", "dW1": {"value", "error_bar", "basis", "order", "asymptotic", "meshes", "rule"}, "dW2": ...};
    a threshold without a study value is None."""
    from ddg.output.io import read_json_object
    from validation.estimates import STUDY_ROOTS, load_study

    study = load_study("fem", COMPRESSION_RATIO, WIDTH_RATIO, root=root)
    folder = Path(root or STUDY_ROOTS["fem"]) / scene()
    raw = read_json_object(folder / "richardson.json") or {}
    out = {"source": study.source if study is not None else str(folder / "richardson.json")}
    for key in THRESHOLDS:
        estimate = study.threshold(key) if study is not None else None
        out[key] = None if estimate is None else {
            "value": estimate.value, "error_bar": estimate.error_bar, "basis": estimate.basis,
            "order": estimate.order, "asymptotic": estimate.asymptotic,
            "meshes": (raw.get(key) or {}).get("meshes"), "rule": (raw.get(key) or {}).get("rule")}
    return out


def threshold_error(record: dict, ref: dict, key: str) -> float | None:
    """|key/L of the entry - the reference value| (None without either)."""
    value, r = record.get(f"{key}_over_L"), ref.get(key)
    if value is None or r is None or r.get("value") is None:
        return None
    return abs(float(value) - float(r["value"]))


# ---------------------------------------------------------------------------- one entry (child)
def _newton_counts(model: str, summary: dict) -> tuple[int, int, int]:
    """(all Newton iterations, those of the path, those of the threshold location): DDG summaries
    count the threshold location apart from newton_iterations, FEM summaries within it."""
    its = int(summary.get("newton_iterations") or 0)
    threshold = int(summary.get("threshold_newton_iterations") or 0)
    if model == "fem":
        return its, its - threshold, threshold
    return its + threshold, its, threshold


def measure(model: str, rows: int | None, along: int | None, across: int | None) -> dict:
    """The record of one entry, in this (fresh) process: the study's run_mesh into a temporary
    folder, timed; a DDG entry after an untimed warm-up."""
    import resource

    from ddg.output.io import read_json_object

    record = {"ddg_source_sha256": source_fingerprint()}
    if model == "fem":
        from benchmarks.fem_path import fem_fingerprint
        from fem_reference.gold import run_mesh

        record["fem_reference_source_sha256"] = fem_fingerprint()
        args = (COMPRESSION_RATIO, WIDTH_RATIO, None, along, across)
    else:
        import ddg
        from validation.plate_gold import model_mesh, run_mesh

        strip = ddg.Strip.from_ratios(WIDTH_RATIO, COMPRESSION_RATIO)
        c0, t0 = time.process_time(), time.perf_counter()
        with warnings.catch_warnings():  # the coarse warm-up's validity warnings are not the entry's
            warnings.simplefilter("ignore")
            ddg.simulate(strip, ddg.LoadingProtocol(COMPRESSION_RATIO, compression_steps=WARMUP_STEPS,
                                                    shear_steps=WARMUP_STEPS),
                         model=model, mesh=model_mesh(model, strip.length, strip.width, WARMUP_ROWS),
                         branches=False, centerline=False)
        record.update(warmup_wall_time_s=time.perf_counter() - t0, warmup_cpu_time_s=time.process_time() - c0)
        args = (scene(), COMPRESSION_RATIO, WIDTH_RATIO, None, rows, model)
    with tempfile.TemporaryDirectory(prefix="speed_accuracy_") as tmp:
        target = Path(tmp) / "run"
        c0, t0 = time.process_time(), time.perf_counter()
        returned = run_mesh(*args, str(target))
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        summary = read_json_object(target / "summary.json") or {}
    record.update(wall_time_s=wall, cpu_time_s=cpu,
                  peak_rss_bytes=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024,
                  run_mesh_returned=returned)
    if "error" in returned or not summary:
        return {**record, "status": "error", "error": returned.get("error", "no summary.json written")}
    all_its, path_its, threshold_its = _newton_counts(model, summary)
    steps = summary.get("recorded_steps")
    mesh = summary.get("mesh") or {}
    return {
        **record,
        "status": "ok",
        "run_status": summary.get("status"),
        "path_complete": summary.get("path_complete"),
        "converged": summary.get("converged"),
        "message": summary.get("message", ""),
        "library_wall_time_s": summary.get("wall_time_s"),
        "threshold_wall_time_s": summary.get("threshold_wall_time_s"),
        "build_wall_time_s": summary.get("build_wall_time_s"),
        "newton_iterations": all_its,
        "path_newton_iterations": path_its,
        "threshold_newton_iterations": threshold_its,
        "newton_iterations_by_phase": summary.get("newton_iterations_by_phase"),
        "recorded_steps": steps,
        "path_iterations_per_recorded_step": path_its / steps if steps else None,
        "dW1_over_L": summary.get("dW1_over_L"),
        "dW2_over_L": summary.get("dW2_over_L"),
        "dW_max_over_L": summary.get("dW_max_over_L"),
        "resolved_up_to_dW_over_L": summary.get("resolved_up_to_dW_over_L"),
        "threshold_tolerances_over_L": summary.get("threshold_tolerances_over_L"),
        "triangles": mesh.get("triangles"),
        "n_dof": summary.get("n_dof"),
        "n_free_dof": summary.get("n_free_dof"),
        "mesh": mesh,
        "warnings": summary.get("warnings"),
    }


# ---------------------------------------------------------------------------- the stored study runs
def bisection_brackets(model: str) -> dict:
    """The bisection brackets (units of L) of the study runs: the FEM gold's, the DDG's."""
    if model == "fem":
        from fem_reference.gold import GOLD_TOLERANCES

        return dict(zip(THRESHOLDS, GOLD_TOLERANCES))
    from validation.plate_gold import DDG_TOLERANCES

    return dict(DDG_TOLERANCES)


def study_comparison(entry: Entry, record: dict, roots: dict | None = None) -> dict:
    """The stored study run on the entry's mesh (its summary.json: dW1/L, dW2/L, status, wall
    time; None where there is none) and the entry's differences from it, each with the bisection
    bracket it is compared with."""
    from ddg.output.io import read_json_object
    from validation.estimates import STUDY_ROOTS

    root = Path((roots or STUDY_ROOTS)[entry.model])
    folder = root / scene() / entry.folder
    stored = read_json_object(folder / "summary.json")
    brackets = bisection_brackets(entry.model)
    repo = Path(__file__).resolve().parents[1]
    shown = folder.resolve().relative_to(repo) if folder.resolve().is_relative_to(repo) else folder
    out = {"study_run": str(shown), "study_run_found": stored is not None,
           "study_status": None if stored is None else stored.get("status"),
           "study_wall_time_s": None if stored is None else stored.get("wall_time_s")}
    for key in THRESHOLDS:
        theirs = None if stored is None else stored.get(f"{key}_over_L")
        ours = record.get(f"{key}_over_L") if record.get("status") == "ok" else None
        diff = None if theirs is None or ours is None else float(ours) - float(theirs)
        out[f"study_{key}_over_L"] = theirs
        out[f"{key}_difference_from_study"] = diff
        out[f"{key}_bisection_bracket"] = brackets[key]
        out[f"{key}_within_bracket_of_study"] = None if diff is None else abs(diff) <= brackets[key]
    return out


# ---------------------------------------------------------------------------- the verdict
def measured(record: dict | None) -> bool:
    return bool(record) and record.get("status") == "ok"


def cheapest_within(records: dict, model: str, ref: dict, target: float = TARGET_DW1_ERROR) -> dict | None:
    """The model's measured entry of least wall time whose dW1 error is <= target:
    {"entry", "wall_time_s", "cpu_time_s", "dW1_error"}; None if it has none."""
    best = None
    for name, r in records.items():
        if not measured(r) or r.get("model") != model:
            continue
        error = threshold_error(r, ref, "dW1")
        if error is not None and error <= target and (best is None or r["wall_time_s"] < best["wall_time_s"]):
            best = {"entry": name, "wall_time_s": r["wall_time_s"], "cpu_time_s": r.get("cpu_time_s"),
                    "dW1_error": error}
    return best


def verdict(records: dict, ref: dict, names=None, target: float = TARGET_DW1_ERROR,
            speedup: float = TARGET_SPEEDUP) -> dict:
    """Issue 29's verdict by the rule of the module docstring, with its figures. `records`: {entry
    name: record}; `names`: every entry of the benchmark (default entry_names())."""
    names = list(entry_names() if names is None else names)
    bar = (ref.get("dW1") or {}).get("error_bar")
    best = {m: cheapest_within(records, m, ref, target) for m in MODELS}
    mid, fem = best["plate-midedge"], best["fem"]
    ratio = fem["wall_time_s"] / mid["wall_time_s"] if mid and fem and mid["wall_time_s"] > 0 else None
    missing = [n for n in names if n.split(":")[0] in ("plate-midedge", "fem") and not measured(records.get(n))]
    out = {"target_dW1_error_over_L": target, "target_speedup": speedup, "reference_dW1_error_bar": bar,
           "cheapest_within_target": best, "ratio": ratio, "unmeasured": missing}
    if bar is None or bar > target:
        what = "has no error bar" if bar is None else f"error bar {bar:.5f} exceeds the target {target:g}"
        return {**out, "verdict": "undecided", "step": 1,
                "reason": f"the reference's dW1 {what}: errors below the bar cannot be resolved"}
    if missing:
        return {**out, "verdict": "undecided", "step": 2,
                "reason": f"not measured: {', '.join(missing)} (a missing run could be the cheapest within {target:g})"}
    if mid is None:
        return {**out, "verdict": "not met", "step": 3,
                "reason": f"no mid-edge plate entry has a dW1 error <= {target:g}"}
    if fem is None:
        return {**out, "verdict": "undecided", "step": 4,
                "reason": f"no FEM entry has a dW1 error <= {target:g}: no FEM time at that accuracy"}
    met = ratio >= speedup
    return {**out, "verdict": "met" if met else "not met", "step": 5,
            "reason": f"FEM time / mid-edge time = {ratio:.2f} {'>=' if met else '<'} {speedup:g}"}


# ---------------------------------------------------------------------------- the report
def study_sentence(ref: dict) -> str:
    parts = []
    for key in THRESHOLDS:
        r = ref.get(key)
        if r is None:
            parts.append(f"{key}/L: no study value")
            continue
        parts.append(f"{key}/L = {r['value']:.5f} \u00b1 {fmt(r['error_bar'], '.5f')} (rule {r.get('rule')}, meshes "
                     f"{'/'.join(map(str, r.get('meshes') or []))} along L; {r['basis']})")
    return "; ".join(parts)


TABLE_HEADER = ("model", "mesh", "status", "triangles", "unknowns", "wall s", "CPU s", "Newton its", "its/step",
                "dW1/L", "dW1 error", "dW2/L", "dW2 error", "study dW1/L", "difference")


def table_rows(report: dict) -> list[tuple]:
    ref, records = report["reference"], report["entries"]
    out = []
    for name in report["entry_order"]:
        model, mesh = name.split(":", 1)
        r = records.get(name)
        if not measured(r):
            status = "not run" if r is None else r.get("status", "?")
            out.append((MODEL_TITLES[model], mesh, status) + ("",) * (len(TABLE_HEADER) - 3))
            continue
        out.append((
            MODEL_TITLES[model], mesh, str(r.get("run_status")),
            fmt(r.get("triangles"), "d"), fmt(r.get("n_free_dof"), "d"), f"{r['wall_time_s']:.1f}",
            f"{r['cpu_time_s']:.1f}", fmt(r.get("newton_iterations"), "d"),
            fmt(r.get("path_iterations_per_recorded_step"), ".2f"), fmt(r.get("dW1_over_L"), ".4f"),
            fmt(threshold_error(r, ref, "dW1"), ".4f"), fmt(r.get("dW2_over_L"), ".4f"),
            fmt(threshold_error(r, ref, "dW2"), ".4f"), fmt(r.get("study_dW1_over_L"), ".4f"),
            fmt(r.get("dW1_difference_from_study"), "+.1e"),
        ))
    return out


def verdict_lines(v: dict) -> list[str]:
    lines = [f"**Verdict: {v['verdict']}** (rule step {v['step']}): {v['reason']}."]
    target, figures = v["target_dW1_error_over_L"], []
    for model in MODELS:
        b = v["cheapest_within_target"].get(model)
        figures.append(f"{MODEL_TITLES[model]}: " + (
            f"{b['entry']}, {b['wall_time_s']:.1f} s wall ({fmt(b['cpu_time_s'], '.1f')} s CPU), dW1 error "
            f"{b['dW1_error']:.4f}" if b else f"no measured entry with a dW1 error <= {target:g}"))
    lines.append(f"Cheapest measured entry with a dW1 error <= {target:g}: " + "; ".join(figures) + ".")
    ratio = v.get("ratio")
    lines.append("FEM time / mid-edge time: " + ("not available (one of the two has no such entry)" if ratio is None
                                                 else f"{ratio:.2f} (target >= {v['target_speedup']:g})") + ".")
    lines.append(f"The reference's dW1 error bar: {fmt(v['reference_dW1_error_bar'], '.5f')} (target "
                 f"{v['target_dW1_error_over_L']:g}).")
    if v["unmeasured"]:
        lines.append(f"Not measured: {', '.join(v['unmeasured'])}.")
    return lines


def reproducibility_lines(report: dict) -> list[str]:
    """Per threshold, the entries compared with their stored study run, the largest difference and
    the entries outside the bisection bracket."""
    records = [(n, report["entries"][n]) for n in report["entry_order"] if measured(report["entries"].get(n))]
    lines = []
    for key in THRESHOLDS:
        diffs = [(n, r[f"{key}_difference_from_study"], r[f"{key}_bisection_bracket"]) for n, r in records
                 if r.get(f"{key}_difference_from_study") is not None]
        if not diffs:
            lines.append(f"{key}/L: no entry to compare with a stored study run")
            continue
        worst = max(diffs, key=lambda d: abs(d[1]))
        outside = [f"{n} ({d:+.1e}, bracket {b:g})" for n, d, b in diffs if abs(d) > b]
        lines.append(f"{key}/L: entries compared {len(diffs)}, largest |difference| {abs(worst[1]):.1e} ({worst[0]}); "
                     + (f"outside the bisection bracket: {', '.join(outside)}" if outside
                        else "all within the bisection bracket"))
    without = [n for n, r in records if not r.get("study_run_found")]
    if without:
        lines.append(f"no stored study run: {', '.join(without)}")
    return lines


def markdown_report(report: dict) -> str:
    ref, sc = report["reference"], report["scene"]
    dw_max = next((r.get("dW_max_over_L") for r in report["entries"].values() if measured(r)
                   and r.get("dW_max_over_L") is not None), None)
    lines = [
        "# Speed against accuracy: paper's plate, mid-edge plate and FEM shell at one scene",
        "",
        f"Scene: W/L = {sc['width_ratio_text']}, dL/L = {sc['compression_ratio']:g}, L/b = {sc['slenderness']:.0f} "
        f"(`ddg.Strip.from_ratios({sc['width_ratio_text']}, {sc['compression_ratio']:g})`); compression in "
        f"{sc['compression_steps']} recorded steps, shear in {sc['shear_steps']} to dW_max/L"
        + (f" = {dw_max:.4f}" if dw_max is not None else "") + ", dW1 and dW2 located, no branch tracing "
        "(`python -m benchmarks.speed_accuracy`). Each entry is one run of its model's mesh study of the scene "
        "(validation.plate_gold.run_mesh, fem_reference.gold.run_mesh) in a fresh process, into a temporary folder; "
        "the DDG entries after an untimed warm-up simulate on a " + f"{sc['warmup_rows']}-row mesh with "
        f"{sc['warmup_steps']} steps per stage. Timeout {fmt(report['timeout_s'], 'g')} s per entry.",
    ]
    lines += section("Reference") + [
        f"The FEM shell's converged values, as the benchmark table uses them (`{ref['source']}`): "
        + study_sentence(ref) + ". The error of an entry is |value - reference value|."]
    lines += section("Runs") + [markdown_table(TABLE_HEADER, table_rows(report)), "", RUNS_CAPTION]
    lines += section(f"Verdict (issue 29: at equal dW1 error of {report['rule']['target_dW1_error_over_L']:g} L the "
                     f"mid-edge plate at least {report['rule']['target_speedup']:g}x faster than the FEM)")
    lines += verdict_lines(report["verdict"])
    lines += ["", "Rule (fixed before any data was measured): " + report["rule"]["text"]]
    lines += section("Reproducibility against the stored study runs", reproducibility_lines(report))
    lines += section("Chart") + [f"![wall time against dW1 error]({report['chart']})" if report.get("chart")
                                 else report.get("chart_note", "no chart")]
    loads = [(n, r.get("load_average_before"), r.get("load_average_after"))
             for n, r in report["entries"].items() if measured(r)]
    lines += ["", load_line(report), *shared_machine_note(report)]
    if loads:
        lines.append("- load average (1 min) before / after each entry: "
                     + ", ".join(f"{n} {a} / {b}" for n, a, b in loads))
    stale = [n for n, r in report["entries"].items() if r.get("ddg_source_sha256") not in (None,
                                                                                          report["ddg_source_sha256"])]
    if stale:
        lines.append(f"- measured with other ddg sources than the current ones: {', '.join(stale)}")
    lines += machine_section(report)
    return "\n".join(lines)


RUNS_CAPTION = (
    "status = summary.json status (complete: the path reached dW_max; stopped: it ended short, the thresholds it "
    "passed are located); unknowns = `summary['n_free_dof']`; wall s = the run_mesh call in the child (the warm-up "
    "excluded); CPU s = the child's CPU time in it (all threads); Newton its = all Newton iterations, path and "
    "threshold location; its/step = the path's Newton iterations / recorded steps; dW1 error, dW2 error = |value - "
    "reference value| (the reference above); study dW1/L = the stored study run on the same mesh, difference = this "
    "run - it (empty: no stored run).")

RULE_TEXT = (
    "for each model, the cheapest measured entry (least wall time) whose dW1 error is <= 0.003; ratio = the FEM's "
    "wall time / the mid-edge plate's. In order: (1) undecided if the reference's dW1 error bar exceeds 0.003 (errors "
    "below the bar cannot be resolved); (2) undecided if a mid-edge or FEM entry is not measured; (3) not met if no "
    "mid-edge entry is within 0.003; (4) undecided if no FEM entry is within 0.003; (5) met if the ratio is >= 10, "
    "else not met.")


def chart(report: dict, path: Path) -> str | None:
    """OUT/speed_accuracy.png: wall time against dW1 error (log-log), one marker series per
    model with mesh labels, the reference's bar shaded, a line at the target. None (and no file)
    if matplotlib is not importable."""
    try:
        from matplotlib.figure import Figure
    except ImportError:
        return None
    from ddg.output.io import save_figure

    ref, target = report["reference"], report["rule"]["target_dW1_error_over_L"]
    fig = Figure(figsize=(9.0, 4.8))
    ax = fig.add_subplot()
    errors_seen = []
    for model, marker in zip(MODELS, ("o", "s", "^")):
        points = []
        for name in report["entry_order"]:
            r = report["entries"].get(name)
            error = threshold_error(r, ref, "dW1") if measured(r) and r.get("model") == model else None
            if error is not None:
                points.append((max(error, CHART_ERROR_FLOOR), r["wall_time_s"], name.split(":", 1)[1]))
        if points:
            errors_seen += [p[0] for p in points]
            ax.plot([p[0] for p in points], [p[1] for p in points], marker=marker, linestyle="-",
                    label=MODEL_TITLES[model])
            for x, y, text in points:
                ax.annotate(text, (x, y), textcoords="offset points", xytext=(4, 4), fontsize=8)
    bar = (ref.get("dW1") or {}).get("error_bar")
    left = max(CHART_ERROR_FLOOR, min([*errors_seen, bar or target, target]) / 3)
    if bar:
        ax.axvspan(left, bar, color="0.85", zorder=0, label=f"reference's dW1 error bar ({bar:.5f}): not resolved")
    ax.axvline(target, color="k", linestyle="--", linewidth=1, label=f"target dW1 error {target:g}")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlim(left, 2.0 * max([*errors_seen, bar or target, target]))
    ax.set_xlabel("|dW1/L - FEM converged dW1/L|")
    ax.set_ylabel("wall time s")
    ax.set_title(f"W/L = {report['scene']['width_ratio_text']}, dL/L = {report['scene']['compression_ratio']:g}")
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.02, 1.0))
    fig.tight_layout()
    save_figure(fig, path, dpi=120)
    return path.name


def build_report(records: dict, timeout: float | None, provenance: Provenance, ref: dict) -> dict:
    import ddg

    order = entry_names()
    ordered = {n: records[n] for n in order if n in records}
    strip = ddg.Strip.from_ratios(WIDTH_RATIO, COMPRESSION_RATIO)
    report = {
        "benchmark": BENCHMARK,
        "scene": {"width_ratio": WIDTH_RATIO, "width_ratio_text": WIDTH_RATIO_TEXT,
                  "compression_ratio": COMPRESSION_RATIO, "slenderness": strip.slenderness,
                  "compression_steps": COMPRESSION_STEPS, "shear_steps": SHEAR_STEPS, "shear_ratio": "dW_max/L",
                  "thresholds": True, "branches": False, "study_scene": scene(),
                  "warmup_rows": WARMUP_ROWS, "warmup_steps": WARMUP_STEPS},
        "timeout_s": timeout,
        "reference": ref,
        "rule": {"target_dW1_error_over_L": TARGET_DW1_ERROR, "target_speedup": TARGET_SPEEDUP, "text": RULE_TEXT},
        "entry_order": order,
        "entries": ordered,
        "verdict": verdict(ordered, ref, order),
    }
    report.update(provenance.report([r for r in ordered.values() if measured(r)]))
    return report


def write_outputs(out: Path, report: dict) -> str:
    """OUT/speed_accuracy.png (if matplotlib is importable), .json and .md, each atomically."""
    name = chart(report, Path(out) / f"{BENCHMARK}.png")
    report["chart"] = name
    report["chart_note"] = None if name else "matplotlib is not importable: no chart (plotting is an optional extra)."
    return write_report(out, BENCHMARK, report, markdown_report(report))


# ---------------------------------------------------------------------------- command line
def kept(record: dict | None, entry: Entry, fingerprint: str, fem_fp: str | None) -> bool:
    """A stored entry that needs no rerun: measured with the same sources."""
    if not measured(record) or record.get("ddg_source_sha256") != fingerprint:
        return False
    return entry.model != "fem" or record.get("fem_reference_source_sha256") == fem_fp


def _describe(record: dict, ref: dict) -> str:
    if not measured(record):
        return f"{record.get('status')}: {' '.join(str(record.get('error', '')).split())[:300]}"
    return (f"{record['run_status']}, {record['wall_time_s']:.1f} s wall, {record['cpu_time_s']:.1f} s CPU, "
            f"{record['newton_iterations']} Newton its, dW1/L {fmt(record['dW1_over_L'], '.4f')} (error "
            f"{fmt(threshold_error(record, ref, 'dW1'), '.4f')}, study difference "
            f"{fmt(record.get('dW1_difference_from_study'), '+.1e')})")


class _Parser(argparse.ArgumentParser):
    """argparse with its errors on one line (no usage block), exit 2."""

    def error(self, message):
        self.exit(2, f"error: {message}\n")


def main(argv=None) -> int:
    from ddg.geometry.strip import InputError
    from ddg.output.interrupts import deferred_signals, exit_code_of, signal_name_of, terminate_as_interrupt
    from ddg.output.io import check_output_directory, read_json_object

    parser = _Parser(prog="python -m benchmarks.speed_accuracy", description=__doc__.split("\n")[0])
    parser.add_argument("--only", nargs="+", default=None, metavar="ENTRY",
                        help=f"entries to run (default all): {', '.join(entry_names())}")
    parser.add_argument("--out", default="benchmarks/results", help="directory for speed_accuracy.json/.md/.png")
    parser.add_argument("--timeout", type=float, default=TIMEOUT_S,
                        help="seconds allowed for one entry (0: no limit); a run over it is stopped and reported")
    parser.add_argument("--rerun", action="store_true", help="rerun entries stored with the same sources")
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # argparse's own errors (exit 2) and --help (exit 0)
        return int(exc.code or 0)
    try:
        selected = parse_entries(args.only)
        if not math.isfinite(args.timeout) or args.timeout < 0:
            raise InputError(f"--timeout = {args.timeout:g}: must be a number of seconds >= 0 (0: no limit)")
        out = check_output_directory(args.out, "--out")
    except InputError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    timeout = args.timeout if args.timeout > 0 else None
    terminate_as_interrupt()  # SIGTERM too keeps the finished entries

    from benchmarks.fem_path import fem_fingerprint

    provenance = Provenance()
    fem_fp = fem_fingerprint()
    ref = reference()
    known = {e.name: e for e in entries()}
    stored = (read_json_object(out / f"{BENCHMARK}.json") or {}).get("entries") or {}
    records = {n: r for n, r in stored.items() if n in known and isinstance(r, dict)}
    try:
        for entry in selected:
            if not args.rerun and kept(records.get(entry.name), entry, provenance.fingerprint, fem_fp):
                print(f"{entry.name}: stored with the same sources, kept (--rerun to rerun)", file=sys.stderr)
                continue
            print(f"{entry.name}: running", file=sys.stderr, flush=True)
            before = load_average()
            status, payload, elapsed = run_in_child(measure, (entry.model, entry.rows, entry.along, entry.across),
                                                    timeout)
            record = payload if status == "ok" else {
                "status": status, "error": payload if status == "error" else
                f"stopped after {elapsed:.0f} s (--timeout {args.timeout:g})"}
            record = {"entry": entry.name, "model": entry.model, "mesh_label": entry.mesh, "rows": entry.rows,
                      "along": entry.along, "across": entry.across, **record,
                      "child_elapsed_s": elapsed, "load_average_before": before, "load_average_after": load_average()}
            record.update(study_comparison(entry, record))
            with deferred_signals():
                records[entry.name] = record
                write_outputs(out, build_report(records, timeout, provenance, ref))
            print(f"{entry.name}: {_describe(record, ref)}", file=sys.stderr, flush=True)
    except KeyboardInterrupt as exc:
        with deferred_signals():
            write_outputs(out, build_report(records, timeout, provenance, ref))
        print(f"error: interrupted by {signal_name_of(exc)}: the finished entries are kept in {out}", file=sys.stderr)
        return exit_code_of(exc)
    report = build_report(records, timeout, provenance, ref)
    wrote = write_outputs(out, report)
    print(text_table(TABLE_HEADER, table_rows(report)))
    print()
    for line in verdict_lines(report["verdict"]):
        print(line.replace("**", ""))
    for line in reproducibility_lines(report):
        print("-", line)
    print(wrote)
    if report["ddg_source_changed_during_run"]:
        print("WARNING: the ddg sources changed while the benchmark ran; the runs may mix library versions",
              file=sys.stderr)
    return 0 if all(measured(records.get(e.name)) for e in selected) else 1


if __name__ == "__main__":
    sys.exit(main())
