"""Pseudo-arclength continuation in the clamp shear dW at fixed compression dL.

Natural continuation (ddg.solve.continuation) prescribes dW and stalls where the branch folds
(dW reaches a limit point and turns back). Here dW is an unknown, and each new equilibrium x =
(q_free, dW) lies a distance ds from the previous one along the branch (Keller's
pseudo-arclength):

    grad_f E(q_free, dW) = 0,        <x - x_prev, T> = ds,

with T the unit tangent of the branch and <.,.> the inner product

    <(a, alpha), (b, beta)> = (1/n) sum_i (a_i b_i / l_i^2) + alpha beta / L^2,

where l_i is each DOF's length scale (L for positions, 1 for angles) and n the number of free DOFs,
so that a unit step moves the shape by about L (root mean square) or the clamp by L. The
bordered Newton system

    [K_ff  f_W] [dq]   [-g_f]         f_W = K_fc dc/dW (the force change per unit clamp shear)
    [T_q   T_W] [dW] = [-N  ]

is solved by block elimination with one banded factorisation of K_ff (Cholesky where it is
positive definite, banded LU otherwise), for two right-hand sides. It also converges to unstable
equilibria, so the whole bifurcation diagram can be traced, stable and unstable parts alike.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from .extrapolation import ARCLENGTH_PREDICTOR_POINTS, lagrange_weights
from .newton import ROUNDOFF_STALL_FACTOR, settled
from .state import State


class ArclengthFailure(RuntimeError):
    """The branch could not be continued; the message says where."""


@dataclass
class ArclengthOptions:
    initial_step: float = 0.005     # ds of the first step (a dW of ~0.005 L on a flat branch)
    max_step: float = 0.02          # largest ds
    min_step: float = 1e-5          # below this ds the branch is given up
    max_iterations: int = 10        # Newton corrections per step
    easy_iterations: int = 4        # converging this fast lets ds grow by `growth`
    growth: float = 1.5
    max_points: int = 400


class ArclengthTracer:
    """Traces one branch of equilibria (q, dW) at the fixed compression of its start state."""

    def __init__(self, model, newton_options, options: ArclengthOptions | None = None):
        self.model = model
        self.newton_options = newton_options
        self.options = options or ArclengthOptions()
        self.newton_iterations = 0
        self.dropped: State | None = None  # the state a stop condition rejected (past a junction)
        free = np.arange(model.n_dof)[model.free]
        self._weight2 = 1.0 / (free.size * model.length_scale()[model.free] ** 2)
        self._length = model.strip.length
        self._residual_scale = model.residual_scale()[model.free]
        self._length_scale = model.length_scale()[model.free]

    # ------------------------------------------------------------------ geometry of the branch
    def inner(self, a_q: np.ndarray, a_w: float, b_q: np.ndarray, b_w: float) -> float:
        return float(np.sum(self._weight2 * a_q * b_q)) + a_w * b_w / self._length**2

    def normalise(self, t_q: np.ndarray, t_w: float) -> tuple[np.ndarray, float]:
        norm = np.sqrt(self.inner(t_q, t_w, t_q, t_w))
        return t_q / norm, t_w / norm

    def _shear_rate(self, compression: float) -> np.ndarray:
        """dc/dW: the clamped DOFs' change per unit shear (clamp values are linear in dW)."""
        model = self.model
        return model.clamp_values(compression, 1.0) - model.clamp_values(compression, 0.0)

    def tangent(self, state: State, previous: tuple[np.ndarray, float] | None = None,
                direction: float = 1.0) -> tuple[np.ndarray, float]:
        """Unit tangent (dq_free, dW) at an equilibrium: K_ff dq = -f_W dW, oriented along
        `previous` (a tangent) if given, else so that dW grows in sign with `direction`."""
        model = self.model
        H = state.evaluation.hessian
        f_w = model.coupling(H, self._shear_rate(state.compression))
        b = -model.free_matrix(H).solve(f_w)
        t_q, t_w = self.normalise(b, 1.0)
        if previous is not None:
            sign = 1.0 if self.inner(t_q, t_w, *previous) >= 0 else -1.0
        else:
            sign = 1.0 if direction >= 0 else -1.0
        return sign * t_q, sign * t_w

    # ------------------------------------------------------------------ one step
    def _correct(self, q: np.ndarray, shear: float, compression: float, anchor: State,
                 tangent: tuple[np.ndarray, float], ds: float) -> State | None:
        """Bordered Newton from the predicted (q, shear); None if it does not converge."""
        model = self.model
        if self.newton_options.compiled and getattr(model, "compiled_energy", lambda: None)() is not None:
            return self._correct_compiled(q, shear, compression, anchor, tangent, ds)
        free = model.free
        rate = self._shear_rate(compression)
        t_q, t_w = tangent
        q = q.copy()
        q[model.constrained] = model.clamp_values(compression, shear)
        ev = model.evaluate(q)
        first, correction = None, np.inf
        for iteration in range(self.options.max_iterations + 1):
            if not np.all(np.isfinite(ev.gradient)):
                return None
            r = ev.gradient[free]
            res = float(np.max(np.abs(r / self._residual_scale)))
            arc = self.inner(q[free] - anchor.q[free], shear - anchor.shear, t_q, t_w) - ds
            K = model.free_matrix(ev.hessian)
            # converged as newton() judges it, round-off stalls included (the rod at M = 400 stalls at
            # 3-4 times its floor estimate: without them every corrector there failed and the
            # branches ended after a few states)
            if settled(model, self.newton_options, res, correction) and abs(arc) < 1e-8 * ds:
                return State(q, ev, compression, shear, bool(K.cholesky()), iteration)
            if iteration == self.options.max_iterations:
                return None
            first = res if first is None else first
            if res > 1e3 * first:
                return None
            f_w = model.coupling(ev.hessian, rate)
            a, b = K.solve(np.column_stack([-r, -f_w])).T
            d_w = (-arc - self.inner(a, 0.0, t_q, t_w)) / (self.inner(b, 0.0, t_q, t_w) + t_w / self._length**2)
            step = a + b * d_w
            correction = float(np.max(np.abs(step / self._length_scale)))
            q[free] += step
            shear += d_w
            q[model.constrained] = model.clamp_values(compression, shear)
            ev = model.evaluate(q)
            self.newton_iterations += 1
            model.commit(q, ev)
        return None

    def _correct_compiled(self, q, shear, compression, anchor, tangent, ds) -> State | None:
        """_correct in one compiled call (the model's compiled_loops, ddg.solve.compiled_newton) for a model
        with a compiled energy; a singular bordered system ends the correction (None) instead of
        raising."""
        model = self.model
        free = model.free
        args = model.compiled_energy()
        base = model.clamp_values(compression, 0.0)
        floor = model.residual_floor()
        correct = model.compiled_loops().arclength_correct
        (converged, q, shear, parts, grad, band, frames, pd, factor, corrections) = correct(
            args, np.ascontiguousarray(q, dtype=float), model.committed_frames(), float(shear),
            (model.bandwidth + 1) * model.n_dof, base, self._shear_rate(compression), model.constrained,
            np.ascontiguousarray(anchor.q[free]), float(anchor.shear), tangent[0], float(tangent[1]), float(ds),
            self._weight2, float(self._length), free.start, free.stop, model.residual_scale(), model.length_scale(),
            max(self.newton_options.residual_tol, floor), self.newton_options.step_tol,
            ROUNDOFF_STALL_FACTOR * floor, self.options.max_iterations)
        self.newton_iterations += int(corrections)
        ev = model.compiled_evaluation(parts, grad, band, frames)
        if corrections:
            model.commit(q, ev)
        if not converged:
            return None
        block = model.free_matrix(ev.hessian)  # its factorisation is the one the corrector made
        block._cholesky, block._cholesky_tried = (factor.T if pd else None), True
        return State(q, ev, compression, float(shear), bool(pd), int(corrections))

    def trace(self, start: State, direction: float = 1.0, tangent: tuple[np.ndarray, float] | None = None,
              shear_range: tuple[float, float] = (-np.inf, np.inf), stop=None,
              max_points: int | None = None, initial_step: float | None = None,
              keep_hessians: bool = True) -> tuple[list[State], str]:
        """Equilibria along the branch through `start` (excluded), until dW leaves shear_range,
        stop(state) is true (that state is included if stop says True, dropped if it says
        "drop"), max_points, or the step falls below min_step. Returns the states and the reason
        it ended.

        keep_hessians=False keeps the Hessian on the last state only (each is a band of the whole
        model, which on a fine plate makes a long trace run out of memory: docs/findings/measured.md);
        the others keep q, energy, gradient and frames, all that interpolating between them needs."""
        model = self.model
        opts = self.options
        free = model.free
        max_points = max_points or opts.max_points
        tangent = tangent or self.tangent(start, direction=direction)
        ds = initial_step or opts.initial_step
        points: list[State] = []
        # arclength coordinates of the last states, for the quadratic predictor
        history: list[tuple[float, np.ndarray, float]] = [(0.0, start.q[free].copy(), start.shear)]
        state = start
        while len(points) < max_points:
            saved = model.save_frames()
            predicted_q, predicted_w = self._predict(history, state, tangent, ds)
            q = state.q.copy()
            q[free] = predicted_q
            new = self._correct(q, predicted_w, state.compression, state, tangent, ds)
            if new is None:
                model.restore_frames(saved)
                ds *= 0.5
                # a failed step falls back to the quadratic through the last three states: a
                # polynomial of higher order extrapolated over unevenly shrinking steps overshoots
                history = history[-3:]
                if ds < opts.min_step:
                    L = self._length
                    return points, (f"pseudo-arclength step below {opts.min_step:g} at dW/L = {state.shear / L:.6g} "
                                    f"(dL/L = {state.compression / L:.6g})")
                continue
            if not shear_range[0] <= new.shear <= shear_range[1]:
                model.restore_frames(saved)
                return points, "left the shear range"
            new.frames = model.save_frames()
            verdict = stop(new) if stop is not None else False
            if verdict == "drop":
                self.dropped = new
                return points, "stop condition"
            tangent = self.tangent(new, previous=tangent)
            travelled = history[-1][0] + ds
            history = (history + [(travelled, new.q[free].copy(), new.shear)])[-ARCLENGTH_PREDICTOR_POINTS:]
            if points and not keep_hessians and points[-1].evaluation is not None:
                points[-1].evaluation = replace(points[-1].evaluation, hessian=None)
            points.append(new)
            state = new
            if verdict:
                return points, "stop condition"
            if new.iterations <= opts.easy_iterations:
                ds = min(opts.max_step, opts.growth * ds)
        return points, "maximum number of points"

    def _predict(self, history, state: State, tangent, ds: float) -> tuple[np.ndarray, float]:
        """Polynomial extrapolation in arclength through the last states (up to
        ARCLENGTH_PREDICTOR_POINTS, at least three), else the tangent."""
        free = self.model.free
        if len(history) < 3:
            return state.q[free] + ds * tangent[0], state.shear + ds * tangent[1]
        s = [h[0] for h in history]
        weights = lagrange_weights(s, s[-1] + ds)
        q = sum(w * h[1] for w, h in zip(weights, history))
        shear = sum(w * h[2] for w, h in zip(weights, history))
        return q, float(shear)
