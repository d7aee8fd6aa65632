"""Newton's method on the free DOFs with an energy line search.

Model interface used here (rod and plate alike): `n_dof`, `free` (slice or indices),
`evaluate(q, gradient, hessian)` -> Evaluation(energy, gradient, hessian), `free_matrix(H)`
-> an operator with cholesky() / solve() / lowest_eigenpairs() / shifted(), `commit(q)`,
`save_frames()` / `restore_frames()`, `residual_scale()` and `length_scale()`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..limits import InputError, check_option  # noqa: F401  (check_option: options' fields)
from . import compiled_newton, trust_region


#: Descending from a saddle to a stable branch (minimize=True) slides along a soft, curved
#: valley: each step is limited by the stiff membrane (a plate of L/b ~ 1000 moves ~5e-4 L per
#: iteration near a pitchfork), so it may take many more iterations than a load step.
MINIMIZE_ITERATION_FACTOR = 15

#: Iterations with a correction below step_tol after which a residual above the round-off band
#: (ROUNDOFF_STALL_FACTOR) that has not halved is a stall, a failure (defined with the compiled
#: loop, which reads it as a constant).
STALL_ITERATIONS = compiled_newton.STALL_ITERATIONS
#: A Newton correction below step_tol with the residual within this factor of the model's
#: estimated round-off floor is round-off, hence converged (settled()): the state is fixed to
#: within the correction (< step_tol L) and Newton cannot lower the noise. The rod at M = 400
#: stalls at 1.1-8 times its floor estimate (the estimate counts one stretching force per node,
#: the gradient sums several).
ROUNDOFF_STALL_FACTOR = 100.0


@dataclass
class NewtonOptions:
    max_iterations: int = 15  # per load step; MINIMIZE_ITERATION_FACTOR times as many when descending from a saddle
    residual_tol: float = 1e-9   # max |dE/dq_i| / (EI2/L^2 or EI2/L), raised to the model's round-off floor
    step_tol: float = 1e-10      # corrections below it (relative to L, or 1 rad) count towards a stall
    max_line_search: int = 30
    # fail fast: a load step whose residual has not fallen below give_up_ratio of its start
    # after give_up_after iterations is outside Newton's basin (converging steps take ~3
    # iterations); the caller then halves the step. None disables (near thresholds, where
    # Newton converges only linearly).
    give_up_after: int | None = 4
    give_up_ratio: float = 0.1
    # Fail fast on contraction (load steps with give_up_after set): the energy norm of the Newton
    # correction, sqrt|r . dq|, must shrink. theta_k = |dq_k| / |dq_k-1| above 1 - alpha / 4
    # (Deuflhard's restricted monotonicity test; alpha the line search's step of iteration k-1)
    # means the iterate is outside Newton's basin; above contraction_limit twice in a row it
    # converges more slowly than the rate 1/2 of Newton at a singular point, and a shorter load step
    # is cheaper. Off near thresholds (the patient steps, where Newton converges linearly) and, for
    # the rest of a path, once the path would stop with it (PathFollower); None switches it off.
    # What it saves on the paths that complete and costs on those that stop anyway:
    # benchmarks/results/newton_contraction.md (benchmarks/newton_contraction.py).
    contraction_limit: float | None = 0.5
    # Run a plain Newton step in one compiled call (ddg.solve.compiled_newton) where the model has a
    # compiled energy (the rod family): the same iterations in less time per step
    # (benchmarks/results/rod_path.md). False runs the loop below for every model.
    compiled: bool = True

    def __post_init__(self) -> None:
        def c(name, *args, **kw):
            setattr(self, name, check_option("NewtonOptions", name, getattr(self, name), *args, **kw))

        c("max_iterations", "int", 1, 1000)
        c("residual_tol", "float", 0.0, 1e-3, low_open=True)
        c("step_tol", "float", 0.0, 1e-3, low_open=True)
        c("max_line_search", "int", 1, 60)
        c("give_up_after", "int", 1, 1000, allow_none=True)
        c("give_up_ratio", "float", 0.0, 1.0, low_open=True)
        c("contraction_limit", "float", 0.0, 1.0, low_open=True, allow_none=True)
        c("compiled", "bool")


@dataclass
class NewtonResult:
    q: np.ndarray
    evaluation: object
    converged: bool
    iterations: int
    residual: float
    positive_definite: bool | None
    message: str = ""
    line_search_trials: int = 0  # shortened steps tried (each an energy or gradient evaluation)


def settled(model, options: "NewtonOptions", residual: float, correction: float) -> bool:
    """A bordered or plain Newton iterate is converged: its scaled residual below the tolerance
    (raised to the model's round-off floor), or converged to round-off as newton() judges a stall:
    the last correction below step_tol (relative to the model's length scale) with the residual
    within ROUNDOFF_STALL_FACTOR of the floor."""
    floor = model.residual_floor()
    return residual < max(options.residual_tol, floor) or (
        correction < options.step_tol and residual <= ROUNDOFF_STALL_FACTOR * floor)


def scaled_residual(model, gradient: np.ndarray) -> float:
    free = model.free
    return float(np.max(np.abs(gradient[free] / model.residual_scale()[free]), initial=0.0))


def newton(model, q: np.ndarray, options: NewtonOptions | None = None, *, minimize: bool = False,
           evaluation=None) -> NewtonResult:
    """Solve grad E = 0 on the free DOFs starting from q (its clamped DOFs already set).

    With minimize=False the plain Newton step is used, which can also converge to unstable
    equilibria (needed to follow the symmetric branch past a pitchfork); the line search then
    uses the energy where the Hessian is positive definite and the residual elsewhere. With
    minimize=True the iteration descends in energy to a stable equilibrium by trust-region Newton
    (ddg.solve.trust_region), which follows the negative curvature of an indefinite Hessian. The
    result counts the shortened (or refused) steps tried (line_search_trials).
    """
    result, trials = _newton(model, q, options, minimize, evaluation)
    result.line_search_trials = trials
    return result


def _message(outcome: int, options: NewtonOptions, residual: float, residual_tol: float, tiny_steps: int,
             ratio: float, max_iterations: int) -> str:
    """NewtonResult.message of an outcome (compiled_newton's codes), for both loops."""
    if outcome == compiled_newton.STALLED:
        return (f"stalled at scaled residual {residual:.3g} (tolerance {residual_tol:.3g}): "
                f"Newton corrections below {options.step_tol:g} for {tiny_steps} iterations")
    return {compiled_newton.CONVERGED: "", compiled_newton.ROUNDOFF: "converged to round-off",
            compiled_newton.NON_FINITE: "non-finite gradient",
            compiled_newton.NOT_CONTRACTING: f"Newton corrections not contracting (ratio {ratio:.3g})",
            compiled_newton.LINE_SEARCH_FAILED: "line search failed",
            compiled_newton.NO_PROGRESS: f"no progress in {options.give_up_after} iterations",
            compiled_newton.NO_CONVERGENCE: f"no convergence in {max_iterations} iterations"}[outcome]


def _compiled(model, q, options, evaluation):
    """newton() for minimize=False in one compiled call (ddg.solve.compiled_newton)."""
    args = model.compiled_energy()
    free = model.free
    ev = evaluation
    if ev is None or ev.gradient is None or ev.hessian is None or ev.frames is None:
        ev = model.evaluate(q)
    residual_tol = max(options.residual_tol, model.residual_floor())
    noise = ROUNDOFF_STALL_FACTOR * model.residual_floor()
    give_up = -1 if options.give_up_after is None else options.give_up_after
    limit = 0.0 if options.contraction_limit is None else options.contraction_limit
    (outcome, q_end, energy_end, parts, grad, band, frames, iterations, res, pd, factor, accepted, trials, ratio,
     tiny) = model.compiled_loops().newton_load_step(
        args, np.ascontiguousarray(q, dtype=float), model.committed_frames(), ev.energy, np.zeros(0),
        ev.gradient, ev.hessian.band.reshape(-1), free.start, free.stop, model.residual_scale(),
        model.length_scale(), residual_tol, options.step_tol, noise, options.max_iterations,
        options.max_line_search, give_up, options.give_up_ratio, limit)
    if outcome == compiled_newton.SINGULAR:
        raise np.linalg.LinAlgError("singular matrix")
    if accepted:
        ev = model.compiled_evaluation(parts, grad, band, frames)
        model.commit(q_end, ev)
    if outcome != compiled_newton.NON_FINITE:
        block = model.free_matrix(ev.hessian)  # its factorisation is the one the loop made
        block._cholesky, block._cholesky_tried = (factor.T if pd else None), True
    converged = outcome in (compiled_newton.CONVERGED, compiled_newton.ROUNDOFF)
    message = _message(outcome, options, res, residual_tol, tiny, ratio, options.max_iterations)
    return NewtonResult(q_end, ev, converged, int(iterations), float(res), bool(pd), message), int(trials)


def _descent(model, q, options, evaluation):
    """newton() for minimize=True: trust-region Newton (ddg.solve.trust_region)."""
    max_iterations = options.max_iterations * MINIMIZE_ITERATION_FACTOR
    residual_tol = max(options.residual_tol, model.residual_floor())
    d = trust_region.minimize(model, q, options, max_iterations, ROUNDOFF_STALL_FACTOR * model.residual_floor(),
                              evaluation)
    converged = d.outcome in (compiled_newton.CONVERGED, compiled_newton.ROUNDOFF)
    message = _message(d.outcome, options, d.residual, residual_tol, d.tiny_steps, 0.0, max_iterations)
    return NewtonResult(d.q, d.evaluation, converged, d.iterations, d.residual, d.positive_definite, message), d.refused


def _newton(model, q, options, minimize, evaluation):
    """Plain Newton (minimize=False) in Python where the model has no compiled loop; the descent
    (minimize=True) is _descent's."""
    options = options or NewtonOptions()
    if minimize:
        return _descent(model, q, options, evaluation)
    if options.compiled and getattr(model, "compiled_energy", lambda: None)() is not None:
        return _compiled(model, q, options, evaluation)
    free = model.free
    rscale = model.residual_scale()[free]
    lscale = model.length_scale()[free]
    residual_tol = max(options.residual_tol, model.residual_floor())
    q = q.copy()
    ev = evaluation if evaluation is not None else model.evaluate(q)
    pd = None
    tiny_steps, stall_residual = 0, np.inf
    trials = 0
    fail_fast = options.give_up_after is not None and options.contraction_limit is not None
    noise = ROUNDOFF_STALL_FACTOR * model.residual_floor()
    previous_norm, previous_alpha, slow = None, 1.0, 0
    max_iterations = options.max_iterations

    def say(outcome, residual, tiny_steps=0, ratio=0.0):
        return _message(outcome, options, residual, residual_tol, tiny_steps, ratio, max_iterations)
    for iteration in range(max_iterations + 1):
        if not np.all(np.isfinite(ev.gradient)):
            return NewtonResult(q, ev, False, iteration, np.inf, pd, say(compiled_newton.NON_FINITE, np.inf)), trials
        r = ev.gradient[free]
        res = float(np.max(np.abs(r / rscale), initial=0.0))
        K = model.free_matrix(ev.hessian)
        pd = K.cholesky()
        if res < residual_tol:
            return NewtonResult(q, ev, True, iteration, res, pd), trials
        use_energy = pd
        dq = -K.solve(r)
        correction = float(np.max(np.abs(dq / lscale)))
        if correction < options.step_tol and res <= noise:
            # fixed to within step_tol, the residual in the round-off band: converged (settled()); it
            # need not be seen to stall for STALL_ITERATIONS more (docs/findings/measured.md)
            return NewtonResult(q, ev, True, iteration, res, pd, say(compiled_newton.ROUNDOFF, res)), trials
        if correction < options.step_tol:
            # The correction is below tolerance but the residual is not: in a stiff (stretching)
            # direction a correction of 1e-10 L still leaves a scaled residual of ~0.1, so the step
            # is taken and convergence is judged by the residual alone. Where corrections stay
            # this small and the residual stops falling, Newton has stalled: a failure.
            tiny_steps += 1
            if tiny_steps >= STALL_ITERATIONS and res > 0.5 * stall_residual:
                stalled = say(compiled_newton.STALLED, res, tiny_steps=tiny_steps)
                return NewtonResult(q, ev, False, iteration, res, pd, stalled), trials
            if tiny_steps == 1:
                stall_residual = res
        else:
            tiny_steps = 0
        if iteration == max_iterations:
            break
        slope = float(r @ dq)
        norm = math.sqrt(abs(slope))
        if fail_fast and previous_norm is not None and res > noise:
            theta = norm / previous_norm if previous_norm > 0.0 else np.inf
            slow = slow + 1 if theta > options.contraction_limit else 0
            if theta > 1.0 - previous_alpha / 4.0 or slow >= 2:
                return NewtonResult(q, ev, False, iteration, res, pd,
                                    say(compiled_newton.NOT_CONTRACTING, res, ratio=theta)), trials
        previous_norm = norm
        alpha = 1.0
        accepted = False
        # a load step whose Newton direction needs more than 1/1024 of a step is better halved
        for trial in range(min(options.max_line_search, 10)):
            q_try = q.copy()
            q_try[free] += alpha * dq
            # the full step is usually accepted: evaluate everything there; shorter trials need
            # only the energy (or the gradient), the Hessian follows once one is accepted
            full = trial == 0
            ev_try = model.evaluate(q_try, gradient=full or not use_energy, hessian=full)
            if np.isfinite(ev_try.energy) and (ev_try.gradient is None or np.all(np.isfinite(ev_try.gradient))):
                if use_energy:
                    ok = ev_try.energy <= ev.energy + 1e-4 * alpha * min(slope, 0.0) + 1e-12 * abs(ev.energy)
                else:
                    res_try = float(np.max(np.abs(ev_try.gradient[free] / rscale)))
                    ok = res_try <= (1.0 - 1e-4 * alpha) * res
                if ok:
                    accepted = True
                    if not full:
                        ev_try = model.evaluate(q_try)
                    break
            alpha *= 0.5
            trials += 1
        if not accepted:
            if tiny_steps and res <= ROUNDOFF_STALL_FACTOR * model.residual_floor():
                # a correction below step_tol that no step length improves: the residual is noise
                return NewtonResult(q, ev, True, iteration, res, pd, say(compiled_newton.ROUNDOFF, res)), trials
            failed = say(compiled_newton.LINE_SEARCH_FAILED, res)
            return NewtonResult(q, ev, False, iteration + 1, res, pd, failed), trials
        if iteration == 0:
            first_residual = res
        if options.give_up_after is not None and iteration >= options.give_up_after \
                and res > options.give_up_ratio * first_residual:
            return NewtonResult(q, ev, False, iteration + 1, res, pd, say(compiled_newton.NO_PROGRESS, res)), trials
        model.commit(q_try, ev_try)
        q, ev = q_try, ev_try
        previous_alpha = alpha
    res = scaled_residual(model, ev.gradient)
    return NewtonResult(q, ev, False, max_iterations, res, pd, say(compiled_newton.NO_CONVERGENCE, res)), trials
