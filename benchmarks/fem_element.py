"""Accuracy per CPU second of the FEM shell's elements (issue 28 item 2): u in [P3]^3, theta in
[P3]^2 against the default u in [P2 + B3]^3, theta in [P2]^2 (fem_reference.elements), on the
paper strip W/L = 1/20, dL/L = 1/2, the whole default path with dW1 and dW2 bisected to the gold
tolerances.

    .venv/bin/python -m benchmarks.fem_element --run-dir DIR [--meshes P3:32x4 P3:48x6 P3:64x8 ...]
        [--gold data/fem_gold/dL0.5_W0.05] [--out benchmarks/results] [--timeout 3600] [--report-only]
        [--note TEXT ...]

Each mesh of --meshes (ELEMENT:ALONGxACROSS) is one run, in a fresh child process, of

    fem_reference.api.simulate(Strip.from_ratios(1/20, 1/2), LoadingProtocol(1/2), along, across=across,
                               element=ELEMENT, options=ContinuationOptions(dw1_tolerance=1e-4,
                               dw2_tolerance=1e-4), fields=False, centerline=False)

as the gold runs (fem_reference.gold.run_mesh, GOLD_TOLERANCES) into DIR/<ELEMENT>_N<along>x<across>/,
with the CPU time of the call (time.process_time: the machine's cores may be shared, so wall time
is reported but not judged on) and the peak resident memory in DIR/.../timing.json. Resumable: a
run whose summary.json is finished (complete or stopped) on that mesh, element and tolerances and
whose timing.json exists is read, not rerun.

The P2 + B3 side also comes from the gold study itself (--gold: its N<along>x<across> runs, read,
never rerun), whose summary.json has wall_time_s but no CPU time: their wall time, from runs
made on an otherwise idle core, stands for their CPU time (a P2B3 mesh in --meshes measures the
two side by side). Every run's dW1, dW2, compressed H_mid and H_mid at H_MID_AT are compared
with the gold's converged values and error bars (--gold/richardson.json), and the compressed
H_mid with the exact clamped elastica (ddg.analysis.analytic.clamped_elastica_midpoint_height).

The verdict (`cpu_to_reach`): per quantity and element, the CPU seconds at which the error falls
to the gold's error bar (the smallest error the gold can tell), interpolated log-log between the
element's runs; bounds where no run or every run is below it. Writes OUT/fem_element.json and
OUT/fem_element.md. Not part of the test run.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import re
import sys
import time
from pathlib import Path

from benchmarks.common import markdown_table, run_in_child, write_report

WIDTH_RATIO = 1.0 / 20.0
COMPRESSION_RATIO = 0.5
GOLD = Path("data/fem_gold/dL0.5_W0.05")
DEFAULT_MESHES = ("P3:32x4", "P3:48x6", "P3:64x8", "P2B3:64x8", "P3:96x12")
#: shear displacements (units of L) where H_mid is compared: on U (before every mesh's dW1) and
#: on US (between dW1 and dW2); the nearest recorded step of the gold's H_mid curve is taken.
H_MID_AT = (0.1, 0.2, 0.3, 0.42)
QUANTITIES = ("dW1", "dW2", "H_mid_compressed", "H_mid_curve")


# ---------------------------------------------------------------------------- one run (child)
def run_one(element: str, along: int, across: int, folder: str) -> dict:
    """The whole path on one mesh into `folder`, as the gold runs; returns and writes timing.json."""
    import resource

    from ddg.geometry.strip import LoadingProtocol, Strip
    from ddg.output.io import atomic_write_text
    from fem_reference.api import simulate
    from fem_reference.continuation import ContinuationOptions
    from fem_reference.gold import GOLD_TOLERANCES

    options = ContinuationOptions(dw1_tolerance=GOLD_TOLERANCES[0], dw2_tolerance=GOLD_TOLERANCES[1])
    strip = Strip.from_ratios(WIDTH_RATIO, COMPRESSION_RATIO)
    Path(folder).mkdir(parents=True, exist_ok=True)
    c0, t0 = time.process_time(), time.perf_counter()
    summary = simulate(strip, LoadingProtocol(COMPRESSION_RATIO), along, out=folder, across=across, options=options,
                       fields=False, progress=False, centerline=False, element=element).summary
    timing = {"cpu_time_s": time.process_time() - c0, "wall_time_s": time.perf_counter() - t0,
              "peak_rss_bytes": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024,
              "status": summary["status"],
              "thread_env": {k: os.environ.get(k) for k in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS")},
              "load_average_after": os.getloadavg()[0], "date": time.strftime("%Y-%m-%dT%H:%M:%S%z")}
    atomic_write_text(Path(folder) / "timing.json", json.dumps(timing, indent=1) + "\n")
    return timing


# ---------------------------------------------------------------------------- runs
def parse_mesh(text: str) -> tuple[str, int, int]:
    from fem_reference.elements import ELEMENTS

    match = re.fullmatch(r"(\w+):(\d+)x(\d+)", text)
    if not match or match.group(1) not in ELEMENTS:
        raise argparse.ArgumentTypeError(f"{text!r}: ELEMENT:ALONGxACROSS with ELEMENT one of {', '.join(ELEMENTS)}")
    return match.group(1), int(match.group(2)), int(match.group(3))


def _read(path: Path) -> dict | None:
    from ddg.output.io import read_json_object

    return read_json_object(path)


def finished(folder: Path, element: str, along: int, across: int) -> bool:
    """A stored run that needs no rerun: finished, on this mesh, element and the gold tolerances,
    with its timing."""
    from fem_reference.elements import ELEMENTS
    from fem_reference.gold import GOLD_TOLERANCES

    s = _read(folder / "summary.json")
    if not s or s.get("status") not in ("complete", "stopped") or _read(folder / "timing.json") is None:
        return False
    mesh = s.get("mesh") or {}
    tolerances = s.get("threshold_tolerances_over_L") or {}
    return ((mesh.get("elements_along_L"), mesh.get("elements_across_W")) == (along, across)
            and mesh.get("element") == ELEMENTS[element].description
            and (tolerances.get("dW1"), tolerances.get("dW2")) == GOLD_TOLERANCES)


def run_folder(run_dir: Path, element: str, along: int, across: int) -> Path:
    return run_dir / f"{element}_N{along}x{across}"


def make_runs(meshes, run_dir: Path, timeout: float) -> None:
    for element, along, across in meshes:
        folder = run_folder(run_dir, element, along, across)
        if finished(folder, element, along, across):
            print(f"{folder.name}: finished, read", file=sys.stderr)
            continue
        print(f"{folder.name}: running", file=sys.stderr, flush=True)
        status, payload, elapsed = run_in_child(run_one, (element, along, across, str(folder)), timeout)
        if status != "ok":
            print(f"{folder.name}: {status} after {elapsed:.0f} s\n{payload}", file=sys.stderr)
            continue
        print(f"{folder.name}: {payload['status']}, CPU {payload['cpu_time_s']:.0f} s, "
              f"wall {payload['wall_time_s']:.0f} s", file=sys.stderr, flush=True)


# ---------------------------------------------------------------------------- comparison
def _row_at(rows: list[dict], dw: float) -> dict | None:
    shear = [r for r in rows if r["stage"] == "shear"]
    best = min(shear, key=lambda r: abs(r["dW_over_L"] - dw), default=None)
    return best if best is not None and abs(best["dW_over_L"] - dw) < 1e-9 else None


def gold_reference(gold_dir: Path) -> dict:
    """The gold's converged values with error bars: dW1, dW2, H_mid compressed, H_mid at H_MID_AT."""
    study = _read(gold_dir / "richardson.json")
    if study is None:
        raise SystemExit(f"{gold_dir}/richardson.json: missing or unreadable")
    curve = [p for p in study["H_mid_curve"] if p.get("value") is not None and p.get("error_bar") is not None]
    points = [min(curve, key=lambda p: abs(p["dW_over_L"] - dw)) for dw in H_MID_AT]
    ref = {q: {"value": study[q]["value"], "error_bar": study[q]["error_bar"], "basis": study[q]["basis"]}
           for q in ("dW1", "dW2")}
    ref["H_mid_compressed"] = {k: study["H_mid_compressed"][k] for k in ("value", "error_bar", "basis")}
    ref["H_mid_curve"] = [{"dW_over_L": p["dW_over_L"], "value": p["value"], "error_bar": p["error_bar"],
                           "asymptotic": p.get("asymptotic")} for p in points]
    ref["meshes"] = [(m["along"], m["across"]) for m in study["meshes"]]
    return ref


def measure(folder: Path, ref: dict, cpu: float | None, cpu_basis: str, element: str) -> dict:
    """One run's figures and its errors against the gold (|value - gold|, the bar beside it)."""
    from ddg.analysis.analytic import clamped_elastica_midpoint_height
    from ddg.output.io import StoredRun

    run = StoredRun(str(folder))
    s = run.summary
    timing = _read(folder / "timing.json") or {}
    exact = clamped_elastica_midpoint_height(COMPRESSION_RATIO)
    out = {"element": element, "folder": str(folder), "along": s["mesh"]["elements_along_L"],
           "across": s["mesh"]["elements_across_W"], "n_dof": s["n_dof"], "status": s["status"],
           "cpu_time_s": cpu, "cpu_basis": cpu_basis, "wall_time_s": timing.get("wall_time_s", s["wall_time_s"]),
           "library_wall_time_s": s["wall_time_s"], "peak_rss_bytes": timing.get("peak_rss_bytes"),
           "newton_iterations": s["newton_iterations"], "newton_iterations_by_phase": s["newton_iterations_by_phase"],
           "message": s["message"], "dW1": s["dW1_over_L"], "dW2": s["dW2_over_L"],
           "H_mid_compressed": s["H_mid_over_L_compressed"],
           "H_mid_compressed_vs_elastica": s["H_mid_over_L_compressed"] / exact - 1.0}
    errors = {}
    for q in ("dW1", "dW2", "H_mid_compressed"):
        errors[q] = None if out[q] is None else abs(out[q] - ref[q]["value"])
    curve = []
    for point in ref["H_mid_curve"]:
        row = _row_at(run.rows, point["dW_over_L"])
        if row is not None:
            error = abs(row["H_mid_over_L"] - point["value"])
            row = {"dW_over_L": point["dW_over_L"], "value": row["H_mid_over_L"], "phase": row["phase"],
                   "error": error, "error_bar": point["error_bar"], "error_over_bar": error / point["error_bar"]}
        curve.append(row)
    out["H_mid_curve"] = curve
    # the curve's bars differ from point to point: its error is the largest error / bar (1 = at the bar)
    errors["H_mid_curve"] = None if None in curve else max(c["error_over_bar"] for c in curve)
    out["errors"] = errors
    return out


def _bar(ref: dict, q: str) -> float:
    """The gold's error bar of q (the curve's errors are already in units of their bars: 1)."""
    return 1.0 if q == "H_mid_curve" else ref[q]["error_bar"]


def cpu_to_reach(runs: list[dict], q: str, target: float, key: str = "cpu_time_s") -> dict:
    """CPU seconds at which the error of q falls to `target`, log-log interpolated between
    successive runs (by CPU time); "at most" the cheapest run's if that one is already below,
    "more than" the dearest run's if none is."""
    pts = sorted((r[key], r["errors"][q]) for r in runs if r["errors"][q] is not None and r[key])
    if not pts:
        return {"bound": None, "cpu_time_s": None}
    if pts[0][1] <= target:
        return {"bound": "at most", "cpu_time_s": pts[0][0]}
    for (c0, e0), (c1, e1) in zip(pts, pts[1:]):
        if e1 <= target:
            if e1 <= 0.0:
                return {"bound": "at most", "cpu_time_s": c1}
            f = math.log(e0 / target) / math.log(e0 / e1)
            return {"bound": "about", "cpu_time_s": math.exp(math.log(c0) + f * math.log(c1 / c0))}
    return {"bound": "more than", "cpu_time_s": pts[-1][0]}


def verdict(by_element: dict, ref: dict, key: str = "cpu_time_s") -> dict:
    """Per quantity: each element's CPU seconds (runs' `key`) to reach the gold's error bar, and
    their ratio P2B3 / P3 with its kind (about, at least, at most, undecided)."""
    out = {}
    for q in QUANTITIES:
        target = _bar(ref, q)
        reach = {e: cpu_to_reach(runs, q, target, key) for e, runs in by_element.items()}
        p3, p2 = reach.get("P3"), reach.get("P2B3")
        speedup = None
        if p3 and p2 and p3["cpu_time_s"] and p2["cpu_time_s"]:
            ratio = p2["cpu_time_s"] / p3["cpu_time_s"]
            # the ratio is a lower bound where P3 is "at most" or P2B3 "more than", an upper one in the reverse case
            low = p3["bound"] == "at most" or p2["bound"] == "more than"
            high = p3["bound"] == "more than" or p2["bound"] == "at most"
            speedup = {"ratio": ratio, "kind": "undecided" if low and high else "at least" if low
                       else "at most" if high else "about"}
        out[q] = {"target_error": target, "reach": reach, "speedup_P3_over_P2B3": speedup}
    return out


def add_trouble_free_cpu(rows: list[dict]) -> None:
    """rows' cpu_trouble_free_s: the CPU time a run would have taken without solver trouble, its
    CPU per Newton iteration times its iterations less those of fold snaps and of the dW1 and dW2
    bisections beyond the largest count of the P2B3 runs (an estimate; None for a run that
    stopped)."""
    p2 = [r["newton_iterations_by_phase"] for r in rows if r["element"] == "P2B3"]
    caps = {phase: max((by[phase] for by in p2), default=0) for phase in ("threshold dW1", "threshold dW2")}
    for r in rows:
        by = r["newton_iterations_by_phase"]
        excess = by["fold snaps"] + sum(max(0, by[phase] - cap) for phase, cap in caps.items())
        r["trouble_free_iterations"] = r["newton_iterations"] - excess
        r["cpu_trouble_free_s"] = (None if r["status"] != "complete" or not r["cpu_time_s"] else
                                   r["cpu_time_s"] * r["trouble_free_iterations"] / r["newton_iterations"])


# ---------------------------------------------------------------------------- report
LABELS = {"dW1": "dW1/L", "dW2": "dW2/L", "H_mid_compressed": "H_mid/L compressed",
          "H_mid_curve": "H_mid/L at dW/L = " + ", ".join(f"{d:g}" for d in H_MID_AT) + " (largest error / bar)"}


def _target(q: str, entry: dict) -> str:
    return "each point's bar" if q == "H_mid_curve" else f"{entry['target_error']:.1e}"


def _e(x, bar=None):
    if x is None:
        return "n/a"
    return f"{x:.1e}" + ("" if bar is None else (" ≤ bar" if x <= bar else ""))


def calibration_note(rows: list[dict]) -> str:
    """The stored wall time of a gold P2B3 run against the CPU time of the same mesh measured here."""
    stored = {(r["along"], r["across"]): r for r in rows if r["element"] == "P2B3" and r["cpu_basis"] != "measured"}
    notes = [f"{r['along']} x {r['across']}: CPU {r['cpu_time_s']:.0f} s measured here (wall {r['wall_time_s']:.0f} s "
             f"on the shared cores) against the stored {stored[(r['along'], r['across'])]['cpu_time_s']:.0f} s, "
             f"ratio {r['cpu_time_s'] / stored[(r['along'], r['across'])]['cpu_time_s']:.2f}"
             for r in rows if r["element"] == "P2B3" and r["cpu_basis"] == "measured"
             and (r["along"], r["across"]) in stored]
    return (" P2B3 " + "; ".join(notes) + ": a stored wall time stands for the CPU time to within that.") \
        if notes else ""


def markdown(report: dict) -> str:
    ref, rows, v = report["gold"], report["runs"], report["verdict"]
    lines = ["# FEM shell elements: accuracy per CPU second (issue 28 item 2)", "",
             "Scene: W/L = 1/20, dL/L = 1/2, L/b = 1181 (the paper strip), the whole default path (40 compression "
             "and 120 shear steps, branch switch), dW1 and dW2 bisected to 1e-4 L as the gold runs. "
             "P2B3: u in [P2 + B3]^3, theta in [P2]^2, PSRI degrees 4/2 (the default); P3: u in [P3]^3, "
             "theta in [P3]^2, PSRI degrees 6/4 (fem_reference/elements.py).", "",
             "Gold (data/fem_gold/dL0.5_W0.05/richardson.json, P2B3 on "
             + ", ".join(f"{a} x {c}" for a, c in ref["meshes"]) + "): "
             + "; ".join(f"{LABELS[q]} {ref[q]['value']:.5f} ± {ref[q]['error_bar']:.1e}"
                         for q in ("dW1", "dW2", "H_mid_compressed"))
             + "; H_mid/L at " + ", ".join(f"{p['dW_over_L']:.4f} L: {p['value']:.5f} ± {p['error_bar']:.1e}"
                                           for p in ref["H_mid_curve"]) + ". "
             f"Exact clamped elastica H_mid/L = {report['elastica_H_mid']:.6f}.", ""]
    header = ["element", "mesh", "DOFs", "CPU s", "wall s", "Newton its", "dW1/L", "dW1 error", "dW2/L",
              "dW2 error", "H_mid/L compressed: error", "relative to the exact elastica",
              "H_mid/L(dW): largest error / bar"]
    table = []
    for r in rows:
        err = r["errors"]
        cpu = "n/a" if r["cpu_time_s"] is None else f"{r['cpu_time_s']:.0f}" + ("*" if r["cpu_basis"] != "measured"
                                                                               else "")
        label = r["element"] + (" (rerun)" if r["element"] == "P2B3" and r["cpu_basis"] == "measured" else "")
        table.append((label, f"{r['along']} x {r['across']}", str(r["n_dof"]), cpu,
                      f"{r['wall_time_s']:.0f}", str(r["newton_iterations"]),
                      "n/a" if r["dW1"] is None else f"{r['dW1']:.4f}", _e(err["dW1"], ref["dW1"]["error_bar"]),
                      "n/a" if r["dW2"] is None else f"{r['dW2']:.4f}", _e(err["dW2"], ref["dW2"]["error_bar"]),
                      _e(err["H_mid_compressed"], ref["H_mid_compressed"]["error_bar"]),
                      f"{r['H_mid_compressed_vs_elastica']:+.1e}",
                      "n/a" if err["H_mid_curve"] is None else f"{err['H_mid_curve']:.2f}"))
    table.append(("gold", "Richardson", "", "", "", "", f"{ref['dW1']['value']:.4f}",
                  f"bar {ref['dW1']['error_bar']:.1e}", f"{ref['dW2']['value']:.4f}",
                  f"bar {ref['dW2']['error_bar']:.1e}", f"bar {ref['H_mid_compressed']['error_bar']:.1e}", "", "1"))
    lines += ["## Runs", "", markdown_table(header, table), "",
              "Errors: abs(value - gold). CPU s: time.process_time of the simulate call (one thread: "
              "OPENBLAS_NUM_THREADS = OMP_NUM_THREADS = 1); "
              "* = the gold run's stored wall_time_s (its summary.json has no CPU time), standing for its CPU "
              "time (a run made on an otherwise idle core; see the Notes). Wall s: elapsed, on 2 cores shared with "
              "two other FEM runs, not judged on. Errors against the gold's converged values; \"≤ bar\": within the "
              "gold's error bar, i.e. as close as the gold can tell. The gold's finest P2B3 mesh is part of the gold "
              "itself (dW2's gold value is that mesh's value), so the P2B3 errors of its finest mesh are "
              "optimistic." + calibration_note(rows), ""]
    trouble = []
    for r in rows:
        by = r["newton_iterations_by_phase"]
        per_it = "n/a" if r["cpu_time_s"] is None else f"{1e3 * r['cpu_time_s'] / r['newton_iterations']:.0f}"
        trouble.append((r["element"], f"{r['along']} x {r['across']}", r["status"], str(r["newton_iterations"]),
                        str(by["accepted steps"] + by["rejected steps"]), str(by["threshold dW1"]),
                        str(by["threshold dW2"]), str(by["fold snaps"]), str(by["failed solves"]), per_it))
    lines += ["## Where the Newton iterations went", "",
              markdown_table(["element", "mesh", "status", "Newton its", "path steps", "dW1 bisection",
                              "dW2 bisection", "fold snaps", "failed solves", "CPU ms / it"], trouble), "",
              "From summary.json's newton_iterations_by_phase (path steps: accepted and rejected load steps). "
              "A run that stopped: " + "; ".join(f"{r['element']} {r['along']} x {r['across']}: {r['message']}"
                                                 for r in rows if r["status"] != "complete") + ".", ""]
    lines += ["## CPU time to reach the gold's error bar", ""]
    vt = []
    for q in QUANTITIES:
        cells = []
        for verdict_ in (v, report["verdict_trouble_free"]):
            x = verdict_[q]
            for e in ("P2B3", "P3"):
                reach = x["reach"].get(e) or {}
                cells.append("n/a" if reach.get("cpu_time_s") is None
                             else f"{reach['bound']} {reach['cpu_time_s']:.0f} s")
            sp = x["speedup_P3_over_P2B3"]
            cells.append("n/a" if sp is None else f"{sp['kind']} {sp['ratio']:.1f}x")
        vt.append((LABELS[q], _target(q, v[q]), *cells))
    lines += [markdown_table(["quantity", "gold error bar", "P2B3", "P3", "P2B3 CPU / P3 CPU",
                              "P2B3 (trouble-free)", "P3 (trouble-free)", "ratio (trouble-free)"], vt), "",
              "Log-log interpolation of each element's error against its CPU time between successive runs; "
              "\"at most\": the element's cheapest run is already within the bar; \"more than\": none of its runs is. "
              "Trouble-free: an estimate, each complete run's CPU per Newton iteration times its iterations less "
              "those of fold snaps and of the threshold bisections beyond the largest count of the P2B3 runs "
              "(runs that stopped left out).",
              "", "## Conclusion", ""] + [f"- {c}" for c in report["conclusion"]]
    if report.get("notes"):
        lines += ["", "## Notes", ""] + [f"- {n}" for n in report["notes"]]
    lines += ["", "## How it was run", "", "    OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 nice -n 5 .venv/bin/python -m "
              f"benchmarks.fem_element --run-dir {report['run_dir']} --meshes {' '.join(report['meshes'])}", "",
              "(each run in a fresh child process, one at a time; the P3 element from the command line: "
              "`python -m fem_reference simulate --width-ratio 0.05 --compression-ratio 0.5 --element P3 "
              "--resolution 32 --across 4`, which bisects dW1 to 1e-4 L and dW2 to 1e-3 L instead of the gold's "
              "1e-4 L). Machine: " + report["machine"] + ".", ""]
    return "\n".join(lines)


#: a bound on P2B3 CPU / P3 CPU read the other way round (P3 CPU / P2B3 CPU)
_FLIP = {"about": "about", "at least": "at most", "at most": "at least"}


def comparison(sp: dict | None) -> str:
    """The P2B3 / P3 CPU ratio in words."""
    if sp is None:
        return "no comparison (missing runs)"
    decided = sp["kind"] == "about" or (sp["kind"] == "at least") == (sp["ratio"] >= 1.0) and sp["kind"] != "undecided"
    if not decided:
        return f"undecided (P2B3 CPU / P3 CPU {sp['kind']} {sp['ratio']:.1f}: a side's runs do not bracket the bar)"
    if sp["ratio"] >= 1.0:
        return f"P3 is cheaper, {sp['kind']} {sp['ratio']:.1f} times fewer CPU seconds"
    return f"P2B3 is cheaper, P3 needs {_FLIP[sp['kind']]} {1.0 / sp['ratio']:.1f} times its CPU seconds"


def conclusion(v: dict, by_element: dict, ref: dict, v_free: dict) -> list[str]:
    """One sentence per quantity from the verdict as measured (and the trouble-free estimate's
    reading where it differs), and the P3 mesh-to-mesh changes."""
    out = []
    for q in QUANTITIES:
        reach = v[q]["reach"]
        if "P3" not in reach or "P2B3" not in reach or reach["P3"]["cpu_time_s"] is None:
            out.append(f"{LABELS[q]}: no comparison (missing runs).")
            continue
        r3, r2 = reach["P3"], reach["P2B3"]
        text = (f"{LABELS[q]} within the gold's error bar ({_target(q, v[q])}): P2B3 {r2['bound']} "
                f"{r2['cpu_time_s']:.0f} s, P3 {r3['bound']} {r3['cpu_time_s']:.0f} s: "
                f"{comparison(v[q]['speedup_P3_over_P2B3'])}")
        free = comparison(v_free[q]["speedup_P3_over_P2B3"])
        if free != comparison(v[q]["speedup_P3_over_P2B3"]):
            text += f"; without the P3 runs' solver trouble (estimate) {free}"
        out.append(text + ".")
    p3 = sorted(by_element.get("P3", []), key=lambda r: r["n_dof"])
    if len(p3) >= 2:
        def changes(q):
            runs = [r for r in p3 if r[q] is not None]
            return ", ".join(f"{abs(b[q] - a[q]):.1e} ({a['along']} x {a['across']} -> {b['along']} x {b['across']})"
                             for a, b in zip(runs, runs[1:])) or "n/a"

        out.append(f"P3 from mesh to mesh: dW1/L changes by {changes('dW1')}; dW2/L by {changes('dW2')} "
                   f"(the gold's error bars {ref['dW1']['error_bar']:.1e} and {ref['dW2']['error_bar']:.1e}).")
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.fem_element", description=__doc__.splitlines()[0])
    parser.add_argument("--run-dir", required=True, help="folder of the runs (one subfolder per mesh)")
    parser.add_argument("--meshes", nargs="*", type=parse_mesh, default=[parse_mesh(m) for m in DEFAULT_MESHES],
                        help="ELEMENT:ALONGxACROSS, e.g. P3:32x4 (default: " + " ".join(DEFAULT_MESHES) + ")")
    parser.add_argument("--gold", default=str(GOLD), help="the gold scene folder (read only)")
    parser.add_argument("--out", default="benchmarks/results")
    parser.add_argument("--timeout", type=float, default=3600.0, help="seconds per run")
    parser.add_argument("--report-only", action="store_true", help="no run: the report from the finished runs")
    parser.add_argument("--note", action="append", default=[],
                        help="a line for the report's Notes (how the machine was shared, what went wrong); repeatable")
    args = parser.parse_args(argv)
    for key in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS"):  # inherited by the spawned runs
        os.environ.setdefault(key, "1")
    run_dir, gold_dir = Path(args.run_dir), Path(args.gold)
    if not args.report_only:
        make_runs(args.meshes, run_dir, args.timeout)

    import platform

    from ddg.analysis.analytic import clamped_elastica_midpoint_height

    ref = gold_reference(gold_dir)
    rows = []
    for along, across in ref["meshes"]:
        folder = gold_dir / f"N{along}x{across}"
        s = _read(folder / "summary.json")
        if s and s.get("status") == "complete":
            rows.append(measure(folder, ref, s["wall_time_s"], "stored wall time", "P2B3"))
    for element, along, across in args.meshes:
        folder = run_folder(run_dir, element, along, across)
        if finished(folder, element, along, across):
            rows.append(measure(folder, ref, _read(folder / "timing.json")["cpu_time_s"], "measured", element))
    by_element = {}
    for r in rows:
        # the gold's own P2B3 runs make the P2B3 sequence; a P2B3 run measured here only calibrates their CPU time
        if r["element"] == "P3" or r["cpu_basis"] != "measured":
            by_element.setdefault(r["element"], []).append(r)
    add_trouble_free_cpu(rows)
    v = verdict(by_element, ref)
    v_free = verdict(by_element, ref, "cpu_trouble_free_s")
    report = {"benchmark": "fem_element", "scene": {"width_ratio": WIDTH_RATIO, "compression_ratio": COMPRESSION_RATIO},
              "gold": ref, "elastica_H_mid": clamped_elastica_midpoint_height(COMPRESSION_RATIO), "runs": rows,
              "verdict": v, "verdict_trouble_free": v_free, "conclusion": conclusion(v, by_element, ref, v_free),
              "run_dir": str(run_dir),
              "meshes": [f"{e}:{a}x{c}" for e, a, c in args.meshes], "notes": args.note,
              "machine": f"{os.cpu_count()} cores, {platform.processor() or platform.machine()}, "
                         f"load average {os.getloadavg()[0]:.1f} at the report"}
    print(write_report(args.out, "fem_element", report, markdown(report)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
