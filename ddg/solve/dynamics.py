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
dynamics has reached; how far it is from equilibrium is in `DynamicResult.trace`. The loading
loop itself is the one of every model (ddg.protocol.driver, ImplicitEulerStepper).
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from ..limits import InputError
from ..geometry.strip import LoadingProtocol, Strip
from .banded import SymmetricBanded
from .newton import NewtonOptions, newton


@dataclass
class DynamicOptions:
    """Settings of the implicit-Euler option.

    clamp_speed (m/s): default 1e-3, the paper's 1 mm/s in both stages (sections 4.1, 4.2).

    time_step (s): the largest step, default 0.01 s, shortened so that every recorded load is
    reached exactly (an integer number of equal steps per recorded interval). At 1 mm/s the clamp
    moves 10 um per step, a small fraction of the rod spacing h = L/(M-2). Implicit Euler is
    unconditionally stable; away from the thresholds the buckled strip's lowest frequencies
    (K v = omega^2 M v) give omega dt > 1 (docs/findings/models.md), so the scheme dissipates
    elastic vibrations within a few steps: as in the paper it is a device for following
    quasi-static equilibria, not for resolving vibrations (use dt << 1/omega for that).

    damping (1/s): rate c of the viscous force -c M v, default 20 1/s. Two conditions make the
    response quasi-static, and away from the thresholds this value meets both with a wide margin:
    (i) disturbances (the start of each stage, a snap past a bifurcation) die out well before the
    next recorded load: a slow, lightly damped mode decays as exp(-c t / 2), with the time constant
    2/c = 0.1 s, a tenth of a millimetre of clamp travel at 1 mm/s; (ii) on a load ramp a mode of
    frequency omega trails its equilibrium by c v / omega^2 (for implicit Euler exactly as in the
    continuous equation, since inertia vanishes on a ramp), far below the spatial discretisation
    error. Near a threshold omega -> 0 and the lag grows (critical slowing down): there the dynamic
    and static paths differ by construction, by a lag proportional to c. c = 0 also works, because
    implicit Euler then dissipates through its own numerical damping (rate ~ omega^2 dt / 2 for
    omega dt < 1), but that depends on dt; c > 0 keeps the decay of slow modes independent of dt.
    What the lag and the frequencies measured: docs/findings/models.md.

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
            raise InputError(f"clamp_speed = {self.clamp_speed:g} m/s needs {steps:.3g} time steps of "
                             f"{self.time_step:g} s "
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


def recorded_targets(total: float, steps: int, duration: float, record_interval: float | None) -> np.ndarray:
    """The recorded loads of one stage (m): `steps` equal steps to `total`, or, with a
    record_interval (s), one every ~record_interval of the `duration` (s) the clamp takes."""
    if record_interval is not None:
        steps = max(1, math.ceil(duration / record_interval - 1e-9)) if duration > 0 else 1
    return total * np.arange(1, steps + 1) / steps
