"""Energy minimisation by trust-region Newton: the descents that leave an unstable or folded state.

The quasi-static path snaps where its branch ends at a limit point of the load, and leaves a
saddle past a pitchfork: both are descents to the nearest stable equilibrium at a fixed load,
from a state where the Hessian K of the free DOFs is indefinite or nearly singular. Each
iteration minimises the quadratic model of the energy in a ball (More and Sorensen, SIAM J. Sci.
Stat. Comput. 4, 1983; Nocedal and Wright, Numerical Optimization, 2006, Algorithm 4.3):

    min_p  m(p) = g.p + p.K p / 2,   |p / l| <= Delta,

with l the model's length scale per DOF (L for positions, 1 rad for angles), so that Delta
bounds the root mean square motion of the shape in units of L times sqrt(n). Its solution is
p(mu) = -(K + mu D^2)^-1 g with D = diag(1/l), mu >= 0 and K + mu D^2 positive definite: mu = 0
where the Newton step is inside the ball, else the root of 1/|p(mu)/l| = 1/Delta found by Newton's
method with the Cholesky factor of the shifted matrix. Where the shift cannot go lower without
losing positive definiteness and the step stays inside the ball (the hard case: a saddle whose
gradient barely points along the unstable mode), the step is completed to the boundary along the
lowest mode, estimated by inverse iteration with the same factor: the negative curvature that
Newton's line search or a Levenberg shift only dampen is what carries the strip off the saddle.

A step is taken if the energy falls by at least a tenth of the model's prediction (rho >= 0.1);
Delta doubles after a step that reached the boundary with rho >= 3/4 and drops to a quarter of
the step after rho < 1/4. A refused step costs an energy evaluation (counted with the line
search trials), an iteration costs an evaluation with gradient and Hessian. Convergence is judged
as in ddg.solve.newton: the scaled residual, or a round-off stall.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
import scipy.linalg as sla
from scipy.linalg import lapack

from . import compiled_newton

#: Initial trust radius: root mean square motion of the free DOFs, in units of their length scale
#: (1 % of L). The Newton step of a positive definite Hessian inside it is taken at once, so a
#: descent from near an equilibrium costs what Newton costs.
INITIAL_RADIUS = 1e-2
#: Largest trust radius (root mean square motion per iteration, units of the length scale).
MAX_RADIUS = 0.5
#: Acceptance and radius rules (Nocedal and Wright, Algorithm 4.1).
ACCEPT, SHRINK, GROW = 0.1, 0.25, 0.75
#: Shifts tried per iteration to solve the secular equation to within SECULAR_TOLERANCE of Delta.
SECULAR_TRIALS = 8
SECULAR_TOLERANCE = 0.2
#: Refused steps per iteration before the descent is given up (Delta then shrank by 4^REFUSALS).
REFUSALS = 12
#: Relative change of the energy that round-off hides: below it steps are judged by the residual.
ENERGY_NOISE = 1e-12
#: Predicted decreases below FLAT times the noise do not shrink the ball (their rho is round-off).
FLAT = 100.0


def _shifted_factor(band: np.ndarray, shift: float):
    """Lower Cholesky factor (LAPACK band storage) of the band matrix plus shift I, None if not
    positive definite."""
    shifted = band.copy()
    shifted[0] += shift
    try:
        return sla.cholesky_banded(shifted, lower=True, check_finite=False)
    except sla.LinAlgError:
        return None


def _model_value(band_matrix, g: np.ndarray, p: np.ndarray) -> float:
    """m(p) = g.p + p.K p / 2 in the scaled variables."""
    return float(g @ p + 0.5 * p @ band_matrix.matvec(p))


def trust_step(scaled, g: np.ndarray, radius: float, newton_step: np.ndarray | None, shift: float):
    """The step of the trust-region subproblem in scaled variables: (p, shift used).

    scaled: the SymmetricBanded K of the scaled variables; g: the scaled gradient; newton_step:
    -K^-1 g where K is positive definite (else None); shift: the last iteration's, a starting
    guess (the shift varies slowly along a descent)."""
    if newton_step is not None and np.linalg.norm(newton_step) <= radius:
        return newton_step, 0.0
    band = scaled.band
    floor = 1e-10 * max(float(np.mean(np.abs(band[0]))), np.finfo(float).tiny)
    failed = 0.0 if newton_step is not None else None  # largest shift known not to be positive definite
    mu = max(shift, floor)
    factor = _shifted_factor(band, mu)
    while factor is None:
        failed = mu
        mu *= 4.0
        factor = _shifted_factor(band, mu)
    p = -sla.cho_solve_banded((factor, True), g, check_finite=False)
    for _ in range(SECULAR_TRIALS):
        size = float(np.linalg.norm(p))
        if abs(size - radius) <= SECULAR_TOLERANCE * radius:
            break
        if size < radius and newton_step is None and failed is not None and mu <= 4.0 * failed + floor:
            break  # the shift cannot go much lower: the hard case, completed below
        w, info = lapack.dtbtrs(factor, p, uplo="L")
        w_norm = float(np.linalg.norm(w))
        if info != 0 or w_norm == 0.0:
            break
        trial = mu + (size / w_norm) ** 2 * (size - radius) / radius
        if failed is not None and trial <= failed:
            trial = 0.5 * (mu + failed)
        trial = max(trial, 0.0)
        trial_factor = _shifted_factor(band, trial)
        if trial_factor is None:
            failed = trial
            continue
        mu, factor = trial, trial_factor
        p = -sla.cho_solve_banded((factor, True), g, check_finite=False)
    size = float(np.linalg.norm(p))
    if size < (1.0 - SECULAR_TOLERANCE) * radius and newton_step is None and failed is not None:
        # hard case: the lowest mode by inverse iteration with the shifted factor, then to the boundary
        v = p / size if size > 0.0 else np.ones_like(p) / math.sqrt(p.size)
        for _ in range(3):
            v = sla.cho_solve_banded((factor, True), v, check_finite=False)
            v /= np.linalg.norm(v)
        along = float(p @ v)
        reach = math.sqrt(max(along * along + radius * radius - size * size, 0.0))
        candidates = [p + (-along + reach) * v, p + (-along - reach) * v]
        p = min(candidates, key=lambda c: _model_value(scaled, g, c))
    return p, mu


#: Longer multiples (2, 4, ..., 2^EXTENSIONS) of an accepted Newton step tried by their energy.
EXTENSIONS = 3


def _extend(model, q: np.ndarray, step: np.ndarray, accepted_energy: float, start_energy: float):
    """The longest multiple of an accepted Newton step of a positive definite model along which the
    energy keeps falling: (factor, q or None where no longer step is lower, energy evaluations made).

    Near a nearly singular minimum (a soft mode along which the energy is quartic, as where a
    snap lands close to a pitchfork of the branch it lands on) the quadratic model holds only
    within a short distance and each Newton step covers a fixed fraction of the way along the
    soft mode (2/3 of it left per step where the energy is quartic): doubling the step while the
    energy keeps falling covers it in a few energy evaluations."""
    free = model.free
    noise = ENERGY_NOISE * abs(start_energy)
    best, best_factor, best_q = accepted_energy, 1.0, None
    evaluations = 0
    for k in range(1, EXTENSIONS + 1):
        factor = 2.0 ** k
        q_long = q.copy()
        q_long[free] += factor * step
        energy = model.evaluate(q_long, gradient=False, hessian=False).energy
        evaluations += 1
        if not (np.isfinite(energy) and energy < best - noise):
            break
        best, best_factor, best_q = energy, factor, q_long
    return best_factor, best_q, evaluations


class Descent(NamedTuple):
    """How a descent ended: outcome (ddg.solve.compiled_newton's codes), the last iterate and its
    evaluation, the steps taken (each ending in an evaluation with gradient and Hessian), the
    scaled residual, whether the Hessian there is positive definite, the corrections below
    step_tol in a row at the end, and the refused steps (an energy evaluation each)."""
    outcome: int
    q: np.ndarray
    evaluation: object
    iterations: int
    residual: float
    positive_definite: bool | None
    tiny_steps: int
    refused: int


def _stall_count(correction: float, step_tol: float, tiny_steps: int, stall_residual: float, residual: float):
    """The count of corrections below step_tol in a row and the residual when it began (a stall:
    ddg.solve.newton's rule)."""
    if correction >= step_tol:
        return 0, np.inf
    return tiny_steps + 1, (residual if tiny_steps == 0 else stall_residual)


def minimize(model, q: np.ndarray, options, max_iterations: int, noise: float, evaluation=None) -> Descent:
    """Trust-region Newton descent to a local minimum of the energy at fixed clamps, from q (its
    clamped DOFs set), with options (ddg.solve.newton.NewtonOptions: residual_tol, step_tol) and
    `noise` the scaled residual below which a stall is round-off. The model's frames are
    committed at every step taken, as in Newton's method."""
    free = model.free
    lengths = model.length_scale()[free]
    rscale = model.residual_scale()[free]
    floor = model.residual_floor()
    residual_tol = max(options.residual_tol, floor)
    q = q.copy()
    ev = evaluation if evaluation is not None else model.evaluate(q)
    n = max(int(lengths.size), 1)
    radius = INITIAL_RADIUS * math.sqrt(n)
    shift = 0.0
    refused = 0
    tiny_steps, stall_residual = 0, np.inf
    pd = None

    def result(outcome, iterations, residual):
        return Descent(outcome, q, ev, iterations, residual, pd, tiny_steps, refused)

    iteration = 0
    while True:
        g = ev.gradient[free]
        if not np.all(np.isfinite(g)):
            return result(compiled_newton.NON_FINITE, iteration, np.inf)
        res = float(np.max(np.abs(g / rscale), initial=0.0))
        K = model.free_matrix(ev.hessian)
        pd = K.cholesky()
        if res < residual_tol:
            return result(compiled_newton.CONVERGED, iteration, res)
        if iteration >= max_iterations:
            return result(compiled_newton.NO_CONVERGENCE, iteration, res)
        scaled = K.scaled(lengths)
        gs = g * lengths
        newton_step = (-K.solve(g) / lengths) if pd else None
        if newton_step is not None and res <= noise and float(np.max(np.abs(newton_step))) < options.step_tol:
            # a minimum fixed to within step_tol, its residual at round-off (ddg.solve.newton.settled)
            return result(compiled_newton.ROUNDOFF, iteration, res)
        if newton_step is not None and -_model_value(scaled, gs, newton_step) <= ENERGY_NOISE * abs(ev.energy):
            # the energy cannot tell steps apart (near a minimum, or along a soft mode at round-off):
            # the Newton step, judged by the residual
            q_try = q.copy()
            q_try[free] += newton_step * lengths
            trial = model.evaluate(q_try)
            if np.all(np.isfinite(trial.gradient)) and \
                    float(np.max(np.abs(trial.gradient[free] / rscale), initial=0.0)) < res:
                radius = max(radius, float(np.linalg.norm(newton_step)))
                correction = float(np.max(np.abs(newton_step), initial=0.0))
                ev = trial
                model.commit(q_try, ev)
                q = q_try
                iteration += 1
                tiny_steps, stall_residual = _stall_count(correction, options.step_tol, tiny_steps, stall_residual, res)
                if tiny_steps >= compiled_newton.STALL_ITERATIONS and res > 0.5 * stall_residual:
                    return result(compiled_newton.ROUNDOFF if res <= noise else compiled_newton.STALLED, iteration, res)
                continue
            refused += 1
        for attempt in range(REFUSALS + 1):
            p_scaled, shift = trust_step(scaled, gs, radius, newton_step, shift)
            predicted = _model_value(scaled, gs, p_scaled)
            step = p_scaled * lengths
            correction = float(np.max(np.abs(p_scaled), initial=0.0))
            q_try = q.copy()
            q_try[free] += step
            trial = model.evaluate(q_try, gradient=False, hessian=False)
            actual = trial.energy - ev.energy
            if np.isfinite(actual) and actual <= ACCEPT * min(predicted, 0.0) + 1e-12 * abs(ev.energy):
                break
            refused += 1
            radius = SHRINK * float(np.linalg.norm(p_scaled))
        else:
            if res <= noise:
                return result(compiled_newton.ROUNDOFF, iteration, res)
            return result(compiled_newton.LINE_SEARCH_FAILED, iteration, res)
        extended = False
        if shift == 0.0 and newton_step is not None:
            factor, longer, evaluations = _extend(model, q, step, trial.energy, ev.energy)
            refused += evaluations  # energy evaluations, counted with the refused steps
            if longer is not None:
                extended, q_try = True, longer
                p_scaled = factor * p_scaled
                correction *= factor
        size = float(np.linalg.norm(p_scaled))
        rho = actual / predicted if predicted < 0.0 else 1.0
        flat = -predicted <= FLAT * ENERGY_NOISE * abs(ev.energy)
        if extended:  # the model was too timid: the ball takes the step that was taken
            radius = min(max(radius, size), MAX_RADIUS * math.sqrt(n))
        elif flat or (rho >= GROW and size >= (1.0 - SECULAR_TOLERANCE) * radius):
            # a good model, or one the energy's round-off cannot check (a flat stretch, the ghost of
            # a fold just passed, where only longer steps get anywhere): a larger ball
            radius = min(2.0 * radius, MAX_RADIUS * math.sqrt(n))
        elif rho < SHRINK:
            radius = SHRINK * size
        ev = model.evaluate(q_try)
        model.commit(q_try, ev)
        q = q_try
        iteration += 1
        tiny_steps, stall_residual = _stall_count(correction, options.step_tol, tiny_steps, stall_residual, res)
        if tiny_steps >= compiled_newton.STALL_ITERATIONS and res > 0.5 * stall_residual:
            return result(compiled_newton.ROUNDOFF if res <= noise else compiled_newton.STALLED, iteration, res)
