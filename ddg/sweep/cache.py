"""Runs cached by content hash: ROOT/<key>/ per run, finished once ROOT/<key>/spec.json exists;
`run_cached` takes what is finished and computes the rest, on Dask or in this process.

The sweep (ROOT = DIR/runs) and the validation report (ROOT = OUT/cache) share it, so both
resume after an interruption or a lost worker with only the unfinished runs.
"""
from __future__ import annotations

import hashlib
import sys
import time
import uuid
from dataclasses import dataclass, field
from pathlib import Path

from .grid import RunSpec, code_version, estimated_cost
from .tasks import RunResult, execute_one, is_finished, load, materialise, run_task


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

    def close(self) -> None:
        if self.enabled and 0 < self.done < self.total:
            sys.stderr.write("\n")


@dataclass
class Outcome:
    """What run_cached did: `results` every finished run (from the cache or computed now),
    `computed` the runs computed now, `errors` spec -> message of the runs that raised or whose
    task failed, `retried` the runs whose earlier attempt had been killed, `interrupted` the
    KeyboardInterrupt that stopped it (None if it ran to the end), `where` what ran the tasks
    ("" if every run was cached)."""

    results: dict[RunSpec, RunResult] = field(default_factory=dict)
    directories: dict[RunSpec, Path] = field(default_factory=dict)
    records: dict[RunSpec, dict] = field(default_factory=dict)
    cached: list[RunSpec] = field(default_factory=list)
    computed: list[RunSpec] = field(default_factory=list)
    errors: dict[RunSpec, str] = field(default_factory=dict)
    retried: list[RunSpec] = field(default_factory=list)
    interrupted: BaseException | None = None
    where: str = ""
    wall_time_s: float = 0.0


def run_cached(specs: list[RunSpec], root, task=None, *, workers: int | None = None, scheduler: str | None = None,
               retries: int = 2, progress: bool = True, in_process: bool = False) -> Outcome:
    """Every spec's result, from ROOT where finished, else computed by `task(spec, directory)`
    (default execute_one): in this process one at a time if `in_process`, else as Dask tasks on
    `scheduler` or on a LocalCluster of `workers` processes (see ddg.sweep.cluster). No cluster
    is started when every run is cached. Ctrl-C (KeyboardInterrupt) stops it: the runs finished
    so far are kept and returned, the exception is in Outcome.interrupted."""
    t0 = time.perf_counter()
    task = execute_one if task is None else task
    code = code_version()
    root = Path(root).resolve()
    outcome = Outcome()
    todo = []
    for spec in dict.fromkeys(specs):
        directory = root / spec.key(code)
        outcome.directories[spec] = directory
        if is_finished(directory):
            outcome.results[spec] = load(directory, spec)
            outcome.cached.append(spec)
        else:
            todo.append((spec, directory))
    todo.sort(key=lambda item: -estimated_cost(item[0]))  # longest first: the workers end together
    bar = Progress(len(todo), progress)

    def finished(spec, directory, record):
        outcome.records[spec] = record
        if record.get("previous_status") == "running":
            outcome.retried.append(spec)
        if record.get("error"):
            outcome.errors[spec] = record["error"]
        if is_finished(directory):
            outcome.results[spec] = load(directory, spec)
            outcome.computed.append(spec)
        elif not record.get("error"):
            outcome.errors[spec] = "the run returned but its folder is not finished (no spec.json)"
        bar.step(spec.label)

    try:
        if todo and in_process:
            outcome.where = "this process"
            for spec, directory in todo:
                finished(spec, directory, task(spec, str(directory)))
        elif todo:
            from .cluster import Task, run_all

            root.mkdir(parents=True, exist_ok=True)
            # the run's own probe: a worker that does not see ROOT runs in a temporary folder and
            # sends the files back (ddg.sweep.tasks.run_task), instead of refusing the run
            probe = root / f".probe-{uuid.uuid4().hex}"
            token = uuid.uuid4().hex
            probe.write_text(token)
            tasks = [Task(f"ddg-run-{directory.name}-{hashlib.sha256(str(directory).encode()).hexdigest()[:8]}",
                          run_task, (task, spec, str(directory), (str(probe), token), code),
                          int(100 * estimated_cost(spec)), (spec, directory)) for spec, directory in todo]

            def filed(job, record, error):
                spec, directory = job.tag
                if error is not None:
                    record = {"error": error, "report_wall_time_s": None}
                materialise(record, directory)
                finished(spec, directory, record)

            try:
                ran = run_all(tasks, filed, scheduler=scheduler, workers=workers, retries=retries)
            finally:
                probe.unlink(missing_ok=True)
            outcome.where = ran.where
            if ran.interrupted is not None:
                raise ran.interrupted
    except KeyboardInterrupt as exc:
        outcome.interrupted = exc
        for spec, directory in todo:  # finished in a worker while the client was being stopped
            if spec not in outcome.results and is_finished(directory):
                outcome.results[spec] = load(directory, spec)
                outcome.computed.append(spec)
    finally:
        bar.close()
    outcome.wall_time_s = time.perf_counter() - t0
    return outcome

