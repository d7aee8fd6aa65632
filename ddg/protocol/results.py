"""A run's result: the recorded rows (path.csv), summary.json and the per-row centerlines.

Every model writes the same files with the same keys (the output contract, docs/reference/output_contract.rst);
base_summary lists every key a run's summary.json has before the run starts, and
finish_summary sets its status, converged flag and message when it ends.
"""
from __future__ import annotations

import platform
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import scipy

from ..analysis.observables import resolved_up_to
from ..geometry.strip import LoadingProtocol, Strip
from ..output.interrupts import signal_name_of
from ..solve.blas_threads import describe as describe_blas_threads
from ..solve.thresholds import THRESHOLD_TOLERANCES
from ..output.io import (STATUS_COMPLETE, STATUS_INTERRUPTED, STATUS_STOPPED, PathTable, write_centerline_csv,
                         write_path_csv, write_summary_json)
from ..version import __version__


@dataclass
class SimulationResult(PathTable):
    """What ddg.simulate returns: the run's recorded path and summary, as written to its folder.

    rows: one dict per recorded equilibrium, the columns of path.csv (PathTable.column lists
    them; normalised: dW/L, H_mid/L, F L/(E b^3)); summary: summary.json as a dict (thresholds
    dW1_over_L, dW2_over_L, status, converged, message, warnings, ... docs/reference/output_contract.rst);
    final_state: the last converged ddg.solve.state.State (SI units: q in m and rad); model: the
    model object (its positions(q), midpoint(q), ...); centerlines: per row the (stations, 3)
    positions of the centreline w = 0 (m); branch_rows: the rows of branches.csv (every branch,
    stable or not), when traced. `column(name, stage)`, `arrays()` and `to_dataframe()` read the
    rows (PathTable); `converged` is summary["converged"]; `write(out)` writes the files."""
    rows: list[dict]
    summary: dict
    final_state: object = None
    model: object = None
    centerlines: list = field(default_factory=list)  # per recorded row: (stations, 3) positions of w = 0
    branch_rows: list = field(default_factory=list)  # rows of branches.csv (every branch, stable or not)

    @property
    def converged(self) -> bool:
        """The loading path reached its end with every step converged (summary["converged"])."""
        return bool(self.summary["converged"])

    def write(self, out: str | Path) -> None:
        out = Path(out)
        write_path_csv(out / "path.csv", self.rows)
        if self.centerlines:
            write_centerline_csv(out / "centerline.csv", self.rows, self.centerlines, self.strip_length)
        if self.branch_rows:
            write_path_csv(out / "branches.csv", self.branch_rows, leading=("branch",))
        write_summary_json(out / "summary.json", self.summary)

    @property
    def strip_length(self) -> float:
        return float(self.summary["scene"]["length"])


@dataclass
class RibbonResult(SimulationResult):
    """A ribbon run; for init="rod" also the rod's own rows (written to rod_path.csv)."""
    rod_rows: list = field(default_factory=list)

    def write(self, out) -> None:
        super().write(out)
        if self.rod_rows:
            write_path_csv(Path(out) / "rod_path.csv", self.rod_rows)


@dataclass
class DynamicResult(SimulationResult):
    """SimulationResult plus, per recorded row, the time, kinetic energy and static residual."""

    trace: list = field(default_factory=list)


def versions() -> dict:
    return {"ddg": __version__, "python": platform.python_version(), "numpy": np.__version__,
            "scipy": scipy.__version__}


def base_summary(model_name: str, strip: Strip, protocol: LoadingProtocol, resolution: int, model) -> dict:
    """summary.json before the run: every contract key, inputs with defaults resolved."""
    L = strip.length
    return {
        "model": model_name,
        "scene": {
            **strip.as_dict(),
            **protocol.as_dict(strip),
            "resolution": resolution,
            "clamp_convention": "clamped edges (rod) / the two clamped node columns (plate) straddle the clamp "
                                "points; free length exactly L",
        },
        "H_mid_over_L_compressed": None,
        "dW_max_over_L": strip.shear_limit(protocol.compression_ratio * L) / L,
        "dW1_over_L": None,
        "dW2_over_L": None,
        "dW2_S_stable_over_L": None,
        "dW2_located_by": None,   # "fold" or "bisection" (ddg.solve.thresholds)
        "threshold_wall_time_s": None,
        "threshold_tolerances_over_L": {"dW1": THRESHOLD_TOLERANCES[0], "dW2": THRESHOLD_TOLERANCES[1]},
        "threshold_newton_iterations": None,
        "branches": None,
        "branches_wall_time_s": None,
        "folds_dW_over_L": [],
        "n_dof": model.n_dof,
        "n_free_dof": int(np.arange(model.n_dof)[model.free].size),
        "newton_iterations": 0,
        "newton_iterations_by_phase": None,
        "blas_threads": describe_blas_threads(),   # what the run's BLAS uses (ddg.solve.blas_threads)
        "wall_time_s": None,
        "converged": False,
        "message": "",
        "status": "running",
        "path_complete": False,
        "warnings": [],
        "unresolved_thresholds": {},
        "mesh": model.mesh.as_dict() if hasattr(model, "mesh") else None,
        # the mid-edge plate's membrane discretisation ("psri" and its alpha, or "full"); null for the others
        "membrane": {"discretisation": model.membrane, "alpha": model.membrane_alpha}
        if hasattr(model, "membrane_alpha") else None,
        "lambda_min_normalisation": "lowest eigenvalue of K v = lambda D v (lumped metric D), times L^4 / EI2",
        "versions": versions(),
    }


def finish_summary(summary: dict, rows: list[dict], *, path_complete: bool, stopped: str | None,
                   interrupted: BaseException | None, stage: str, error: BaseException | None = None) -> None:
    """status, converged and message of a run that ended (the driver calls this for every model).

    path_complete: the loading path reached its end; stopped: the stepper's failure message if
    it did not; interrupted: the KeyboardInterrupt (SIGINT/SIGTERM) that stopped the run, in
    `stage`; error: an unexpected exception (a bug or a resource failure), re-raised after the
    files are written."""
    summary["path_complete"] = bool(path_complete)
    summary["recorded_steps"] = len(rows)
    summary["resolved_up_to_dW_over_L"] = resolved_up_to(rows)
    kept = f"{len(rows)} converged steps written" if rows else "no step had converged"
    if error is not None:
        summary.update(status="error", converged=False,
                       message=f"internal error during {stage}: {type(error).__name__}: {error}; {kept}")
    elif interrupted is not None:
        what = "the path is complete; " if path_complete else ""
        summary.update(status=STATUS_INTERRUPTED, converged=False,
                       message=f"interrupted by {signal_name_of(interrupted)} during {stage}; {what}{kept}")
    elif stopped is not None:
        summary.update(status=STATUS_STOPPED, converged=False, message=stopped)
    else:
        summary.update(status=STATUS_COMPLETE, converged=True, message="path complete")
