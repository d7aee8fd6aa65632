"""The output contract: DIR/path.csv and DIR/summary.json, written atomically; figures saved
byte-stable (save_figure)."""
from __future__ import annotations

import contextlib
import csv
import io
import json
import math
import os
import tempfile
from pathlib import Path

import numpy as np

from ..limits import InputError
from ..analysis.observables import EXTRA_COLUMNS, PATH_COLUMNS


@contextlib.contextmanager
def atomic_path(path: Path, suffix: str = ""):
    """A temporary file name in path's folder to write to; on success it is synced, made 0644
    and moved onto path with os.replace (readers see the old file or the whole new one, never a
    part); on any exception, Ctrl-C included, it is removed and path is left as it was. The one
    atomic writer of the project: atomic_write_text, the VTU frames and the rendered images use it."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=suffix, dir=path.parent)
    os.close(fd)
    try:
        yield tmp
        with open(tmp, "rb+") as fh:
            os.fsync(fh.fileno())
        os.chmod(tmp, 0o644)  # mkstemp creates 0600
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def atomic_write_text(path: Path, text: str) -> None:
    """Write text to path atomically (atomic_path)."""
    with atomic_path(path) as tmp:
        with open(tmp, "w", newline="") as fh:
            fh.write(text)


#: What matplotlib stamps into a saved figure besides the drawing (the date, its own name and
#: version), per format; None leaves the key out, so the same figure gives the same bytes on
#: every regeneration, with or without SOURCE_DATE_EPOCH.
FIGURE_METADATA = {"png": {"Software": None},
                   "pdf": {"CreationDate": None, "Creator": None, "Producer": None},
                   "svg": {"Date": None, "Creator": None}}
#: Salt of the SVG element ids (matplotlib's default, svg.hashsalt None, is a fresh random one per save).
SVG_HASH_SALT = "ddg-strips"


def figure_bytes(fig, fmt: str = "png", **options) -> bytes:
    """A matplotlib figure as PNG, PDF or SVG bytes without date or software stamps
    (FIGURE_METADATA) and with fixed SVG ids: byte-identical for the same drawing. `options` go
    to savefig (dpi, bbox_inches, ...)."""
    import matplotlib

    fmt = str(fmt).lower()
    if fmt not in FIGURE_METADATA:
        raise ValueError(f"figure format {fmt!r} is not one of {', '.join(FIGURE_METADATA)}")
    buf = io.BytesIO()
    with matplotlib.rc_context({"svg.hashsalt": SVG_HASH_SALT}):
        fig.savefig(buf, format=fmt, metadata=FIGURE_METADATA[fmt], **options)
    return buf.getvalue()


def save_figure(fig, path, **options) -> Path:
    """Save a matplotlib figure to `path` (format from the suffix: .png, .pdf or .svg), atomically
    and byte-stable (figure_bytes): the one place the project saves figures."""
    path = Path(path)
    data = figure_bytes(fig, path.suffix.lstrip("."), **options)
    with atomic_path(path, suffix=path.suffix) as tmp:
        with open(tmp, "wb") as fh:
            fh.write(data)
    return path


def write_table_csv(path: Path, rows: list[dict], fieldnames: list[str] | None = None) -> None:
    """Rows of dicts as a CSV table (header: fieldnames, default the first row's keys), written atomically."""
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=fieldnames or list(rows[0]), lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    atomic_write_text(path, buf.getvalue())


def read_json_object(path: Path) -> dict | None:
    """A JSON file holding an object (summary.json, richardson.json), or None if it is missing,
    unreadable or not an object."""
    try:
        value = json.loads(Path(path).read_text())
    except (OSError, ValueError):
        return None
    return value if isinstance(value, dict) else None


def finite_float(value) -> float | None:
    """value (a number or a CSV cell) as a finite float; None for '', None, text or inf/nan."""
    if value is None or value == "":
        return None
    try:
        number = float(value)
    except (TypeError, ValueError):
        return None
    return number if math.isfinite(number) else None


def finished_run_summary(folder: Path) -> dict | None:
    """The summary.json of a run folder whose run ended (status "complete" or "stopped"), else
    None: the test by which resumable studies keep a finished run and redo any other."""
    summary = read_json_object(Path(folder) / "summary.json")
    return summary if summary and summary.get("status") in ("complete", "stopped") else None


def _format(value):
    if isinstance(value, (bool, np.bool_)):
        return "1" if value else "0"
    if isinstance(value, float):
        return "" if math.isnan(value) else repr(value)
    return value


def path_columns(row: dict, leading: tuple[str, ...] = (), trailing: tuple[str, ...] = ()) -> list[str]:
    """path.csv's header: `leading`, the contract columns, the extras `row` has, then the
    `trailing` ones not already named (each column once: the shell's trailing columns repeat
    negative_eigenvalues, one of the extras)."""
    columns = list(leading) + list(PATH_COLUMNS) + [c for c in EXTRA_COLUMNS if c in row]
    return columns + [c for c in trailing if c not in columns]


def write_path_csv(path: Path, rows: list[dict], leading: tuple[str, ...] = (), trailing: tuple[str, ...] = ()) -> None:
    """path.csv: the contract columns, then the extras present, then a model's own `trailing` ones
    (branches.csv: leading=("branch",))."""
    columns = path_columns(rows[0] if rows else {}, leading, trailing)
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(columns)
    for row in rows:
        writer.writerow([_format(row.get(c, "")) for c in columns])
    atomic_write_text(Path(path), buf.getvalue())


def _json_safe(value):
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _json_safe(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_json_safe(v) for v in value]
    return value


def write_summary_json(path: Path, summary: dict) -> None:
    atomic_write_text(Path(path), json.dumps(_json_safe(summary), indent=2, sort_keys=False) + "\n")


def write_centerline_csv(path: Path, rows: list[dict], centerlines: list, length: float) -> None:
    """centerline.csv: the deformed material line w = 0 (the rod's centerline) per recorded row,
    columns row (index into path.csv), stage, dL_over_L, dW_over_L, s_over_L, x/y/z_over_L."""
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(["row", "stage", "dL_over_L", "dW_over_L", "s_over_L", "x_over_L", "y_over_L", "z_over_L"])
    for index, (row, points) in enumerate(zip(rows, centerlines)):
        stations = len(points)
        for k, p in enumerate(points / length):
            writer.writerow([index, row["stage"], _format(row["dL_over_L"]), _format(row["dW_over_L"]),
                             repr(k / (stations - 1)), repr(float(p[0])), repr(float(p[1])), repr(float(p[2]))])
    atomic_write_text(Path(path), buf.getvalue())


def read_path_csv(path: Path) -> list[dict]:
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


#: path.csv / branches.csv columns that hold text; every other column is read as a number.
TEXT_COLUMNS = ("stage", "phase", "branch")


def read_numeric_rows(path: Path) -> list[dict]:
    """A path.csv-style file with numbers as floats (empty cells nan), TEXT_COLUMNS as strings."""
    out = []
    for row in read_path_csv(path):
        parsed = {}
        for key, value in row.items():
            if key in TEXT_COLUMNS:
                parsed[key] = value
            else:
                try:
                    parsed[key] = float(value) if value != "" else float("nan")
                except ValueError:
                    parsed[key] = value
        out.append(parsed)
    return out


class PathTable:
    """The recorded rows of a run (path.csv: one row per recorded equilibrium, docs/reference/output_contract.rst)
    as numpy arrays or a pandas DataFrame; shared by SimulationResult and StoredRun."""

    rows: list[dict]

    def column(self, name: str, stage: str | None = None) -> np.ndarray:
        """One column of path.csv as a numpy array, e.g. column("H_mid_over_L", "shear"): every
        recorded row, or those of `stage` ("compression" or "shear"). Columns (the output contract): stage,
        dL_over_L, dW_over_L (dL/L, dW/L), H_mid_over_L (mid-point height / L), F_shear_norm
        (F_y L / (E b^3), App. E), energy (J), lambda_min (lowest eigenvalue, normalised), phase (U,
        US+, US-, S+, S-), then F_axial_norm, stable, newton_iterations, branch_switched,
        max_turn_angle_deg, max_strain, negative_eigenvalues. KeyError naming the columns for an
        unknown name."""
        rows = self.rows if stage is None else [r for r in self.rows if r["stage"] == stage]
        if rows and name not in rows[0]:
            raise KeyError(f"no column {name!r}; the columns are {', '.join(rows[0])}")
        return np.array([r[name] for r in rows])

    def arrays(self, stage: str | None = None) -> dict[str, np.ndarray]:
        """Every column as a numpy array (of `stage`'s rows if given): {name: array}."""
        rows = self.rows if stage is None else [r for r in self.rows if r["stage"] == stage]
        names = list(rows[0]) if rows else list(PATH_COLUMNS + EXTRA_COLUMNS)
        return {name: np.array([r.get(name) for r in rows]) for name in names}

    def to_dataframe(self, stage: str | None = None):
        """The rows as a pandas DataFrame (pandas: Debian python3-pandas, or pip install
        'ddg-strips[dataframe]'); ImportError in one line naming it when pandas is missing."""
        return require_pandas("result.arrays() gives numpy arrays").DataFrame(self.arrays(stage))


def require_pandas(without: str):
    """pandas, or ImportError in one line naming the extra and what works `without` it."""
    try:
        import pandas
    except ImportError:
        raise ImportError("to_dataframe needs pandas, which is not installed: pip install 'ddg-strips[dataframe]' "
                          f"(or apt install python3-pandas); without it {without}") from None
    return pandas


class StoredRun(PathTable):
    """A finished output folder read back, for any model (they all write this contract):
    `.rows` (path.csv, numbers parsed), `.summary` (summary.json as a dict), `.converged`,
    `.directory`; `.column(name, stage)`, `.arrays()`, `.to_dataframe()` (PathTable), and
    `.branch_rows` (branches.csv where it exists, else []). ddg.read_run(directory) is this."""

    def __init__(self, directory):
        self.directory = Path(directory)
        self.summary = json.loads((self.directory / "summary.json").read_text())
        self.rows = read_numeric_rows(self.directory / "path.csv")
        self.converged = bool(self.summary.get("converged"))
        branches = self.directory / "branches.csv"
        self.branch_rows = read_numeric_rows(branches) if branches.is_file() else []

    def __repr__(self) -> str:
        return (f"StoredRun({str(self.directory)!r}: {self.summary.get('model')}, {len(self.rows)} rows, "
                f"status {self.summary.get('status')})")


def check_output_directory(out, name: str = "out") -> Path:
    """The output directory `out`, created if missing and proven writable, before any work.

    Refused with a one-line InputError: a value that is not a path, an empty name (which would
    write into the current directory), an existing file or device (/dev/null), a path under a
    file, a name the file system refuses (too long), a directory that cannot be written."""
    if out is None or isinstance(out, bool) or not isinstance(out, (str, os.PathLike)):
        raise InputError(f"{name} = {out!r} must be a directory path (str or os.PathLike)")
    text = os.fspath(out)
    if isinstance(text, bytes):
        text = os.fsdecode(text)
    if text.strip() == "":
        raise InputError(f"{name} = {text!r} is empty; give an output directory (e.g. out/run1)")
    if "\0" in text:
        raise InputError(f"{name} = {text!r} contains a NUL character; give a valid directory path")
    path = Path(text)
    try:
        if path.exists() and not path.is_dir():
            raise InputError(f"{name} = {text!r} exists and is not a directory")
        path.mkdir(parents=True, exist_ok=True)
    except InputError:
        raise
    except OSError as exc:
        raise InputError(f"{name} = {text!r} cannot be created: {exc.strerror or exc}") from None
    try:
        fd, probe = tempfile.mkstemp(prefix=".write-test-", dir=path)
        os.close(fd)
        os.unlink(probe)
    except OSError as exc:
        raise InputError(f"{name} = {text!r} is not writable: {exc.strerror or exc}") from None
    return path


#: Files a run writes into its folder; a new run removes them first so none is left from an
#: earlier run with other inputs (frames/ is a folder of the same kind).
RESULT_FILES = ("path.csv", "summary.json", "centerline.csv", "branches.csv", "rod_path.csv", "fields.xdmf",
                "fields.h5")
RESULT_FOLDERS = ("frames",)

#: summary.json "status": running (the run is in progress or was killed), complete, stopped (did
#: not converge; the converged part is kept), interrupted (SIGINT/SIGTERM; the computed part kept).
STATUS_RUNNING, STATUS_COMPLETE, STATUS_STOPPED, STATUS_INTERRUPTED = "running", "complete", "stopped", "interrupted"


class RunFolder:
    """An output folder over the life of one run.

    - At creation (before any work): the folder is checked writable, the files of an earlier
      run are removed and summary.json says status "running", converged false, so a killed run
      can never be mistaken for a finished one.
    - append(row): the row goes to path.csv at once (appended and flushed), so SIGKILL loses at
      most the step being computed.
    - checkpoint(summary): summary.json rewritten atomically, still "running".
    - finish(result): every file rewritten atomically by result.write (path.csv whole).
    """

    def __init__(self, out, summary: dict | None = None, *, leading: tuple[str, ...] = (),
                 trailing: tuple[str, ...] = (), name: str = "out"):
        self.path = check_output_directory(out, name)
        self.leading, self.trailing = tuple(leading), tuple(trailing)
        self._columns: list[str] | None = None
        self._handle = None
        for file in RESULT_FILES:
            (self.path / file).unlink(missing_ok=True)
        for folder in RESULT_FOLDERS:
            if (self.path / folder).is_dir():
                import shutil

                shutil.rmtree(self.path / folder, ignore_errors=True)
        if summary is not None:
            self.checkpoint(summary)

    def checkpoint(self, summary: dict) -> None:
        marked = dict(summary)
        marked["status"] = STATUS_RUNNING
        marked["converged"] = False
        if not marked.get("message"):
            marked["message"] = f"running (process {os.getpid()}); if no process runs, it was killed"
        write_summary_json(self.path / "summary.json", marked)

    def append(self, row: dict) -> None:
        if self._columns is None:
            self._columns = path_columns(row, self.leading, self.trailing)
            self._handle = open(self.path / "path.csv", "w", newline="")
            csv.writer(self._handle, lineterminator="\n").writerow(self._columns)
        csv.writer(self._handle, lineterminator="\n").writerow([_format(row.get(c, "")) for c in self._columns])
        self._handle.flush()

    def close(self) -> None:
        if self._handle is not None:
            self._handle.close()
            self._handle = None

    def finish(self, result) -> None:
        """Write the result's files atomically (signals held until done)."""
        from .interrupts import deferred_signals

        self.close()
        with deferred_signals():
            result.write(self.path)
