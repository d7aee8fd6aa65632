"""Python API: ddg.simulate(strip, protocol, model="rod") mirrors `python -m ddg simulate`."""
from __future__ import annotations

import platform
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import scipy

from .geometry.strip import InputError, LoadingProtocol, Strip
from .io import write_centerline_csv, write_path_csv, write_summary_json
from .observables import observe, resolved_up_to
from .solve.continuation import ContinuationFailure, ContinuationOptions, PathFollower

DEFAULT_RESOLUTION = {"rod": 100, "plate": 2000, "ribbon": 101}  # ribbon: M not a multiple of 4, see RibbonModel


#: Stations along the centerline exported per recorded step (centerline.csv).
CENTERLINE_STATIONS = 101


def make_model(name: str, strip: Strip, resolution: int | None = None, mesh=None):
    """The model `name` of the strip at `resolution` (rod: nodes M; plate: target triangles).

    mesh (plate only): a PlateMesh, the path of a mesh file meshio reads, or "gmsh" for an
    unstructured gmsh mesh with about `resolution` triangles; default the structured mesh.
    """
    cls = _model_class(name)
    resolution = DEFAULT_RESOLUTION[name] if resolution is None else resolution
    if mesh is None:
        return cls(strip, resolution)
    if name != "plate":
        raise InputError(f"a mesh is used by the plate model only, not {name!r}")
    from .geometry.plate_mesh import PlateMesh

    if not isinstance(mesh, PlateMesh):
        from .geometry import mesh_io

        if str(mesh) == "gmsh":
            mesh = mesh_io.gmsh_mesh(strip.length, strip.width, resolution)
        else:
            mesh = mesh_io.read_mesh(mesh, strip.length, strip.width)
    return cls(strip, mesh=mesh)


def _frame_writer(model, directory: Path):
    from .frames_output import FrameWriter, polyline_cells

    if hasattr(model, "mesh"):
        return FrameWriter(directory, model.mesh)
    return FrameWriter(directory, polyline_cells(model.nodes), reference=model.rest_state()[model.node_dofs])


def _model_class(name: str):
    from .models.plate import PlateModel
    from .models.ribbon import RibbonModel
    from .models.rod import RodModel

    models = {"rod": RodModel, "plate": PlateModel, "ribbon": RibbonModel}
    if name not in models:
        raise InputError(f"model = {name!r} is not available; choose one of {sorted(models)}")
    return models[name]


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
    from .solve.thresholds import Snapshot

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
    return diagram.rows()


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
        "branches": None,
        "branches_wall_time_s": None,
        "folds_dW_over_L": [],
        "n_dof": model.n_dof,
        "n_free_dof": int(np.arange(model.n_dof)[model.free].size),
        "newton_iterations": 0,
        "wall_time_s": None,
        "converged": False,
        "message": "",
        "mesh": model.mesh.as_dict() if hasattr(model, "mesh") else None,
        "lambda_min_normalisation": "lowest eigenvalue of K v = lambda D v (lumped metric D), times L^4 / EI2",
        "versions": versions(),
    }


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
    (path.csv, summary.json, centerline.csv) if given, also when the run stops early (the
    converged part of the path is kept). frames=True also writes out/frames/frame_NNNNN.vtu per
    recorded step and out/frames/frames.pvd (ParaView). mesh: see make_model. thresholds=True
    locates dW1 and dW2 from stability after the path (ddg.solve.thresholds; summary keys
    dW1_over_L, dW2_over_L, dW2_S_stable_over_L) when the recorded path brackets them.
    branches=True (with thresholds; default None: True for the rod, False for the plate, whose
    diagram costs more than its path, 440 s against 265 s at 2000 triangles) then traces every branch of the shear stage by
    pseudo-arclength continuation, stable and unstable parts, through folds (U, US+, US-, and
    S from the first S state of the path; ddg.solve.branches): rows in result.branch_rows and
    out/branches.csv (path.csv's columns after a `branch` column), per-branch summary under
    the summary key `branches`.
    """
    if solver not in ("static", "dynamic"):
        raise InputError(f"solver = {solver!r} is not available; choose 'static' or 'dynamic'")
    if solver == "dynamic":
        if model != "rod":
            raise InputError(f"solver = 'dynamic' is available for model 'rod' only, not {model!r}")
        if frames or mesh is not None:
            raise InputError("frames and mesh are options of the static solver; drop them or use solver='static'")
        from .solve.dynamics import simulate_dynamic

        result = simulate_dynamic(strip, protocol, DEFAULT_RESOLUTION["rod"] if resolution is None else resolution,
                                  dynamic_options)
        if out is not None:
            result.write(out)
        return result
    if not isinstance(strip, Strip):
        raise InputError(f"strip = {strip!r} must be a ddg.Strip")
    if not isinstance(protocol, LoadingProtocol):
        raise InputError(f"protocol = {protocol!r} must be a ddg.LoadingProtocol")
    resolution = DEFAULT_RESOLUTION.get(model) if resolution is None else resolution
    branches = (model != "plate") if branches is None else bool(branches)
    shear_ratio = protocol.resolved_shear_ratio(strip)
    instance = make_model(model, strip, resolution, mesh)
    if frames and out is None:
        raise InputError("frames=True needs an output directory (out)")
    writer = _frame_writer(instance, Path(out) / "frames") if frames else None
    options = options or ContinuationOptions()
    follower = PathFollower(instance, options)
    L = strip.length
    dL = protocol.compression_ratio * L
    dW = protocol.shear_sign * shear_ratio * L

    rows: list[dict] = []
    centerlines: list[np.ndarray] = []
    progress_bar = ProgressBar(protocol.compression_steps + protocol.shear_steps + 1, progress)
    summary = base_summary(model, strip, protocol, resolution, instance)
    t0 = time.perf_counter()
    state = None

    brackets = {"last_u": None, "first_us": None, "last_us": None, "first_s": None}
    compressed = None
    branch_rows: list[dict] = []

    def record(stage):
        row = observe(instance, state, stage, options.eigenvalues)
        rows.append(row)
        if stage == "shear" and thresholds:
            track_brackets(brackets, instance, state, row["phase"])
        centerlines.append(instance.centerline_positions(state.q, CENTERLINE_STATIONS)[0])
        if writer is not None:
            writer.write(instance.positions(state.q), step=len(rows) - 1, dL_over_L=row["dL_over_L"],
                         dW_over_L=row["dW_over_L"], stage=stage)
        progress_bar.update(f"{stage} dL/L={row['dL_over_L']:.4f} dW/L={row['dW_over_L']:.4f}")

    try:
        state = follower.rest()
        record("compression")
        for k in range(1, protocol.compression_steps + 1):
            target = dL * k / protocol.compression_steps
            state = follower.start_compression(target) if k == 1 else follower.advance(state, target, 0.0)
            record("compression")
        summary["H_mid_over_L_compressed"] = rows[-1]["H_mid_over_L"]
        from .solve.thresholds import Snapshot

        compressed = Snapshot.take(instance, state)
        for k in range(1, protocol.shear_steps + 1 if dW != 0.0 else 1):
            state = follower.advance(state, dL, dW * k / protocol.shear_steps)
            record("shear")
        summary["converged"] = True
        summary["message"] = "path complete"
    except ContinuationFailure as exc:
        summary["message"] = str(exc)
    except KeyboardInterrupt:
        summary["message"] = "interrupted"
        raise
    finally:
        progress_bar.close()
        if thresholds and options.eigenvalues and state is not None and summary["message"] != "interrupted":
            fill_thresholds(summary, instance, options, brackets)
            if branches and compressed is not None and dW != 0.0:
                branch_rows = trace_all_branches(summary, instance, options, compressed, dW, brackets)
        summary["newton_iterations"] = follower.newton_iterations
        summary["folds_dW_over_L"] = _distinct([abs(f) / L for f in follower.folds], 1e-4)
        summary["wall_time_s"] = time.perf_counter() - t0
        summary["recorded_steps"] = len(rows)
        summary["resolved_up_to_dW_over_L"] = resolved_up_to(rows)
        if writer is not None:
            writer.close()
        result = SimulationResult(rows, summary, state, instance, centerlines, branch_rows)
        if out is not None:
            result.write(out)
    return result
