"""Shared parts of the benchmark scripts (rod_path, plate_path, plate_linear_algebra).

- PathInstrument: the base of the run-time instrumentation of one ddg.simulate run. It keeps
  the monkeypatches (and undoes them in restore()), and counts the Newton solves (wrapping
  ddg.solve.continuation.newton: caller, iterations, converged) and the recorded continuation
  steps (wrapping PathFollower.advance / start_compression: load, time, solves). The scripts
  subclass it with their own timers (which functions, how they are grouped).
- timed_simulate: one instrumented, timed ddg.simulate call; path_timing: the record fields
  every path run has; newton_by_caller / stage_summary: aggregates of the counters.
- run_in_child / best_of: one run in a fresh (spawned) process with a timeout, and the best of
  --repeat such runs.
- provenance: machine info (optionally the BLAS/LAPACK libraries), ddg source fingerprint,
  load average, whether the sources changed during the run.
- reporting: fit_slope / path_slopes, text and markdown tables, the common report lines,
  write_report (atomic JSON + markdown).

Nothing here is specific to one model; the library is not modified (patches are made at run
time, in the benchmark's own child process only).
"""
from __future__ import annotations

import argparse
import contextlib
import datetime as _dt
import functools
import hashlib
import importlib
import inspect
import io
import json
import math
import multiprocessing as mp
import os
import platform
import sys
import time
import traceback
from collections import defaultdict
from fractions import Fraction
from pathlib import Path

from ddg.output.io import atomic_write_text

CHANGED_NOTE = " (CHANGED during the run: runs may mix library versions)"


# ---------------------------------------------------------------------------- instrumentation
def tally(acc: dict, iterations: int, converged: bool,
          names=("solves", "iterations", "failed", "iterations_failed")) -> None:
    """Add one Newton solve to the counters `names` (solves, iterations, failed solves, iterations
    in failed solves) of acc."""
    solves, its, failed, its_failed = names
    acc[solves] += 1
    acc[its] += iterations
    if not converged:
        acc[failed] += 1
        acc[its_failed] += iterations


class PathInstrument:
    """Patches installed around one run and removed by restore(), with the Newton-solve and
    recorded-step counters of the path benchmarks. Subclasses define install()."""

    def __init__(self):
        self.newton_calls: list[dict] = []
        self.steps: list[dict] = []
        self._current_step: dict | None = None
        self._patches: list[tuple[object, str, object]] = []

    def _set(self, owner, name: str, replacement) -> None:
        self._patches.append((owner, name, getattr(owner, name) if isinstance(owner, type(sys))
                              else owner.__dict__[name]))
        setattr(owner, name, replacement)

    def restore(self) -> None:
        while self._patches:
            owner, name, original = self._patches.pop()
            setattr(owner, name, original)

    def install_path_counters(self, branch_callers: tuple[str, ...] | None = None, required: bool = False) -> None:
        """Count the Newton solves (self.newton_calls) and time the recorded steps (self.steps).

        branch_callers: callers whose solves count as branch solves of the step (the step then
        has a "branch_solves" entry); required: fail if a PathFollower step method is missing
        (otherwise it is not wrapped)."""
        from ddg.solve import continuation

        inst = self
        newton = continuation.__dict__["newton"]

        @functools.wraps(newton)
        def newton_counting(model, q, *args, **kwargs):
            caller = sys._getframe(1).f_code.co_name
            result = newton(model, q, *args, **kwargs)
            rec = {"caller": caller, "iterations": int(result.iterations), "converged": bool(result.converged),
                   "minimize": bool(kwargs.get("minimize", False))}
            inst.newton_calls.append(rec)
            step = inst._current_step
            if step is not None:
                tally(step, rec["iterations"], rec["converged"],
                      ("newton_solves", "iterations_all", "failed_solves", "iterations_failed"))
                if branch_callers is not None and caller in branch_callers:
                    step["branch_solves"] += 1
            return result

        self._set(continuation, "newton", newton_counting)

        PF = continuation.PathFollower

        def stepper(name):
            original = PF.__dict__[name]
            sig = inspect.signature(original)

            @functools.wraps(original)
            def wrapper(self_, *args, **kwargs):
                L = self_.model.strip.length
                try:
                    bound = sig.bind(self_, *args, **kwargs).arguments
                    compression, shear = float(bound.get("compression", math.nan)), float(bound.get("shear", 0.0))
                except (TypeError, ValueError):
                    compression, shear = math.nan, math.nan
                step = {"dL_over_L": compression / L, "dW_over_L": shear / L, "newton_solves": 0,
                        "iterations_all": 0, "failed_solves": 0, "iterations_failed": 0}
                if branch_callers is not None:
                    step["branch_solves"] = 0
                inst._current_step = step
                t0 = time.perf_counter()
                try:
                    return original(self_, *args, **kwargs)
                finally:
                    step["time_s"] = time.perf_counter() - t0
                    inst._current_step = None
                    inst.steps.append(step)

            return wrapper

        for name in ("advance", "start_compression"):
            if name in PF.__dict__ or required:
                self._set(PF, name, stepper(name))


def timed_simulate(inst: PathInstrument, strip, protocol, model: str, resolution: int):
    """ddg.simulate twice in this (fresh) process: first uninstrumented, timed as the first call
    (it loads the compiled kernels from numba's cache and the lazily imported modules), then with
    inst installed (and restored afterwards), timed as the warm call. Returns (warm result, wall s,
    cpu s); result.timings holds {"first_call_wall_s", "first_call_cpu_s"}."""
    import ddg

    c0, t0 = time.process_time(), time.perf_counter()
    ddg.simulate(strip, protocol, model=model, resolution=resolution)
    first = {"first_call_wall_s": time.perf_counter() - t0, "first_call_cpu_s": time.process_time() - c0}
    inst.install()
    try:
        c0, t0 = time.process_time(), time.perf_counter()
        result = ddg.simulate(strip, protocol, model=model, resolution=resolution)
        wall = time.perf_counter() - t0
        cpu = time.process_time() - c0
    finally:
        inst.restore()
    result.timings = first
    return result, wall, cpu


def path_timing(result, wall: float, cpu: float) -> dict:
    """The timing and size fields of one path run's record."""
    s, rows = result.summary, result.rows
    its = int(s["newton_iterations"])
    return {
        "wall_time_s": wall,
        "cpu_time_s": cpu,
        **getattr(result, "timings", {}),
        "library_wall_time_s": s.get("wall_time_s"),
        "newton_iterations": its,
        "time_per_newton_iteration_ms": 1e3 * wall / its if its else None,
        "recorded_steps": len(rows),
        "recorded_shear_steps": sum(1 for r in rows if r["stage"] == "shear"),
    }


def newton_by_caller(newton_calls: list[dict], label=lambda rec: rec["caller"]) -> dict:
    """Newton solves, iterations and failures per caller (label(record))."""
    by_caller = defaultdict(lambda: {"solves": 0, "iterations": 0, "failed": 0, "iterations_failed": 0})
    for rec in newton_calls:
        tally(by_caller[label(rec)], rec["iterations"], rec["converged"])
    return dict(by_caller)


def stage_summary(steps: list[dict]) -> dict:
    """Time, iterations and failed solves of the compression steps (dW = 0) and the shear steps."""
    comp_steps = [st for st in steps if st["dW_over_L"] == 0.0]
    shear_steps = [st for st in steps if st["dW_over_L"] != 0.0]
    return {
        name: {"time_s": sum(st["time_s"] for st in group), "iterations": sum(st["iterations_all"] for st in group),
               "failed_solves": sum(st["failed_solves"] for st in group)}
        for name, group in (("compression", comp_steps), ("shear", shear_steps))
    }


# ---------------------------------------------------------------------------- runs in a child process
def _child(target, args: tuple, conn) -> None:
    try:
        conn.send(("ok", target(*args)))
    except BaseException:  # report any failure to the parent instead of dying silently
        conn.send(("error", traceback.format_exc()))
    finally:
        conn.close()


def run_in_child(target, args: tuple, timeout: float | None) -> tuple[str, object, float]:
    """target(*args) in a fresh (spawned) process; returns (status, payload, elapsed): status "ok"
    with target's result, "error" with the traceback, or "timeout". target must be a module-level
    function (it is pickled by name)."""
    ctx = mp.get_context("spawn")
    parent, child = ctx.Pipe(duplex=False)
    proc = ctx.Process(target=_child, args=(target, args, child), daemon=True)
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


def best_of(run, repeat: int, label: str, ident: dict, describe, timeout_arg: float) -> dict:
    """The record with the least wall time of `repeat` calls of run() -> (status, payload, elapsed).

    Progress goes to stderr as "<label> run k/repeat: <describe(payload)>". A timeout or error
    stops the repeats (it would happen again); if no run succeeded the record is ident with the
    status and the error. A successful record gets status "ok" and all_wall_times_s."""
    best, attempts = None, []
    for k in range(repeat):
        status, payload, elapsed = run()
        if status == "ok":
            attempts.append(payload["wall_time_s"])
            if best is None or payload["wall_time_s"] < best["wall_time_s"]:
                best = payload
            print(f"{label} run {k + 1}/{repeat}: {describe(payload)}", file=sys.stderr)
        else:
            print(f"{label} run {k + 1}/{repeat}: {status} after {elapsed:.0f} s", file=sys.stderr)
            if best is None:
                best = {**ident, "status": status, "error": payload if status == "error" else
                        f"stopped after {elapsed:.0f} s (--timeout {timeout_arg:g})"}
                if status == "error":
                    print(payload, file=sys.stderr)
            break  # a timeout or crash will repeat; do not wait again
    if "status" not in best:
        best["status"] = "ok"
        best["all_wall_times_s"] = attempts
    return best


# ---------------------------------------------------------------------------- provenance
def source_fingerprint() -> str:
    """sha256 over the ddg package sources, to tie the numbers to one state of the library."""
    import ddg

    root = Path(ddg.__file__).resolve().parent
    digest = hashlib.sha256()
    for path in sorted(root.rglob("*.py")):
        digest.update(str(path.relative_to(root)).encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()


def load_average() -> float | None:
    try:
        return round(os.getloadavg()[0], 2)
    except OSError:
        return None


def blas_info() -> dict:
    """The BLAS/LAPACK libraries numpy/scipy were built against (numpy.show_config) and the ones
    actually loaded in this process (/proc/self/maps: real paths, so Debian's BLAS alternatives show)."""
    import numpy

    importlib.import_module("scipy.linalg")  # loads LAPACK, so that /proc/self/maps lists it

    buf = io.StringIO()
    try:
        with contextlib.redirect_stdout(buf):
            numpy.show_config()
    except Exception as exc:  # pragma: no cover
        buf.write(f"show_config failed: {exc}")
    built, section = {}, None
    for line in buf.getvalue().splitlines():
        if line and not line.startswith(" ") and line.rstrip().endswith(":"):
            section = line.rstrip()[:-1]
        elif section and line.strip().startswith("libraries"):
            built[section] = line.split("=", 1)[1].strip()
    loaded = set()
    try:
        with open("/proc/self/maps") as fh:
            for line in fh:
                path = line.split()[-1] if len(line.split()) >= 6 else ""
                name = os.path.basename(path).lower()
                if name.startswith("lib") and any(t in name for t in ("blas", "lapack", "mkl", "blis", "atlas")):
                    loaded.add(path)
    except OSError:
        pass
    return {"numpy_show_config": built, "loaded": sorted(loaded)}


def machine_info(blas: bool = False) -> dict:
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
    info = {
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
    if blas:
        info["blas"] = blas_info()
    return info


class Provenance:
    """Source fingerprint and load average at the start of a benchmark; report() gives the
    closing entries of its JSON report."""

    def __init__(self):
        self.fingerprint = source_fingerprint()
        self.load = load_average()

    def report(self, results=(), blas: bool = False) -> dict:
        """machine, ddg_source_sha256, load_average (start, now) and ddg_source_changed_during_run
        (the sources now, or those a result recorded, differ from the start)."""
        fp = self.fingerprint
        return {
            "machine": machine_info(blas),
            "ddg_source_sha256": fp,
            "load_average": [self.load, load_average()],
            "ddg_source_changed_during_run": source_fingerprint() != fp or any(
                r.get("ddg_source_sha256", fp) != fp for r in results),
        }


def warn_if_changed(report: dict) -> None:
    if report["ddg_source_changed_during_run"]:
        print("WARNING: the ddg sources changed while the benchmark ran; the runs may mix library versions",
              file=sys.stderr)


# ---------------------------------------------------------------------------- reporting
def ratio(text: str) -> float:
    """A ratio given as a decimal or a fraction: 0.1667 or 1/6."""
    try:
        return float(Fraction(text))
    except (ValueError, ZeroDivisionError):
        raise argparse.ArgumentTypeError(f"{text!r} is not a number or fraction") from None


def fmt(x, spec=".3f"):
    return "n/a" if x is None else format(x, spec)


def fit_slope(xs, ys):
    """Least-squares slope of log(y) against log(x)."""
    if len(xs) < 2:
        return None
    lx = [math.log(x) for x in xs]
    ly = [math.log(y) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    sxx = sum((a - mx) ** 2 for a in lx)
    return sum((a - mx) * (b - my) for a, b in zip(lx, ly)) / sxx


def path_slopes(xs: list, ok: list[dict], categories, slope=fit_slope) -> dict:
    """Growth exponents against xs of the wall time, the Newton iterations, the time per iteration
    and the time of each category (split_s) of the runs ok."""
    return {
        "wall_time_slope": slope(xs, [r["wall_time_s"] for r in ok]),
        "newton_iterations_slope": slope(xs, [r["newton_iterations"] for r in ok]),
        "time_per_iteration_slope": slope(xs, [r["time_per_newton_iteration_ms"] for r in ok]),
        "category_slopes": {c: slope(xs, [max(r["split_s"][c], 1e-12) for r in ok]) for c in categories},
    }


def slopes_text(sc: dict) -> str:
    """The wall-time exponent with those of the iterations and time per iteration (stdout form)."""
    return (f"{fmt(sc['wall_time_slope'], '.2f')} (Newton iterations {fmt(sc['newton_iterations_slope'], '.2f')}, "
            f"time/iteration {fmt(sc['time_per_iteration_slope'], '.2f')})")


def slopes_markdown(sc: dict) -> str:
    """The same with the per-category exponents (markdown form)."""
    return (f"**{fmt(sc['wall_time_slope'], '.2f')}** (Newton iterations: {fmt(sc['newton_iterations_slope'], '.2f')}, "
            f"time per iteration: {fmt(sc['time_per_iteration_slope'], '.2f')}); per category: "
            + ", ".join(f"{k} {fmt(v, '.2f')}" for k, v in sc["category_slopes"].items()))


def load_line(report: dict) -> str:
    return (f"- load average (1 min) before / after the runs: {report['load_average'][0]} / "
            f"{report['load_average'][1]} (other processes on the machine inflate wall times)")


def run_notes(results: list[dict], label, note) -> list[str]:
    """note(r) for each successful run r, "<label(r)>: <status> (<error>)" for the others."""
    return [note(r) if r["status"] == "ok" else f"{label(r)}: {r['status']} ({r.get('error', '')})".strip()
            for r in results]


def newton_notes(r: dict) -> tuple[str, int, str]:
    """(the three most expensive recorded steps, iterations in failed solves, solves per caller)
    of one path run, as text."""
    nb = r["newton_by_caller"]
    steps = sorted(r["steps"], key=lambda s: -s["iterations_all"])[:3]
    worst = ", ".join(f"dL/L={s['dL_over_L']:.3f} dW/L={s['dW_over_L']:.4f}: {s['iterations_all']} its, "
                      f"{s['time_s']:.2f} s ({s['newton_solves']} solves, {s['failed_solves']} failed)" for s in steps)
    failed = sum(b["iterations_failed"] for b in nb.values())
    caller = ", ".join(f"{k} {v['solves']} solves/{v['iterations']} its" for k, v in sorted(nb.items()))
    return worst, failed, caller


def eigen_paths_text(r: dict) -> str:
    """Calls and time per path of lowest_eigenpairs in one run ("" if none)."""
    paths = r["calls"]["lowest_eigenpairs_paths"]
    return "; ".join(f"{k} {v['calls']} calls/{v['time_s']:.2f} s" for k, v in paths.items())


def text_table(header, rows) -> str:
    rows = [tuple(header)] + list(rows)
    widths = [max(len(row[i]) for row in rows) for i in range(len(header))]
    lines = ["  ".join(c.rjust(w) for c, w in zip(row, widths)) for row in rows]
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines)


def markdown_table(header, rows) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---:" for _ in header) + "|"]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return "\n".join(lines)


def section(title: str, items=()) -> list[str]:
    """A markdown section heading (with the blank lines around it) and its items as a list."""
    return ["", f"## {title}", ""] + [f"- {x}" for x in items]


def table_section(title: str, header, rows, caption: str) -> list[str]:
    """A markdown section with one table and the caption under it."""
    return section(title) + [markdown_table(header, rows), "", caption]


def machine_section(report: dict, extra: str = "", changed_note: str = CHANGED_NOTE) -> list[str]:
    """The "## Machine" section: machine info (with the loaded BLAS/LAPACK and the thread
    settings when the machine info has them), extra, the ddg source fingerprint."""
    mi = report["machine"]
    text = (f"{mi['cpu_count']} CPUs ({mi['cpu_model']}), {mi['platform']}, Python {mi['python']}, "
            f"numpy {mi['numpy']}, scipy {mi['scipy']}, ddg {mi['ddg']}; {mi['date']}.")
    if "blas" in mi:
        text += (" BLAS/LAPACK loaded: " + ("; ".join(f"`{x}`" for x in mi["blas"].get("loaded", [])) or "unknown")
                 + f". Thread settings: {mi['thread_env']}.")
    text += (f"{extra} ddg sources sha256 `{report['ddg_source_sha256'][:16]}`"
             + (changed_note if report["ddg_source_changed_during_run"] else "") + ".")
    return section("Machine") + [text, ""]


def write_report(out, name: str, report: dict, markdown: str, json_default=float) -> str:
    """OUT/name.json and OUT/name.md, atomically; returns the "wrote ..." line."""
    out = Path(out)
    atomic_write_text(out / f"{name}.json", json.dumps(report, indent=1, default=json_default) + "\n")
    atomic_write_text(out / f"{name}.md", markdown)
    return f"wrote {out / f'{name}.json'} and {out / f'{name}.md'}"


def finish_path_report(report: dict, provenance: Provenance, scaling, observations, markdown_report, out,
                       blas: bool = False) -> str:
    """Complete the report of a path benchmark (its "results" are in): scaling(results), the
    provenance entries, observations(results); write OUT/<benchmark>.json and .md; warn on stderr
    if the ddg sources changed during the run. Returns the "wrote ..." line."""
    results = report["results"]
    report["scaling"] = scaling(results)
    report.update(provenance.report(results, blas=blas))
    report["observations"] = observations(results)
    wrote = write_report(out, report["benchmark"], report, markdown_report(report))
    warn_if_changed(report)
    return wrote
