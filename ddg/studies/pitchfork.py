"""Why the direct Sadowsky ribbon misses dW1 (paper Appendix A, Fig. A.11): research diagnostics.

`pitchfork_analysis` compares the ribbon's lambda_min at the rod's pitchfork and the energy
barrier between the ribbon's U state and the US state reached from the rod, concentrated in the
quartic twist term at the inflection points (straight-line and drag estimates of the barrier).
"""
from __future__ import annotations

import numpy as np

from ..geometry.frames import cross, rowdot
from ..geometry.strip import LoadingProtocol, Strip
from ..api import simulate
from ..models.names import RIBBON, ROD
from ..solve.continuation import ContinuationFailure, ContinuationOptions
from .curvature_studies import states_at_shears
from ..solve.stability import lowest_modes
from ..solve.state import State
from ..analysis.observables import observe


#: Largest recorded load step of the paths (units of L): quasi-static, as the ribbon's U needs
PATH_STEP = 0.025


def same_state_in_frames(model, q_from: np.ndarray, frames_from, q: np.ndarray, frames) -> np.ndarray:
    """q (positions, twist angles in the reference frames `frames`) rewritten with twist angles
    measured from the reference frames `frames_from` of state q_from transported to q's
    tangents: the same material frames, so states of two runs can be interpolated."""
    saved = model.save_frames()
    try:
        model.restore_frames(frames)
        _, _, m1, _, _ = model.frames(q)
        model.restore_frames(frames_from)
        t, d1, _, _, _ = model.frames(q)
    finally:
        model.restore_frames(saved)
    d2 = cross(t, d1)
    out = q.copy()
    theta_from = q_from[model.theta_dofs]
    angle = np.arctan2(rowdot(m1, d2), rowdot(m1, d1))
    # the branch of the angle closest to the source's twist angles
    out[model.theta_dofs] = theta_from + np.remainder(angle - theta_from + np.pi, 2 * np.pi) - np.pi
    return out


def straight_line_barrier(model, a: State, frames_a, b: State, frames_b, samples: int = 41) -> dict:
    """Energy along the straight line in DOF space from equilibrium a to equilibrium b (b's twist
    angles re-expressed in a's frames): an upper bound on the barrier between them. Returns the
    fractions t, energies E(t) - E(a) and the quartic (Sadowsky) share of the energy change, and
    the node (s/L) whose quartic term rises most at the top of the path."""
    qb = same_state_in_frames(model, a.q, frames_a, b.q, frames_b)
    saved = model.save_frames()
    t = np.linspace(0.0, 1.0, samples)
    energy, quartic = np.zeros(samples), np.zeros(samples)
    try:
        model.restore_frames(frames_a)
        for k, tk in enumerate(t):
            ev = model.evaluate((1 - tk) * a.q + tk * qb, gradient=False, hessian=False)
            energy[k] = ev.energy
            quartic[k] = ev.parts.get("sadowsky", 0.0)
        top = int(np.argmax(energy))
        per_node = _quartic_per_node(model, (1 - t[top]) * a.q + t[top] * qb) - _quartic_per_node(model, a.q)
    finally:
        model.restore_frames(saved)
    s_nodes = model.centerline.node_arclength[1:-1] / model.strip.length
    return {"t": t, "energy": energy - energy[0], "quartic": quartic - quartic[0], "top": top,
            "barrier": float(energy[top] - energy[0]), "end_difference": float(energy[-1] - energy[0]),
            "peak_node_s_over_L": float(s_nodes[int(np.argmax(per_node))])}


def _drag(model, start: State, frames_start, end_q: np.ndarray, t: np.ndarray, iterations: int, tolerance: float):
    """Constrained minima along the line from start.q to end_q (twist angles in the start's
    frames): at each fraction t the energy is minimised on the hyperplane through the point at
    t normal to the line, continuing from the previous minimum. Energies, quartic parts, the
    worst projected residual (EI2 / L^2 units)."""
    free = model.free
    c = (end_q - start.q)[free]
    cc = float(c @ c)
    rscale = model.residual_scale()[free]
    energy, quartic = np.zeros(len(t)), np.zeros(len(t))
    worst = 0.0
    model.restore_frames(frames_start)
    q = start.q.copy()
    for k, tk in enumerate(t):
        target = start.q + tk * (end_q - start.q)
        q[free] += (c @ (target - q)[free]) / cc * c
        model.commit(q)
        ev = model.evaluate(q)
        shift = 0.0
        for _ in range(iterations):
            g = ev.gradient[free]
            residual = float(np.max(np.abs((g - (g @ c) / cc * c) / rscale)))
            if residual < tolerance:
                break
            K = model.free_matrix(ev.hessian)
            if not K.cholesky():
                shift = max(0.25 * shift, 1e-8 * K.mean_diagonal())
                while not K.shifted(shift).cholesky():
                    shift *= 4.0
                K = K.shifted(shift)
            u, v = K.solve(g), K.solve(c)
            dq = -(u - (c @ u) / (c @ v) * v)
            alpha, accepted = 1.0, False
            for _ in range(30):
                trial = q.copy()
                trial[free] += alpha * dq
                ev_trial = model.evaluate(trial)
                if ev_trial.energy <= ev.energy:
                    accepted = True
                    break
                alpha *= 0.5
            if not accepted:
                break
            q, ev = trial, ev_trial
            model.commit(q, ev)
        worst = max(worst, residual)
        energy[k] = ev.energy
        quartic[k] = ev.parts.get("sadowsky", 0.0)
    return energy, quartic, worst


def drag_barrier(model, a: State, frames_a, b: State, frames_b, samples: int = 21, iterations: int = 80,
                 tolerance: float = 1e-7) -> dict:
    """Energy barrier between equilibria a and b by the two-sided drag method: constrained minima
    on hyperplanes normal to the straight line from a to b, followed from a forwards and from b
    backwards (_drag). Each side rises in its own basin until it drops into the other; the
    barrier estimate is min over t of the larger of the two basin parts (over E(a)), rough: the
    drag method can jump between basins and miss the saddle.
    Returns t, both curves and their quartic parts (over E(a)), the estimate, the t where it
    sits, and the worst projected residual left."""
    qb = same_state_in_frames(model, a.q, frames_a, b.q, frames_b)
    qa_in_b = same_state_in_frames(model, b.q, frames_b, a.q, frames_a)
    saved = model.save_frames()
    t = np.linspace(0.0, 1.0, samples)
    try:
        e_fwd, q_fwd, w_fwd = _drag(model, a, frames_a, qb, t, iterations, tolerance)
        e_bwd, q_bwd, w_bwd = _drag(model, b, frames_b, qa_in_b, t, iterations, tolerance)
    finally:
        model.restore_frames(saved)
    e_bwd, q_bwd = e_bwd[::-1], q_bwd[::-1]  # backward fraction s = 1 - t
    # each curve describes its own basin only until its first marked drop (over a tenth of its
    # range: the drag fell into the other basin there); beyond it says nothing about the barrier
    def basin(curve):
        drops = np.flatnonzero(np.diff(curve) < -0.1 * np.ptp(curve))
        out = curve.copy()
        if drops.size:
            out[drops[0] + 1:] = np.inf
        return out

    upper = np.maximum(basin(e_fwd), basin(e_bwd[::-1])[::-1])
    top = int(np.argmin(upper))
    return {"t": t, "forward": e_fwd - e_fwd[0], "backward": e_bwd - e_fwd[0],
            "forward_quartic": q_fwd - q_fwd[0], "backward_quartic": q_bwd - q_fwd[0],
            "barrier": float(upper[top] - e_fwd[0]), "at_t": float(t[top]),
            "quartic_at_top": float((q_fwd if e_fwd[top] >= e_bwd[top] else q_bwd)[top] - q_fwd[0]),
            "worst_residual": max(w_fwd, w_bwd)}


def _quartic_per_node(model, q):
    from ..energies.rod_curvature import material_curvatures
    from ..energies.rod_twist import discrete_twist
    from ..energies.sadowsky import sadowsky_density

    x = q[model.node_dofs]
    _, _, m1, m2, m_ref = model.frames(q)
    kappa_n, _ = material_curvatures(x, m1, m2)
    tau = discrete_twist(q[model.theta_dofs], m_ref)
    return sadowsky_density(kappa_n, tau, model.voronoi_lengths, model.strip.bending_stiffness, model.zeta)[0]


def pitchfork_analysis(strip: Strip, compression_ratio: float = 0.5, zeta: float | None = None,
                       resolution: int = 101, beyond: float = 0.05, options: ContinuationOptions | None = None,
                       drag_samples: int = 0) -> dict:
    """Why the direct ribbon misses dW1 (all shears in units of L, energies in EI2 / L):

    - rod_dW1: the rod's pitchfork (lambda_min = 0 on its U branch, ddg.solve.thresholds);
    - rod_lambda_min / ribbon_lambda_min at rod_dW1: normalised lowest eigenvalues of both
      models' U states there (the ribbon's U branch followed directly from the flat strip);
    - at dW = rod_dW1 + beyond: the ribbon's U state (direct) and its US state (relaxed from the
      rod's US), their energies, H_mid, and the straight-line barrier between them (and, with
      drag_samples > 0, the two-sided drag estimate of the barrier, a constrained minimisation
      per sample).
    """
    options = options or ContinuationOptions()
    L = strip.length
    unit = strip.bending_stiffness / L
    lam = lambda m, s: float(lowest_modes(m, s.evaluation.hessian, 1)[0])  # noqa: E731
    # the rod's pitchfork: lambda_min = 0 on its U branch, located by the protocol's thresholds
    rod_run = simulate(strip, LoadingProtocol(compression_ratio), model=ROD, resolution=resolution, options=options,
                       branches=False)
    if rod_run.summary.get("dW1_over_L") is None:
        raise ContinuationFailure(f"the rod at W/L = {strip.width / L:g}, dL/L = {compression_ratio:g} has no "
                                  "pitchfork on its path: nothing to compare the ribbon with")
    dw1 = rod_run.summary["dW1_over_L"] * L
    target = dw1 + beyond * L
    shears = [dw1 / L, target / L]

    def along(model_name, **kw):
        """The (model, state, frames) at dW1 and beyond on the quasi-static path through the driver."""
        return [(m, st, m.save_frames()) for m, st in states_at_shears(
            model_name, strip, compression_ratio, shears, resolution, zeta=zeta, max_step=PATH_STEP,
            options=options, **kw)]

    (rod, rod_at, _), (_, rod_us, _) = along(ROD)
    rod_lam = lam(rod, rod_at)
    rod_height_beyond = float(rod.midpoint(rod_us.q)[2]) / L
    # the direct ribbon along its own path: at dW1 and beyond (U, metastable) ...
    (ribbon, rib_state, frames_at), (_, rib_u, frames_u) = along(RIBBON)
    ribbon.restore_frames(frames_at)
    rib_lam = lam(ribbon, rib_state)
    rib_phase_at = observe(ribbon, rib_state, "shear")["phase"]
    # ... and the ribbon relaxed from the rod's US beyond dW1, in the direct ribbon's model
    (_, _, _), (_, rib_us, frames_us) = along(RIBBON, ribbon_init=ROD)
    barrier = straight_line_barrier(ribbon, rib_u, frames_u, rib_us, frames_us)
    drag = drag_barrier(ribbon, rib_u, frames_u, rib_us, frames_us, drag_samples) if drag_samples else None
    ribbon.restore_frames(frames_u)
    row_u = observe(ribbon, rib_u, "shear")
    ribbon.restore_frames(frames_us)
    row_us = observe(ribbon, rib_us, "shear")
    top = barrier["top"]
    return {
        "rod_dW1_over_L": dw1 / L,
        "rod_lambda_min_at_rod_dW1": rod_lam,
        "ribbon_lambda_min_at_rod_dW1": rib_lam,
        "ribbon_phase_at_rod_dW1": rib_phase_at,
        "dW_over_L_beyond": target / L,
        "ribbon_U": {"phase": row_u["phase"], "H_mid_over_L": row_u["H_mid_over_L"], "lambda_min": row_u["lambda_min"],
                     "energy": rib_u.evaluation.energy / unit},
        "ribbon_from_rod": {"phase": row_us["phase"], "H_mid_over_L": row_us["H_mid_over_L"],
                            "lambda_min": row_us["lambda_min"], "energy": rib_us.evaluation.energy / unit},
        "rod_H_mid_over_L_beyond": rod_height_beyond,
        "straight_line_barrier": barrier["barrier"] / unit,
        "straight_line_barrier_quartic_share": (float(barrier["quartic"][top] / barrier["energy"][top])
                                                if barrier["energy"][top] > 0 else float("nan")),
        "barrier_peak_node_s_over_L": barrier["peak_node_s_over_L"],
        **({} if drag is None else {"drag_barrier": drag["barrier"] / unit,
                                    "drag_barrier_quartic": drag["quartic_at_top"] / unit,
                                     "drag_barrier_at_t": drag["at_t"], "drag_worst_residual": drag["worst_residual"]}),
    }
