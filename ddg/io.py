"""The output contract: DIR/path.csv and DIR/summary.json, written atomically."""
from __future__ import annotations

import csv
import io
import json
import math
import os
import tempfile
from pathlib import Path

import numpy as np

from .observables import EXTRA_COLUMNS, PATH_COLUMNS


def atomic_write_text(path: Path, text: str) -> None:
    """Write text to path via a temporary file in the same folder and os.replace."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
    try:
        with os.fdopen(fd, "w", newline="") as fh:
            fh.write(text)
            fh.flush()
            os.fsync(fh.fileno())
        os.chmod(tmp, 0o644)  # mkstemp creates 0600
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def _format(value):
    if isinstance(value, (bool, np.bool_)):
        return "1" if value else "0"
    if isinstance(value, float):
        return "" if math.isnan(value) else repr(value)
    return value


def write_path_csv(path: Path, rows: list[dict], leading: tuple[str, ...] = (), trailing: tuple[str, ...] = ()) -> None:
    """path.csv: the contract columns, then the extras present, then a model's own `trailing` ones
    (branches.csv: leading=("branch",))."""
    columns = list(leading) + list(PATH_COLUMNS) + [c for c in EXTRA_COLUMNS if rows and c in rows[0]] + list(trailing)
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


class StoredRun:
    """A finished output folder read back: `.rows` (path.csv, numbers parsed), `.summary`
    (summary.json), `.converged` and `.column(name, stage)`; any model writes this contract."""

    def __init__(self, directory):
        self.directory = Path(directory)
        self.summary = json.loads((self.directory / "summary.json").read_text())
        self.rows = read_numeric_rows(self.directory / "path.csv")
        self.converged = bool(self.summary.get("converged"))

    def column(self, name: str, stage: str | None = None) -> np.ndarray:
        return np.array([r[name] for r in self.rows if stage is None or r["stage"] == stage])
