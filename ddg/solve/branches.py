"""The bifurcation diagram of the shear stage: every branch, stable and unstable parts alike.

After the recorded path (which follows the stable branch), the branches are traced by
pseudo-arclength continuation in dW (ddg.solve.arclength), so folds are passed, not jumped:

- U: the symmetric branch from the compressed state, without branch switching, to dW_max; it
  turns unstable at the pitchfork dW1 (lambda_min < 0).
- US+ and US-: from the U state next to dW1, the first arclength step goes along plus and minus
  the critical mode at fixed dW (Keller's branch switching: no imperfection, no energy descent);
  each branch is then traced until it reaches the point-symmetric S branch (the shape is S) or
  dW_max. Where US folds (the narrow plate), the tracer goes round the fold and follows the
  unstable part back to S. Where the model maps a state onto its half turn (the rod layout without
  edge fields: model.half_turn), US- is US+ turned, each image checked an equilibrium of the same
  stability and the mirror phase, and traced only where a check fails.
- S+ (S- with branch_sign = -1): from the first S state of the recorded path, backwards as far as
  the branch goes and forwards to dW_max.

The two US branches are mirror images (the scene is invariant under the half turn about the
vertical axis through the midpoint between the clamps), which the tests check point by point.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .arclength import ArclengthOptions, ArclengthTracer
from .continuation import ContinuationOptions
from .newton import ROUNDOFF_STALL_FACTOR, scaled_residual
from .stability import lowest_modes
from .state import Snapshot, State, crosses, phase_of


#: Amplitude (root mean square of the shape change over L) of the first step off the pitchfork.
PITCHFORK_STEP = 2e-3


@dataclass
class Branch:
    name: str
    states: list[State] = field(default_factory=list)
    end: str = ""
    #: how its states were found: "pseudo-arclength", or "half turn of US+" (each image checked)
    source: str = "pseudo-arclength"

    def folds(self) -> list[float]:
        """dW (m) at the limit points: where the branch turns back in dW."""
        shear = np.array([s.shear for s in self.states])
        if shear.size < 3:
            return []
        step = np.diff(shear)
        turns = np.nonzero(step[:-1] * step[1:] < 0)[0] + 1
        return [float(shear[i]) for i in turns]


@dataclass
class BifurcationDiagram:
    branches: list[Branch]
    newton_iterations: int

    def summary(self, length: float) -> dict:
        """Per branch: points, dW/L range, folds (dW/L), how it ended and how it was found
        (source); for summary.json."""
        out = {}
        for b in self.branches:
            shear = [s.shear / length for s in b.states]
            out[b.name] = {"points": len(b.states),
                           "dW_over_L_range": [min(shear), max(shear)] if shear else None,
                           "folds_dW_over_L": [f / length for f in b.folds()],
                           "stable_points": int(sum(bool(s.stable) for s in b.states)),
                           "end": b.end,
                           "source": b.source}
        return out


def half_turn_branch(model, options: ContinuationOptions, branch: Branch) -> list[State] | None:
    """The half turn's image of every state of `branch` (model.half_turn: US+ onto US-), each
    evaluated and checked an equilibrium: its scaled residual within Newton's converged band
    (residual_tol, or ROUNDOFF_STALL_FACTOR times the model's floor estimate) and its phase the
    mirror of the original's. None where the model has no such map, a state kept no frames, or a
    check fails (the caller then traces the branch)."""
    turn = getattr(model, "half_turn", None)
    if turn is None or not branch.states:
        return None
    band = max(options.newton.residual_tol, ROUNDOFF_STALL_FACTOR * model.residual_floor())
    saved = model.save_frames()
    images = []
    try:
        for state in branch.states:
            mapped = turn(state.q, state.frames, state.compression, state.shear) if state.frames is not None else None
            if mapped is None:
                return None
            q, frames = mapped
            model.restore_frames(frames)
            ev = model.evaluate(q)
            image = State(q, ev, state.compression, state.shear, bool(model.free_matrix(ev.hessian).cholesky()),
                          frames=frames)
            mirror = {"US+": "US-", "US-": "US+"}.get(phase_of(model, state), phase_of(model, state))
            if scaled_residual(model, ev.gradient) > band or image.stable != state.stable or \
                    phase_of(model, image) != mirror:
                return None
            images.append(image)
    finally:
        model.restore_frames(saved)
    return images


def trace_branches(model, options: ContinuationOptions, compressed: Snapshot, shear_max: float,
                   first_s: Snapshot | None = None,
                   arclength: ArclengthOptions | None = None) -> "BifurcationDiagram":
    """Trace U, US+, US- (and S from first_s, a recorded S state) at the compression of the
    recorded state `compressed`, for shear between 0 and shear_max (signed). The branches carry
    their equilibria; their rows (branches.csv) are the caller's observation of them."""
    direction = 1.0 if shear_max >= 0 else -1.0
    lo, hi = sorted((0.0, shear_max))
    in_range = (lo - 1e-12, hi + 1e-12)
    tracer = ArclengthTracer(model, options.newton, arclength)
    branches: list[Branch] = []

    def finish(branch: Branch, states: list[State]) -> Branch:
        branch.states = states
        branches.append(branch)
        return branch

    # U: the symmetric branch, stable up to dW1
    model.restore_frames(compressed.frames)
    u_states, why = tracer.trace(compressed.state, direction, shear_range=in_range)
    u = finish(Branch("U", end=why), [compressed.state] + u_states)
    lam = np.array([float(lowest_modes(model, s.evaluation.hessian, 1)[0]) for s in u.states])
    crossing = np.nonzero((lam[:-1] > 0) & (lam[1:] <= 0))[0]
    if crossing.size:
        # branch switching at the pitchfork (Keller): from the U state next to it, the first
        # arclength step goes along plus or minus the critical mode at fixed dW (tangent (phi, 0));
        # the corrector lands on US with that amplitude, at its own dW
        k = int(crossing[0])
        near = u.states[k] if abs(lam[k]) <= abs(lam[k + 1]) else u.states[k + 1]
        _, modes = lowest_modes(model, near.evaluation.hessian, 1, vectors=True)
        mode = np.zeros(model.n_dof)
        mode[model.free] = modes[:, 0]
        if model.mode_sign(mode, 0) < 0:
            mode = -mode  # + raises the first half of the strip: the US+ side
        # the mode made orthogonal to U's own tangent (U states at another dW differ from `near`
        # by a field with a component along the mode: the symmetry centre moves with the clamp)
        u_q, u_w = tracer.tangent(near, direction=direction)
        phi = mode[model.free]
        along = tracer.inner(phi, 0.0, u_q, u_w)
        critical = (phi - along * u_q, -along * u_w)
        for sign, name in ((1.0, "US+"), (-1.0, "US-")):
            if name == "US-" and branches[-1].name == "US+":
                mirrored = half_turn_branch(model, options, branches[-1])
                if mirrored is not None:
                    finish(Branch(name, end=branches[-1].end, source="half turn of US+"), mirrored)
                    continue
            model.restore_frames(near.frames)
            tangent = tracer.normalise(sign * critical[0], sign * critical[1])
            # the US branches join S at the S branch's own pitchfork, and the tracer would go
            # through the junction onto the mirror branch: stop where H_mid changes sign
            first, _ = tracer.trace(near, tangent=tangent, shear_range=in_range, max_points=1,
                                    initial_step=PITCHFORK_STEP)
            if not first:
                branches.append(Branch(name, end="no US state found next to the pitchfork"))
                continue
            ahead, why = tracer.trace(first[0], tangent=tracer.tangent(first[0], previous=tangent),
                                      shear_range=in_range,
                                      stop=crosses(lambda st: model.midpoint(st.q)[2], first[0], "S", model))
            finish(Branch(name, end=why), first + ahead)
    if first_s is not None:
        state, frames = first_s.state, first_s.frames
        model.restore_frames(frames)
        back, _ = tracer.trace(state, -direction, shear_range=in_range, max_points=80)
        model.restore_frames(frames)
        ahead, why = tracer.trace(state, direction, shear_range=in_range)
        finish(Branch(phase_of(model, state) or "S", end=why), back[::-1] + [state] + ahead)
    return BifurcationDiagram(branches, tracer.newton_iterations)
