"""The sweep's tidy table: one row per run (its inputs, thresholds, H_mid after compression, how it
ended, its cost, its folder), written to DIR/sweep.csv and, if pyarrow imports, DIR/sweep.parquet."""
from __future__ import annotations

import csv
import io
import math
from pathlib import Path

from ..output.io import atomic_write_text

#: The table's columns, in order; *_over_L are normalised by L, L_over_b is the slenderness.
COLUMNS = ("model", "W_over_L", "dL_over_L", "L_over_b", "resolution", "dW1_over_L", "dW2_over_L",
           "H_mid_over_L_compressed", "converged", "status", "wall_time_s", "newton_iterations", "run_dir",
           "dW2_S_stable_over_L", "dW_max_over_L", "threshold_newton_iterations", "message")
#: Column types for Parquet (and for reading sweep.csv back).
FLOAT, INT, TEXT = "float", "int", "text"
TYPES = {"model": TEXT, "resolution": INT, "converged": INT, "status": TEXT, "newton_iterations": INT,
         "run_dir": TEXT, "threshold_newton_iterations": INT, "message": TEXT}


def sweep_rows(specs, outcome, out) -> list[dict]:
    """The rows of the runs that finished (or failed), in the order of `specs`; runs not reached
    (the sweep was interrupted) have no row."""
    out = Path(out).resolve()
    rows = []
    for spec in dict.fromkeys(specs):
        result = outcome.results.get(spec)
        if result is None and spec not in outcome.errors:
            continue
        strip = spec.strip()
        row = {"model": spec.model, "W_over_L": spec.width_ratio, "dL_over_L": spec.compression_ratio,
               "L_over_b": strip.slenderness, "resolution": spec.resolution}
        directory = outcome.directories.get(spec)
        if directory is not None:
            row["run_dir"] = _relative(directory, out)
        if result is not None:
            s = result.summary
            record = outcome.records.get(spec) or result.record
            row.update(resolution=s.get("scene", {}).get("resolution", spec.resolution),
                       dW1_over_L=s.get("dW1_over_L"), dW2_over_L=s.get("dW2_over_L"),
                       H_mid_over_L_compressed=s.get("H_mid_over_L_compressed"),
                       converged=int(bool(s.get("converged"))), status=s.get("status"),
                       wall_time_s=record.get("report_wall_time_s"), newton_iterations=s.get("newton_iterations"),
                       dW2_S_stable_over_L=s.get("dW2_S_stable_over_L"), dW_max_over_L=s.get("dW_max_over_L"),
                       threshold_newton_iterations=s.get("threshold_newton_iterations"), message=s.get("message"))
        else:
            record = outcome.records.get(spec) or {}
            row.update(converged=0, status="error", wall_time_s=record.get("report_wall_time_s"),
                       message=outcome.errors[spec])
        rows.append({c: row.get(c) for c in COLUMNS})
    return rows


def write_table(out, rows: list[dict]) -> list[Path]:
    """DIR/sweep.csv (atomically), and DIR/sweep.parquet if pyarrow is importable; the paths written."""
    out = Path(out)
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(COLUMNS)
    for row in rows:
        writer.writerow([_cell(row.get(c)) for c in COLUMNS])
    atomic_write_text(out / "sweep.csv", buf.getvalue())
    written = [out / "sweep.csv"]
    parquet = out / "sweep.parquet"
    try:
        import pyarrow
        import pyarrow.parquet
    except ImportError:
        parquet.unlink(missing_ok=True)  # one from an earlier sweep would no longer match sweep.csv
        return written
    arrow = {FLOAT: pyarrow.float64(), INT: pyarrow.int64(), TEXT: pyarrow.string()}
    schema = pyarrow.schema([(c, arrow[TYPES.get(c, FLOAT)]) for c in COLUMNS])
    table = pyarrow.Table.from_pydict({c: [_typed(r.get(c), TYPES.get(c, FLOAT)) for r in rows] for c in COLUMNS},
                                      schema=schema)
    tmp = parquet.with_name(".sweep.parquet.tmp")
    pyarrow.parquet.write_table(table, str(tmp))
    tmp.replace(parquet)
    written.append(parquet)
    return written


def read_table(path) -> list[dict]:
    """sweep.csv read back with its column types (empty cells as None)."""
    with open(path, newline="") as fh:
        return [{c: _typed(v if v != "" else None, TYPES.get(c, FLOAT)) for c, v in row.items()}
                for row in csv.DictReader(fh)]


def _relative(directory: Path, out: Path) -> str:
    try:
        return str(Path(directory).resolve().relative_to(out))
    except ValueError:
        return str(directory)


def _cell(value):
    if value is None:
        return ""
    if isinstance(value, bool):
        return int(value)
    if isinstance(value, float):
        return "" if math.isnan(value) else repr(value)
    return value


def _typed(value, kind):
    if value is None:
        return None
    if kind == FLOAT:
        return float(value)
    if kind == INT:
        return int(float(value))
    return str(value)
