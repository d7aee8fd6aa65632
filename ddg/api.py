"""Python API: ddg.simulate(strip, protocol, model="rod") mirrors `python -m ddg simulate`."""
from __future__ import annotations

import platform
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import scipy

from .geometry.strip import InputError, LoadingProtocol, Strip
from .io import write_path_csv, write_summary_json
from .observables import observe
from .solve.continuation import ContinuationFailure, ContinuationOptions, PathFollower

DEFAULT_RESOLUTION = {"rod": 100, "plate": 2000}


def _model_class(name: str):
    from .models.plate import PlateModel
    from .models.rod import RodModel

    models = {"rod": RodModel, "plate": PlateModel}
    if name not in models:
        raise InputError(f"model = {name!r} is not available; choose one of {sorted(models)}")
    return models[name]


@dataclass
class SimulationResult:
    rows: list[dict]
    summary: dict
    final_state: object = None
    model: object = None

    @property
    def converged(self) -> bool:
        return bool(self.summary["converged"])

    def column(self, name: str, stage: str | None = None) -> np.ndarray:
        rows = self.rows if stage is None else [r for r in self.rows if r["stage"] == stage]
        return np.array([r[name] for r in rows])

    def write(self, out: str | Path) -> None:
        out = Path(out)
        write_path_csv(out / "path.csv", self.rows)
        write_summary_json(out / "summary.json", self.summary)


class _Progress:
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
            "clamp_convention": "clamped edges straddle the clamp points; free length exactly L",
        },
        "H_mid_over_L_compressed": None,
        "dW_max_over_L": strip.shear_limit(protocol.compression_ratio * L) / L,
        "dW1_over_L": None,
        "dW2_over_L": None,
        "n_dof": model.n_dof,
        "n_free_dof": int(np.arange(model.n_dof)[model.free].size),
        "newton_iterations": 0,
        "wall_time_s": None,
        "converged": False,
        "message": "",
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
) -> SimulationResult:
    """Run the two-stage protocol (compress by dL, then shear by dW) on one model.

    solver="static" (default): Newton continuation of equilibria; solver="dynamic": the
    paper's implicit-Euler time marching (Eq. 7) with the clamp moved at a finite speed
    (rod only; see ddg.solve.dynamics). Returns every recorded equilibrium (rows of
    path.csv) and the summary; writes both to `out` if given, also when the run stops early
    (the converged part of the path is kept).
    """
    if solver not in ("static", "dynamic"):
        raise InputError(f"solver = {solver!r} is not available; choose 'static' or 'dynamic'")
    if solver == "dynamic":
        if model != "rod":
            raise InputError(f"solver = 'dynamic' is available for model 'rod' only, not {model!r}")
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
    cls = _model_class(model)
    resolution = DEFAULT_RESOLUTION[model] if resolution is None else resolution
    shear_ratio = protocol.resolved_shear_ratio(strip)
    instance = cls(strip, resolution)
    options = options or ContinuationOptions()
    follower = PathFollower(instance, options)
    L = strip.length
    dL = protocol.compression_ratio * L
    dW = protocol.shear_sign * shear_ratio * L

    rows: list[dict] = []
    progress_bar = _Progress(protocol.compression_steps + protocol.shear_steps + 1, progress)
    summary = base_summary(model, strip, protocol, resolution, instance)
    t0 = time.perf_counter()
    state = None

    def record(stage):
        row = observe(instance, state, stage, options.eigenvalues)
        rows.append(row)
        progress_bar.update(f"{stage} dL/L={row['dL_over_L']:.4f} dW/L={row['dW_over_L']:.4f}")

    try:
        state = follower.rest()
        record("compression")
        for k in range(1, protocol.compression_steps + 1):
            target = dL * k / protocol.compression_steps
            state = follower.start_compression(target) if k == 1 else follower.advance(state, target, 0.0)
            record("compression")
        summary["H_mid_over_L_compressed"] = rows[-1]["H_mid_over_L"]
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
        summary["newton_iterations"] = follower.newton_iterations
        summary["wall_time_s"] = time.perf_counter() - t0
        summary["recorded_steps"] = len(rows)
        result = SimulationResult(rows, summary, state, instance)
        if out is not None:
            result.write(out)
    return result
