"""One run as a task: `execute_one` runs a RunSpec into its folder (spec.json written last, the mark
of a finished run); `run_task` wraps it for a Dask worker; `load` reads a finished folder back.

A run's folder follows the output contract (path.csv, summary.json, centerline.csv, ...; see
ddg.output.io.RunFolder): from its start summary.json says "running" and path.csv grows by one row
per step, so a worker killed mid-run leaves a folder without spec.json, which never counts as
finished; the retry starts the folder afresh. Nothing here imports dask: these functions run in
any process.
"""
from __future__ import annotations

import contextlib
import json
import os
import shutil
import socket
import tempfile
import time
import traceback
from dataclasses import asdict, dataclass
from pathlib import Path

from ..models.names import RIBBON
from ..output.io import atomic_write_text, read_numeric_rows
from .grid import RunSpec, code_version

#: Written last, atomically, when the run has returned (converged or not): the folder is finished.
FINISHED = "spec.json"
#: A run that raised (an internal error) leaves its traceback here, not on the worker's stderr.
TRACEBACK = "traceback.txt"


def is_finished(directory) -> bool:
    return (Path(directory) / FINISHED).exists()


@dataclass
class RunResult:
    """A finished run read back: rows of path.csv (numbers parsed), summary.json, branches.csv."""

    spec: RunSpec
    directory: Path
    rows: list[dict]
    summary: dict
    branch_rows: list[dict]

    def column(self, name: str, stage: str | None = None) -> list:
        return [float(r[name]) if name != "phase" and name != "stage" else r[name]
                for r in self.rows if stage is None or r["stage"] == stage]

    @property
    def record(self) -> dict:
        """spec.json: the spec, the error (None) and the task's wall time."""
        return json.loads((self.directory / FINISHED).read_text())


def load(directory: Path, spec: RunSpec) -> RunResult:
    directory = Path(directory)
    rows = read_numeric_rows(directory / "path.csv") if (directory / "path.csv").exists() else []
    branches = directory / "branches.csv"
    branch_rows = read_numeric_rows(branches) if branches.exists() else []
    summary = json.loads((directory / "summary.json").read_text())
    return RunResult(spec, directory, rows, summary, branch_rows)


def execute_one(spec: RunSpec, directory: str) -> dict:
    """Run one spec into `directory` (in a worker process); spec.json is written last.

    Returns the record written to spec.json ({"spec", "error", "report_wall_time_s", "host"}; with
    "previous_status" when an earlier attempt left the folder unfinished, e.g. its worker was
    killed). A run that raises is reported in "error" (its traceback in traceback.txt) and not
    marked finished; Ctrl-C (KeyboardInterrupt) propagates after the run has written its part."""
    import ddg

    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    with _exclusive(directory):
        if is_finished(directory):  # a duplicate attempt finished it while this one waited
            return json.loads((directory / FINISHED).read_text())
        previous = _status(directory)
        (directory / TRACEBACK).unlink(missing_ok=True)
        t0 = time.perf_counter()
        try:
            strip, protocol = spec.strip(), spec.protocol()
            if spec.model == RIBBON:  # started from the flat strip, as `python -m ddg simulate --model ribbon`
                ddg.run_ribbon(strip, protocol, "direct", None, spec.resolution, out=directory,
                               thresholds=spec.thresholds)
            else:
                ddg.simulate(strip, protocol, model=spec.model, resolution=spec.resolution, out=directory,
                             thresholds=spec.thresholds, branches=spec.branches, frames=spec.frames)
            error = None
        except Exception as exc:  # a failed run is reported, not fatal to the sweep
            error = f"{type(exc).__name__}: {' '.join(str(exc).split())}"
            (directory / TRACEBACK).write_text(traceback.format_exc())
        record = {"spec": asdict(spec), "error": error, "report_wall_time_s": time.perf_counter() - t0,
                  "host": socket.gethostname()}
        if previous is not None:
            record["previous_status"] = previous
        if error is None:
            atomic_write_text(directory / FINISHED, json.dumps(record, indent=2) + "\n")
        return record


def run_task(task, spec: RunSpec, directory: str, probe: tuple[str, str] | None = None,
             code: str | None = None) -> dict:
    """`task(spec, folder)` in a Dask worker. With a `probe` (a file the client wrote and its
    content) the worker first checks that it sees the client's folder: if so (a LocalCluster, a
    shared file system) the run writes in place; if not, it runs in a temporary folder and its
    files come back in record["files"] for the client to write. `code`: the client's
    code_version(); a worker with other ddg sources refuses the run."""
    mine = code_version()
    if code is not None and mine != code:
        return {"spec": asdict(spec), "error": f"the worker on {socket.gethostname()} runs other ddg sources (code "
                f"{mine}, the client's {code}); install the same code on every worker", "report_wall_time_s": 0.0,
                "host": socket.gethostname()}
    if probe is None or _sees(probe):
        return task(spec, directory)
    with tempfile.TemporaryDirectory(prefix="ddg-run-") as tmp:
        record = task(spec, tmp)
        record["files"] = {str(p.relative_to(tmp)): p.read_bytes() for p in sorted(Path(tmp).rglob("*"))
                           if p.is_file() and p.name not in (FINISHED, ".lock")}
    return record


def materialise(record: dict, directory) -> None:
    """Write the files a worker sent back (run_task without a shared folder) into `directory`,
    spec.json last and atomically, as execute_one would have."""
    directory = Path(directory)
    files = record.pop("files", None)
    if files is None:
        return
    if directory.exists():  # what an earlier, unfinished attempt left
        shutil.rmtree(directory)
    directory.mkdir(parents=True)
    for name, data in files.items():
        path = directory / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(data)
    if record.get("error") is None:
        atomic_write_text(directory / FINISHED, json.dumps(record, indent=2) + "\n")


def _sees(probe: tuple[str, str]) -> bool:
    path, token = probe
    try:
        return Path(path).read_text() == token
    except OSError:
        return False


def _status(directory: Path) -> str | None:
    """status of an unfinished folder's summary.json ("running": its attempt was killed)."""
    try:
        return json.loads((directory / "summary.json").read_text()).get("status")
    except (OSError, ValueError):
        return None


@contextlib.contextmanager
def _exclusive(directory: Path):
    """Hold an exclusive lock on directory/.lock: should two attempts of one run ever overlap (a
    worker presumed dead that still runs), the second waits and then finds the run finished. The
    kernel drops the lock of a killed process."""
    try:
        import fcntl
    except ImportError:  # not POSIX: no lock
        yield
        return
    fd = os.open(directory / ".lock", os.O_RDWR | os.O_CREAT, 0o644)
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX)
        except OSError:  # a file system without locks (some NFS mounts): spec.json still marks the end
            pass
        yield
    finally:
        os.close(fd)
