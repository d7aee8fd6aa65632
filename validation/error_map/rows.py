"""The error map's rows: one per (model, resolution, scene), the errors of a run against the
scene's reference study, and the resumable table they are kept in (OUT/error_map.csv).

Per row, for q in dW1/L, dW2/L: |q - reference| (q_error), the reference's error bar
(q_ref_error_bar) and their sum (q_bound); for H_mid/L, on the reference curve's dW grid inside
the run's range and more than validation.claims.THRESHOLD_BAND from the reference's dW1 and dW2
and from the run's own (a small shift of a threshold is a large H_mid difference there, and the
thresholds' own errors are the dW1 and dW2 columns), the largest |H_mid - reference| (H_mid_error),
the largest reference error bar (H_mid_ref_error_bar) and the largest pointwise sum (H_mid_bound,
as validation.estimates.Study.mesh_error); the wall time of the run and a reason where a value is
missing. A bound is left empty where the run did not complete its path (its comparison would cover
part of the path only), and the H_mid bound where the reference curve stops short of dW_max.

The table keeps a row per key (model, resolution label, scene); a row is current when it was made
from the same sources (source_hash), against the same reference (reference_hash) and under the
same rules (RULES_VERSION). A failed run (status FAILED) is not a measurement: never written, and
one read from an older table is dropped.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ddg.advise import QUANTITIES
from ddg.output.io import finite_float

from ..claims import THRESHOLD_BAND
from ..estimates import Study, difference_away_from_thresholds
from ..table import Table

CSV_NAME = "error_map.csv"
#: The row status of a run that raised or ran out of time: never written to the table.
FAILED = "error"
#: A reference curve that ends more than this short of dW_max/L gives no H_mid bound (units of L):
#: the recorded shear steps are dW_max/120 ~ 0.007 L apart, so a complete path ends within one.
REFERENCE_PATH_SLACK = 0.02

COLUMNS = ("scene", "role", "compression_ratio", "width_ratio", "slenderness", "width_squared_over_thickness_length",
           "model", "resolution", "resolution_label", "n_dof", "status",
           "dW1", "ref_dW1", "dW1_error", "dW1_ref_error_bar", "dW1_bound",
           "dW2", "ref_dW2", "dW2_error", "dW2_ref_error_bar", "dW2_bound",
           "H_mid_error", "H_mid_ref_error_bar", "H_mid_bound", "H_mid_points",
           "wall_time_s", "reason", "reference", "run_source", "source_hash", "reference_hash", "rules_version")
#: The columns that name a row.
KEY = ("model", "resolution_label", "scene")
#: The version of the rules that turn a run and its reference into a row (row_errors: the
#: quantities, the excluded band, REFERENCE_PATH_SLACK, the reasons). A row of another version is
#: recomputed (is_current), so that a rule change reaches every row, not only the rows rerun for
#: another cause. Bump it with any change of those rules. Rows without the column are from before
#: version 2; version 3 leaves the H_mid band out about the run's own thresholds too.
RULES_VERSION = "3"


# ------------------------------------------------------------------------------------ errors
def _threshold_reason(summary: dict, key: str) -> str:
    unresolved = (summary.get("unresolved_thresholds") or {}).get(f"{key}_over_L")
    if unresolved:
        return f"{key} null: located at {unresolved.get('value'):.4f} but unresolved ({unresolved.get('reason')})"
    if summary.get("status") not in ("complete", None):
        return f"{key} null: the run {summary.get('status')} ({summary.get('message')})"
    if key == "dW1":
        return "dW1 null: not located (lambda_min of the U branch never changes sign on the path)"
    return "dW2 null: not located (the stable path never reaches S)"


def row_errors(reference: Study | None, summary: dict, rows: list[dict]) -> dict:
    """The error columns of one run against the reference study (module docstring)."""
    out: dict = {}
    reasons = []
    complete = summary.get("status") == "complete" and bool(summary.get("path_complete", True))
    for key in ("dW1", "dW2"):
        ours = summary.get(f"{key}_over_L")
        ref = reference.threshold(key) if reference is not None else None
        out[key] = ours
        out[f"ref_{key}"] = None if ref is None else ref.value
        out[f"{key}_ref_error_bar"] = None if ref is None else ref.error_bar
        if ours is None:
            reasons.append(_threshold_reason(summary, key))
        elif ref is None or ref.error_bar is None:
            reasons.append(f"{key}: the reference has no value with an error bar")
        else:
            out[f"{key}_error"] = abs(ours - ref.value)
            out[f"{key}_bound"] = out[f"{key}_error"] + ref.error_bar
    shear = [r for r in rows if r.get("stage") == "shear"]
    curve = reference.curve if reference is not None else None
    if curve is None:
        reasons.append("H_mid: the reference has no curve with error bars")
    elif len(shear) < 2:
        reasons.append("H_mid: the run has fewer than two shear states")
    else:
        dw = np.array([float(r["dW_over_L"]) for r in shear])
        h = np.array([float(r["H_mid_over_L"]) for r in shear])
        order = np.argsort(dw)
        dw, h = dw[order], h[order]
        # away from both curves' thresholds: the reference's and the run's own (rules version 3). Near
        # either, H_mid jumps (US -> S) or turns (U -> US), and a threshold error shows as an H_mid
        # error of order the jump; the thresholds are measured by their own quantities
        own = [summary.get(f"{k}_over_L") for k in ("dW1", "dW2")]
        keep, signed = difference_away_from_thresholds(curve, list(reference.thresholds()) + own, dw, h,
                                                       THRESHOLD_BAND)
        if not np.any(keep):
            reasons.append("H_mid: no reference point inside the run's range away from the thresholds")
        else:
            diff = np.abs(signed)
            bar = curve.error_bar[keep]
            out["H_mid_error"] = float(diff.max())
            out["H_mid_ref_error_bar"] = float(bar.max())
            out["H_mid_bound"] = float((diff + bar).max())
            out["H_mid_points"] = int(keep.sum())
            if dw[-1] < curve.dw[-1] - 1e-9:
                reasons.append(f"H_mid compared up to dW/L = {dw[-1]:.4f} only (the reference goes to "
                               f"{curve.dw[-1]:.4f})")
            limit = summary.get("dW_max_over_L")
            if limit is not None and curve.dw[-1] < float(limit) - REFERENCE_PATH_SLACK:
                # a bound over part of the path is another quantity than over all of it (it leaves out
                # US -> S, where the errors are largest): not one ddg.advise may compare or interpolate
                out.pop("H_mid_bound", None)
                reasons.append(f"H_mid: the reference stops at dW/L = {curve.dw[-1]:.4f} of dW_max/L = "
                               f"{float(limit):.4f} (its runs stopped), so no bound over the path")
    if not complete:
        reasons.append(f"run not complete ({summary.get('status')}: {summary.get('message')}): no bounds")
        for q in QUANTITIES:
            out.pop(f"{q}_bound", None)
    out["reason"] = "; ".join(reasons)
    return out


# ------------------------------------------------------------------------------------ the table
def read_table(path: Path) -> list[dict]:
    """The CSV's rows as strings (empty cells ''), [] if it does not exist."""
    return Table.read(path).rows


def open_table(path: Path) -> Table:
    """OUT/error_map.csv as a Table keyed by KEY, its failed rows (status FAILED) dropped; put_row
    rewrites it atomically after every row."""
    table = Table.read(path, "error_map", list(COLUMNS), key=KEY)
    table.rows = [r for r in table.rows if r.get("status") != FAILED]
    return table


def is_current(table: Table, key: tuple, source_hash: str, reference_hash: str) -> bool:
    """`table` has a row of `key` (model, resolution label, scene) made from this source, against this
    reference, under RULES_VERSION."""
    return any(table.key_of(r) == tuple(key) and r.get("source_hash") == source_hash
               and r.get("reference_hash") == reference_hash and r.get("rules_version") == RULES_VERSION
               for r in table.rows)


def put_row(table: Table, row: dict) -> bool:
    """`row`, under RULES_VERSION, in place of the table's row of its key; False, and nothing
    written, for a failed run (status FAILED): the table keeps what it had for that key."""
    if row.get("status") == FAILED:
        return False
    table.put({**row, "rules_version": RULES_VERSION})
    return True


def set_role(table: Table, scene: str, role: str) -> None:
    """The role column of a scene's rows (rows written before the column existed have none); the
    file rewritten only where a role changes."""
    if any(r["scene"] == scene and r.get("role") != role for r in table.rows):
        for r in table.rows:
            if r["scene"] == scene:
                r["role"] = role
        table.write()


# ------------------------------------------------------------------------------------ what a row says
_f = finite_float


def within(row: dict, tolerance: float, quantities=QUANTITIES) -> bool:
    """The row's error plus reference error bar is at most `tolerance` on every quantity."""
    return all(_f(row.get(f"{q}_bound")) is not None and _f(row[f"{q}_bound"]) <= tolerance for q in quantities)


def cheapest_within(rows: list[dict], tolerance: float, quantities=QUANTITIES, runnable_only: bool = False):
    """The row of least wall time within `tolerance` on `quantities` (None if none is)."""
    ok = [r for r in rows if within(r, tolerance, quantities) and _f(r.get("wall_time_s")) is not None
          and not (runnable_only and r["model"] == "fem")]
    return min(ok, key=lambda r: _f(r["wall_time_s"]), default=None)


def combined_error(row: dict) -> float | None:
    """The largest error + reference error bar over the three quantities (None if one is missing)."""
    values = [_f(row.get(f"{q}_bound")) for q in QUANTITIES]
    return None if any(v is None for v in values) else max(values)
