"""The error map's computation: the rows of the stored studies' runs (read, not rerun) and the runs
made here, each a Dask task (ddg.sweep.cluster), every row written to the table as it ends.

The runs made here: the rod's family registered in ddg.api.DEFAULT_RESOLUTION at run time (the rod
at M = 50/100/200, the ribbons at M = 51/101/201), run through ddg.api.run_candidate (the default
path: 40 compression and 120 shear steps to dW_max, thresholds from stability, no branch tracing;
nothing written to disk), each stopped after its time limit (checked at each Newton solve). The
stored runs: the plates at each mesh of their studies (data/plate_gold, data/midedge_gold,
data/narrow_limit) and the FEM at each mesh of its study. A row is skipped where the table has it
current (validation.error_map.rows.is_current): the source hash of a run made here is that of the
ddg sources (validation.runs.code_version), of a stored run its summary.json.
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

from ddg.output.io import StoredRun
from ddg.solve.probe import Probe

from ..reference import gold_name
from .rows import CSV_NAME, is_current, open_table, put_row, row_errors, set_role
from .scenes import ReferenceScene, StoredMesh, file_hash, reference_scenes, relative_path, rod_family

#: Seconds one run made here may take before it is stopped as failed (a model that stalls).
RUN_TIMEOUT = 120
#: Most seconds --timeout may give a run (a day: no run of the map's scenes needs a tenth of it).
MAX_TIMEOUT = 86400


def _base(scene: ReferenceScene, model: str, resolution: int, label: str) -> dict:
    s = scene.actual_slenderness
    return {"scene": scene.name, "role": scene.role, "compression_ratio": scene.compression_ratio,
            "width_ratio": scene.width_ratio, "slenderness": s,
            "width_squared_over_thickness_length": scene.width_ratio**2 * s, "model": model,
            "resolution": resolution, "resolution_label": label, "reference": scene.reference_source,
            "reference_hash": scene.reference_hash}


def _with_summary(row: dict, scene: ReferenceScene, summary: dict, path_rows: list[dict]) -> dict:
    row.update(row_errors(scene.reference, summary, path_rows))
    row.update(n_dof=summary.get("n_dof"), status=summary.get("status"), wall_time_s=summary.get("wall_time_s"))
    return row


class _Timeout(Exception):
    pass


class _Deadline(Probe):
    """A run's time limit, checked at each Newton solve and recorded step (in any thread: a Dask
    worker runs its tasks outside the main thread, where SIGALRM cannot be used)."""

    def __init__(self, seconds: float):
        self.seconds, self.end = seconds, time.monotonic() + seconds

    def solve(self, phase: str, iterations: int, converged: bool) -> None:
        self._check()

    def step(self, stage: str, row: dict, wall_s: float) -> None:
        self._check()

    def _check(self) -> None:
        if time.monotonic() > self.end:
            raise _Timeout(f"the run took more than {self.seconds:g} s")


def run_row(scene: ReferenceScene, model: str, resolution: int, timeout: int = RUN_TIMEOUT) -> dict:
    """One run made here or in a Dask worker (ddg.api.run_candidate, nothing written) and its row;
    stopped after `timeout` s (0: no limit)."""
    import ddg
    from ddg.api import run_candidate

    strip = ddg.Strip.from_ratios(scene.width_ratio, scene.compression_ratio, scene.slenderness)
    row = _base(scene, model, resolution, f"M{resolution}")
    row["run_source"] = "ddg.api.run_candidate"
    t0 = time.perf_counter()
    try:
        result = run_candidate(strip, ddg.LoadingProtocol(scene.compression_ratio), model, resolution,
                               probe=_Deadline(timeout) if timeout else None)
    except Exception as exc:  # noqa: BLE001  (a failing model, or one out of time, is a row with its reason)
        result = getattr(exc, "result", None)
        if result is None:
            row.update(status="error", wall_time_s=time.perf_counter() - t0,
                       reason=f"run failed: {type(exc).__name__}: {' '.join(str(exc).split())[:200]}")
            return row
    return _with_summary(row, scene, result.summary, result.rows)


def stored_row(scene: ReferenceScene, mesh: StoredMesh) -> dict:
    """A stored study's run and its row."""
    run = StoredRun(mesh.folder)
    row = _base(scene, mesh.model, mesh.resolution, mesh.label)
    row["run_source"] = relative_path(mesh.folder)
    return _with_summary(row, scene, run.summary, run.rows)


def build(out: Path, only=None, models=None, quiet: bool = False, timeout: int = RUN_TIMEOUT, *,
          scheduler: str | None = None, workers: int | None = None, retries: int = 2,
          failures: list | None = None) -> list[dict]:
    """Every row into OUT/error_map.csv, skipping current ones; the table's rows. The stored runs'
    rows are made here; the runs made here are Dask tasks (run_row on a worker,
    ddg.sweep.cluster.run_all: `scheduler`, else a LocalCluster of `workers` processes), each row
    written as its run ends. A failed run is not written: one line on stderr, and its
    "scene model label: reason" appended to `failures`. Ctrl-C: the rows written are kept, the
    interrupt is raised with a `run_message`."""
    from ddg.output.interrupts import signal_name_of
    from ddg.sweep.cluster import Task, run_all

    from ..runs import code_version

    table = open_table(Path(out) / CSV_NAME)
    code = code_version()

    def failed(what: str, why: str) -> None:
        print(f"error: {what}: {why}; not written to the map (a rerun retries it)", file=sys.stderr, flush=True)
        if failures is not None:
            failures.append(f"{what}: {why}")

    family = rod_family()
    tasks = []
    for scene in reference_scenes():
        if only and scene.name not in only and (scene.folder_name or gold_name(scene.compression_ratio,
                                                                               scene.width_ratio)) not in only:
            continue
        if scene.reference is None:
            print(f"{scene.name}: no FEM reference study, skipped", file=sys.stderr, flush=True)
            continue
        set_role(table, scene.name, scene.role)
        for mesh in scene.stored:
            if models and mesh.model not in models:
                continue
            source = file_hash(mesh.folder / "summary.json")
            if is_current(table, (mesh.model, mesh.label, scene.name), source, scene.reference_hash):
                continue
            row = stored_row(scene, mesh)
            row["source_hash"] = source
            if not put_row(table, row):
                failed(f"{scene.name} {mesh.model} {mesh.label}", row.get("reason") or "the run failed")
        for model, resolutions in family:
            if models and model not in models:
                continue
            for m in resolutions:
                if not is_current(table, (model, f"M{m}", scene.name), code, scene.reference_hash):
                    tasks.append(Task(f"error-map-{scene.name}-{model}-M{m}-{scene.reference_hash}-{code}", run_row,
                                      (scene, model, m, timeout), m))

    def finished(task, row, error):
        scene, model, m, _ = task.args
        if error is not None:  # the task itself failed (its worker died at every attempt): no row, rerun next time
            failed(f"{scene.name} {model} M{m}", error)
            return
        row["source_hash"] = code
        if not put_row(table, row):   # the run raised or ran out of time: not a measurement
            failed(f"{scene.name} {model} M{m}", row.get("reason") or "the run failed")
            return
        if not quiet:
            print(f"{scene.name} {model} M{m}: {row.get('status')}, {row.get('wall_time_s') or 0:.1f} s, "
                  f"dW1 err {row.get('dW1_error')}, dW2 err {row.get('dW2_error')}, H_mid err "
                  f"{row.get('H_mid_error')} {row.get('reason') or ''}", file=sys.stderr, flush=True)

    ran = run_all(tasks, finished, scheduler=scheduler, workers=workers, retries=retries, code=code)
    if ran.interrupted is not None:
        done = sum(is_current(table, (t.args[1], f"M{t.args[2]}", t.args[0].name), code, t.args[0].reference_hash)
                   for t in tasks)
        ran.interrupted.run_message = (f"interrupted by {signal_name_of(ran.interrupted)}: {done} of {len(tasks)} "
                                       f"runs finished and written to {table.path}; a rerun computes only the "
                                       f"other {len(tasks) - done}")
        raise ran.interrupted
    return table.rows
