"""Leaving a saddle and snapping past a fold (ddg.solve.continuation.PathFollower): the slide along
the critical mode on the wide rod, where the constrained branch bends too fast for a linear
predictor, and the rule that a snap's descent that did not converge is not repeated from the same
state at every shorter substep."""
import numpy as np
import pytest

import ddg
from ddg.api import make_model
from ddg.solve.continuation import ContinuationFailure, ContinuationOptions, PathFollower
from ddg.solve.newton import ROUNDOFF_STALL_FACTOR, NewtonOptions, NewtonResult, scaled_residual
from ddg.solve.state import phase_label


def compressed_follower(width_ratio: float, resolution: int):
    strip = ddg.Strip.from_ratios(width_ratio, 0.5)
    L = strip.length
    model = make_model("rod", strip, resolution)
    follower = PathFollower(model, ContinuationOptions(branch_switching=False))
    state = follower.start_compression(0.5 * L / 20)
    for k in range(2, 21):
        state = follower.advance(state, 0.5 * L * k / 20, 0.0)
    return model, follower, state, L


def test_the_slide_lands_on_us_on_the_wide_rod():
    """Rod M = 100 at W/L = 1/2 just past dW1 (0.3512 L): the constrained branch (amplitude along the
    critical mode held) bends so fast that Newton from a line through two solved points diverged
    beyond a = 0.008 L and the slide gave up (measured: then 127 iterations of pushes and descents).
    The quadratic through three points brackets the multiplier's root (a = 0.0225 L, measured) and
    lands on a stable US+ equilibrium."""
    model, follower, state, L = compressed_follower(0.5, 100)
    state = follower.advance(state, 0.5 * L, 0.3542 * L)  # on U past dW1, unstable
    assert not state.stable and phase_label(model, state.q, state.compression, state.shear) == "U"
    from ddg.solve.stability import lowest_modes

    _, modes = lowest_modes(model, state.evaluation.hessian, 1, vectors=True)
    mode = np.zeros(model.n_dof)
    mode[model.free] = modes[:, 0]
    mode /= np.max(np.abs(mode[model.node_dofs]))
    mode *= 1.0 if model.mode_sign(mode, 0) >= 0 else -1.0
    follower.options = ContinuationOptions()
    before = follower.iterations_by_phase["branch switching"]
    slid = follower._slide_along_mode(state, mode)
    spent = follower.iterations_by_phase["branch switching"] - before
    assert slid is not None and slid.stable
    assert phase_label(model, slid.q, slid.compression, slid.shear) == "US+"
    assert scaled_residual(model, slid.evaluation.gradient) <= max(NewtonOptions().residual_tol,
                                                                   ROUNDOFF_STALL_FACTOR * model.residual_floor())
    # measured 54 (with the line through two points: 82 and no landing)
    assert spent < 110, f"{spent} Newton iterations to leave the saddle"


def test_a_descent_that_does_not_converge_is_not_repeated_from_the_same_state(monkeypatch):
    """Where every load step fails near a hard spot, the snap's energy descent from the last state
    runs once, not once per halving of the substep (the paper's plate at L/b = 4000 spent 17 failed
    descents of 225 iterations each on its way to where its path stops, measured)."""
    model, follower, state, L = compressed_follower(0.05, 20)
    follower.options = ContinuationOptions()
    descents = []

    def failing_descent(model_, q, options=None, *, minimize=False, evaluation=None):
        assert minimize
        descents.append(1)
        ev = model_.evaluate(q)
        return NewtonResult(q, ev, False, 3, 1.0, False, "no convergence")

    monkeypatch.setattr(follower, "_step", lambda *args, **kwargs: None)  # every load step fails
    monkeypatch.setattr(follower, "_across_fold", lambda *args, **kwargs: None)
    monkeypatch.setattr("ddg.solve.continuation.newton", failing_descent)
    with pytest.raises(ContinuationFailure):
        follower.advance(state, state.compression, 0.01 * L)
    assert len(descents) == 1
