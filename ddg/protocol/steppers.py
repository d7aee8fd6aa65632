"""Steppers of the loading protocol: what reaches the next recorded load (ddg.protocol.driver).

- StaticStepper: Newton continuation of equilibria with stability and branch switching
  (ddg.solve.continuation); the first compression step starts from the inextensible buckled
  guess.
- RodDrivenStepper: the paper's DAR-Sadowsky (Appendix A): the rod follows its own stable path
  and each recorded rod state is relaxed under the ribbon's energy (Eq. A.5).
- ImplicitEulerStepper: the paper's time marching (section 3.1, Eqs. 7-9) with the clamp moved
  at a finite speed (ddg.solve.dynamics).
"""
from __future__ import annotations

import math

import numpy as np

from ..solve.continuation import ContinuationFailure, ContinuationOptions, PathFollower, relax_from
from ..geometry.strip import LoadingProtocol, Strip
from ..solve.dynamics import DynamicOptions, ImplicitEuler, StepFailure, recorded_targets
from ..solve.newton import scaled_residual
from ..solve.state import State
from .driver import Loading, distinct


class StaticStepper:
    """Static continuation (PathFollower) through the recorded loads."""

    failure = ContinuationFailure

    def __init__(self, model, options: ContinuationOptions, folds: bool = True, probe=None):
        self.model = model
        self.options = options
        self.follower = PathFollower(model, options, probe)
        self.report_folds = folds

    def rest(self) -> State:
        return self.follower.rest()

    def advance(self, state: State, compression: float, shear: float, stage: str, index: int) -> State:
        if stage == "compression" and index == 0:
            return self.follower.start_compression(compression)
        return self.follower.advance(state, compression, shear)

    def failure_message(self, exc: BaseException) -> str:
        return str(exc)

    def summarise(self, summary: dict) -> None:
        f = self.follower
        summary["newton_iterations"] = f.newton_iterations
        summary["newton_iterations_by_phase"] = f.iteration_breakdown()
        if self.report_folds:
            summary["folds_dW_over_L"] = distinct([abs(x) / self.model.strip.length for x in f.folds], 1e-4)


class RodDrivenStepper:
    """The rod (DAR) follows its own path; every recorded rod state (DOFs and reference frames,
    which the two models share) starts an energy descent under the ribbon's energy. The rod's
    state is kept in `driven` for the rod's own rows."""

    failure = ContinuationFailure

    def __init__(self, ribbon, rod, options: ContinuationOptions, probe=None):
        self.model = ribbon
        self.rod = rod
        self.options = options
        self.inner = StaticStepper(rod, options, folds=False, probe=probe)
        self.driven: State | None = None
        self.relax_iterations = 0

    def _relaxed(self, driven: State) -> State:
        self.driven = driven
        state = relax_from(self.model, self.rod, driven, self.options)
        self.relax_iterations += state.iterations
        return state

    def rest(self) -> State:
        return self._relaxed(self.inner.rest())

    def advance(self, state: State, compression: float, shear: float, stage: str, index: int) -> State:
        return self._relaxed(self.inner.advance(self.driven, compression, shear, stage, index))

    def failure_message(self, exc: BaseException) -> str:
        return str(exc)

    def summarise(self, summary: dict) -> None:
        self.inner.summarise(summary)
        summary["newton_iterations"] += self.relax_iterations


class ImplicitEulerStepper:
    """Implicit-Euler time marching of the rod, the clamp moved at options.clamp_speed; each
    recorded state is the elastic state the dynamics has reached at that load (evaluated with
    the bare elastic energy), its time, kinetic energy and static residual kept in `trace`."""

    failure = (StepFailure, ContinuationFailure)

    def __init__(self, model, options: DynamicOptions):
        self.model = model
        self.options = options
        self.integrator: ImplicitEuler | None = None
        self.start_iterations = 0
        self.trace: list[dict] = []

    def _recorded(self, q: np.ndarray, load, iterations: int, kinetic: float, t: float) -> State:
        model = self.model
        ev = model.evaluate(q)
        stable = bool(model.free_matrix(ev.hessian).cholesky())
        self.trace.append({"time": t, "kinetic_energy": kinetic,
                           "static_residual": scaled_residual(model, ev.gradient)})
        return State(q, ev, float(load[0]), float(load[1]), stable, iterations)

    def rest(self) -> State:
        return self._recorded(self.model.reset(), (0.0, 0.0), 0, 0.0, 0.0)

    def _start(self, first: float) -> int:
        """The march starts from model.buckled_guess at the first recorded compression, relaxed to
        the nearby static equilibrium or released as is (DynamicOptions.relax_start)."""
        model, options = self.model, self.options
        if options.relax_start:
            follower = PathFollower(model, ContinuationOptions(newton=options.newton))
            start = follower.start_compression(first)  # may halve the compression if needed
            q0, c0 = start.q, start.compression
            self.start_iterations = follower.newton_iterations
        else:
            model.reset()
            q0 = model.apply_clamps(model.buckled_guess(first), first, 0.0)
            c0 = first
        model.commit(q0)
        self.integrator = ImplicitEuler(model, options, q0, (c0, 0.0))
        self.integrator.t = c0 / options.clamp_speed
        self.integrator.newton_iterations = self.start_iterations
        return self.start_iterations

    def advance(self, state: State, compression: float, shear: float, stage: str, index: int) -> State:
        v = self.options.clamp_speed
        iterations = self._start(compression) if self.integrator is None else 0
        march = self.integrator
        distance = math.hypot(compression - march.load[0], shear - march.load[1])
        if distance > 0.0:
            iterations += march.advance((compression, shear), distance / v)
        return self._recorded(march.q, march.load, iterations, march.kinetic_energy(), march.t)

    def failure_message(self, exc: BaseException) -> str:
        if isinstance(exc, StepFailure):
            c, s = self.integrator.load
            L = self.model.strip.length
            return (f"implicit Euler failed to converge beyond dL/L = {c / L:.6g}, dW/L = {s / L:.6g} "
                    f"(t = {self.integrator.t:.6g} s; time step halved {self.options.max_halvings} times to "
                    f"{exc.args[0]:.3g} s)")
        return f"implicit Euler could not start: {exc}"

    def summarise(self, summary: dict) -> None:
        march = self.integrator
        summary["newton_iterations"] = march.newton_iterations if march is not None else self.start_iterations


def dynamic_loading(strip: Strip, protocol: LoadingProtocol, options: DynamicOptions) -> Loading:
    """The recorded loads of a dynamic run: the static solver's (protocol.compression_steps and
    protocol.shear_steps equal steps), or one every options.record_interval seconds."""
    L, v = strip.length, options.clamp_speed
    dL = protocol.compression_ratio * L
    dW = protocol.shear_sign * protocol.resolved_shear_ratio(strip) * L
    compressions = recorded_targets(dL, protocol.compression_steps, dL / v, options.record_interval)
    shears = recorded_targets(dW, protocol.shear_steps, abs(dW) / v, options.record_interval) if dW != 0.0 else ()
    return Loading(tuple(float(c) for c in compressions), tuple(float(s) for s in shears), dL)
