"""Shared parts of the benchmark scripts (rod_path, plate_path, plate_linear_algebra).

- measurement through the library's public hooks only (no patching): PathProbe, a
  ddg.solve.probe.Probe that records every Newton solve of the path (phase, iterations,
  converged) and every recorded step with its wall time; measure_path: the first call, a warm
  call with the probe (the wall time reported) and a separate warm call under cProfile;
  CallGraph / category_split: the time of categories of functions (their outermost calls: a
  category's call inside another's counts once, for the outer one) from cProfile's caller data,
  scaled to the un-profiled wall time; path_timing: the record fields every path run has.
- run_in_child / best_of: one run in a fresh (spawned) process with a timeout, and the best of
  --repeat such runs.
- provenance: machine info (optionally the BLAS/LAPACK libraries), ddg source fingerprint,
  load average, whether the sources changed during the run.
- reporting: fit_slope / path_slopes, text and markdown tables, the common report lines,
  write_report (atomic JSON + markdown).

Nothing here is specific to one model, and nothing touches the library's objects: the numbers
come from the probe, summary.json and cProfile.
"""
from __future__ import annotations

import argparse
import contextlib
import cProfile
import datetime as _dt
import hashlib
import importlib
import inspect
import io
import json
import math
import multiprocessing as mp
import os
import platform
import pstats
import sys
import time
import traceback
from collections import defaultdict
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path

from ddg.output.io import atomic_write_text
from ddg.solve.continuation import PHASES
from ddg.solve.probe import Probe

#: how the path benchmarks measure (the "method" of their reports)
PROBE_METHOD = ("probe (ddg.solve.probe) on the warm call; split under cProfile in a separate warm call, outermost "
                "calls per category, scaled to the un-profiled wall time (see the module docstring)")
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


#: The phase of the path follower's solves that leave unstable states (a step's "branch_solves").
BRANCH_PHASE = "branch switching"
_STEP_COUNTERS = ("newton_solves", "iterations_all", "failed_solves", "iterations_failed")


def _solve_counters(names=("solves", "iterations", "failed", "iterations_failed")) -> dict:
    return dict.fromkeys(names, 0)


class PathProbe(Probe):
    """What the path benchmarks read of a run through its public timing/callback interface
    (ddg.solve.probe): every Newton solve of the path follower (phase, iterations, converged) and
    every recorded step with its wall time and the solves made to reach it."""

    def __init__(self):
        self.solves: list[tuple[str, int, bool]] = []
        self.steps: list[dict] = []
        self._next = {**_solve_counters(_STEP_COUNTERS), "branch_solves": 0}

    def solve(self, phase: str, iterations: int, converged: bool) -> None:
        self.solves.append((phase, int(iterations), bool(converged)))
        tally(self._next, int(iterations), bool(converged), _STEP_COUNTERS)
        if phase == BRANCH_PHASE:
            self._next["branch_solves"] += 1

    def step(self, stage: str, row: dict, wall_s: float) -> None:
        self.steps.append({"stage": stage, "dL_over_L": float(row["dL_over_L"]), "dW_over_L": float(row["dW_over_L"]),
                           **self._next, "time_s": float(wall_s)})
        self._next = {**_solve_counters(_STEP_COUNTERS), "branch_solves": 0}

    def by_phase(self) -> dict:
        """Newton solves, iterations, failed solves and iterations in them per phase (PHASES order)."""
        out = {phase: _solve_counters() for phase in PHASES}
        for phase, iterations, converged in self.solves:
            tally(out.setdefault(phase, _solve_counters()), iterations, converged)
        return out

    def stage_summary(self) -> dict:
        """Wall time, iterations and failed solves of the compression steps and of the shear steps."""
        return {stage: {"time_s": sum(st["time_s"] for st in self.steps if st["stage"] == stage),
                        "iterations": sum(st["iterations_all"] for st in self.steps if st["stage"] == stage),
                        "failed_solves": sum(st["failed_solves"] for st in self.steps if st["stage"] == stage)}
                for stage in ("compression", "shear")}

    def matches(self, summary: dict) -> bool:
        """The solves add up to summary.json's newton_iterations, phase by phase."""
        by_phase = summary.get("newton_iterations_by_phase") or {}
        return (sum(its for _, its, _ in self.solves) == summary["newton_iterations"]
                and all(v["iterations"] == by_phase.get(k, 0) for k, v in self.by_phase().items()))


def function_key(fn) -> tuple[str, int, str]:
    """The key cProfile and pstats give a Python function: (file, first line, name)."""
    code = inspect.unwrap(fn).__code__
    return code.co_filename, code.co_firstlineno, code.co_name


class Attribution:
    """A profiled call's time and calls per function, split by the context they were made in
    (CallGraph.attribute): per level, the label of the outermost enclosing call of that level's
    functions, or None."""

    def __init__(self, levels: list[dict], time_in: dict, calls_in: dict):
        self.levels, self.time_in, self.calls_in = levels, time_in, calls_in

    @staticmethod
    def _key(fn):
        return fn if isinstance(fn, tuple) else function_key(fn)

    def time(self, fn) -> dict:
        """{caller context: s} of fn's calls."""
        return self.time_in.get(self._key(fn), {})

    def calls(self, fn) -> dict:
        """{caller context: calls} of fn."""
        return self.calls_in.get(self._key(fn), {})

    def outermost(self, label: str, level: int = 0, where: dict | None = None) -> float:
        """Time of the calls of the functions labelled `label` (in levels[level]) made outside any
        call of that level's functions, and (where = {level: label}) inside those of other levels."""
        where = where or {}
        return sum(t for f, lab in self.levels[level].items() if lab == label
                   for ctx, t in self.time_in.get(f, {}).items()
                   if ctx[level] is None and all(ctx[i] == w for i, w in where.items()))

    def by_context(self, fn, level: int = 0) -> dict:
        """{enclosing label or "top": {"calls", "time_s"}} of fn's calls (the other levels summed)."""
        out: dict = {}
        for source, field in ((self.calls(fn), "calls"), (self.time(fn), "time_s")):
            for ctx, v in source.items():
                slot = out.setdefault(ctx[level] or "top", {"calls": 0, "time_s": 0.0})
                slot[field] += v
        for slot in out.values():
            slot["calls"] = round(slot["calls"])
        return out


class CallGraph:
    """The call graph of one cProfile run (pstats data: per function its calls, own and cumulative
    time, and per caller the calls and cumulative time made from that caller).

    cProfile keeps one level of callers, not whole stacks; attribute() walks the graph from its
    roots and splits every function's calls and time by the context they were made in, so that a
    category's time inside another category's call counts once, for the outer one. A function
    called from several contexts passes its callees' time on in proportion to its own time in each
    (gprof's assumption); where a caller is only ever called in one context (the Lanczos operator
    inside lowest_eigenpairs, Newton outside every category) the split is exact. Compiled (numba)
    kernels are not Python calls for cProfile: their time is the own time of their caller."""

    def __init__(self, stats: dict):
        self.stats = stats

    @classmethod
    def of(cls, profile: cProfile.Profile) -> "CallGraph":
        return cls(pstats.Stats(profile).stats)

    def row(self, fn) -> tuple:
        """(primitive calls, calls, own s, cumulative s) of fn; zeros if it was not called."""
        row = self.stats.get(fn if isinstance(fn, tuple) else function_key(fn))
        return tuple(row[:4]) if row else (0, 0, 0.0, 0.0)

    def attribute(self, levels: list[dict]) -> Attribution:
        """levels: dicts {function key: label}; a call of a labelled function opens its label's
        context on its level unless a call of that level is already open (the outermost wins)."""
        stats = self.stats
        none = (None,) * len(levels)
        callers = {f: {c: e for c, e in row[4].items() if c != f and c in stats} for f, row in stats.items()}
        callees = defaultdict(list)
        for f, cs in callers.items():
            for c in cs:
                callees[c].append(f)
        order = _topological(list(stats), callers, callees)

        def enter(f, ctx):
            return tuple(level.get(f) if cur is None else cur for cur, level in zip(ctx, levels))

        found = []
        for edge, own in ((3, 3), (0, 1)):  # (edge, row) index: cumulative time, then calls
            inside = {f: {enter(f, none): 1.0} for f in stats}  # context within f's calls (fractions)
            absolute: dict = {}
            for _ in range(100):
                change = 0.0
                for f in order:
                    acc: dict = defaultdict(float)
                    for c, e in callers[f].items():
                        for ctx, p in inside[c].items():
                            acc[ctx] += e[edge] * p
                    total = sum(acc.values())
                    if total <= 0.0:  # a root, or calls too short for the clock
                        acc, total = {none: float(stats[f][own])}, float(stats[f][own])
                    absolute[f] = dict(acc)
                    new: dict = defaultdict(float)
                    for ctx, v in acc.items():
                        new[enter(f, ctx)] += v / total if total > 0.0 else 1.0 / len(acc)
                    old = inside[f]
                    change = max([change] + [abs(new[k] - old.get(k, 0.0)) for k in new]
                                 + [abs(old[k]) for k in old if k not in new])
                    inside[f] = dict(new)
                if change < 1e-12:
                    break
            found.append(absolute)
        return Attribution(levels, found[0], found[1])


def _topological(nodes: list, callers: dict, callees: dict) -> list:
    """Callers before callees (reverse DFS post-order from the roots; cycles broken anywhere)."""
    seen, post = set(), []
    roots = [n for n in nodes if not callers[n]] + nodes
    for root in roots:
        if root in seen:
            continue
        seen.add(root)
        stack = [(root, iter(callees.get(root, ())))]
        while stack:
            node, it = stack[-1]
            nxt = next((c for c in it if c not in seen), None)
            if nxt is None:
                post.append(node)
                stack.pop()
            else:
                seen.add(nxt)
                stack.append((nxt, iter(callees.get(nxt, ()))))
    return post[::-1]


def profiled(fn, *args, **kwargs):
    """fn(*args, **kwargs) under cProfile: (its result, CallGraph, wall s including the profiler's overhead)."""
    profile = cProfile.Profile()
    t0 = time.perf_counter()
    profile.enable()
    try:
        result = fn(*args, **kwargs)
    finally:
        profile.disable()
    return result, CallGraph.of(profile), time.perf_counter() - t0


@dataclass
class PathMeasurement:
    """The three simulate calls of measure_path."""
    result: object                 # the warm call's SimulationResult
    wall_s: float
    cpu_s: float
    first_call_wall_s: float
    first_call_cpu_s: float
    probe: PathProbe               # the warm call's solves and recorded steps
    graph: CallGraph               # the profiled call's
    profiled_wall_s: float
    profiled_summary: dict


def measure_path(strip, protocol, model: str, resolution: int, **options) -> PathMeasurement:
    """ddg.simulate three times in this (fresh) process: the first, timed as the first call (it
    loads the compiled kernels from numba's cache and the lazily imported modules); the second,
    warm, with a PathProbe, timed as the run's wall and CPU time; the third under cProfile, for
    the split of the time (cProfile's overhead stays out of the second call's wall time)."""
    import ddg

    def run(**extra):
        return ddg.simulate(strip, protocol, model=model, resolution=resolution, **options, **extra)

    c0, t0 = time.process_time(), time.perf_counter()
    run()
    first_wall, first_cpu = time.perf_counter() - t0, time.process_time() - c0
    probe = PathProbe()
    c0, t0 = time.process_time(), time.perf_counter()
    result = run(probe=probe)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    again, graph, profiled_wall = profiled(run)
    return PathMeasurement(result, wall, cpu, first_wall, first_cpu, probe, graph, profiled_wall, again.summary)


def category_split(m: PathMeasurement, categories: dict, extra=None) -> tuple[dict, Attribution]:
    """The split of the warm call's wall time between categories ({name: functions whose calls
    are the category's entry points}) and "other": each category's outermost time under cProfile
    (a call inside another category's call counts once, for the outer one) as a share of the
    profiled wall time, times the un-profiled wall time. extra(attribution): more {name: seconds
    under cProfile}, scaled the same way (sub-splits). Returns (record fields, the attribution)."""
    level = {function_key(f): name for name, fns in categories.items() for f in fns}
    attr = m.graph.attribute([level])
    profiled_s = {name: attr.outermost(name) for name in categories}
    profiled_s["other"] = m.profiled_wall_s - sum(profiled_s.values())
    if extra is not None:
        profiled_s.update(extra(attr))
    scale = m.wall_s / m.profiled_wall_s if m.profiled_wall_s > 0 else math.nan
    split = {k: v * scale for k, v in profiled_s.items()}
    return {
        "split_s": split,
        "split_fraction": {k: v / m.wall_s for k, v in split.items()},
        "split_profiled_s": profiled_s,
        "profiled_wall_time_s": m.profiled_wall_s,
        "split_method": "cProfile: outermost calls of the category entry points in a separate warm call, as shares "
                        "of its wall time, scaled to the un-profiled wall time",
    }, attr


def path_timing(m: PathMeasurement) -> dict:
    """The timing, size and Newton fields every path run's record has (the probe's and the summary's)."""
    s, rows = m.result.summary, m.result.rows
    its = int(s["newton_iterations"])
    return {
        "wall_time_s": m.wall_s,
        "cpu_time_s": m.cpu_s,
        "first_call_wall_s": m.first_call_wall_s,
        "first_call_cpu_s": m.first_call_cpu_s,
        "profiled_wall_time_s": m.profiled_wall_s,
        "library_wall_time_s": s.get("wall_time_s"),
        "newton_iterations": its,
        "newton_iterations_by_phase": s.get("newton_iterations_by_phase"),
        "profiled_run_newton_iterations": m.profiled_summary.get("newton_iterations"),
        "threshold_newton_iterations": s.get("threshold_newton_iterations"),
        "threshold_wall_time_s": s.get("threshold_wall_time_s"),
        "branches_newton_iterations": s.get("branches_newton_iterations"),
        "branches_wall_time_s": s.get("branches_wall_time_s"),
        "time_per_newton_iteration_ms": 1e3 * m.wall_s / its if its else None,
        "recorded_steps": len(rows),
        "recorded_shear_steps": sum(1 for r in rows if r["stage"] == "shear"),
        "newton_by_phase": m.probe.by_phase(),
        "probe_matches_summary": m.probe.matches(s),
        "stage": m.probe.stage_summary(),
        "steps": m.probe.steps,
    }


def eigen_calls(attr: Attribution, functions: dict) -> dict:
    """{label: {"calls", "time_s"}} of the eigenvalue functions named (under cProfile, unscaled)."""
    out = {}
    for label, fn in functions.items():
        calls, t = sum(attr.calls(fn).values()), sum(attr.time(fn).values())
        if calls:
            out[label] = {"calls": round(calls), "time_s": t}
    return out


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


def loads_line(report: dict, loads) -> str:
    """The closing line of the child-process benchmarks: the load average before each run, the
    cores, the date and the ddg sources (report: machine, source)."""
    return (f"Load average (1 min) before each run: {', '.join(str(x) for x in loads)}; "
            f"{report['machine']['cpu_count']} cores; {report['machine']['date']}; "
            f"ddg sources {report['source'][:12]}.")


def run_notes(results: list[dict], label, note) -> list[str]:
    """note(r) for each successful run r, "<label(r)>: <status> (<error>)" for the others."""
    return [note(r) if r["status"] == "ok" else f"{label(r)}: {r['status']} ({r.get('error', '')})".strip()
            for r in results]


def newton_notes(r: dict) -> tuple[str, int, str]:
    """(the three most expensive recorded steps, iterations in failed solves, solves per phase)
    of one path run, as text (from the probe)."""
    nb = r["newton_by_phase"]
    steps = sorted(r["steps"], key=lambda s: -s["iterations_all"])[:3]
    worst = ", ".join(f"dL/L={s['dL_over_L']:.3f} dW/L={s['dW_over_L']:.4f}: {s['iterations_all']} its, "
                      f"{s['time_s']:.2f} s ({s['newton_solves']} solves, {s['failed_solves']} failed)" for s in steps)
    failed = sum(b["iterations_failed"] for b in nb.values())
    phase = ", ".join(f"{k} {v['solves']} solves/{v['iterations']} its" for k, v in nb.items() if v["solves"])
    return worst, failed, phase


def after_path_text(r: dict) -> str:
    """Threshold location and branch tracing after the path (summary.json), as text."""
    parts = [f"{name} {r.get(f'{key}_newton_iterations')} its / {fmt(r.get(f'{key}_wall_time_s'), '.2f')} s"
             for name, key in (("threshold location", "threshold"), ("branch tracing", "branches"))
             if r.get(f"{key}_newton_iterations") is not None or r.get(f"{key}_wall_time_s") is not None]
    return ", ".join(parts) or "none"


def eigen_paths_text(r: dict) -> str:
    """Calls and time (s under cProfile) of the eigenvalue functions in one run ("" if none)."""
    paths = r["calls"]["eigen_calls"]
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


# ---------------------------------------------------------------------------- targets (issue 31)
def wall_target(name: str, bound: float, r: dict, kinds: tuple[str, ...]) -> dict:
    """A wall-time target of one run's record (path_timing's keys, split_s): the measured wall
    time made of the path, threshold location, branch tracing and the rest, and again by kind
    (split_s's `kinds`, which add up to the wall time)."""
    stage = r["stage"]
    path_s = stage["compression"]["time_s"] + stage["shear"]["time_s"]
    thresholds, branches = r.get("threshold_wall_time_s") or 0.0, r.get("branches_wall_time_s") or 0.0
    made_of = {"path (compression + shear)": path_s, "threshold location": thresholds, "branch tracing": branches,
               "rest (set-up, observables, outputs)": r["wall_time_s"] - path_s - thresholds - branches}
    made_of.update({f"by kind: {k}": r["split_s"][k] for k in kinds})
    return {"target": name, "bound": bound, "measured": r["wall_time_s"], "unit": "s",
            "met": bool(r["wall_time_s"] <= bound), "made_of": made_of}


def iterations_target(name: str, bound: float, r: dict) -> dict:
    """Newton iterations per recorded step of one run's record, made of its phases' iterations
    per recorded step (newton_by_phase)."""
    steps = r["recorded_steps"]
    per_step = r["newton_iterations"] / steps
    return {"target": name, "bound": bound, "measured": per_step, "unit": "its/step",
            "met": bool(per_step <= bound),
            "made_of": {f"{phase} ({v['solves']} solves)": v["iterations"] / steps
                        for phase, v in r["newton_by_phase"].items()}}


def targets_markdown(title: str, targets: list[dict]) -> list[str]:
    """A report section: each target, its bound, the measured figure, met or not, and its parts."""
    if not targets:
        return []
    lines = ["", f"## {title}", "", "| target | bound | measured | met | made of |", "|---|---:|---:|---|---|"]
    for t in targets:
        unit = t["unit"]
        parts = "; ".join(f"{k} {fmt(v, '.2f')}" for k, v in t["made_of"].items() if v is not None)
        lines.append(f"| {t['target']} | {t['bound']:g} {unit} | {t['measured']:.2f} {unit} | "
                     f"{'yes' if t['met'] else 'NOT met'} | {parts} |")
    lines += ["", "made of: the parts of the measured figure, from the same run: seconds (path, threshold location, "
              "branch tracing, the rest; and again by the kind of work, which adds up to the same wall time) or "
              "Newton iterations per recorded step by phase."]
    return lines


#: Load average above which other processes are taken to have shared the 2 cores.
SHARED_LOAD = 1.5

def shared_machine_note(report: dict) -> list[str]:
    """A warning line when the load average says other processes shared the 2 cores."""
    loads = [x for x in report["load_average"] if x is not None]
    if not loads or max(loads) <= SHARED_LOAD:
        return []
    return [f"- the load average exceeded {SHARED_LOAD} (up to {max(loads):.1f} on {report['machine']['cpu_count']} "
            "cores): other jobs shared the machine, so wall times are inflated; the CPU times and the iteration "
            "counts are the figures to compare with other runs"]
