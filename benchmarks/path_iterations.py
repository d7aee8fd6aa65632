"""Newton iterations of the path, per recorded step and per phase, model by model and scene by scene
(issue 49: "path iterations per recorded step"), with a before/after comparison.

    .venv/bin/python -m benchmarks.path_iterations [--models rod ribbon ... plate-midedge plate]
        [--scenes 1/20:1/2,1/6:1/4] [--rows 8 12 18] [--timeout 900] [--repeat 1] [--jobs 1]
        [--label before] [--resume] [--report-only] [--out benchmarks/results]
    .venv/bin/python -m benchmarks.path_iterations --compare before after [--out benchmarks/results]

Runs (each in a fresh child process, at most --jobs at a time): every model of --models on every
scene of --scenes (W/L:dL/L; default the six of W/L in {1/20, 1/6, 1/2} x dL/L in {1/2, 1/4}):

    ddg.simulate(ddg.Strip.from_ratios(W/L, dL/L), ddg.LoadingProtocol(dL/L), model=..., resolution=...,
                 mesh=..., probe=...)

(the default strip, L/b from Strip.from_ratios; 40 compression and 120 shear recorded steps to dW_max;
thresholds located; branch tracing at each model's default: on for the rod and the 1D ribbons, off for
the plates), with

- the rod at M = 100 and the ribbons (ribbon, ribbon-sano-wada, ribbon-trapeze, ribbon-wunderlich,
  ribbon-cross-section) at M = 101;
- the mid-edge plate on ghost_clamp_mesh(L, W, rows=R) for R in --rows (default 8, 12, 18), passed as
  simulate's mesh (as benchmarks/plate_path.py does);
- the paper's plate at resolution 2100 (about 2100 triangles).

The child first makes an untimed warm-up simulate of the same model and mesh (4 compression and 2
shear steps to 2 % of dW_max, no branches), which loads numba's compiled kernels, then --repeat
timed runs. Iteration counts come from the first timed run; the wall time (summary wall_time_s) is
the best of the repeats, and the record says whether the repeats gave the same counts. The child's
time limit is --timeout x --repeat seconds; a child that errors or times out is recorded as such
and the others go on. OUT/path_iterations_<label>.json and .md are rewritten (atomically) after
every run; --resume keeps the runs stored with the same ddg source fingerprint and protocol
instead of rerunning them (stored runs outside this invocation's selection are kept only if their
fingerprint is the current one). --report-only rewrites the markdown from the JSON.

Measured through public hooks only: a ddg.solve.probe.Probe subclass (StepPhaseProbe, on
benchmarks.common.PathProbe: every Newton solve of the path with its phase, every recorded step
with the phases of the solves that reached it) and summary.json: newton_iterations,
newton_iterations_by_phase (accepted steps, rejected steps, branch switching, compression start,
fold snaps; "line search trials" are shortened steps, not iterations, and are reported apart),
threshold_newton_iterations, branches_newton_iterations, dW1/dW2/dW2_S_stable, folds_dW_over_L,
status, wall_time_s; path.csv's rows (recorded steps) and their "phase" column.

Definitions (the report repeats them):
- path iterations = summary newton_iterations (every solve of the path follower, failed ones and
  fold snaps included); per recorded step = over the rows of path.csv (the flat start included);
- a fold snap = a recorded step whose solves include one of phase "fold snaps" (solves after the
  last recorded step of a stopped path count as one more step); iterations per snap = the fold
  snaps phase's iterations / snaps;
- thresholds located = the non-null ones of dW1, dW2, dW2_S_stable; iterations per threshold =
  threshold_newton_iterations / thresholds located;
- whole run = path + threshold location + branch tracing iterations;
- branch sequence = path.csv's "phase" over the shear stage, consecutive repeats collapsed.

--compare BEFORE AFTER reads OUT/path_iterations_BEFORE.json and OUT/path_iterations_AFTER.json and
writes OUT/path_iterations.md: per run side by side (iterations per step and per phase), the
targets before and after, and "physics unchanged": the same branch sequence, |dW1 after - dW1
before| (flagged above 1e-4 L), |dW2 after - dW2 before| (flagged above 1e-3 L), folds before/after.

Not part of the test run; nothing asserts on timings.
"""
from __future__ import annotations

import argparse
import itertools
import json
import math
import multiprocessing as mp
import sys
import time
import traceback
from fractions import Fraction
from multiprocessing.connection import wait
from pathlib import Path

from benchmarks.common import (PathProbe, Provenance, load_average, machine_section, markdown_table, section,
                               shared_machine_note, source_fingerprint, text_table, warn_if_changed)

BENCHMARK = "path_iterations"
PHASES = ("accepted steps", "rejected steps", "branch switching", "compression start", "fold snaps")
SNAP_PHASE = "fold snaps"
LINE_SEARCH = "line search trials"
ONE_D = ("rod", "ribbon", "ribbon-sano-wada", "ribbon-trapeze", "ribbon-wunderlich", "ribbon-cross-section")
MODELS = ONE_D + ("plate-midedge", "plate")
#: resolution per model (the mid-edge plate is sized by --rows instead)
RESOLUTION = {"rod": 100, **{m: 101 for m in ONE_D[1:]}, "plate": 2100}
DEFAULT_ROWS = (8, 12, 18)
DEFAULT_SCENES = "1/20:1/2,1/6:1/2,1/2:1/2,1/20:1/4,1/6:1/4,1/2:1/4"
COMPRESSION_STEPS, SHEAR_STEPS = 40, 120
TIMEOUT_S = 900.0
FAMILIES = (("Rod and 1D ribbons", ONE_D), ("Mid-edge plate", ("plate-midedge",)), ("The paper's plate", ("plate",)))
#: the warm-up run of each child: recorded steps per stage and the fraction of dW_max it shears to
WARMUP_STEPS = (4, 2)
WARMUP_SHEAR_FRACTION = 0.02

# ---------------------------------------------------------------------------- issue 49's targets
#: path iterations per recorded step, per model
STEP_BOUND = {**{m: 4.0 for m in ONE_D}, "plate-midedge": 5.0, "plate": 6.0}
ROD_WHOLE_RUN_BOUND = 900
WIDE_RIBBONS = ("ribbon-wunderlich", "ribbon-cross-section")
WIDE_RIBBON_FACTOR = 3.0
SNAP_BOUND = 25.0
THRESHOLD_BOUND = 15.0
#: compare mode: differences flagged (units of L)
DW1_FLAG, DW2_FLAG = 1e-4, 1e-3

DEFINITIONS = [
    "path its = summary `newton_iterations` (every Newton solve of the path follower: failed ones and fold "
    "snaps included); its/step = path its / recorded steps (rows of path.csv, the flat start included); "
    "the phases (summary `newton_iterations_by_phase`) add up to the path its; LS trials = `line search "
    "trials`, shortened Newton steps (evaluations, not iterations)",
    "rej. solves = Newton solves of phase \"rejected steps\" (from the probe); failed = solves that did not "
    "converge (any phase)",
    "snaps = recorded steps whose solves include one of phase \"fold snaps\" (from the probe; solves after "
    "the last recorded step of a stopped path count as one more step); its/snap = fold-snap iterations / snaps",
    "thr. = thresholds located (non-null of dW1, dW2, dW2_S_stable); its/thr. = summary "
    "`threshold_newton_iterations` / thr.",
    "branch its = summary `branches_newton_iterations` (- where the model's default does not trace branches)",
    "whole = path + threshold + branch iterations",
    "sequence = path.csv's `phase` over the shear stage, consecutive repeats collapsed",
]


# ---------------------------------------------------------------------------- runs and scenes
def fraction_label(x: float) -> str:
    return str(Fraction(x).limit_denominator(1000))


def parse_scenes(text) -> list[tuple[str, str]]:
    """"1/20:1/2,1/6:1/4" (or a list of such) -> [("1/20", "1/2"), ("1/6", "1/4")] (W/L, dL/L labels)."""
    items = text if isinstance(text, (list, tuple)) else [text]
    scenes = []
    for part in (p.strip() for item in items for p in str(item).split(",")):
        if not part:
            continue
        try:
            w, c = part.split(":")
            w, c = float(Fraction(w)), float(Fraction(c))
        except (ValueError, ZeroDivisionError):
            raise argparse.ArgumentTypeError(f"scene {part!r} is not W/L:dL/L (e.g. 1/20:1/2)") from None
        if not (0.0 < w <= 1.0 and 0.0 < c < 1.0):
            raise argparse.ArgumentTypeError(f"scene {part!r}: W/L must be in (0, 1] and dL/L in (0, 1)")
        scene = (fraction_label(w), fraction_label(c))
        if scene not in scenes:
            scenes.append(scene)
    if not scenes:
        raise argparse.ArgumentTypeError(f"no scene in {text!r}")
    return scenes


def run_specs(models, scenes, rows=DEFAULT_ROWS) -> list[dict]:
    """One spec per (model, size, scene), in report order (model, size, then scene)."""
    specs = []
    for model in (m for m in MODELS if m in models):
        sizes = [(None, r) for r in rows] if model == "plate-midedge" else [(RESOLUTION[model], None)]
        for (resolution, r), (w, c) in itertools.product(sizes, scenes):
            specs.append({"model": model, "resolution": resolution, "rows": r,
                          "width_ratio": float(Fraction(w)), "compression_ratio": float(Fraction(c)),
                          "scene": f"{w}:{c}"})
    return specs


def size_label(r: dict) -> str:
    return f"{r['rows']} rows" if r.get("rows") else (f"M={r['resolution']}" if r["model"] in ONE_D
                                                       else f"N={r['resolution']}")


def run_key(r: dict) -> str:
    return f"{r['model']}|{size_label(r)}|{r['scene']}"


def scene_text(scene: str) -> str:
    w, c = scene.split(":")
    return f"W/L={w} dL/L={c}"


# ---------------------------------------------------------------------------- the child's measurement
class StepPhaseProbe(PathProbe):
    """PathProbe that also records, per recorded step, the phases of the Newton solves that reached it."""

    def __init__(self):
        super().__init__()
        self._phases: set = set()

    def solve(self, phase: str, iterations: int, converged: bool) -> None:
        super().solve(phase, iterations, converged)
        self._phases.add(phase)

    def step(self, stage: str, row: dict, wall_s: float) -> None:
        super().step(stage, row, wall_s)
        self.steps[-1]["phases"] = sorted(self._phases)
        self._phases = set()

    def fold_snaps(self) -> int:
        """Recorded steps whose solves include a fold snap (and the solves after the last step, as one)."""
        return sum(SNAP_PHASE in st["phases"] for st in self.steps) + (SNAP_PHASE in self._phases)

    def trailing(self) -> dict:
        """The solves made after the last recorded step (a stopped path's last attempts)."""
        return {**self._next, "phases": sorted(self._phases)}


def branch_sequence(rows) -> list[str]:
    """path.csv's phase over the shear stage, consecutive repeats collapsed."""
    return [k for k, _ in itertools.groupby(str(row.get("phase")) for row in rows if row.get("stage") == "shear")]


def run_counts(s: dict, probe: StepPhaseProbe) -> dict:
    """The iteration counts of one run (compared between repeats)."""
    return {"path": s.get("newton_iterations"), "by_phase": s.get("newton_iterations_by_phase"),
            "threshold": s.get("threshold_newton_iterations"), "branches": s.get("branches_newton_iterations"),
            "solves": len(probe.solves)}


def record_of(spec: dict, result, probe: StepPhaseProbe) -> dict:
    """The record of one run from its SimulationResult and probe (the first timed run)."""
    s, rows = result.summary, result.rows
    steps = len(rows)
    path_its = int(s["newton_iterations"])
    by_phase_summary = s.get("newton_iterations_by_phase") or {}
    by_phase = {p: int(by_phase_summary.get(p, 0)) for p in PHASES}
    probe_phase = probe.by_phase()
    snaps = probe.fold_snaps()
    located = [k for k in ("dW1_over_L", "dW2_over_L", "dW2_S_stable_over_L") if s.get(k) is not None]
    thr_its = s.get("threshold_newton_iterations")
    branch_its = s.get("branches_newton_iterations")
    worst = sorted(probe.steps, key=lambda st: -st["iterations_all"])[:5]
    return {
        **spec, "size": size_label(spec),
        "status": s.get("status"), "message": s.get("message"), "path_complete": s.get("path_complete"),
        "recorded_steps": steps, "recorded_shear_steps": sum(1 for r in rows if r.get("stage") == "shear"),
        "path_iterations": path_its, "iterations_per_step": path_its / steps if steps else None,
        "iterations_by_phase": by_phase, "line_search_trials": by_phase_summary.get(LINE_SEARCH),
        "solves_by_phase": {p: v["solves"] for p, v in probe_phase.items()},
        "failed_solves_by_phase": {p: v["failed"] for p, v in probe_phase.items()},
        "rejected_solves": probe_phase.get("rejected steps", {}).get("solves", 0),
        "failed_solves": sum(v["failed"] for v in probe_phase.values()),
        "fold_snaps": snaps,
        "iterations_per_snap": by_phase["fold snaps"] / snaps if snaps else None,
        "threshold_iterations": thr_its, "thresholds_located": len(located), "thresholds_located_keys": located,
        "iterations_per_threshold": thr_its / len(located) if located and thr_its is not None else None,
        "branch_iterations": branch_its, "branches_traced": branch_its is not None,
        "whole_run_iterations": path_its + (thr_its or 0) + (branch_its or 0),
        "dW1_over_L": s.get("dW1_over_L"), "dW2_over_L": s.get("dW2_over_L"),
        "dW2_S_stable_over_L": s.get("dW2_S_stable_over_L"), "folds_dW_over_L": list(s.get("folds_dW_over_L") or []),
        "dW_max_over_L": s.get("dW_max_over_L"), "resolved_up_to_dW_over_L": s.get("resolved_up_to_dW_over_L"),
        "branch_sequence": branch_sequence(rows),
        "n_free_dof": s.get("n_free_dof"), "warnings": list(s.get("warnings") or []),
        "probe_matches_summary": probe.matches(s),
        "after_last_step": probe.trailing(),
        "most_expensive_steps": [{k: st[k] for k in ("stage", "dL_over_L", "dW_over_L", "iterations_all",
                                                     "newton_solves", "failed_solves", "phases", "time_s")}
                                 for st in worst],
    }


def measure(spec: dict, repeat: int = 1, compression_steps: int = COMPRESSION_STEPS,
            shear_steps: int = SHEAR_STEPS, warmup: bool = True) -> dict:
    """One run's record, in this process: the warm-up (untimed), then `repeat` timed runs. The
    library's warnings are not printed (the record keeps the summary's "warnings")."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return _measure(spec, repeat, compression_steps, shear_steps, warmup)


def _measure(spec: dict, repeat: int, compression_steps: int, shear_steps: int, warmup: bool) -> dict:
    import ddg

    strip = ddg.Strip.from_ratios(spec["width_ratio"], spec["compression_ratio"])
    protocol = ddg.LoadingProtocol(spec["compression_ratio"], compression_steps=compression_steps,
                                   shear_steps=shear_steps)
    kwargs = {"model": spec["model"], "resolution": spec["resolution"]}
    if spec.get("rows"):
        from ddg.geometry.plate_mesh import ghost_clamp_mesh

        kwargs["mesh"] = ghost_clamp_mesh(strip.length, strip.width, rows=spec["rows"])
    warm = {"warmup_wall_s": None, "warmup_error": None}
    if warmup:
        short = ddg.LoadingProtocol(spec["compression_ratio"],
                                    WARMUP_SHEAR_FRACTION * protocol.resolved_shear_ratio(strip),
                                    compression_steps=WARMUP_STEPS[0], shear_steps=WARMUP_STEPS[1])
        t0 = time.perf_counter()
        try:
            ddg.simulate(strip, short, branches=False, **kwargs)
        except Exception as exc:  # the timed run will show whether it matters
            warm["warmup_error"] = f"{type(exc).__name__}: {exc}"
        warm["warmup_wall_s"] = time.perf_counter() - t0
    record, counts, walls, elapsed, cpu = None, [], [], [], []
    for _ in range(repeat):
        probe = StepPhaseProbe()
        c0, t0 = time.process_time(), time.perf_counter()
        result = ddg.simulate(strip, protocol, probe=probe, **kwargs)
        elapsed.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
        walls.append(float(result.summary.get("wall_time_s") or elapsed[-1]))
        counts.append(run_counts(result.summary, probe))
        if record is None:
            record = record_of(spec, result, probe)
        del result
    record.update(warm)
    record.update({
        "wall_time_s": min(walls), "all_wall_times_s": walls, "all_elapsed_s": elapsed, "all_cpu_times_s": cpu,
        "cpu_time_s": cpu[walls.index(min(walls))], "repeat": repeat,
        "repeats_same_counts": all(c == counts[0] for c in counts) if repeat > 1 else None,
        "compression_steps": compression_steps, "shear_steps": shear_steps,
        "ddg_source_sha256": source_fingerprint(),
    })
    return record


# ---------------------------------------------------------------------------- children, in parallel
def _child(conn, spec, repeat, compression_steps, shear_steps) -> None:
    try:
        conn.send(("ok", measure(spec, repeat, compression_steps, shear_steps)))
    except BaseException:
        conn.send(("error", traceback.format_exc()))
    finally:
        conn.close()


def run_parallel(specs: list[dict], jobs: int, limit: float | None, on_done, protocol_steps) -> None:
    """Each spec in a fresh (spawned) child process, at most `jobs` at a time, each stopped after
    `limit` seconds; on_done(spec, status, payload, elapsed) in this process as each one finishes.
    Only the children started here are ever terminated (by their Process object)."""
    ctx = mp.get_context("spawn")
    pending = list(specs)
    active: dict = {}  # connection -> (spec, process, start)
    try:
        while pending or active:
            while pending and len(active) < jobs:
                spec = pending.pop(0)
                parent, child = ctx.Pipe(duplex=False)
                proc = ctx.Process(target=_child, args=(child, spec, *protocol_steps), daemon=True)
                proc.start()
                child.close()
                active[parent] = (spec, proc, time.perf_counter(), load_average())
                print(f"{run_key(spec)}: started (pid {proc.pid})", file=sys.stderr, flush=True)
            now = time.perf_counter()
            waits = [start + limit - now for _, _, start, _ in active.values()] if limit else []
            ready = wait(list(active), timeout=max(0.05, min(waits + [5.0])))
            now = time.perf_counter()
            for conn in list(active):
                spec, proc, start, load = active[conn]
                if conn in ready:
                    try:
                        status, payload = conn.recv()
                    except EOFError:
                        status, payload = "error", f"child exited with code {proc.exitcode} without a result"
                elif limit and now - start > limit:
                    status, payload = "timeout", f"no result within {limit:g} s"
                else:
                    continue
                del active[conn]
                _stop(proc)
                conn.close()
                on_done(spec, status, payload, now - start, load)
    finally:
        for conn, (_, proc, _, _) in active.items():
            _stop(proc)
            conn.close()


def _stop(proc) -> None:
    proc.join(5 if proc.is_alive() else None)
    if proc.is_alive():
        proc.terminate()
        proc.join(5)
    if proc.is_alive():
        proc.kill()
        proc.join()


# ---------------------------------------------------------------------------- targets
def _ok(r) -> bool:
    return r is not None and r.get("status") not in ("error", "timeout", None) and "path_iterations" in r


def _complete(r) -> bool:
    return _ok(r) and r.get("status") == "complete"


def _f(x, spec=".2f") -> str:
    return "-" if x is None else format(x, spec)


def _yes(flag) -> str:
    return "-" if flag is None else ("yes" if flag else "NO")


def model_sizes(results: list[dict]) -> list[tuple[str, str]]:
    return list(dict.fromkeys((r["model"], r["size"]) for r in results))


def compute_targets(results: list[dict]) -> list[dict]:
    """Issue 49's targets, each with the measured figure and met or not, computed from the records.
    A per-step target is met only where every scene's path is complete and within the bound."""
    targets = []
    by = {(r["model"], r["size"], r["scene"]): r for r in results}
    for model, size in model_sizes(results):
        runs = [r for r in results if (r["model"], r["size"]) == (model, size)]
        bound = STEP_BOUND[model]
        measured = [r for r in runs if _ok(r) and r.get("iterations_per_step") is not None]
        worst = max(measured, key=lambda r: r["iterations_per_step"], default=None)
        within = [r for r in runs if _complete(r) and r["iterations_per_step"] <= bound]
        targets.append({
            "target": f"path its per recorded step, {model} {size}", "kind": "per step", "model": model,
            "size": size, "bound": bound, "unit": "its/step",
            "measured": worst["iterations_per_step"] if worst else None,
            "where": f"worst of {len(measured)} scenes: {worst['scene']}" + (
                "" if _complete(worst) else f" ({worst['status']})") if worst else "no run measured",
            "scenes_met": len(within), "scenes": len(runs), "met": bool(runs) and len(within) == len(runs)})
    rod = [r for r in results if r["model"] == "rod" and r.get("resolution") == 100]
    if rod:
        measured = [r for r in rod if _ok(r)]
        worst = max(measured, key=lambda r: r["whole_run_iterations"], default=None)
        within = [r for r in rod if _complete(r) and r["whole_run_iterations"] <= ROD_WHOLE_RUN_BOUND]
        targets.append({
            "target": "rod M=100 whole run (path + thresholds + branches)", "kind": "rod whole run", "model": "rod",
            "size": "M=100", "bound": ROD_WHOLE_RUN_BOUND, "unit": "its",
            "measured": worst["whole_run_iterations"] if worst else None,
            "where": f"worst of {len(measured)} scenes: {worst['scene']}" if worst else "no run measured",
            "scenes_met": len(within), "scenes": len(rod), "met": len(within) == len(rod)})
    for model in WIDE_RIBBONS:
        runs = [r for r in results if r["model"] == model]
        if not runs:
            continue
        ratios = []
        for r in runs:
            base = by.get(("rod", "M=100", r["scene"]))
            if _ok(r) and _ok(base) and base["path_iterations"]:
                ratios.append((r["path_iterations"] / base["path_iterations"], r, base))
        worst = max(ratios, key=lambda t: t[0], default=None)
        within = [t for t in ratios if t[0] <= WIDE_RIBBON_FACTOR and _complete(t[1])]
        targets.append({
            "target": f"{model} path its / rod M=100 path its", "kind": "wide ribbon", "model": model,
            "size": runs[0]["size"], "bound": WIDE_RIBBON_FACTOR, "unit": "x",
            "measured": worst[0] if worst else None,
            "where": f"worst of {len(ratios)} scenes: {worst[1]['scene']}" + (
                "" if _complete(worst[1]) else f" ({worst[1]['status']})") if worst else "no pair measured",
            "scenes_met": len(within), "scenes": len(runs), "met": len(within) == len(runs)})
    ok = [r for r in results if _ok(r)]
    groups = [(f"{m} {s}", [r for r in ok if (r["model"], r["size"]) == (m, s)]) for m, s in model_sizes(results)]
    groups.append(("all runs", ok))
    for name, runs in groups:
        snaps = sum(r["fold_snaps"] for r in runs)
        its = sum(r["iterations_by_phase"]["fold snaps"] for r in runs)
        targets.append({"target": f"mean fold snap, {name}", "kind": "fold snap", "group": name, "bound": SNAP_BOUND,
                        "unit": "its/snap", "measured": its / snaps if snaps else None,
                        "where": f"{its} its in {snaps} snaps over {len(runs)} runs",
                        "met": (its / snaps <= SNAP_BOUND) if snaps else (None if not runs else True)})
    for name, runs in groups:
        located = sum(r["thresholds_located"] for r in runs)
        its = sum(r["threshold_iterations"] or 0 for r in runs)
        targets.append({"target": f"threshold location, {name}", "kind": "threshold", "group": name,
                        "bound": THRESHOLD_BOUND, "unit": "its/threshold",
                        "measured": its / located if located else None,
                        "where": f"{its} its for {located} thresholds over {len(runs)} runs",
                        "met": (its / located <= THRESHOLD_BOUND) if located else None})
    return targets


def targets_table(targets: list[dict]) -> list[str]:
    rows = []
    for t in targets:
        spec = ".0f" if t["unit"] == "its" else ".2f"
        met = _yes(t["met"])
        if "scenes" in t:
            met += f" ({t['scenes_met']}/{t['scenes']} scenes)"
        rows.append((t["target"], f"<= {t['bound']:g} {t['unit']}", _f(t["measured"], spec), met, t["where"]))
    return [markdown_table(("target (issue 49)", "bound", "measured", "met", "measured as"), rows)]


def per_step_matrix(results: list[dict]) -> list[str]:
    """Path its per recorded step, model x scene, against each model's bound."""
    scenes = list(dict.fromkeys(r["scene"] for r in results))
    by = {(r["model"], r["size"], r["scene"]): r for r in results}
    rows = []
    for model, size in model_sizes(results):
        cells = []
        for scene in scenes:
            r = by.get((model, size, scene))
            if r is None:
                cells.append("")
            elif not _ok(r):
                cells.append(r.get("status", "?"))
            else:
                mark = "" if r["iterations_per_step"] <= STEP_BOUND[model] else " >"
                cells.append(_f(r["iterations_per_step"]) + mark + ("" if _complete(r) else f" ({r['status']})"))
        rows.append((model, size, f"{STEP_BOUND[model]:g}", *cells))
    return [markdown_table(("model", "size", "bound", *scenes), rows), "",
            "W/L:dL/L per column; `>` marks a figure above the bound; a status in brackets marks a path that did "
            "not complete (its figure is over the steps it recorded)."]


# ---------------------------------------------------------------------------- the report
def iterations_rows(runs: list[dict]) -> list[tuple]:
    rows = []
    for r in runs:
        if not _ok(r):
            rows.append((r["model"], r["size"], r["scene"], r.get("status", "?"), *["-"] * 20))
            continue
        p = r["iterations_by_phase"]
        rows.append((r["model"], r["size"], r["scene"], r["status"], str(r["recorded_steps"]),
                     str(r["path_iterations"]), _f(r["iterations_per_step"]),
                     *(str(p[k]) for k in PHASES), _f(r["line_search_trials"], "d"),
                     str(r["rejected_solves"]), str(r["failed_solves"]), str(r["fold_snaps"]),
                     _f(r["iterations_per_snap"], ".1f"), _f(r["threshold_iterations"], "d"),
                     str(r["thresholds_located"]), _f(r["iterations_per_threshold"], ".1f"),
                     _f(r["branch_iterations"], "d"), str(r["whole_run_iterations"]), _f(r["wall_time_s"]),
                     _f(r.get("cpu_time_s"))))
    return rows


ITERATIONS_HEADER = ("model", "size", "W/L:dL/L", "status", "steps", "path its", "its/step", "accepted",
                     "rejected", "branch sw.", "compr. start", "fold snaps", "LS trials", "rej. solves", "failed",
                     "snaps", "its/snap", "threshold its", "thr.", "its/thr.", "branch its", "whole", "wall s",
                     "cpu s")


def physics_rows(runs: list[dict]) -> list[tuple]:
    rows = []
    for r in runs:
        if not _ok(r):
            err = (r.get("error") or "").strip().splitlines()
            rows.append((r["model"], r["size"], r["scene"], r.get("status", "?"), "-", "-", "-", "-", "-",
                         (err[-1] if err else "")[:160].replace("|", "/")))
            continue
        folds = ", ".join(f"{x:.4f}" for x in r["folds_dW_over_L"]) or "-"
        rows.append((r["model"], r["size"], r["scene"], r["status"], _f(r["dW1_over_L"], ".5f"),
                     _f(r["dW2_over_L"], ".5f"), _f(r["dW2_S_stable_over_L"], ".5f"), folds,
                     " > ".join(r["branch_sequence"]) or "-",
                     "" if r["status"] == "complete" else (r.get("message") or "")[:160].replace("|", "/")))
    return rows


PHYSICS_HEADER = ("model", "size", "W/L:dL/L", "status", "dW1/L", "dW2/L", "dW2_S_stable/L", "folds dW/L",
                  "shear-stage sequence", "message")


def summary_sentences(results: list[dict], targets: list[dict]) -> list[str]:
    """Sentences computed from the records and targets."""
    ok = [r for r in results if _ok(r)]
    complete = [r for r in ok if _complete(r)]
    failed = [r for r in results if not _ok(r)]
    step_targets = [t for t in targets if t["kind"] == "per step"]
    within = sum(t["scenes_met"] for t in step_targets)
    total = sum(t["scenes"] for t in step_targets)
    met = [t for t in targets if t["met"]]
    stopped = ", ".join(f"{r['model']} {r['size']} {r['scene']}" for r in ok if not _complete(r)) or "none"
    broken = ", ".join(f"{r['model']} {r['size']} {r['scene']}: {r['status']}" for r in failed) or "none"
    lines = [f"{len(results)} runs: {len(complete)} complete paths, {len(ok) - len(complete)} stopped early "
             f"({stopped}), {len(failed)} errors or timeouts ({broken}).",
             f"Iterations per recorded step within the model's bound on a complete path: {within} of {total} runs; "
             f"{len(met)} of {len(targets)} target rows met."]
    if ok:
        per = sorted(ok, key=lambda r: r["iterations_per_step"])
        lines.append(f"Iterations per recorded step range from {per[0]['iterations_per_step']:.2f} "
                     f"({per[0]['model']} {per[0]['size']} {per[0]['scene']}) to {per[-1]['iterations_per_step']:.2f} "
                     f"({per[-1]['model']} {per[-1]['size']} {per[-1]['scene']}).")
        shares = {p: sum(r["iterations_by_phase"][p] for r in ok) for p in PHASES}
        total_its = sum(shares.values())
        if total_its:
            lines.append("Share of all path iterations by phase: " + ", ".join(
                f"{p} {100 * v / total_its:.1f} %" for p, v in shares.items()) + ".")
    different = [r for r in ok if r.get("repeats_same_counts") is False]
    repeated = [r for r in ok if r.get("repeats_same_counts") is not None]
    if repeated:
        lines.append(f"Repeats gave the same iteration counts in {len(repeated) - len(different)} of "
                     f"{len(repeated)} repeated runs.")
    mismatch = [r for r in ok if not r.get("probe_matches_summary")]
    lines.append(f"The probe's solves add up to summary.json's iterations phase by phase in "
                 f"{len(ok) - len(mismatch)} of {len(ok)} runs.")
    return lines


def markdown_report(report: dict) -> str:
    results = report["results"]
    targets = report["targets"]
    cfg = report["config"]
    lines = [f"# Path iterations per recorded step, by phase (benchmarks/path_iterations.py, label "
             f"\"{report['label']}\")", "",
             f"Each model on each scene: `ddg.simulate(Strip.from_ratios(W/L, dL/L), LoadingProtocol(dL/L, "
             f"compression_steps={cfg['compression_steps']}, shear_steps={cfg['shear_steps']}), ...)` to dW_max, "
             "thresholds located, branch tracing at the model's default (rod and 1D ribbons on, plates off); the rod "
             "at M = 100, the ribbons at M = 101, the mid-edge plate on `ghost_clamp_mesh(L, W, rows=R)`, the paper's "
             "plate at resolution 2100.", ""]
    lines += [f"- {s}" for s in summary_sentences(results, targets)]
    lines += section("Targets (issue 49)") + targets_table(targets) + [
        "", "A per-step, rod or ribbon target is met only where every scene's path is complete and within the bound; "
        "the fold-snap and threshold targets are the totals over the runs named (all fold-snap iterations / snaps; "
        "all threshold-location iterations, those of runs that located none included, / thresholds located). "
        "\"Nothing physical changes\" is a before/after check: `--compare BEFORE AFTER`."]
    lines += section("Iterations per recorded step against the bound") + per_step_matrix(results)
    for title, models in FAMILIES:
        runs = [r for r in results if r["model"] in models]
        if not runs:
            continue
        lines += section(f"{title}: iterations by phase") + [markdown_table(ITERATIONS_HEADER, iterations_rows(runs))]
        lines += section(f"{title}: thresholds, folds and branches") + [markdown_table(PHYSICS_HEADER,
                                                                                      physics_rows(runs))]
    lines += section("Definitions", DEFINITIONS)
    loads = [r.get("load_average_before") for r in results]
    lines += section("Method", [
        "each run in a fresh child process (spawned), at most "
        f"{cfg['jobs']} at a time on {report['machine']['cpu_count']} cores; an untimed warm-up simulate of the same "
        f"model and mesh first ({WARMUP_STEPS[0]} compression and {WARMUP_STEPS[1]} shear steps to "
        f"{WARMUP_SHEAR_FRACTION:g} dW_max, no branches) loads numba's compiled kernels",
        f"iteration counts from the first timed run; wall s = summary `wall_time_s`, best of --repeat "
        f"{cfg['repeat']} (with --jobs > 1 two runs share the cores, so wall times are inflated: the iteration "
        "counts are the figures to compare)",
        f"time limit per child {cfg['timeout_s']:g} s x --repeat; a child that errors or times out is recorded as "
        "such",
        "measured through public hooks only: the probe (ddg.solve.probe.Probe subclass on "
        "benchmarks.common.PathProbe) and summary.json",
        "load average (1 min) before each run: " + ", ".join(str(x) for x in loads if x is not None),
    ] + ([f"the whole benchmark took {report['elapsed_s'] / 60:.1f} min"] if report.get("elapsed_s") else [])
        + [line.removeprefix("- ") for line in shared_machine_note(report)])
    lines += machine_section(report)
    return "\n".join(lines) + "\n"


def build_report(records: dict, label: str, config: dict, provenance: Provenance | None, stored: dict | None) -> dict:
    """The report from the records ({run key: record}) in run order."""
    order = {run_key(s): i for i, s in enumerate(config.get("order") or [])}
    results = sorted(records.values(), key=lambda r: (order.get(run_key(r), len(order)),
                                                      MODELS.index(r["model"]), r["size"], r["scene"]))
    report = {"benchmark": BENCHMARK, "label": label, "config": {k: v for k, v in config.items() if k != "order"},
              "results": results, "targets": compute_targets(results)}
    if provenance is not None:
        report.update(provenance.report(results))
    elif stored is not None:
        report.update({k: stored[k] for k in ("machine", "ddg_source_sha256", "load_average",
                                              "ddg_source_changed_during_run") if k in stored})
    return report


def write_outputs(out: Path, name: str, report: dict, markdown: str) -> str:
    from ddg.output.io import atomic_write_text

    atomic_write_text(out / f"{name}.json", json.dumps(report, indent=1, default=float) + "\n")
    atomic_write_text(out / f"{name}.md", markdown)
    return f"wrote {out / f'{name}.json'} and {out / f'{name}.md'}"


# ---------------------------------------------------------------------------- compare mode
def _diff(a, b):
    return None if a is None or b is None else abs(b - a)


def _pair(a, b, spec="d") -> str:
    return f"{_f(a, spec)} / {_f(b, spec)}"


def compare_runs(before: dict, after: dict) -> list[dict]:
    """Per run present in either report: the before and after records side by side, and the physics checks."""
    b = {run_key(r): r for r in before["results"]}
    a = {run_key(r): r for r in after["results"]}
    rows = []
    for key in list(dict.fromkeys(list(b) + list(a))):
        rb, ra = b.get(key), a.get(key)
        row = {"key": key, "before": rb, "after": ra}
        if _ok(rb) and _ok(ra):
            d1 = _diff(rb["dW1_over_L"], ra["dW1_over_L"])
            d2 = _diff(rb["dW2_over_L"], ra["dW2_over_L"])
            one1 = (rb["dW1_over_L"] is None) != (ra["dW1_over_L"] is None)
            one2 = (rb["dW2_over_L"] is None) != (ra["dW2_over_L"] is None)
            row.update({
                "same_sequence": rb["branch_sequence"] == ra["branch_sequence"],
                "dW1_diff": d1, "dW2_diff": d2,
                "dW1_flag": (d1 is not None and d1 > DW1_FLAG) or one1,
                "dW2_flag": (d2 is not None and d2 > DW2_FLAG) or one2,
                "folds_same_count": len(rb["folds_dW_over_L"]) == len(ra["folds_dW_over_L"]),
                "status_same": rb["status"] == ra["status"]})
        rows.append(row)
    return rows


def compare_markdown(before: dict, after: dict, labels: tuple[str, str]) -> str:
    lb, la = labels
    rows = compare_runs(before, after)
    both = [r for r in rows if _ok(r["before"]) and _ok(r["after"])]
    side, phys = [], []
    for row in rows:
        rb, ra = row["before"] or {}, row["after"] or {}
        model, size, scene = row["key"].split("|")
        if not (_ok(rb) and _ok(ra)):
            side.append((model, size, scene, f"{rb.get('status', 'not run')} / {ra.get('status', 'not run')}",
                         *["-"] * 11))
            phys.append((model, size, scene, "-", "-", "-", "-", "-", "-", "-"))
            continue
        pb, pa = rb["iterations_by_phase"], ra["iterations_by_phase"]
        change = ra["iterations_per_step"] / rb["iterations_per_step"] if rb["iterations_per_step"] else None
        side.append((model, size, scene, f"{rb['status']} / {ra['status']}",
                     _pair(rb["iterations_per_step"], ra["iterations_per_step"], ".2f"), _f(change, ".2f"),
                     *(_pair(pb[p], pa[p]) for p in PHASES),
                     _pair(rb["fold_snaps"], ra["fold_snaps"]),
                     _pair(rb["iterations_per_snap"], ra["iterations_per_snap"], ".1f"),
                     _pair(rb["iterations_per_threshold"], ra["iterations_per_threshold"], ".1f"),
                     _pair(rb["branch_iterations"], ra["branch_iterations"]),
                     _pair(rb["whole_run_iterations"], ra["whole_run_iterations"])))
        seq = "yes" if row["same_sequence"] else ("NO: " + " > ".join(rb["branch_sequence"]) + " / "
                                                   + " > ".join(ra["branch_sequence"]))
        d1 = _f(row["dW1_diff"], ".1e") + (" FLAG" if row["dW1_flag"] else "")
        d2 = _f(row["dW2_diff"], ".1e") + (" FLAG" if row["dW2_flag"] else "")
        phys.append((model, size, scene, seq, _f(rb["dW1_over_L"], ".5f"), d1, _f(rb["dW2_over_L"], ".5f"), d2,
                     f"{len(rb['folds_dW_over_L'])} / {len(ra['folds_dW_over_L'])}",
                     "yes" if row["status_same"] else f"NO: {rb['status']} / {ra['status']}"))
    fewer = sum(1 for r in both if r["after"]["iterations_per_step"] < r["before"]["iterations_per_step"])
    more = sum(1 for r in both if r["after"]["iterations_per_step"] > r["before"]["iterations_per_step"])
    flags = [r["key"] for r in both if not r["same_sequence"] or r["dW1_flag"] or r["dW2_flag"]
             or not r["folds_same_count"] or not r["status_same"]]
    tb = {t["target"]: t for t in before["targets"]}
    ta = {t["target"]: t for t in after["targets"]}
    trows = []
    for name in dict.fromkeys(list(tb) + list(ta)):
        x, y = tb.get(name), ta.get(name)
        ref = x or y
        spec = ".0f" if ref["unit"] == "its" else ".2f"
        trows.append((name, f"<= {ref['bound']:g} {ref['unit']}", _f(x and x["measured"], spec),
                      _yes(x and x["met"]), _f(y and y["measured"], spec), _yes(y and y["met"])))
    met_b = sum(1 for t in before["targets"] if t["met"])
    met_a = sum(1 for t in after["targets"] if t["met"])
    lines = [f"# Path iterations: {lb} against {la} (benchmarks/path_iterations.py --compare)", "",
             f"- {len(both)} runs measured in both; iterations per recorded step fewer {la} in {fewer}, more in "
             f"{more}, equal in {len(both) - fewer - more}.",
             f"- targets met: {met_b} of {len(before['targets'])} {lb}, {met_a} of {len(after['targets'])} {la}.",
             f"- physics: {len(both) - len(flags)} of {len(both)} runs with the same branch sequence, status and "
             f"folds count and dW1 within {DW1_FLAG:g} L, dW2 within {DW2_FLAG:g} L"
             + (f"; flagged: {', '.join(flags)}" if flags else "") + "."]
    lines += section("Targets (issue 49)") + [markdown_table(("target", "bound", f"{lb}", "met", f"{la}", "met"),
                                                             trows)]
    header = ("model", "size", "W/L:dL/L", "status", "its/step", "ratio", *PHASES, "snaps", "its/snap", "its/thr.",
              "branch its", "whole")
    lines += section(f"Side by side ({lb} / {la})") + [markdown_table(header, side), "",
                                                       "ratio = its/step after / before; per phase: path iterations."]
    lines += section("Physics unchanged") + [markdown_table(
        ("model", "size", "W/L:dL/L", "same sequence", f"dW1/L {lb}", "abs dW1 diff", f"dW2/L {lb}", "abs dW2 diff",
         "folds", "same status"), phys), "",
        f"FLAG: |dW1 {la} - dW1 {lb}| > {DW1_FLAG:g} L, |dW2 {la} - dW2 {lb}| > {DW2_FLAG:g} L, or the threshold found "
        "in one run only."]
    lines += section("Definitions", DEFINITIONS)
    lines += section("Provenance", [
        f"{lb}: ddg sources `{before.get('ddg_source_sha256', '?')[:16]}`, {before.get('machine', {}).get('date')}, "
        f"config {before.get('config')}",
        f"{la}: ddg sources `{after.get('ddg_source_sha256', '?')[:16]}`, {after.get('machine', {}).get('date')}, "
        f"config {after.get('config')}"])
    return "\n".join(lines) + "\n"


def compare(out: Path, labels: tuple[str, str]) -> str:
    from ddg.output.io import atomic_write_text

    reports = []
    for label in labels:
        path = out / f"{BENCHMARK}_{label}.json"
        reports.append(json.loads(path.read_text()))
    atomic_write_text(out / f"{BENCHMARK}.md", compare_markdown(*reports, labels))
    return f"wrote {out / f'{BENCHMARK}.md'}"


# ---------------------------------------------------------------------------- command line
def _describe(r: dict) -> str:
    if not _ok(r):
        err = (r.get("error") or "").strip().splitlines()
        return f"{r.get('status')}: {err[-1] if err else ''}"
    return (f"{r['status']}, {r['recorded_steps']} steps, {r['path_iterations']} its ({r['iterations_per_step']:.2f}"
            f"/step), snaps {r['fold_snaps']}, thresholds {r['threshold_iterations']} its, branches "
            f"{r['branch_iterations']}, {r['wall_time_s']:.2f} s")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.path_iterations", description=__doc__.split("\n")[0])
    parser.add_argument("--models", nargs="+", choices=MODELS, default=list(MODELS))
    parser.add_argument("--scenes", nargs="+", default=[DEFAULT_SCENES], help="W/L:dL/L, comma separated")
    parser.add_argument("--rows", type=int, nargs="+", default=list(DEFAULT_ROWS), help="mid-edge plate rows")
    parser.add_argument("--timeout", type=float, default=TIMEOUT_S, help="seconds per run (x --repeat); 0: none")
    parser.add_argument("--repeat", type=int, default=1)
    parser.add_argument("--jobs", type=int, default=1, help="runs in parallel child processes")
    parser.add_argument("--label", default="before", help="results go to path_iterations_<label>.json/.md")
    parser.add_argument("--out", default="benchmarks/results")
    parser.add_argument("--resume", action="store_true", help="skip runs stored with the same sources and protocol")
    parser.add_argument("--report-only", action="store_true", help="rewrite the markdown from the stored JSON")
    parser.add_argument("--compare", nargs=2, metavar=("BEFORE", "AFTER"), default=None)
    parser.add_argument("--compression-steps", type=int, default=COMPRESSION_STEPS)
    parser.add_argument("--shear-steps", type=int, default=SHEAR_STEPS)
    args = parser.parse_args(argv)
    out = Path(args.out)
    if args.compare:
        print(compare(out, tuple(args.compare)))
        return 0
    try:
        scenes = parse_scenes(args.scenes)
    except argparse.ArgumentTypeError as exc:
        parser.error(str(exc))
    if not 1 <= args.repeat <= 10 or args.jobs < 1 or not math.isfinite(args.timeout) or args.timeout < 0:
        parser.error("--repeat must be in 1..10, --jobs >= 1, --timeout >= 0")
    if any(r < 2 or r % 2 for r in args.rows):
        parser.error(f"--rows {args.rows}: rows across W must be even and >= 2")
    if any(c in args.label for c in "/\\ ") or not args.label:
        parser.error(f"--label {args.label!r}: a plain name (no spaces or slashes)")
    name = f"{BENCHMARK}_{args.label}"
    path = out / f"{name}.json"
    stored = json.loads(path.read_text()) if path.exists() else None
    if args.report_only:
        if stored is None:
            parser.error(f"--report-only: {path} does not exist")
        stored["targets"] = compute_targets(stored["results"])
        from ddg.output.io import atomic_write_text

        atomic_write_text(path, json.dumps(stored, indent=1, default=float) + "\n")
        atomic_write_text(out / f"{name}.md", markdown_report(stored))
        print(f"wrote {out / f'{name}.md'} (and the targets into {path})")
        return 0
    from ddg.output.interrupts import deferred_signals, terminate_as_interrupt

    out.mkdir(parents=True, exist_ok=True)
    provenance = Provenance()
    specs = run_specs(args.models, scenes, args.rows)
    steps = (args.compression_steps, args.shear_steps)
    config = {"models": args.models, "scenes": [f"{w}:{c}" for w, c in scenes], "rows": args.rows,
              "timeout_s": args.timeout, "repeat": args.repeat, "jobs": args.jobs, "compression_steps": steps[0],
              "shear_steps": steps[1], "order": specs}

    def current(r) -> bool:
        return (r.get("ddg_source_sha256") == provenance.fingerprint
                and (r.get("compression_steps"), r.get("shear_steps")) == steps)

    records = {run_key(r): r for r in (stored or {}).get("results", []) if current(r)}
    selected = {run_key(s) for s in specs}
    records = {k: r for k, r in records.items() if k not in selected or args.resume}
    todo = [s for s in specs if run_key(s) not in records]
    for key in sorted(selected - {run_key(s) for s in todo}):
        print(f"{key}: stored with the same sources, kept", file=sys.stderr)

    def on_done(spec, status, payload, elapsed, load):
        record = payload if status == "ok" else {**spec, "size": size_label(spec), "status": status,
                                                 "error": payload if status == "error" else
                                                 f"stopped after {elapsed:.0f} s (--timeout {args.timeout:g} x "
                                                 f"--repeat {args.repeat})",
                                                 "ddg_source_sha256": provenance.fingerprint,
                                                 "compression_steps": steps[0], "shear_steps": steps[1]}
        record.update({"child_elapsed_s": elapsed, "load_average_before": load, "load_average_after": load_average()})
        records[run_key(spec)] = record
        report = build_report(records, args.label, config, provenance, None)
        with deferred_signals():
            write_outputs(out, name, report, markdown_report(report))
        print(f"{run_key(spec)}: {_describe(record)} [{elapsed:.0f} s]", file=sys.stderr, flush=True)

    limit = args.timeout * args.repeat if args.timeout > 0 else None
    terminate_as_interrupt()  # SIGTERM too stops the children and keeps the finished runs
    t0 = time.perf_counter()
    try:
        run_parallel(todo, args.jobs, limit, on_done, (args.repeat, *steps))
    except KeyboardInterrupt:
        print(f"interrupted: the finished runs are kept in {path} (--resume continues)", file=sys.stderr)
        return 130
    report = build_report(records, args.label, config, provenance, None)
    report["elapsed_s"] = time.perf_counter() - t0
    wrote = write_outputs(out, name, report, markdown_report(report))
    print(text_table(("model", "size", "scene", "status", "its/step", "snaps", "its/thr.", "whole"),
                     [(r["model"], r["size"], r["scene"], r.get("status", "?"), _f(r.get("iterations_per_step")),
                       str(r.get("fold_snaps", "-")), _f(r.get("iterations_per_threshold"), ".1f"),
                       str(r.get("whole_run_iterations", "-"))) for r in report["results"]]))
    print(wrote)
    warn_if_changed(report)
    return 0 if all(_ok(r) for r in report["results"]) else 1


if __name__ == "__main__":
    sys.exit(main())
