"""Newton's method for a load step, and the pseudo-arclength corrector, in one compiled call (numba)
for the models assembled by the rod family's compiled energy (ddg.models.rod_assembly.ENERGIES,
one per kind of width terms). The loops call the energy directly, bound per kind when they are
compiled (ddg.assembly.specialise: numba does not cache a compiled function that takes another as an
argument), so each model compiles the loops with its own energy only.

The algorithm is ddg.solve.newton's plain Newton (minimize=False) step for step: the same
residual and correction measures, the banded Cholesky where the free Hessian is positive
definite and otherwise LDL^T without pivoting checked by its residual, then LU (as
SymmetricBanded.solve), the same energy or residual line search, the round-off stall, the give-up
and contraction tests, the frames committed at each accepted iterate. Python is touched once per
load step instead of about ten times per iteration (what each costs: docs/findings/measured.md;
benchmarks/rod_path.py measures the path). ddg.solve.newton.newton calls it where the model offers a
compiled energy (`assembly_args`) and falls back to its own loop otherwise; tests/
test_compiled_newton.py checks that both take the same iterations to the same states.

`args` are the model's constants for the energy (RodModel.assembly_args), `state` the committed
frames it transports trial states' frames from.
"""
from __future__ import annotations

import math
from typing import Callable, NamedTuple

import numpy as np
from numba import njit

from .band_ldlt import ldlt_unblocked, solve_transposed_1
from ..assembly.band_scatter import band_matvec
from .banded import SymmetricBanded
from .lapack import band_cholesky, band_cholesky_solve, band_lu_solve
from ..assembly.specialise import specialise

def energy(q, state, args, want_gradient, want_hessian, grad, band):
    """The compiled energy the loops call, with the signature of ddg.models.rod_assembly.rod_energy:
    a name that compile_loops binds; the unbound loops are never compiled."""
    raise NotImplementedError("the loops run as compiled by compile_loops(suffix, energy)")


#: Outcomes (NewtonResult.message is written from them in ddg.solve.newton).
(CONVERGED, ROUNDOFF, NON_FINITE, STALLED, NOT_CONTRACTING, LINE_SEARCH_FAILED, NO_PROGRESS, NO_CONVERGENCE,
 SINGULAR) = range(9)

#: Iterations with a correction below step_tol after which a residual that has not halved is a
#: stall (ddg.solve.newton.STALL_ITERATIONS, which is this).
STALL_ITERATIONS = 3

#: An LDL^T solve is kept below this relative residual, else LU (as SymmetricBanded.solve).
LDLT_RESIDUAL = SymmetricBanded.LDLT_RESIDUAL


@njit(cache=True)
def _free_block(band, n, start, stop):
    """The free DOFs' principal block of the flattened lower band, transposed: t[j, d] = A[j + d, j]."""
    w = band.shape[0] // n
    m = stop - start
    t = np.zeros((m, w))
    for d in range(w):
        for j in range(m - d):
            t[j, d] = band[d * n + start + j]
    return t


@njit(cache=True)
def _column(matrix, c):
    """Column c of a 2-D array as a new contiguous vector (a loop: numpy's strided copy and array
    expressions compile to many times the code in every loop that links this module's helpers)."""
    out = np.empty(matrix.shape[0])
    for i in range(matrix.shape[0]):
        out[i] = matrix[i, c]
    return out


@njit(cache=True)
def _norm(v):
    total = 0.0
    for i in range(v.shape[0]):
        total += v[i] * v[i]
    return math.sqrt(total)


@njit(cache=True)
def _residual_norm(t, x, b):
    """|A x - b| for the symmetric A of the transposed lower band t (m, w), t[j, d] = A[j + d, j]."""
    m, w = t.shape
    r = np.empty(m)
    for j in range(m):
        r[j] = t[j, 0] * x[j]
    for d in range(1, w):
        for j in range(m - d):
            v = t[j, d]
            r[j + d] += v * x[j]
            r[j] += v * x[j + d]
    for j in range(m):
        r[j] -= b[j]
    return _norm(r)


@njit(cache=True)
def _solve_indefinite(t, rhs):
    """SymmetricBanded.solve where the Cholesky failed, for the columns of rhs (m, k): LDL^T kept
    if every column's residual is below LDLT_RESIDUAL, else banded LU. Returns (x, ok)."""
    m, w = t.shape
    diag_max = 0.0
    for j in range(m):
        if math.isfinite(t[j, 0]):
            diag_max = max(diag_max, abs(t[j, 0]))
    tolerance = m * np.finfo(np.float64).eps * diag_max
    f = t.copy()
    first_tiny = -1
    if m:
        _, first_tiny, _ = ldlt_unblocked(f, tolerance)
    x = np.empty_like(rhs)
    if first_tiny < 0:
        good = True
        for c in range(rhs.shape[1]):
            b = _column(rhs, c)
            xc = solve_transposed_1(f, b.copy())
            if not _all_finite(xc) or _residual_norm(t, xc, b) > LDLT_RESIDUAL * _norm(b):
                good = False
                break
            for i in range(m):
                x[i, c] = xc[i]
        if good:
            return x, True
    for c in range(rhs.shape[1]):
        xc, ok = band_lu_solve(t, _column(rhs, c))
        if not ok:
            return x, False
        for i in range(m):
            x[i, c] = xc[i]
    return x, True


@njit(cache=True)
def _factor_and_solve(t, rhs):
    """SymmetricBanded.cholesky then .solve for the columns of rhs (m, k): returns (x, ok,
    positive_definite, factor) with the Cholesky factor (empty where not positive definite)."""
    factor = t.copy()
    pd = band_cholesky(factor)
    if pd:
        x = np.empty_like(rhs)
        for c in range(rhs.shape[1]):
            xc = _column(rhs, c)
            band_cholesky_solve(factor, xc)
            for i in range(xc.shape[0]):
                x[i, c] = xc[i]
        return x, True, True, factor
    x, ok = _solve_indefinite(t, rhs)
    return x, ok, False, np.empty((0, 0))


@njit(cache=True)
def _max_scaled(v, scale):
    out = 0.0
    for i in range(v.shape[0]):
        out = max(out, abs(v[i] / scale[i]))
    return out


@njit(cache=True)
def _all_finite(v):
    for x in v:
        if not math.isfinite(x):
            return False
    return True


@njit(cache=True)
def _total(parts):
    total = 0.0
    for p in parts:
        total += p
    return total


def _newton_load_step(args, q, state, energy0, parts0, grad0, band0, start, stop, rscale, lscale,
                     residual_tol, step_tol, noise, max_iterations, max_line_search, give_up_after, give_up_ratio,
                     contraction_limit):
    """Plain Newton from q (clamped DOFs set) with its evaluation (energy0, parts0, grad0, band0;
    state: the committed frames). give_up_after < 0 or contraction_limit <= 0 switch those tests off.

    Returns (outcome, q, energy, parts, grad, band, state, iterations, residual, positive_definite,
    factor, accepted, trials, ratio, tiny_steps): the last accepted iterate and its evaluation and
    frames, the free Hessian's Cholesky factor there (transposed lower band; empty where not
    positive definite), the number of accepted iterates, the shortened steps tried, the last
    contraction ratio and the count of consecutive tiny corrections."""
    n = q.shape[0]
    q = q.copy()
    # a runtime True: numba types a constant argument as Literal[bool] and would compile a second
    # specialisation of rod_energy (the whole compiled energy again) for it
    everything = n > 0
    e, parts, grad, band = energy0, parts0, grad0, band0
    rs, ls = rscale[start:stop], lscale[start:stop]
    pd = False
    factor = np.empty((0, 0))
    tiny_steps, stall_residual = 0, np.inf
    trials, accepted_count = 0, 0
    fail_fast = give_up_after >= 0 and contraction_limit > 0.0
    previous_norm, previous_alpha, slow = -1.0, 1.0, 0
    first_residual = 0.0
    theta = 0.0
    res = np.inf
    for iteration in range(max_iterations + 1):
        if not _all_finite(grad):
            return (NON_FINITE, q, e, parts, grad, band, state, iteration, np.inf, pd, factor, accepted_count,
                    trials, theta, tiny_steps)
        r = grad[start:stop]
        res = _max_scaled(r, rs)
        t = _free_block(band, n, start, stop)
        rhs = np.empty((stop - start, 1))
        rhs[:, 0] = r
        solution, ok, pd, factor = _factor_and_solve(t, rhs)
        if res < residual_tol:
            return (CONVERGED, q, e, parts, grad, band, state, iteration, res, pd, factor, accepted_count, trials,
                    theta, tiny_steps)
        use_energy = pd
        if not ok:  # SymmetricBanded.solve raises LinAlgError (scipy's banded LU)
            return (SINGULAR, q, e, parts, grad, band, state, iteration, res, pd, factor, accepted_count, trials,
                    theta, tiny_steps)
        dq = -solution[:, 0]
        correction = _max_scaled(dq, ls)
        if correction < step_tol and res <= noise:  # converged to round-off (ddg.solve.newton.settled)
            return (ROUNDOFF, q, e, parts, grad, band, state, iteration, res, pd, factor, accepted_count, trials,
                    theta, tiny_steps + 1)
        if correction < step_tol:
            tiny_steps += 1
            if tiny_steps >= STALL_ITERATIONS and res > 0.5 * stall_residual:
                return (STALLED, q, e, parts, grad, band, state, iteration, res, pd, factor, accepted_count, trials,
                        theta, tiny_steps)
            if tiny_steps == 1:
                stall_residual = res
        else:
            tiny_steps = 0
        if iteration == max_iterations:
            break
        slope = np.dot(r, dq)
        norm = math.sqrt(abs(slope))
        if fail_fast and previous_norm >= 0.0 and res > noise:
            theta = norm / previous_norm if previous_norm > 0.0 else np.inf
            slow = slow + 1 if theta > contraction_limit else 0
            if theta > 1.0 - previous_alpha / 4.0 or slow >= 2:
                return (NOT_CONTRACTING, q, e, parts, grad, band, state, iteration, res, pd, factor, accepted_count,
                        trials, theta, tiny_steps)
        previous_norm = norm
        alpha = 1.0
        accepted = False
        q_try = q
        for trial in range(min(max_line_search, 10)):
            q_try = q.copy()
            for i in range(stop - start):
                q_try[start + i] += alpha * dq[i]
            full = trial == 0
            want_gradient = full or not use_energy
            g_try = np.zeros(n) if want_gradient else np.empty(0)
            b_try = np.zeros(band.shape[0]) if full else np.empty(0)
            p_try, s_try = energy(q_try, state, args, want_gradient, full, g_try, b_try)
            e_try = _total(p_try)
            if math.isfinite(e_try) and (not want_gradient or _all_finite(g_try)):
                if use_energy:
                    ok = e_try <= e + 1e-4 * alpha * min(slope, 0.0) + 1e-12 * abs(e)
                else:
                    ok = _max_scaled(g_try[start:stop], rs) <= (1.0 - 1e-4 * alpha) * res
                if ok:
                    accepted = True
                    if not full:
                        g_try = np.zeros(n)
                        b_try = np.zeros(band.shape[0])
                        p_try, s_try = energy(q_try, state, args, everything, everything, g_try, b_try)
                        e_try = _total(p_try)
                    break
            alpha *= 0.5
            trials += 1
        if not accepted:
            if tiny_steps > 0 and res <= noise:
                return (ROUNDOFF, q, e, parts, grad, band, state, iteration, res, pd, factor, accepted_count, trials,
                        theta, tiny_steps)
            return (LINE_SEARCH_FAILED, q, e, parts, grad, band, state, iteration + 1, res, pd, factor,
                    accepted_count, trials, theta, tiny_steps)
        if iteration == 0:
            first_residual = res
        if give_up_after >= 0 and iteration >= give_up_after and res > give_up_ratio * first_residual:
            return (NO_PROGRESS, q, e, parts, grad, band, state, iteration + 1, res, pd, factor, accepted_count,
                    trials, theta, tiny_steps)
        q, e, parts, grad, band, state = q_try, e_try, p_try, g_try, b_try, s_try
        accepted_count += 1
        previous_alpha = alpha
    res = _max_scaled(grad[start:stop], rs)
    return (NO_CONVERGENCE, q, e, parts, grad, band, state, max_iterations, res, pd, factor, accepted_count, trials,
            theta, tiny_steps)


@njit(cache=True)
def _inner(weight2, a_q, a_w, b_q, b_w, length):
    """ArclengthTracer.inner: (1/n) sum a_i b_i / l_i^2 + a_w b_w / L^2 (weight2 = 1 / (n l_i^2))."""
    total = 0.0
    for i in range(weight2.shape[0]):
        total += weight2[i] * a_q[i] * b_q[i]
    return total + a_w * b_w / (length * length)


def _arclength_correct(args, q, state, shear, band_size, clamp_base, clamp_rate, constrained, anchor_q,
                      anchor_shear, t_q, t_w, ds, weight2, length, start, stop, rscale, lscale, residual_tol,
                      step_tol, noise, max_iterations):
    """ddg.solve.arclength.ArclengthTracer._correct in one call: bordered Newton from the predicted
    (q, shear), the clamped DOFs `constrained` at clamp_base + shear clamp_rate.

    Returns (converged, q, shear, parts, grad, band, frames, positive_definite, factor, corrections):
    the last iterate, its evaluation and frames (committed after each correction), its free
    Hessian's Cholesky factor (empty where not positive definite) and the number of corrections
    made (each one evaluation)."""
    n = q.shape[0]
    q = q.copy()
    rate = np.zeros(n)
    for k in range(constrained.shape[0]):
        q[constrained[k]] = clamp_base[k] + shear * clamp_rate[k]
        rate[constrained[k]] = clamp_rate[k]
    grad = np.zeros(n)
    band = np.zeros(band_size)
    everything = n > 0   # a runtime True (see newton_load_step)
    # the predictor's frames are not committed: the first correction is transported from the
    # anchor's, as in the Python corrector (transport in time depends on the path it takes)
    parts, frames = energy(q, state, args, everything, everything, grad, band)
    first, correction = -1.0, np.inf
    rs, ls = rscale[start:stop], lscale[start:stop]
    m = stop - start
    factor = np.empty((0, 0))
    pd = False
    for iteration in range(max_iterations + 1):
        if not _all_finite(grad):
            return False, q, shear, parts, grad, band, frames, pd, factor, iteration
        r = grad[start:stop]
        res = _max_scaled(r, rs)
        arc = _inner(weight2, q[start:stop] - anchor_q, shear - anchor_shear, t_q, t_w, length) - ds
        t = _free_block(band, n, start, stop)
        w = t.shape[1]
        coupling = band_matvec(band.reshape(w, n), rate)[start:stop]
        rhs = np.empty((m, 2))
        rhs[:, 0] = -r
        rhs[:, 1] = -coupling
        solution, ok, pd, factor = _factor_and_solve(t, rhs)
        settled = res < residual_tol or (correction < step_tol and res <= noise)  # ddg.solve.newton.settled
        if settled and abs(arc) < 1e-8 * ds:
            return True, q, shear, parts, grad, band, frames, pd, factor, iteration
        if iteration == max_iterations or not ok:
            return False, q, shear, parts, grad, band, frames, pd, factor, iteration
        if first < 0.0:
            first = res
        if res > 1e3 * first:
            return False, q, shear, parts, grad, band, frames, pd, factor, iteration
        a = solution[:, 0].copy()
        b = solution[:, 1].copy()
        d_w = (-arc - _inner(weight2, a, 0.0, t_q, t_w, length)) / (_inner(weight2, b, 0.0, t_q, t_w, length)
                                                                      + t_w / length**2)
        step = a + b * d_w
        correction = _max_scaled(step, ls)
        for i in range(m):
            q[start + i] += step[i]
        shear += d_w
        for k in range(constrained.shape[0]):
            q[constrained[k]] = clamp_base[k] + shear * clamp_rate[k]
        grad = np.zeros(n)
        band = np.zeros(band_size)
        parts, frames = energy(q, state, args, everything, everything, grad, band)
        state = frames
    return False, q, shear, parts, grad, band, frames, pd, factor, max_iterations


class CompiledLoops(NamedTuple):
    """The two loops compiled with one energy: newton_load_step(args, q, state, ...) is
    _newton_load_step, arclength_correct(args, q, state, shear, ...) is _arclength_correct."""
    newton_load_step: Callable
    arclength_correct: Callable


def compile_loops(suffix: str, energy) -> CompiledLoops:
    """_newton_load_step and _arclength_correct bound to `energy` (a compiled function with the
    signature of ddg.models.rod_assembly.rod_energy), cached apart under `suffix`; each compiles on
    its first call."""
    return CompiledLoops(specialise(_newton_load_step, suffix, energy=energy),
                         specialise(_arclength_correct, suffix, energy=energy))
