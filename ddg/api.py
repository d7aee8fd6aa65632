"""Python API: ddg.simulate(strip, protocol, model="rod") mirrors `python -m ddg simulate`."""
from __future__ import annotations

import os
import platform
import sys
import time
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
import scipy

from .geometry.strip import InputError, LoadingProtocol, Strip
from .output.io import write_centerline_csv, write_path_csv, write_summary_json
from .analysis.observables import observe, resolved_up_to
from .solve.continuation import ContinuationFailure, ContinuationOptions, PathFollower
from .solve.state import Snapshot

DEFAULT_RESOLUTION = {"rod": 100, "plate": 2000, "ribbon": 101}  # ribbon: M not a multiple of 4, see RibbonModel


#: Stations along the centerline exported per recorded step (centerline.csv).
CENTERLINE_STATIONS = 101


def make_model(name: str, strip: Strip, resolution: int | None = None, mesh=None):
    """The model `name` of the strip at `resolution` (rod: nodes M; plate: target triangles).

    mesh (plate only): a PlateMesh, the path of a mesh file meshio reads, or "gmsh" for an
    unstructured gmsh mesh with about `resolution` triangles; default the structured mesh.
    """
    cls = _model_class(name)
    resolution = check_resolution(name, resolution)
    if mesh is None:
        return cls(strip, resolution)
    if name != "plate":
        raise InputError(f"a mesh is used by the plate model only, not {name!r}")
    from .geometry.plate_mesh import PlateMesh

    if not isinstance(mesh, (PlateMesh, str, os.PathLike)) or isinstance(mesh, bool):
        raise InputError(f"mesh = {mesh!r} must be a PlateMesh, a mesh file path or 'gmsh'")
    if not isinstance(mesh, PlateMesh):
        from .geometry import mesh_io

        if str(mesh) == "gmsh":
            mesh = mesh_io.gmsh_mesh(strip.length, strip.width, resolution)
        else:
            mesh = mesh_io.read_mesh(mesh, strip.length, strip.width)
    return cls(strip, mesh=mesh)


def _frame_writer(model, directory: Path):
    from .output.frames import FrameWriter, polyline_cells

    if hasattr(model, "mesh"):
        return FrameWriter(directory, model.mesh)
    return FrameWriter(directory, polyline_cells(model.nodes), reference=model.rest_state()[model.node_dofs])


def _model_class(name: str):
    from .models.plate import PlateModel
    from .models.ribbon import RibbonModel
    from .models.rod import RodModel

    models = {"rod": RodModel, "plate": PlateModel, "ribbon": RibbonModel}
    return models[check_model_name(name)]


@dataclass
class SimulationResult:
    rows: list[dict]
    summary: dict
    final_state: object = None
    model: object = None
    centerlines: list = field(default_factory=list)  # per recorded row: (stations, 3) positions of w = 0
    branch_rows: list = field(default_factory=list)  # rows of branches.csv (every branch, stable or not)

    @property
    def converged(self) -> bool:
        return bool(self.summary["converged"])

    def column(self, name: str, stage: str | None = None) -> np.ndarray:
        rows = self.rows if stage is None else [r for r in self.rows if r["stage"] == stage]
        return np.array([r[name] for r in rows])

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


class ProgressBar:
    """A one-line progress bar on stderr when it is a terminal."""

    def __init__(self, total: int, enabled: bool):
        self.total, self.count = total, 0
        self.enabled = enabled and sys.stderr.isatty()

    def update(self, text: str) -> None:
        self.count += 1
        if self.enabled:
            frac = self.count / self.total
            bar = "#" * int(30 * frac)
            sys.stderr.write(f"\r[{bar:<30}] {100 * frac:5.1f}% {text}   ")
            sys.stderr.flush()

    def close(self) -> None:
        if self.enabled:
            sys.stderr.write("\n")


def track_brackets(brackets: dict, model, state, phase: str) -> None:
    """Remember the recorded states that bracket the phase changes U -> US and US -> S."""
    if phase == "U" and brackets["first_us"] is None:
        brackets["last_u"] = Snapshot.take(model, state)
    elif phase.startswith("US"):
        if brackets["first_us"] is None and brackets["last_u"] is not None:
            brackets["first_us"] = state.shear
        if brackets["first_s"] is None:
            brackets["last_us"] = Snapshot.take(model, state)
    elif phase.startswith("S") and brackets["first_s"] is None and brackets["last_us"] is not None:
        brackets["first_s"] = Snapshot.take(model, state)


def fill_thresholds(summary: dict, model, options, brackets: dict) -> None:
    from .solve.thresholds import shear_thresholds

    t0 = time.perf_counter()
    found = shear_thresholds(model, options, brackets["last_u"], brackets["first_us"], brackets["last_us"],
                             brackets["first_s"])
    L = model.strip.length
    for key, name in (("dW1", "dW1_over_L"), ("dW2", "dW2_over_L"), ("dW2_S_stable", "dW2_S_stable_over_L")):
        summary[name] = None if found[key] is None else abs(found[key]) / L
    summary["threshold_wall_time_s"] = time.perf_counter() - t0
    summary["threshold_newton_iterations"] = found["newton_iterations"]


THRESHOLD_KEYS = ("dW1_over_L", "dW2_over_L", "dW2_S_stable_over_L")


def check_thresholds_resolved(summary: dict, rows: list[dict]) -> None:
    """Null every threshold located from states the discretisation does not resolve
    (ddg.analysis.observables.unresolved_reason); its value and the reason go to
    `unresolved_thresholds`, a line to `warnings`. No threshold is printed from such a state."""
    from .analysis.observables import unresolved_reason

    for key in THRESHOLD_KEYS:
        value = summary.get(key)
        if value is None:
            continue
        reason = unresolved_reason(rows, value)
        if reason is not None:
            summary[key] = None
            summary["unresolved_thresholds"][key] = {"value": value, "reason": reason}
            summary["warnings"].append(f"{key} = {value:.4g} not reported (unresolved): {reason}")


def trace_all_branches(summary: dict, model, options, compressed, shear_max: float, brackets: dict) -> list[dict]:
    """Every branch of the shear stage by pseudo-arclength (ddg.solve.branches); its rows."""
    from .solve.branches import trace_branches

    t0 = time.perf_counter()
    saved = model.save_frames()
    try:
        diagram = trace_branches(model, options, compressed, shear_max, brackets["first_s"])
    finally:
        model.restore_frames(saved)
    summary["branches"] = diagram.summary(model.strip.length)
    summary["branches_newton_iterations"] = diagram.newton_iterations
    summary["branches_wall_time_s"] = time.perf_counter() - t0
    return [{"branch": b.name, **observe(model, s, "shear", True)} for b in diagram.branches for s in b.states]


def _distinct(values: list[float], tolerance: float) -> list[float]:
    """values without the ones within tolerance of an earlier one (a fold met by several substeps)."""
    out: list[float] = []
    for v in values:
        if all(abs(v - w) > tolerance for w in out):
            out.append(v)
    return out


def versions() -> dict:
    from . import __version__

    return {"ddg": __version__, "python": platform.python_version(), "numpy": np.__version__, "scipy": scipy.__version__}


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
        "threshold_wall_time_s": None,
        "threshold_newton_iterations": None,
        "branches": None,
        "branches_wall_time_s": None,
        "folds_dW_over_L": [],
        "n_dof": model.n_dof,
        "n_free_dof": int(np.arange(model.n_dof)[model.free].size),
        "newton_iterations": 0,
        "newton_iterations_by_phase": None,
        "wall_time_s": None,
        "converged": False,
        "message": "",
        "status": "running",
        "path_complete": False,
        "warnings": [],
        "unresolved_thresholds": {},
        "mesh": model.mesh.as_dict() if hasattr(model, "mesh") else None,
        "lambda_min_normalisation": "lowest eigenvalue of K v = lambda D v (lumped metric D), times L^4 / EI2",
        "versions": versions(),
    }


def check_model_name(model) -> str:
    """model as one of the available names (a one-line InputError otherwise)."""
    if not isinstance(model, str) or model not in DEFAULT_RESOLUTION:
        raise InputError(f"model = {model!r} is not available; choose one of {sorted(DEFAULT_RESOLUTION)}")
    return model


def check_resolution(model: str, resolution, strip: Strip | None = None, mesh=None) -> int:
    """The resolution of `model` within what the model needs and the machine can run.

    rod, ribbon: node count M in [MIN_NODES, MAX_NODES]; plate: target triangle count in
    [16, MAX_TRIANGLES], its memory estimated (ddg.geometry.plate_mesh) and compared with the
    memory available (ddg.limits.check_memory)."""
    from .geometry.centerline import MIN_NODES
    from .limits import check_integer

    check_model_name(model)
    if resolution is None:
        return DEFAULT_RESOLUTION[model]
    if model in ("rod", "ribbon"):
        return check_integer("resolution (node count M)", resolution, MIN_NODES, MAX_NODES,
                             "M = 200 already resolves the thresholds to 1e-4 L")
    value = check_integer("resolution (target triangle count)", resolution, 16, MAX_TRIANGLES)
    if strip is not None and (mesh is None or str(mesh) == "gmsh"):
        from .geometry import plate_mesh
        from .limits import check_memory

        estimate = getattr(plate_mesh, "plate_memory_estimate_bytes", None)
        if estimate is not None:
            check_memory("resolution (target triangle count)", value, estimate(strip.length, strip.width, value))
    return value


#: Largest rod/ribbon node count: the error of the thresholds is ~1.8 / M^2 (dW1/L: 0.0044 at
#: M = 20, 0.0020 at 30, 0.0006 at 50, measured); 5000 nodes cost ~40 s per path and gain nothing.
MAX_NODES = 5000
#: Largest plate triangle count accepted before the memory estimate is even consulted.
MAX_TRIANGLES = 1_000_000


def finish_summary(summary: dict, rows: list[dict], *, path_complete: bool, stopped: str | None,
                   interrupted: BaseException | None, stage: str, error: BaseException | None = None) -> None:
    """status, converged and message of a run that ended (every model's loop calls this).

    path_complete: the loading path reached its end; stopped: the ContinuationFailure message if
    it did not; interrupted: the KeyboardInterrupt (SIGINT/SIGTERM) that stopped the run, in
    `stage`; error: an unexpected exception."""
    from .output.interrupts import signal_name_of
    from .output.io import STATUS_COMPLETE, STATUS_INTERRUPTED, STATUS_STOPPED

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


def conclude_run(folder, result, interrupted: BaseException | None, error: BaseException | None):
    """Write the result's files into its folder (atomically, signals held) and return it; an
    interruption or an unexpected error is re-raised after that, with the result as exc.result."""
    if folder is not None:
        folder.finish(result)
    if interrupted is not None or error is not None:
        raised = interrupted if interrupted is not None else error
        raised.result = result
        raise raised
    return result


def open_run_folder(out, summary: dict, trailing: tuple[str, ...] = ()):
    """The RunFolder of `out` (None if out is None), marked in progress with this summary."""
    if out is None:
        return None
    from .output.io import RunFolder

    return RunFolder(out, summary, trailing=trailing)


def simulate(
    strip: Strip,
    protocol: LoadingProtocol,
    model: str = "rod",
    resolution: int | None = None,
    out: str | Path | None = None,
    options: ContinuationOptions | None = None,
    progress: bool = False,
    solver: str = "static",
    dynamic_options=None,
    mesh=None,
    frames: bool = False,
    thresholds: bool = True,
    branches: bool | None = None,
) -> SimulationResult:
    """Run the two-stage protocol (compress by dL, then shear by dW) on one model.

    solver="static" (default): Newton continuation of equilibria; solver="dynamic": the
    paper's implicit-Euler time marching (Eq. 7) with the clamp moved at a finite speed
    (rod only; see ddg.solve.dynamics). Returns every recorded equilibrium (rows of
    path.csv), the summary and the deformed centerline (w = 0) per row; writes them to `out`
    (path.csv, summary.json, centerline.csv) if given. `out` is checked writable before any
    work; from the start summary.json says status "running" and path.csv grows by one row per
    recorded step, so a killed run keeps every converged step and is never mistaken for a
    finished one. A run that stops converging keeps the converged part (status "stopped");
    Ctrl-C or SIGTERM (KeyboardInterrupt) writes what was computed (status "interrupted"),
    then re-raises with the result attached as `exc.result`.
    frames=True also writes out/frames/frame_NNNNN.vtu per
    recorded step and out/frames/frames.pvd (ParaView). mesh: see make_model. thresholds=True
    locates dW1 and dW2 from stability after the path (ddg.solve.thresholds; summary keys
    dW1_over_L, dW2_over_L, dW2_S_stable_over_L) when the recorded path brackets them; a
    threshold whose states the discretisation does not resolve is reported null, with its
    value and the reason under `unresolved_thresholds` and in `warnings`.
    branches=True (with thresholds; default None: True for the rod, False for the plate, whose
    diagram costs more than its path, 440 s against 265 s at 2000 triangles) then traces every branch of the shear stage by
    pseudo-arclength continuation, stable and unstable parts, through folds (U, US+, US-, and
    S from the first S state of the path; ddg.solve.branches): rows in result.branch_rows and
    out/branches.csv (path.csv's columns after a `branch` column), per-branch summary under
    the summary key `branches`.
    """
    if not isinstance(strip, Strip):
        raise InputError(f"strip = {strip!r} must be a ddg.Strip")
    if not isinstance(protocol, LoadingProtocol):
        raise InputError(f"protocol = {protocol!r} must be a ddg.LoadingProtocol")
    if not isinstance(solver, str) or solver not in ("static", "dynamic"):
        raise InputError(f"solver = {solver!r} is not available; choose 'static' or 'dynamic'")
    check_model_name(model)
    if options is not None and not isinstance(options, ContinuationOptions):
        raise InputError(f"options = {options!r} must be a ddg.ContinuationOptions")
    for name, value in (("progress", progress), ("frames", frames), ("thresholds", thresholds)):
        if not isinstance(value, (bool, np.bool_)):
            raise InputError(f"{name} = {value!r} must be True or False")
    if branches is not None and not isinstance(branches, (bool, np.bool_)):
        raise InputError(f"branches = {branches!r} must be True, False or None")
    resolution = check_resolution(model, resolution, strip, mesh)
    shear_ratio = protocol.resolved_shear_ratio(strip)
    if out is not None:
        from .output.io import check_output_directory

        check_output_directory(out)
    if solver == "dynamic":
        if model != "rod":
            raise InputError(f"solver = 'dynamic' is available for model 'rod' only, not {model!r}")
        if frames or mesh is not None:
            raise InputError("frames and mesh are options of the static solver; drop them or use solver='static'")
        from .solve.dynamics import simulate_dynamic

        return simulate_dynamic(strip, protocol, resolution, dynamic_options, out=out)
    if dynamic_options is not None:
        raise InputError("dynamic_options apply to solver='dynamic' only")
    branches = (model != "plate") if branches is None else bool(branches)
    instance = make_model(model, strip, resolution, mesh)
    if frames and out is None:
        raise InputError("frames=True needs an output directory (out)")
    options = replace(options) if options is not None else ContinuationOptions()  # re-validated
    follower = PathFollower(instance, options)
    L = strip.length
    dL = protocol.compression_ratio * L
    dW = protocol.shear_sign * shear_ratio * L

    rows: list[dict] = []
    centerlines: list[np.ndarray] = []
    summary = base_summary(model, strip, protocol, resolution, instance)
    folder = open_run_folder(out, summary)
    writer = _frame_writer(instance, Path(out) / "frames") if frames else None
    progress_bar = ProgressBar(protocol.compression_steps + protocol.shear_steps + 1, progress)
    t0 = time.perf_counter()
    state = None

    brackets = {"last_u": None, "first_us": None, "last_us": None, "first_s": None}
    compressed = None
    branch_rows: list[dict] = []

    def record(stage):
        row = observe(instance, state, stage, options.eigenvalues)
        rows.append(row)
        if folder is not None:
            folder.append(row)
        if stage == "shear" and thresholds:
            track_brackets(brackets, instance, state, row["phase"])
        centerlines.append(instance.centerline_positions(state.q, CENTERLINE_STATIONS)[0])
        if writer is not None:
            writer.write(instance.positions(state.q), step=len(rows) - 1, dL_over_L=row["dL_over_L"],
                         dW_over_L=row["dW_over_L"], stage=stage)
        progress_bar.update(f"{stage} dL/L={row['dL_over_L']:.4f} dW/L={row['dW_over_L']:.4f}")

    stage, stopped, interrupted, error, path_complete = "compression", None, None, None, False
    try:
        state = follower.rest()
        record("compression")
        for k in range(1, protocol.compression_steps + 1):
            target = dL * k / protocol.compression_steps
            state = follower.start_compression(target) if k == 1 else follower.advance(state, target, 0.0)
            record("compression")
        summary["H_mid_over_L_compressed"] = rows[-1]["H_mid_over_L"]
        compressed = Snapshot.take(instance, state)
        if folder is not None:
            folder.checkpoint({**summary, "message": "running: compression complete, shearing"})
        stage = "shear"
        for k in range(1, protocol.shear_steps + 1 if dW != 0.0 else 1):
            state = follower.advance(state, dL, dW * k / protocol.shear_steps)
            record("shear")
        path_complete = True
    except ContinuationFailure as exc:
        stopped = str(exc)
    except KeyboardInterrupt as exc:
        interrupted = exc
    except Exception as exc:  # noqa: BLE001  (written as status "error", then re-raised)
        error = exc
    progress_bar.close()
    try:
        if interrupted is None and error is None and thresholds and options.eigenvalues and state is not None:
            if folder is not None:
                folder.checkpoint({**summary, "message": "running: path done, locating thresholds"})
            stage = "threshold location"
            fill_thresholds(summary, instance, options, brackets)
            check_thresholds_resolved(summary, rows)
            if branches and compressed is not None and dW != 0.0:
                stage = "branch tracing"
                if folder is not None:
                    folder.checkpoint({**summary, "message": "running: thresholds located, tracing branches"})
                branch_rows = trace_all_branches(summary, instance, options, compressed, dW, brackets)
    except KeyboardInterrupt as exc:
        interrupted = exc
    except Exception as exc:  # noqa: BLE001
        error = exc
    summary["newton_iterations"] = follower.newton_iterations
    summary["newton_iterations_by_phase"] = follower.iteration_breakdown()
    summary["folds_dW_over_L"] = _distinct([abs(f) / L for f in follower.folds], 1e-4)
    summary["wall_time_s"] = time.perf_counter() - t0
    finish_summary(summary, rows, path_complete=path_complete, stopped=stopped, interrupted=interrupted,
                   stage=stage, error=error)
    if writer is not None:
        writer.close()
    result = SimulationResult(rows, summary, state, instance, centerlines, branch_rows)
    return conclude_run(folder, result, interrupted, error)
