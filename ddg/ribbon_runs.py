"""The two ways of running the discrete Sadowsky ribbon (paper Appendix A, Fig. A.11).

- "direct" (the paper's Direct-Sadowsky): the ribbon itself is followed from the flat strip
  through compression and shear by the same continuation as the rod (ddg.solve.continuation,
  branch switching and stability checks included).
- "rod" (the paper's DAR-Sadowsky): the rod (DAR) is followed along its own stable path; at each
  recorded step its converged state (DOFs and reference frames, which the two models share)
  starts an energy descent under the ribbon's energy (Eq. A.5).

`pitchfork_analysis` explains why the direct ribbon misses dW1: the ribbon's lambda_min at the
rod's pitchfork, and the energy barrier between the ribbon's U state and the US state reached
from the rod, concentrated in the quartic twist term at the inflection points.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field, replace
from pathlib import Path


from .api import (CENTERLINE_STATIONS, SimulationResult, base_summary, check_resolution, check_thresholds_resolved,
                  conclude_run,
                  fill_thresholds, finish_summary, open_run_folder, ProgressBar, track_brackets)
from .geometry.strip import InputError, LoadingProtocol, Strip
from .output.io import write_path_csv
from .models.ribbon import RIBBON_INITS, RibbonModel
from .models.rod import RodModel
from .analysis.observables import observe
from .solve.continuation import ContinuationFailure, ContinuationOptions, PathFollower, relax_from



@dataclass
class RibbonResult(SimulationResult):
    """A ribbon run; for init="rod" also the rod's own rows (written to rod_path.csv)."""
    rod_rows: list = field(default_factory=list)

    def write(self, out) -> None:
        super().write(out)
        if self.rod_rows:
            write_path_csv(Path(out) / "rod_path.csv", self.rod_rows)


def run_ribbon(strip: Strip, protocol: LoadingProtocol, init: str = "direct", zeta: float | None = None,
               resolution: int | None = None, out=None, options: ContinuationOptions | None = None,
               thresholds: bool = True, progress: bool = False) -> RibbonResult:
    """The ribbon (Eq. A.5) through the two-stage protocol, started "direct" or from the "rod".

    Rows, summary and centerlines as ddg.simulate (path.csv, summary.json, centerline.csv);
    summary adds ribbon_init, zeta, zeta_over_L. init="direct" locates dW1 from the ribbon's own
    stability where its path leaves U (None if it never does); init="rod" reports the rod's
    thresholds as rod_dW1_over_L, rod_dW2_over_L and writes the rod's rows to rod_path.csv.
    """
    if init not in RIBBON_INITS:
        raise InputError(f"ribbon init = {init!r} is not available; choose one of {list(RIBBON_INITS)}")
    if not isinstance(strip, Strip) or not isinstance(protocol, LoadingProtocol):
        raise InputError("run_ribbon needs a ddg.Strip and a ddg.LoadingProtocol")
    resolution = check_resolution("ribbon", resolution)
    if out is not None:
        from .output.io import check_output_directory

        check_output_directory(out)
    if options is not None and not isinstance(options, ContinuationOptions):
        raise InputError(f"options = {options!r} must be a ddg.ContinuationOptions")
    options = replace(options) if options is not None else ContinuationOptions()  # re-validated
    ribbon = RibbonModel(strip, resolution, zeta=zeta)
    rod = RodModel(strip, resolution) if init == "rod" else None
    driver = rod if rod is not None else ribbon
    follower = PathFollower(driver, options)
    L = strip.length
    dL = protocol.compression_ratio * L
    dW = protocol.shear_sign * protocol.resolved_shear_ratio(strip) * L
    summary = base_summary("ribbon", strip, protocol, resolution, ribbon)
    summary.update(ribbon_init=init, zeta=ribbon.zeta, zeta_over_L=ribbon.zeta / L)
    folder = open_run_folder(out, summary)
    rows, rod_rows, centerlines = [], [], []
    brackets = {"last_u": None, "first_us": None, "last_us": None, "first_s": None}
    bar = ProgressBar(protocol.compression_steps + protocol.shear_steps + 1, progress)
    relax_iterations = 0
    t0 = time.perf_counter()
    state = None

    def record(stage, driven):
        nonlocal state, relax_iterations
        if rod is not None:
            rod_rows.append(observe(rod, driven, stage, options.eigenvalues))
            if stage == "shear" and thresholds:
                track_brackets(brackets, rod, driven, rod_rows[-1]["phase"])
            state = relax_from(ribbon, rod, driven, options)
            relax_iterations += state.iterations
        else:
            state = driven
        row = observe(ribbon, state, stage, options.eigenvalues)
        rows.append(row)
        if folder is not None:
            folder.append(row)
        if stage == "shear" and thresholds and rod is None:
            track_brackets(brackets, ribbon, state, row["phase"])
        centerlines.append(ribbon.centerline_positions(state.q, CENTERLINE_STATIONS)[0])
        bar.update(f"{stage} dL/L={row['dL_over_L']:.4f} dW/L={row['dW_over_L']:.4f}")

    driven = None
    stage, stopped, interrupted, error, path_complete = "compression", None, None, None, False
    try:
        driven = follower.rest()
        record("compression", driven)
        for k in range(1, protocol.compression_steps + 1):
            target = dL * k / protocol.compression_steps
            driven = follower.start_compression(target) if k == 1 else follower.advance(driven, target, 0.0)
            record("compression", driven)
        summary["H_mid_over_L_compressed"] = rows[-1]["H_mid_over_L"]
        stage = "shear"
        for k in range(1, protocol.shear_steps + 1 if dW != 0.0 else 1):
            driven = follower.advance(driven, dL, dW * k / protocol.shear_steps)
            record("shear", driven)
        path_complete = True
    except ContinuationFailure as exc:
        stopped = str(exc)
    except KeyboardInterrupt as exc:
        interrupted = exc
    except Exception as exc:  # noqa: BLE001  (written as status "error", then re-raised)
        error = exc
    bar.close()
    try:
        if interrupted is None and error is None and thresholds and options.eigenvalues and state is not None:
            stage = "threshold location"
            if rod is None:
                fill_thresholds(summary, ribbon, options, brackets)
                check_thresholds_resolved(summary, rows)
            else:
                rod_thresholds(summary, rod, options, brackets, rod_rows)
    except KeyboardInterrupt as exc:
        interrupted = exc
    except Exception as exc:  # noqa: BLE001
        error = exc
    summary["newton_iterations"] = follower.newton_iterations + relax_iterations
    summary["newton_iterations_by_phase"] = follower.iteration_breakdown()
    summary["wall_time_s"] = time.perf_counter() - t0
    finish_summary(summary, rows, path_complete=path_complete, stopped=stopped, interrupted=interrupted,
                   stage=stage, error=error)
    result = RibbonResult(rows, summary, state, ribbon, centerlines, rod_rows=rod_rows)
    return conclude_run(folder, result, interrupted, error)


def rod_thresholds(summary: dict, rod, options: ContinuationOptions, brackets: dict, rod_rows: list[dict]) -> None:
    """The thresholds of the rod that drove a rod-initialised ribbon run, located from the rod's
    stability as ddg.simulate does (summary keys rod_dW1_over_L, rod_dW2_over_L,
    rod_dW2_S_stable_over_L); the ribbon's own stay null: it follows the rod's branch choice."""
    found = {"warnings": [], "unresolved_thresholds": {}}
    fill_thresholds(found, rod, options, brackets)
    check_thresholds_resolved(found, rod_rows)
    for key in ("dW1_over_L", "dW2_over_L", "dW2_S_stable_over_L"):
        summary[f"rod_{key}"] = found[key]
    summary["threshold_wall_time_s"] = found["threshold_wall_time_s"]
    summary["threshold_newton_iterations"] = found["threshold_newton_iterations"]
    summary["warnings"].extend(f"rod: {w}" for w in found["warnings"])
