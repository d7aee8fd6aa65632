"""Leaving an unstable or vanished equilibrium along a soft mode, with the amplitude controlled.

Where the strip snaps (a fold of the load path) or leaves a pitchfork, the way to the new stable
state runs along a long, curved valley of the energy: plain (modified) Newton descent moves
only ~5e-4 L per iteration there on a thin plate, because every straight step leaves the valley
and stretches the membrane. Here the amplitude a = phi . (q - q_ref) along the soft mode phi is
prescribed instead (a Lagrange multiplier mu enforces it; mu = dE/da is the generalised force
along the mode), and a is stepped until mu changes sign: each constrained problem is well
conditioned, the valley is followed in a few large steps, and the sign change brackets the new
equilibrium, which a final unconstrained Newton solve then converges to. Nothing depends on a
kick size: the branch is found, not guessed.

Bordered Newton step for g(q) - mu phi = 0, phi . (q - q_ref) = a:
    K u = -(g - mu phi),  K v = phi,  d_mu = (a - phi.(q - q_ref) - phi.u) / (phi.v),  dq = u + d_mu v.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .newton import NewtonOptions, NewtonResult, newton


@dataclass
class SlideOptions:
    first_step: float = 2e-3      # first amplitude step, relative to L
    largest_step: float = 0.05    # amplitude steps grow (x2 after easy solves) up to this, relative to L
    smallest_step: float = 1e-6   # give up below this
    farthest: float = 1.0         # give up beyond this total amplitude, relative to L
    constrained_iterations: int = 12
    easy_iterations: int = 4


class _Constrained:
    def __init__(self, model, mode, q_ref, options: NewtonOptions):
        self.model = model
        self.free = model.free
        phi = mode[model.free]
        self.phi = phi / float(phi @ phi)  # so that a = phi . dq is the amplitude of dq = a * mode
        self.q_ref = q_ref[model.free].copy()
        self.rscale = model.residual_scale()[model.free]
        self.tol = max(options.residual_tol, model.residual_floor())
        self.iterations = 0

    def amplitude(self, q) -> float:
        return float(self.phi @ (q[self.free] - self.q_ref))

    def solve(self, q, mu, a, max_iterations):
        """Constrained equilibrium at amplitude a from (q, mu); returns (q, mu, ev, its) or None."""
        model = self.model
        q = q.copy()
        ev = model.evaluate(q)
        best = np.inf
        for it in range(max_iterations + 1):
            r = ev.gradient[self.free] - mu * self.phi
            res = float(np.max(np.abs(r / self.rscale)))
            gap = a - self.amplitude(q)
            if res < self.tol and abs(gap) < 1e-12 * model.strip.length:
                self.iterations += it
                return q, mu, ev, it
            if it == max_iterations or not np.isfinite(res) or (it >= 4 and res > 10 * best):
                break
            best = min(best, res)
            K = model.free_matrix(ev.hessian)
            u = K.solve(-r)
            v = K.solve(self.phi)
            pv = float(self.phi @ v)
            if pv == 0.0 or not np.isfinite(pv):
                break
            d_mu = (gap - float(self.phi @ u)) / pv
            # damped: halve the step until the equilibrium residual falls (the constraint is
            # linear, so any fraction of the step keeps its share of the amplitude correction)
            for _ in range(12):
                q_try = q.copy()
                q_try[self.free] += u + d_mu * v
                ev_try = model.evaluate(q_try)
                res_try = float(np.max(np.abs((ev_try.gradient[self.free] - (mu + d_mu) * self.phi) / self.rscale)))
                if np.isfinite(res_try) and res_try < res:
                    break
                u, d_mu, v = 0.5 * u, 0.5 * d_mu, v
            q, mu, ev = q_try, mu + d_mu, ev_try
            model.commit(q)
        self.iterations += it
        return None

    def tangent(self, ev) -> np.ndarray:
        """dq_free/da on the constrained path: K^-1 phi / (phi . K^-1 phi)."""
        v = self.model.free_matrix(ev.hessian).solve(self.phi)
        return v / float(self.phi @ v)


def slide_along_mode(model, q_start: np.ndarray, mode: np.ndarray, direction: float | None = None,
                     newton_options: NewtonOptions | None = None,
                     options: SlideOptions | None = None) -> NewtonResult | None:
    """From q_start (clamps set), move along `mode` (n_dof, zero on the clamped DOFs, scaled so
    its largest nodal displacement is 1) to the nearest equilibrium downhill in energy.

    The valley curves away from the starting mode, so after every step the constraint direction
    is renewed to the secant of the last step (pseudo-arclength in the configuration space, at
    fixed load). direction: +1 / -1 to leave a saddle on that side (mu = 0 there); None to go
    downhill from a non-equilibrium start (past a fold). Returns the final Newton result
    (minimize=True, so it converges to a stable state if any) or None if nothing was bracketed.
    """
    newton_options = newton_options or NewtonOptions()
    options = options or SlideOptions()
    L = model.strip.length
    path = _Constrained(model, mode, q_start, newton_options)
    found = path.solve(q_start, 0.0, 0.0, options.constrained_iterations)
    if found is None:
        return None
    q, mu, ev, _ = found
    iterations = path.iterations
    if direction is None:
        if mu == 0.0:
            return None
        direction = -np.sign(mu)
    heading = direction * mode
    step, travelled = options.first_step * L, 0.0
    while travelled < options.farthest * L:
        path = _Constrained(model, heading, q, newton_options)
        g = ev.gradient[model.free]
        mu = float(g @ path.phi) / float(path.phi @ path.phi)  # dE/da along the new heading
        guess = q.copy()
        guess[model.free] += step * path.tangent(ev)
        found = path.solve(guess, mu, step, options.constrained_iterations)
        iterations += path.iterations
        if found is None:
            step *= 0.5
            if step < options.smallest_step * L:
                return None
            continue
        q_new, mu_new, ev_new, its = found
        if mu_new > 0.0 and mu < 0.0:
            # dE/da has turned uphill: the equilibrium lies within this step (secant guess)
            frac = mu / (mu - mu_new)
            root = path.solve(q + frac * (q_new - q), mu + frac * (mu_new - mu), frac * step,
                              options.constrained_iterations)
            iterations += path.iterations
            result = newton(model, root[0] if root is not None else q_new, newton_options, minimize=True)
            result.iterations += iterations
            return result
        heading = np.zeros(model.n_dof)
        heading[model.free] = q_new[model.free] - q[model.free]
        heading /= np.max(np.abs(heading[model.node_dofs]))
        q, ev = q_new, ev_new
        travelled += step
        if its <= options.easy_iterations:
            step = min(2.0 * step, options.largest_step * L)
    return None
