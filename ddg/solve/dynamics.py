"""Implicit-Euler time marching of the rod (paper section 3.1, Eqs. 7-9), for comparison.

The paper reaches its quasi-static equilibria dynamically: lumped masses M (RodModel.mass),
first-order implicit Euler steps, viscous damping, and the clamp at s = L moved at 1 mm/s.
Here one step from (q_k, v_k) to t_{k+1} = t_k + dt minimises the incremental potential

    Phi(q) = E(q) + 1/(2 dt^2) (q - q_k - dt v_k)^T M (q - q_k - dt v_k) + c/(2 dt) (q - q_k)^T M (q - q_k)

over the free DOFs, with the clamped DOFs prescribed at their t_{k+1} values. Its stationarity
condition times dt^2 is Eq. (7a) with F_ext = -c M v_{k+1} (mass-proportional viscous damping
at rate c), its Hessian times dt^2 is the Jacobian of Eq. (9), and v_{k+1} = (q_{k+1} - q_k)/dt
is Eq. (7c). `IncrementalPotential` wraps a model with these terms, so the ordinary Newton
solver (ddg.solve.newton) performs each step; the twist angles are measured from reference
frames parallel-transported in time (the model's commit), as in the paper.

Outputs are those of ddg.simulate: rows recorded at the loads where the static solver
records (or every `record_interval` seconds), evaluated with the bare elastic energy, so
`energy`, the clamp forces, `lambda_min` and `stable` describe the elastic state that the
dynamics has reached; how far it is from equilibrium is in `DynamicResult.trace`.
"""
from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..api import SimulationResult, base_summary, conclude_run, finish_summary, open_run_folder
from ..geometry.strip import InputError, LoadingProtocol, Strip
from ..analysis.observables import observe
from .banded import SymmetricBanded
from .continuation import ContinuationFailure, ContinuationOptions, PathFollower
from .state import State
from .newton import NewtonOptions, newton, scaled_residual


@dataclass
class DynamicOptions:
    """Settings of the implicit-Euler option.

    clamp_speed (m/s): 1e-3, the paper's 1 mm/s in both stages (sections 4.1, 4.2).

    time_step (s): largest step, 0.01 s. At 1 mm/s the clamp moves 10 um per step, under 1 %
    of the rod spacing h = L/(M-2) (1.5 mm for the paper's L = 0.15 m at M = 100). The step is
    shortened so that every recorded load is reached exactly (an integer number of equal steps
    per recorded interval). Implicit Euler is unconditionally stable; the buckled strip's lowest
    frequencies are omega ~ 180-520 rad/s away from the thresholds (K v = omega^2 M v measured for
    W/L = 1/20, dL/L = 1/2, M = 100, over the whole shear path), so omega dt > 1 and the scheme
    dissipates elastic vibrations within a few steps: as in the paper it is a device for
    following quasi-static equilibria, not for resolving vibrations (use dt << 1/omega for that).

    damping (1/s): rate c of the viscous force -c M v, 20 1/s. Two conditions make the response
    quasi-static at 1 mm/s, and away from the thresholds this value meets both by orders of
    magnitude: (i) disturbances (the start of each stage, a snap past a bifurcation) must die
    out well before the next recorded load; the amplitude of a slow, lightly damped mode decays as exp(-c t / 2), a
    time constant of 0.1 s = 0.1 mm of clamp travel, against ~1-2 mm between recorded loads;
    (ii) on a load ramp a mode of frequency omega trails its equilibrium by c v / omega^2 (for
    implicit Euler exactly as in the continuous equation, since inertia vanishes on a ramp):
    with omega >= 180 rad/s this is <= 6e-7 m, ~4e-6 L, far below the spatial discretisation
    error. Near a threshold omega -> 0 and the lag grows (critical slowing down); there the
    dynamic and static paths differ by construction (measured: up to ~6e-4 L in H_mid/L at
    the US -> S transition, M = 100, 1 mm/s). That lag is proportional to c (measured at M = 30,
    3 mm/s: max |dH_mid|/L = 3.7e-6, 2.4e-5, 8.5e-5, 3.2e-4 for c = 0, 5, 20, 80 1/s). c = 0 also
    works at dt = 0.01 s, because implicit Euler then dissipates through its own numerical
    damping (rate ~ omega^2 dt / 2 for omega dt < 1), but that depends on dt; c = 20 1/s keeps
    the decay of slow modes independent of dt, at a cost of ~1e-4 L at the thresholds (median
    over the path 3e-8 L) in that measurement.

    record_interval (s): None records at the static solver's loads (protocol.compression_steps
    and protocol.shear_steps equally spaced targets per stage); a number records every
    ~record_interval seconds instead (rounded so that each stage ends on a recorded load).

    max_halvings: on a Newton failure the step is halved (then regrows by doubling), at most
    this many times below its nominal value, before the run stops with converged=False.

    relax_start: the straight strip is a symmetric equilibrium that dynamics alone would not
    leave without a perturbation, so the march starts from model.buckled_guess at the first
    recorded compression. True: that guess is first relaxed to the nearby static equilibrium
    (as the static solver starts), with zero velocity; False: the raw guess is released at
    rest and the damping removes the transient.
    """

    clamp_speed: float = 1e-3
    time_step: float = 0.01
    damping: float = 20.0
    record_interval: float | None = None
    max_halvings: int = 8
    relax_start: bool = True
    eigenvalues: bool = True
    newton: NewtonOptions = field(default_factory=NewtonOptions)

    def __post_init__(self) -> None:
        for name in ("clamp_speed", "time_step"):
            value = getattr(self, name)
            if isinstance(value, (bool, np.bool_)) or not (isinstance(value, (int, float)) and math.isfinite(value)
                                                           and value > 0):
                raise InputError(f"{name} = {value!r} must be a positive finite number")
        if isinstance(self.damping, (bool, np.bool_)) or not (isinstance(self.damping, (int, float))
                                                              and math.isfinite(self.damping) and self.damping >= 0):
            raise InputError(f"damping = {self.damping!r} must be a finite number >= 0 (1/s)")
        if self.record_interval is not None and not (math.isfinite(self.record_interval) and self.record_interval > 0):
            raise InputError(f"record_interval = {self.record_interval!r} must be None or a positive number (s)")
        if not (isinstance(self.max_halvings, int) and not isinstance(self.max_halvings, bool)
                and 0 <= self.max_halvings <= 30):
            raise InputError(f"max_halvings = {self.max_halvings!r} must be an integer in [0, 30]")
        for name in ("relax_start", "eigenvalues"):
            if not isinstance(getattr(self, name), bool):
                raise InputError(f"{name} = {getattr(self, name)!r} must be True or False")
        if not isinstance(self.newton, NewtonOptions):
            raise InputError(f"newton = {self.newton!r} must be a ddg.NewtonOptions")
        self.newton = dataclasses.replace(self.newton)  # validated again (options can change after creation)

    def check_scene(self, strip: Strip, protocol: LoadingProtocol) -> None:
        """Refuse a clamp speed the scene cannot use, in physical terms, before any work:
        faster than the lowest bending wave (2 pi / L) sqrt(EI2 / (rho A)) the clamp outruns the
        strip (no longer the paper's quasi-static loading, Eq. 7 with the clamp at 1 mm/s); so
        slow that the march needs more than MAX_TIME_STEPS steps of time_step."""
        L = strip.length
        wave = 2.0 * math.pi / L * math.sqrt(strip.bending_stiffness / (strip.density * strip.width * strip.thickness))
        if self.clamp_speed > wave:
            raise InputError(f"clamp_speed = {self.clamp_speed:g} m/s outside the allowed range (0, {wave:.3g}] m/s: "
                             f"faster than the strip's lowest bending wave (paper: 1e-3 m/s)")
        travel = protocol.compression_ratio * L + protocol.resolved_shear_ratio(strip) * L
        steps = travel / self.clamp_speed / self.time_step  # inf, not an overflow, for a denormal speed
        if steps > MAX_TIME_STEPS:
            slowest = travel / MAX_TIME_STEPS / self.time_step
            raise InputError(f"clamp_speed = {self.clamp_speed:g} m/s needs {steps:.3g} time steps of {self.time_step:g} s "
                             f"({travel / self.clamp_speed:.3g} s of loading); allowed up to {MAX_TIME_STEPS:g} "
                             f"steps, i.e. clamp_speed >= {slowest:.3g} m/s")


#: Most implicit-Euler steps a run may plan (a rod step costs ~3 Newton iterations of ~3 ms:
#: 1e5 steps are ~15 minutes).
MAX_TIME_STEPS = 1e5


class IncrementalPotential:
    """A model plus the inertia and damping terms of one implicit-Euler step (Eq. 7).

    Phi(q) = E(q) + 1/(2 dt^2) |q - q_k - dt v_k|_M^2 + c/(2 dt) |q - q_k|_M^2, with M the lumped
    masses of the free DOFs only (the clamped DOFs are prescribed, so their terms would merely
    add constants to the energy and spurious forces to the clamp reactions). Gradient and
    Hessian follow; the Hessian gains (1/dt^2 + c/dt) M on its diagonal and stays banded.
    Everything else (free, constrained, commit, frames, scales, observables) is the model's.
    """

    def __init__(self, model, damping: float = 0.0):
        self.model = model
        self.damping = float(damping)
        mass = np.zeros(model.n_dof)
        mass[model.free] = model.mass()[model.free]
        self.free_mass = mass
        self.q_prev = None
        self.v_prev = None
        self.dt = None

    def __getattr__(self, name):
        # only reached for attributes not defined here: delegate to the wrapped model
        return getattr(self.__dict__["model"], name)

    def set_step(self, q_prev: np.ndarray, v_prev: np.ndarray, dt: float) -> None:
        self.q_prev = np.array(q_prev, dtype=float)
        self.v_prev = np.array(v_prev, dtype=float)
        self.dt = float(dt)

    def inertia_terms(self, q: np.ndarray):
        """(energy, gradient, diagonal Hessian) of the inertia and damping terms."""
        m, dt, c = self.free_mass, self.dt, self.damping
        d = q - self.q_prev
        y = d - dt * self.v_prev
        a, b = 1.0 / dt**2, c / dt
        kinetic = 0.5 * a * float(np.dot(m * y, y))
        damping = 0.5 * b * float(np.dot(m * d, d))
        return kinetic, damping, m * (a * y + b * d), (a + b) * m

    def evaluate(self, q: np.ndarray, gradient: bool = True, hessian: bool = True):
        ev = self.model.evaluate(q, gradient=gradient, hessian=hessian)
        kinetic, damping, g, diag = self.inertia_terms(q)
        parts = dict(ev.parts or {}, inertia=kinetic, damping=damping)
        changes = {"energy": ev.energy + kinetic + damping, "parts": parts}
        if gradient and ev.gradient is not None:
            changes["gradient"] = ev.gradient + g
        if hessian and ev.hessian is not None:
            band = ev.hessian.band.copy()
            band[0] += diag
            changes["hessian"] = SymmetricBanded(band)
        return dataclasses.replace(ev, **changes)


class StepFailure(RuntimeError):
    """A step failed even at the smallest allowed time step (args[0])."""


class ImplicitEuler:
    """State (q, v, t) of the march: `step` takes one implicit-Euler step to a given clamp load,
    `advance` marches at constant clamp velocity to a load, halving the step on a Newton failure.

    The model's committed frames must be those of q (call model.commit(q) before).
    """

    def __init__(self, model, options: DynamicOptions, q: np.ndarray, load: tuple[float, float]):
        self.model = model
        self.options = options
        self.potential = IncrementalPotential(model, options.damping)
        self.q = q.copy()
        self.v = np.zeros_like(q)
        self.t = 0.0
        self.load = load
        self.steps = 0
        self.newton_iterations = 0

    def step(self, dt: float, load: tuple[float, float]) -> int | None:
        model = self.model
        saved = model.save_frames()
        self.potential.set_step(self.q, self.v, dt)
        guess = model.apply_clamps(self.q + dt * self.v, *load)
        result = newton(self.potential, guess, self.options.newton, minimize=True)
        self.newton_iterations += result.iterations
        if not result.converged:
            model.restore_frames(saved)
            return None
        model.commit(result.q, result.evaluation)
        self.v = (result.q - self.q) / dt
        self.q = result.q
        self.t += dt
        self.load = load
        self.steps += 1
        return result.iterations

    def advance(self, target: tuple[float, float], duration: float) -> int:
        """March at constant clamp velocity from the current load to `target` in `duration` s."""
        start = np.array(self.load, dtype=float)
        end = np.array(target, dtype=float)
        iterations = 0
        if duration <= 0.0:
            self.load = tuple(end)
            return 0
        n = max(1, math.ceil(duration / self.options.time_step * (1.0 - 1e-12)))
        nominal = duration / n
        smallest = nominal / 2**self.options.max_halvings
        s, dt = 0.0, nominal
        while s < duration:
            last = duration - s <= dt * (1.0 + 1e-9)
            s_next = duration if last else s + dt
            load = tuple(end) if last else tuple(start + (s_next / duration) * (end - start))
            it = self.step(s_next - s, load)
            if it is None:
                if dt / 2.0 < smallest * (1.0 - 1e-12):
                    raise StepFailure(dt)
                dt /= 2.0
                continue
            iterations += it
            s = s_next
            if dt < nominal and it <= 4:
                dt = min(nominal, 2.0 * dt)
        return iterations

    def kinetic_energy(self) -> float:
        m = self.potential.free_mass
        return 0.5 * float(np.dot(m * self.v, self.v))


@dataclass
class DynamicResult(SimulationResult):
    """SimulationResult plus, per recorded row, the time, kinetic energy and static residual."""

    trace: list = field(default_factory=list)


def _targets(total: float, steps: int, duration: float, record_interval: float | None) -> np.ndarray:
    if record_interval is not None:
        steps = max(1, math.ceil(duration / record_interval - 1e-9)) if duration > 0 else 1
    return total * np.arange(1, steps + 1) / steps


def simulate_dynamic(
    strip: Strip,
    protocol: LoadingProtocol,
    resolution: int = 100,
    options: DynamicOptions | None = None,
    out: str | Path | None = None,
) -> DynamicResult:
    """The two-stage protocol of ddg.simulate (model "rod") by implicit-Euler time marching.

    Stage 1 moves the clamp at s = L along -x at options.clamp_speed until dL = protocol
    .compression_ratio L; stage 2 moves it along y (sign protocol.shear_sign) until
    dW = protocol.resolved_shear_ratio(strip) L. Rows (the columns of ddg.analysis.observables.observe)
    are recorded at the static solver's loads, which the time steps hit exactly; the summary
    has the static summary's keys plus "solver": "implicit-euler", the options under
    scene["dynamics"]. On a Newton failure the step is halved up to options.max_halvings times;
    then the run stops with converged=False, keeping the rows so far.
    """
    from ..models.rod import RodModel

    if not isinstance(strip, Strip):
        raise InputError(f"strip = {strip!r} must be a ddg.Strip")
    if not isinstance(protocol, LoadingProtocol):
        raise InputError(f"protocol = {protocol!r} must be a ddg.LoadingProtocol")
    if options is not None and not isinstance(options, DynamicOptions):
        raise InputError(f"options = {options!r} must be a ddg.solve.dynamics.DynamicOptions")
    options = dataclasses.replace(options) if options is not None else DynamicOptions()  # re-validated
    options.check_scene(strip, protocol)
    shear_ratio = protocol.resolved_shear_ratio(strip)
    model = RodModel(strip, resolution)
    L = strip.length
    v = options.clamp_speed
    dL = protocol.compression_ratio * L
    dW = protocol.shear_sign * shear_ratio * L
    compressions = _targets(dL, protocol.compression_steps, dL / v, options.record_interval)
    shears = _targets(dW, protocol.shear_steps, abs(dW) / v, options.record_interval)

    summary = base_summary("rod", strip, protocol, resolution, model)
    summary["solver"] = "implicit-euler"
    summary["scene"]["dynamics"] = dataclasses.asdict(options)
    folder = open_run_folder(out, summary)
    rows: list[dict] = []
    trace: list[dict] = []
    t0 = time.perf_counter()
    state = None
    integrator = None
    start_iterations = 0

    def record(stage: str, q: np.ndarray, load, iterations: int, kinetic: float, t: float):
        ev = model.evaluate(q)
        stable = bool(model.free_matrix(ev.hessian).cholesky())
        st = State(q, ev, float(load[0]), float(load[1]), stable, iterations)
        rows.append(observe(model, st, stage, options.eigenvalues))
        if folder is not None:
            folder.append(rows[-1])
        trace.append({"time": t, "kinetic_energy": kinetic, "static_residual": scaled_residual(model, ev.gradient)})
        return st

    stage, stopped, interrupted, error, path_complete = "compression", None, None, None, False
    try:
        # the rest state, recorded as the static solver does
        q_rest = model.reset()
        state = record("compression", q_rest, (0.0, 0.0), 0, 0.0, 0.0)
        # start: buckled guess at the first recorded compression (see DynamicOptions.relax_start)
        first = float(compressions[0])
        if options.relax_start:
            follower = PathFollower(model, ContinuationOptions(newton=options.newton))
            start = follower.start_compression(first)  # may halve the compression if needed
            q0, c0 = start.q, start.compression
            start_iterations = follower.newton_iterations
        else:
            model.reset()
            q0 = model.apply_clamps(model.buckled_guess(first), first, 0.0)
            c0 = first
        model.commit(q0)
        integrator = ImplicitEuler(model, options, q0, (c0, 0.0))
        integrator.t = c0 / v
        integrator.newton_iterations = start_iterations
        pending = start_iterations
        for k, target in enumerate(compressions):
            if k > 0 or c0 < target:
                pending += integrator.advance((float(target), 0.0), (float(target) - integrator.load[0]) / v)
            state = record("compression", integrator.q, integrator.load, pending, integrator.kinetic_energy(), integrator.t)
            pending = 0
        summary["H_mid_over_L_compressed"] = rows[-1]["H_mid_over_L"]
        stage = "shear"
        for target in shears if dW != 0.0 else ():  # as ddg.simulate: no shear rows when dW = 0
            pending = integrator.advance((dL, float(target)), abs(float(target) - integrator.load[1]) / v)
            state = record("shear", integrator.q, integrator.load, pending, integrator.kinetic_energy(), integrator.t)
        path_complete = True
    except StepFailure as exc:
        c, s = integrator.load
        stopped = (
            f"implicit Euler failed to converge beyond dL/L = {c / L:.6g}, dW/L = {s / L:.6g} "
            f"(t = {integrator.t:.6g} s; time step halved {options.max_halvings} times to {exc.args[0]:.3g} s)"
        )
    except ContinuationFailure as exc:
        stopped = f"implicit Euler could not start: {exc}"
    except KeyboardInterrupt as exc:
        interrupted = exc
    except Exception as exc:  # noqa: BLE001  (written as status "error", then re-raised)
        error = exc
    summary["newton_iterations"] = integrator.newton_iterations if integrator is not None else start_iterations
    summary["wall_time_s"] = time.perf_counter() - t0
    finish_summary(summary, rows, path_complete=path_complete, stopped=stopped, interrupted=interrupted,
                   stage=stage, error=error)
    result = DynamicResult(rows, summary, state, model, trace=trace)
    return conclude_run(folder, result, interrupted, error)
