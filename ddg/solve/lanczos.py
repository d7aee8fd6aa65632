"""The lowest eigenvalue of K v = lambda D v for a positive definite banded K, from its Cholesky
factor: Lanczos on M = D^(1/2) K^-1 D^(1/2) (symmetric; its largest eigenvalue is 1 / lambda_min),
compiled (numba), with full reorthogonalisation.

Every recorded equilibrium's lambda_min (path.csv) is computed here when its free-DOF Hessian is
positive definite, which Newton has already proved by factorising it: the factor is reused, the
scaled matrix D^(-1/2) K D^(-1/2) is never formed nor factorised again. Each Lanczos step is two
banded triangular solves (4 n b flops). Convergence: the Ritz value's residual bound
|beta_m y_m| below `tolerance` times the Ritz value; `lowest_eigenvalue` returns None when it is
not reached in `max_steps` (the caller falls back to ARPACK).
"""
from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def _cholesky_solve(factor, x):
    """x <- (L L^T)^-1 x in place, L the lower band Cholesky factor (factor[d, j] = L[j + d, j])."""
    u = factor.shape[0] - 1
    n = factor.shape[1]
    for j in range(n):  # L y = x
        acc = x[j]
        for d in range(1, min(u, j) + 1):
            acc -= factor[d, j - d] * x[j - d]
        x[j] = acc / factor[0, j]
    for j in range(n - 1, -1, -1):  # L^T z = y
        acc = x[j]
        for d in range(1, min(u, n - 1 - j) + 1):
            acc -= factor[d, j] * x[j + d]
        x[j] = acc / factor[0, j]


@njit(cache=True)
def _largest_ritz(factor, root_metric, start, max_steps, tolerance):
    """Largest eigenvalue of M = S K^-1 S (S = diag(root_metric)) by Lanczos from `start` (unit);
    returns (theta, converged)."""
    n = factor.shape[1]
    m = min(max_steps, n)
    basis = np.zeros((m + 1, n))
    alpha = np.zeros(m)
    beta = np.zeros(m)
    basis[0] = start
    w = np.empty(n)
    theta = 0.0
    for k in range(m):
        for i in range(n):
            w[i] = root_metric[i] * basis[k, i]
        _cholesky_solve(factor, w)
        for i in range(n):
            w[i] *= root_metric[i]
        a = 0.0
        for i in range(n):
            a += w[i] * basis[k, i]
        alpha[k] = a
        # full reorthogonalisation (twice is enough)
        for _ in range(2):
            for j in range(k + 1):
                c = 0.0
                for i in range(n):
                    c += w[i] * basis[j, i]
                for i in range(n):
                    w[i] -= c * basis[j, i]
        b = np.sqrt(np.sum(w * w))
        beta[k] = b
        if k >= 2 and (k % 3 == 2 or k == m - 1 or b == 0.0):
            t = np.zeros((k + 1, k + 1))
            for j in range(k + 1):
                t[j, j] = alpha[j]
                if j < k:
                    t[j, j + 1] = beta[j]
                    t[j + 1, j] = beta[j]
            values, vectors = np.linalg.eigh(t)
            theta = values[k]
            if b * abs(vectors[k, k]) <= tolerance * abs(theta) or b == 0.0:
                return theta, True
        if b == 0.0 or k == m - 1:
            break
        for i in range(n):
            basis[k + 1, i] = w[i] / b
    return theta, False


_STARTS: dict[int, np.ndarray] = {}


def _start(n: int) -> np.ndarray:
    """A fixed pseudo-random unit start vector per size: a constant one has no component on the
    modes that are antisymmetric about the strip's middle (the critical mode of the pitchfork on
    the symmetric U branch), which Lanczos would then never find."""
    if n not in _STARTS:
        v = np.random.default_rng(20261124).standard_normal(n)
        _STARTS[n] = v / np.linalg.norm(v)
    return _STARTS[n]


def lowest_eigenvalue(cholesky_factor: np.ndarray, metric: np.ndarray, tolerance: float = 1e-12,
                      max_steps: int = 60) -> float | None:
    """lambda_min of K v = lambda D v (D = diag(metric)) from K's lower band Cholesky factor; None
    if Lanczos has not converged within max_steps."""
    factor = np.ascontiguousarray(cholesky_factor, dtype=float)
    theta, converged = _largest_ritz(factor, np.sqrt(np.asarray(metric, dtype=float)), _start(factor.shape[1]),
                                     max_steps, tolerance)
    if not converged or theta <= 0.0:
        return None
    return 1.0 / theta
