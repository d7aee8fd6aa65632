"""Runs of the validation report: what to run (RunSpec), where its result is cached, running many.

A run is one `ddg.simulate` call (rod, plate or ribbon) on one scene. Its results (path.csv,
summary.json, branches.csv) are cached under CACHE/<key>/, where key is a hash of the run's inputs
and of the ddg source code, so a rerun computes only what changed and an interrupted report
resumes without losing finished runs (a run counts as finished once CACHE/<key>/spec.json exists;
it is written last, atomically). FEM reference curves are not run here: they are read from the
gold data in data/fem_gold (validation/reference.py load_gold), which `python -m fem_reference gold
--out data/fem_gold` regenerates (data/fem_gold/README.md).
"""
from __future__ import annotations

import hashlib
import json
import sys
import time
import traceback
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import asdict, dataclass
from pathlib import Path

from ddg.output.io import atomic_write_text, read_numeric_rows

ROOT = Path(__file__).resolve().parent.parent


@dataclass(frozen=True)
class RunSpec:
    model: str                     # rod | plate | ribbon
    width_ratio: float
    compression_ratio: float
    resolution: int | None = None  # None: the model's default
    shear_ratio: float | None = None  # None: dW_max/L; 0: compression only
    compression_steps: int = 40
    shear_steps: int = 120
    poisson_ratio: float = 0.0
    slenderness: float | None = None
    thresholds: bool = True
    branches: bool = False
    frames: bool = False           # plate shapes per step (VTU) for the 3D snapshots

    @property
    def label(self) -> str:
        res = "" if self.resolution is None else f" N={self.resolution}"
        nu = f" nu={self.poisson_ratio:g}" if self.poisson_ratio else ""
        return f"{self.model} W/L={self.width_ratio:.4g} dL/L={self.compression_ratio:.4g}{res}{nu}"

    def key(self, code: str) -> str:
        spec = asdict(self)
        if not spec["frames"]:  # added later: runs without frames keep their cache keys
            del spec["frames"]
        text = json.dumps({"spec": spec, "code": code}, sort_keys=True)
        return hashlib.sha256(text.encode()).hexdigest()[:16]


def code_version() -> str:
    """sha256 of the ddg package's sources: a change of the solver invalidates the cache."""
    digest = hashlib.sha256()
    for path in sorted((ROOT / "ddg").rglob("*.py")):
        digest.update(str(path.relative_to(ROOT)).encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()[:16]


@dataclass
class RunResult:
    spec: RunSpec
    directory: Path
    rows: list[dict]
    summary: dict
    branch_rows: list[dict]

    def column(self, name: str, stage: str | None = None) -> list:
        return [float(r[name]) if name != "phase" and name != "stage" else r[name]
                for r in self.rows if stage is None or r["stage"] == stage]


def load(directory: Path, spec: RunSpec) -> RunResult:
    rows = read_numeric_rows(directory / "path.csv") if (directory / "path.csv").exists() else []
    branches = directory / "branches.csv"
    branch_rows = read_numeric_rows(branches) if branches.exists() else []
    summary = json.loads((directory / "summary.json").read_text())
    return RunResult(spec, directory, rows, summary, branch_rows)


def execute_one(spec: RunSpec, directory: str) -> dict:
    """Run one spec into `directory` (in a worker process); spec.json is written last."""
    import ddg

    directory = Path(directory)
    t0 = time.perf_counter()
    try:
        strip = ddg.Strip.from_ratios(spec.width_ratio, spec.compression_ratio, spec.slenderness,
                                      poisson_ratio=spec.poisson_ratio)
        protocol = ddg.LoadingProtocol(spec.compression_ratio, spec.shear_ratio, spec.compression_steps,
                                       spec.shear_steps)
        if spec.model == "ribbon":
            from ddg.ribbon_runs import run_ribbon

            run_ribbon(strip, protocol, "direct", None, spec.resolution, out=directory, thresholds=spec.thresholds)
        else:
            ddg.simulate(strip, protocol, model=spec.model, resolution=spec.resolution, out=directory,
                         thresholds=spec.thresholds, branches=spec.branches, frames=spec.frames)
        error = None
    except Exception as exc:  # a failed run is reported, not fatal to the report
        error = f"{type(exc).__name__}: {exc}"
        traceback.print_exc(file=sys.stderr)
    record = {"spec": asdict(spec), "error": error, "report_wall_time_s": time.perf_counter() - t0}
    if error is None:
        atomic_write_text(directory / "spec.json", json.dumps(record, indent=2) + "\n")
    return record


class Progress:
    """One line on stderr: [#####     ] done/total label."""

    def __init__(self, total: int, enabled: bool = True):
        self.total, self.done = total, 0
        self.enabled = enabled and total > 0

    def step(self, label: str) -> None:
        self.done += 1
        if self.enabled:
            bar = "#" * int(30 * self.done / self.total)
            end = "\n" if self.done == self.total else ""
            sys.stderr.write(f"\r[{bar:<30}] {self.done}/{self.total} {label[:60]:<60}{end}")
            sys.stderr.flush()


def estimated_cost(spec: RunSpec) -> float:
    """Rough relative cost of a run, for ordering (the plate's path grows about linearly with its
    triangles, 2000 triangles ~ 20 rods of 100 nodes)."""
    if spec.model == "plate":
        return (spec.resolution or 2000) / 100.0
    return (spec.resolution or 100) / 100.0


def run_all(specs: list[RunSpec], cache: Path, jobs: int = 1, progress: bool = True) -> dict[RunSpec, RunResult]:
    """Every spec's result, from the cache where present, else computed (jobs worker processes)."""
    code = code_version()
    cache = Path(cache)
    results: dict[RunSpec, RunResult] = {}
    todo = []
    for spec in dict.fromkeys(specs):
        directory = cache / spec.key(code)
        if (directory / "spec.json").exists():
            results[spec] = load(directory, spec)
        else:
            todo.append((spec, directory))
    todo.sort(key=lambda item: -estimated_cost(item[0]))  # longest first: the pool ends together
    bar = Progress(len(todo), progress)
    if todo and jobs > 1:
        with ProcessPoolExecutor(max_workers=jobs) as pool:
            futures = {pool.submit(execute_one, spec, str(d)): (spec, d) for spec, d in todo}
            for future in as_completed(futures):
                spec, directory = futures[future]
                future.result()
                bar.step(spec.label)
                if (directory / "spec.json").exists():
                    results[spec] = load(directory, spec)
    else:
        for spec, directory in todo:
            execute_one(spec, str(directory))
            bar.step(spec.label)
            if (directory / "spec.json").exists():
                results[spec] = load(directory, spec)
    return results
