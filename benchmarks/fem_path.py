"""Speed benchmark of the FEM shell reference's full path (fem_reference: Naghdi shell, dolfinx,
MUMPS, SLEPc), with the same per-phase breakdown as the DDG path benchmarks.

    .venv/bin/python -m benchmarks.fem_path [--resolution 60] [--width-ratio 1/6]
        [--compression-ratio 0.5] [--before benchmarks/results/fem_path.json] [--note TEXT ...]
        [--out benchmarks/results] [--run-dir DIR] [--no-fields] [--progress] [--timeout 3600]

It runs, once, in a fresh child process (so that a run over --timeout can be stopped),

    fem_reference.api.simulate(Strip.from_ratios(W/L, dL/L),
                               LoadingProtocol(dL/L, compression_steps=40, shear_steps=120),
                               resolution, out=DIR)

as `python -m fem_reference simulate` does by default (thresholds located, branch switch, XDMF
fields written; DIR a temporary folder unless --run-dir), and reports the wall and CPU time,
Newton iterations, iterations per recorded step, the library's own breakdowns from summary.json
(newton_iterations_by_phase, wall_time_by_phase_s, wall_time_within_phases_s: perf_counter sums
kept by fem_reference.solver.Solver, no patching), the most expensive recorded steps, dW1/L,
dW2/L and the load average before and after.

--before FILE (a fem_path.json written earlier) puts that run's figures beside this one's (the
file's own "before" entry if it has one, so the figures from before a series of changes are
carried along) and compares the results: dW1/L and dW2/L against their tolerances
(fem_reference.continuation.DW1_TOLERANCE, DW2_TOLERANCE), H_mid/L step by step where both runs
are on the same branch (same phase label), against 1e-6 L.

Writes OUT/fem_path.json (all numbers, every recorded step, machine info) and OUT/fem_path.md,
atomically. Not part of the test run.
"""
from __future__ import annotations

import argparse
import hashlib
import json
import subprocess
import sys
import time
from fractions import Fraction
from pathlib import Path

from benchmarks.common import (Provenance, load_line, machine_section, markdown_table, ratio, run_in_child,
                               section, source_fingerprint, text_table, write_report)

RESOLUTION = 60
WIDTH_RATIO = 1.0 / 6.0
COMPRESSION_RATIO = 0.5
COMPRESSION_STEPS = 40
SHEAR_STEPS = 120
#: agreement of H_mid/L between two runs on the same branch (units of L), issue 14
H_MID_TOLERANCE = 1e-6
TOP_STEPS = 6


def fem_fingerprint() -> str:
    """sha256 over the fem_reference sources (the ddg fingerprint of common does not cover them)."""
    import fem_reference

    root = Path(fem_reference.__file__).resolve().parent
    digest = hashlib.sha256()
    for path in sorted(root.glob("*.py")):
        digest.update(path.name.encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()


def git_state() -> dict:
    """HEAD commit and whether fem_reference has uncommitted changes (None outside a checkout)."""
    def git(*args):
        try:
            return subprocess.run(["git", *args], capture_output=True, text=True, timeout=30,
                                  cwd=Path(__file__).resolve().parent.parent).stdout.strip()
        except (OSError, subprocess.SubprocessError):
            return None

    head = git("rev-parse", "--short", "HEAD")
    dirty = git("status", "--porcelain", "--", "fem_reference")
    return {"commit": head or None, "fem_reference_uncommitted_changes": bool(dirty) if dirty is not None else None}


# ---------------------------------------------------------------------------- one run (child)
def _run_once(resolution: int, width_ratio: float, compression_ratio: float, run_dir: str | None, fields: bool,
              progress: bool) -> dict:
    import tempfile

    from ddg.geometry.strip import LoadingProtocol, Strip
    from fem_reference.api import simulate
    from fem_reference.continuation import DW1_TOLERANCE, DW2_TOLERANCE
    from fem_reference.solver import ITERATION_PHASES, TIME_PHASES

    strip = Strip.from_ratios(width_ratio, compression_ratio)
    protocol = LoadingProtocol(compression_ratio, compression_steps=COMPRESSION_STEPS, shear_steps=SHEAR_STEPS)
    with tempfile.TemporaryDirectory(prefix="fem_path_") as tmp:
        out = Path(run_dir) if run_dir else Path(tmp)
        out.mkdir(parents=True, exist_ok=True)
        c0, t0 = time.process_time(), time.perf_counter()
        result = simulate(strip, protocol, resolution, out=out, fields=fields, progress=progress)
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        written = json.loads((out / "summary.json").read_text())
    s, rows = result.summary, result.rows
    by_phase = s["newton_iterations_by_phase"]
    its = int(s["newton_iterations"])
    threshold_its = by_phase["threshold dW1"] + by_phase["threshold dW2"]
    times = s["wall_time_by_phase_s"]
    newton_time = sum(times.get(k, 0.0) for k in ("assembly", "factorisation", "linear solves"))
    n = len(rows)
    return {
        "status": "ok",
        "ddg_source_sha256": source_fingerprint(),
        "fem_reference_source_sha256": fem_fingerprint(),
        "git": git_state(),
        "date": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
        "resolution": resolution,
        "mesh": s.get("mesh"),
        "n_dof": s.get("n_dof"),
        "n_free_dof": s.get("n_free_dof"),
        "fields_written": fields,
        "converged": bool(s["converged"]),
        "message": s.get("message", ""),
        "summary_json_matches_result": written.get("newton_iterations") == its,
        "wall_time_s": wall,
        "cpu_time_s": cpu,
        "library_wall_time_s": s.get("wall_time_s"),
        "build_wall_time_s": s.get("build_wall_time_s"),
        "path_wall_time_s": s.get("path_wall_time_s"),
        "threshold_wall_time_s": s.get("threshold_wall_time_s"),
        "newton_iterations": its,
        "threshold_newton_iterations": threshold_its,
        "recorded_steps": n,
        "iterations_per_recorded_step": its / n if n else None,
        "path_iterations_per_recorded_step": (its - threshold_its) / n if n else None,
        "time_per_newton_iteration_ms": 1e3 * wall / its if its else None,
        "newton_time_per_iteration_ms": 1e3 * newton_time / its if its else None,
        "iteration_phases": list(ITERATION_PHASES),
        "time_phases": list(TIME_PHASES),
        "newton_iterations_by_phase": by_phase,
        "wall_time_by_phase_s": times,
        "wall_time_within_phases_s": s.get("wall_time_within_phases_s"),
        "dW1_over_L": s.get("dW1_over_L"),
        "dW2_over_L": s.get("dW2_over_L"),
        "dW1_tolerance": DW1_TOLERANCE,
        "dW2_tolerance": DW2_TOLERANCE,
        "dW_max_over_L": s.get("dW_max_over_L"),
        "H_mid_over_L_compressed": s.get("H_mid_over_L_compressed"),
        "branch_switch": s.get("branch_switch"),
        "steps": [{"stage": r["stage"], "dL_over_L": r["dL_over_L"], "dW_over_L": r["dW_over_L"],
                   "H_mid_over_L": r["H_mid_over_L"], "phase": r["phase"],
                   "negative_eigenvalues": r["negative_eigenvalues"],
                   "lambda_min": r["lambda_min"], "newton_iterations": r["newton_iterations"],
                   "branch_switched": r["branch_switched"], "wall_time_s": r["wall_time_s"]} for r in rows],
    }


# ---------------------------------------------------------------------------- comparison
def load_before(path) -> dict | None:
    """The "before" figures of a fem_path.json: its own "before" entry if it carries one, else
    its result."""
    if path is None:
        return None
    data = json.loads(Path(path).read_text())
    before = data.get("before") or data.get("result")
    if not before or before.get("status") != "ok":
        raise SystemExit(f"{path}: no successful run to compare with")
    before = dict(before)
    before.setdefault("load_average", data.get("load_average"))  # of the run that measured it
    return before


def agreement(before: dict | None, now: dict) -> dict | None:
    """dW1/L, dW2/L and H_mid/L of `now` against `before` (see the module docstring)."""
    if before is None or now.get("status") != "ok":
        return None

    def diff(key):
        a, b = before.get(key), now.get(key)
        return None if a is None or b is None else b - a

    out = {"dW1_over_L_change": diff("dW1_over_L"), "dW2_over_L_change": diff("dW2_over_L"),
           "H_mid_over_L_compressed_change": diff("H_mid_over_L_compressed"),
           "dW1_tolerance": now["dW1_tolerance"], "dW2_tolerance": now["dW2_tolerance"],
           "H_mid_tolerance": H_MID_TOLERANCE}
    out["dW1_within_tolerance"] = (None if out["dW1_over_L_change"] is None
                                   else abs(out["dW1_over_L_change"]) <= now["dW1_tolerance"])
    out["dW2_within_tolerance"] = (None if out["dW2_over_L_change"] is None
                                   else abs(out["dW2_over_L_change"]) <= now["dW2_tolerance"])
    key = lambda r: (r["stage"], round(r["dL_over_L"], 12), round(r["dW_over_L"], 12))  # noqa: E731
    old = {key(r): r for r in before["steps"]}
    same, other_branch, missing = [], [], 0
    for r in now["steps"]:
        b = old.get(key(r))
        if b is None:
            missing += 1
        elif b["phase"] == r["phase"]:
            same.append({"stage": r["stage"], "dW_over_L": r["dW_over_L"], "phase": r["phase"],
                         "change": r["H_mid_over_L"] - b["H_mid_over_L"]})
        else:
            other_branch.append({"stage": r["stage"], "dW_over_L": r["dW_over_L"], "before": b["phase"],
                                 "now": r["phase"], "change": r["H_mid_over_L"] - b["H_mid_over_L"]})
    worst = max(same, key=lambda d: abs(d["change"]), default=None)
    out.update({
        "steps_compared": len(same),
        "steps_without_counterpart": missing,
        "H_mid_max_abs_change": abs(worst["change"]) if worst else None,
        "H_mid_worst_step": worst,
        "H_mid_steps_over_tolerance": [d for d in same if abs(d["change"]) > H_MID_TOLERANCE],
        "steps_on_another_branch": other_branch,
    })
    out["H_mid_within_tolerance"] = None if worst is None else abs(worst["change"]) <= H_MID_TOLERANCE
    return out


# ---------------------------------------------------------------------------- reporting
def _pct(part, whole):
    return "" if not whole else f"{100.0 * part / whole:.1f}"


def _num(x, spec):
    return "" if x is None else format(x, spec)


def _change(before, now, spec=".2f", relative=True):
    if before is None or now is None:
        return ""
    text = format(now - before, "+" + spec)
    if relative and before:
        text += f" ({100.0 * (now - before) / before:+.0f} %)"
    return text


def overview_rows(before: dict | None, now: dict) -> list[tuple]:
    b = before or {}
    bp, np_ = b.get("newton_iterations_by_phase") or {}, now["newton_iterations_by_phase"]
    items = [
        ("wall time s", b.get("wall_time_s"), now["wall_time_s"], ".1f", True),
        ("CPU time s", b.get("cpu_time_s"), now["cpu_time_s"], ".1f", True),
        ("build s (mesh, forms)", b.get("build_wall_time_s"), now["build_wall_time_s"], ".2f", False),
        ("Newton iterations", b.get("newton_iterations"), now["newton_iterations"], "d", True),
        ("  of which threshold location", b.get("threshold_newton_iterations"), now["threshold_newton_iterations"],
         "d", True),
        ("recorded steps", b.get("recorded_steps"), now["recorded_steps"], "d", False),
        ("iterations per recorded step", b.get("iterations_per_recorded_step"), now["iterations_per_recorded_step"],
         ".2f", True),
        ("  without threshold location", b.get("path_iterations_per_recorded_step"),
         now["path_iterations_per_recorded_step"], ".2f", True),
        ("wall ms per Newton iteration", b.get("time_per_newton_iteration_ms"), now["time_per_newton_iteration_ms"],
         ".1f", True),
        ("assembly+factorisation+solves ms per iteration", b.get("newton_time_per_iteration_ms"),
         now["newton_time_per_iteration_ms"], ".1f", True),
        ("failed Newton solves", bp.get("failed solves"), np_["failed solves"], "d", True),
        ("step halvings", bp.get("step halvings"), np_["step halvings"], "d", True),
        ("snaps (energy descent)", bp.get("snaps"), np_["snaps"], "d", False),
        ("dW1/L", b.get("dW1_over_L"), now["dW1_over_L"], ".5f", False),
        ("dW2/L", b.get("dW2_over_L"), now["dW2_over_L"], ".5f", False),
        ("H_mid/L compressed", b.get("H_mid_over_L_compressed"), now["H_mid_over_L_compressed"], ".7f", False),
    ]
    out = []
    for label, x, y, spec, rel in items:
        out.append((label, _num(x, spec) if before else "", _num(y, spec),
                    _change(x, y, spec, rel) if before and x is not None and y is not None else ""))
    return out


def phase_rows(before: dict | None, now: dict) -> list[tuple]:
    b = (before or {}).get("newton_iterations_by_phase") or {}
    n = now["newton_iterations_by_phase"]
    names = list(now["iteration_phases"])
    rows = [(p, str(b[p]) if p in b else "", str(n[p]), _pct(n[p], now["newton_iterations"])) for p in names]
    rows.append(("total (newton_iterations)", str(before["newton_iterations"]) if before else "",
                 str(now["newton_iterations"]), "100.0"))
    return rows


def time_rows(before: dict | None, now: dict) -> list[tuple]:
    b = (before or {}).get("wall_time_by_phase_s") or {}
    n = now["wall_time_by_phase_s"]
    names = list(now["time_phases"]) + [k for k in n if k not in now["time_phases"]]
    total_b, total_n = sum(b.values()) if b else None, sum(n.values())
    rows = [(p, _num(b.get(p), ".1f") if b else "", _pct(b.get(p, 0.0), total_b) if b else "",
             f"{n.get(p, 0.0):.1f}", _pct(n.get(p, 0.0), total_n)) for p in names]
    rows.append(("total (wall_time_s)", _num(total_b, ".1f"), "100.0" if b else "", f"{total_n:.1f}", "100.0"))
    return rows


def within_rows(before: dict | None, now: dict) -> list[tuple]:
    b = (before or {}).get("wall_time_within_phases_s") or {}
    n = now.get("wall_time_within_phases_s") or {}
    rows = []
    for phase in ("threshold location", "branch switching"):
        inner_n, inner_b = n.get(phase, {}), b.get(phase, {})
        for name in sorted(set(inner_n) | set(inner_b), key=lambda k: -inner_n.get(k, 0.0)):
            rows.append((phase, name, _num(inner_b.get(name), ".1f") if before else "", _num(inner_n.get(name), ".1f")))
    return rows


def expensive_steps(record: dict, count: int = TOP_STEPS) -> list[dict]:
    return sorted(record["steps"], key=lambda r: -r["wall_time_s"])[:count]


def step_rows(record: dict) -> list[tuple]:
    return [(r["stage"], f"{r['dW_over_L']:.4f}", r["phase"] + (" (switched)" if r["branch_switched"] else ""),
             str(r["newton_iterations"]), f"{r['wall_time_s']:.2f}") for r in expensive_steps(record)]


def agreement_lines(ag: dict | None) -> list[str]:
    if ag is None:
        return ["no --before run to compare with"]
    lines = [
        f"dW1/L: {_change(0.0, ag['dW1_over_L_change'], '.2e', False) or 'n/a'} against the tolerance "
        f"{ag['dW1_tolerance']:g} ({'within' if ag['dW1_within_tolerance'] else 'OUTSIDE'})",
        f"dW2/L: {_change(0.0, ag['dW2_over_L_change'], '.2e', False) or 'n/a'} against the tolerance "
        f"{ag['dW2_tolerance']:g} ({'within' if ag['dW2_within_tolerance'] else 'OUTSIDE'})",
        f"H_mid/L compressed: {_change(0.0, ag['H_mid_over_L_compressed_change'], '.2e', False) or 'n/a'}",
    ]
    worst = ag["H_mid_worst_step"]
    if worst is not None:
        lines.append(f"H_mid/L on {ag['steps_compared']} recorded steps on the same branch in both runs: largest "
                     f"change {ag['H_mid_max_abs_change']:.2e} L ({worst['stage']} dW/L = {worst['dW_over_L']:.4f}, "
                     f"{worst['phase']}); {len(ag['H_mid_steps_over_tolerance'])} steps over {H_MID_TOLERANCE:g} L"
                     + (": " + ", ".join(f"{d['stage']} {d['dW_over_L']:.4f} {d['phase']} {d['change']:+.2e}"
                                         for d in ag["H_mid_steps_over_tolerance"][:10])
                        if ag["H_mid_steps_over_tolerance"] else ""))
    other = ag["steps_on_another_branch"]
    lines.append(f"recorded steps on another branch than before: {len(other)}"
                 + (" (" + ", ".join(f"dW/L = {d['dW_over_L']:.4f}: {d['before']} -> {d['now']}" for d in other[:10])
                    + ")" if other else "")
                 + f"; steps without a counterpart: {ag['steps_without_counterpart']}")
    return lines


def markdown_report(report: dict) -> str:
    now, before = report["result"], report.get("before")
    sc = report["scene"]
    if now.get("status") != "ok":
        return "\n".join(["# FEM shell, full path", "", f"run failed: {now.get('status')}: {now.get('error', '')}", ""])
    mesh = now.get("mesh") or {}
    size = f"{mesh.get('elements_along_L', sc['resolution'])} x {mesh.get('elements_across_W', '?')} elements"
    lines = [
        "# FEM shell reference, full path: Newton iterations and wall time by phase",
        "",
        f"Scene: Naghdi shell (fem_reference), W/L = {sc['width_ratio_text']}, dL/L = {sc['compression_ratio']} in "
        f"{COMPRESSION_STEPS} recorded steps, then shear to dW_max in {SHEAR_STEPS} recorded steps, "
        f"{sc['resolution']} elements along L ({size}, {now['n_dof']} unknowns); thresholds located and the branch "
        "switched as `python -m fem_reference simulate` does, XDMF fields "
        f"{'written' if now['fields_written'] else 'not written'}. "
        "One run in a fresh process (`python -m benchmarks.fem_path`); the breakdowns are the library's own "
        "(summary.json `newton_iterations_by_phase`, `wall_time_by_phase_s`, `wall_time_within_phases_s`).",
        "",
        f"now: commit {now['git']['commit']}"
        + (" with uncommitted fem_reference changes" if now["git"]["fem_reference_uncommitted_changes"] else "")
        + f", {now['date']}, status {now['message']!r}"
        + (f"; before: commit {before['git']['commit']}"
           + (" with uncommitted fem_reference changes" if before["git"]["fem_reference_uncommitted_changes"] else "")
           + f", {before['date']}" if before else ""),
        "",
        markdown_table(("", "before", "now", "change"), overview_rows(before, now)),
        "",
        "iterations per recorded step = newton_iterations / recorded steps (161: the flat state, 40 compression, "
        "120 shear); without threshold location = the same without the dW1 and dW2 bisections. CPU time is the "
        "benchmark process's, MUMPS's second thread included (busy-waiting too): it rises when the second core "
        "is free and falls when another process holds it, so compare wall times (at similar load) and "
        "iterations; wall time above CPU time means the process waited for a core.",
    ]
    lines += section("Newton iterations by phase") + [
        markdown_table(("phase", "before", "now", "now %"), phase_rows(before, now)), "",
        "accepted / rejected steps: Newton solves of the path's load substeps that converged / failed (the substep "
        "was then retried without the secant predictor, or halved); compression start: Newton from the inextensible "
        "guess; branch switching: the bordered amplitude continuation off U and the closing Newton; fold snaps: "
        "Levenberg-Marquardt descent past a fold; threshold dW1 / dW2: every solve of the bisections (converged or "
        "not). Counts (not iterations): "
        f"failed solves {now['newton_iterations_by_phase']['failed solves']}, step halvings "
        f"{now['newton_iterations_by_phase']['step halvings']}, snaps {now['newton_iterations_by_phase']['snaps']}"
        + (f" (before: {before['newton_iterations_by_phase']['failed solves']}, "
           f"{before['newton_iterations_by_phase']['step halvings']}, {before['newton_iterations_by_phase']['snaps']})"
           if before else "") + "."]
    lines += section("Wall time by phase") + [
        markdown_table(("phase", "before s", "before %", "now s", "now %"), time_rows(before, now)), "",
        "assembly: residual and tangent (dolfinx); factorisation: MUMPS L D L^T of the Newton tangent; linear solves: "
        "its triangular solves; eigenvalues and inertia: the inertia factorisation of the stability test and SLEPc's "
        "shift-invert solve (each with its own factorisation) after every recorded step; threshold location and "
        "branch switching: all of their time (split below); I/O: XDMF fields, path.csv rows, summary checkpoints; "
        "other: the rest (observables, centerlines, state copies, Python).",
    ]
    lines += section("Inside threshold location and branch switching") + [
        markdown_table(("phase", "section", "before s", "now s"), within_rows(before, now))]
    lines += section("Most expensive recorded steps (now)") + [
        markdown_table(("stage", "dW/L", "phase", "Newton its", "wall s"), step_rows(now)), "",
        "A recorded step's wall time includes the threshold location and branch switch done at it."]
    if before:
        lines += ["", "Before: " + "; ".join(f"{r['stage']} dW/L = {r['dW_over_L']:.4f} {r['phase']}: "
                                              f"{r['newton_iterations']} its, {r['wall_time_s']:.2f} s"
                                              for r in expensive_steps(before))]
    lines += section("Agreement with the before run", agreement_lines(report.get("agreement")))
    if report.get("notes"):
        lines += section("Changes measured here", report["notes"])
    lines += [""] + [load_line(report)]
    if before and before.get("load_average"):
        lines.append(f"- load average (1 min) before / after the before run: {before['load_average'][0]} / "
                     f"{before['load_average'][1]}")
    fem_sha = now["fem_reference_source_sha256"][:16]
    lines += machine_section(report, extra=f" fem_reference sources sha256 `{fem_sha}`;")
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.fem_path", description=__doc__.split("\n")[0])
    parser.add_argument("--resolution", type=int, default=RESOLUTION, help="elements along L (default 60)")
    parser.add_argument("--width-ratio", type=ratio, default=Fraction(1, 6), help="W/L (default 1/6)")
    parser.add_argument("--compression-ratio", type=ratio, default=COMPRESSION_RATIO, help="dL/L (default 0.5)")
    parser.add_argument("--before", default=None, help="a fem_path.json to compare with (its 'before' entry if any)")
    parser.add_argument("--note", action="append", default=[], help="a line for 'Changes measured here' (repeatable)")
    parser.add_argument("--out", default="benchmarks/results", help="directory for fem_path.json and fem_path.md")
    parser.add_argument("--run-dir", default=None, help="keep the run's folder here (default: a temporary folder)")
    parser.add_argument("--no-fields", action="store_true", help="do not write the XDMF fields")
    parser.add_argument("--progress", action="store_true", help="print one line per recorded step")
    parser.add_argument("--timeout", type=float, default=3600.0, help="seconds allowed for the run (0: no limit)")
    args = parser.parse_args(argv)
    before = load_before(args.before)
    width = float(args.width_ratio)
    simple = Fraction(width).limit_denominator(1000)
    width_text = str(simple) if abs(float(simple) - width) < 1e-12 else f"{width:g}"

    provenance = Provenance()
    status, payload, elapsed = run_in_child(
        _run_once, (args.resolution, width, float(args.compression_ratio), args.run_dir, not args.no_fields,
                    args.progress), args.timeout if args.timeout > 0 else None)
    record = payload if status == "ok" else {"status": status, "error": payload, "elapsed_s": elapsed}
    report = {
        "benchmark": "fem_path",
        "scene": {"model": "fem (Naghdi shell)", "resolution": args.resolution, "width_ratio": width,
                  "width_ratio_text": width_text, "compression_ratio": float(args.compression_ratio),
                  "compression_steps": COMPRESSION_STEPS, "shear_steps": SHEAR_STEPS, "shear_ratio": "dW_max/L"},
        "timeout_s": args.timeout,
        "result": record,
        "before": before,
        "agreement": agreement(before, record),
        "notes": args.note,
    }
    report.update(provenance.report([record] if status == "ok" else []))
    wrote = write_report(args.out, "fem_path", report, markdown_report(report))
    if status != "ok":
        print(f"run {status}: {payload}", file=sys.stderr)
        print(wrote)
        return 1
    print(text_table(("", "before", "now", "change"), overview_rows(before, record)))
    print()
    print(text_table(("phase", "before", "now", "now %"), phase_rows(before, record)))
    print()
    print(text_table(("phase", "before s", "before %", "now s", "now %"), time_rows(before, record)))
    for line in agreement_lines(report["agreement"]):
        print("-", line)
    print(wrote)
    return 0


if __name__ == "__main__":
    sys.exit(main())
