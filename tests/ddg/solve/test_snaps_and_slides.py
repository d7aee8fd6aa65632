"""Leaving a saddle and snapping past a fold (ddg.solve.continuation.PathFollower): the slide along
the critical mode on the wide rod, where the constrained branch bends too fast for a linear
predictor, and the rule that a snap's descent that did not converge is not repeated from the same
state at every shorter substep."""
import pytest

import ddg
from ddg.api import make_model
from ddg.solve.continuation import ContinuationFailure, ContinuationOptions, PathFollower
from ddg.solve.newton import ROUNDOFF_STALL_FACTOR, NewtonOptions, NewtonResult, scaled_residual
from ddg.solve.state import phase_label
from rod_states import compressed_state


def compressed_follower(width_ratio: float, resolution: int):
    model = make_model("rod", ddg.Strip.from_ratios(width_ratio, 0.5), resolution)
    follower = PathFollower(model, ContinuationOptions(branch_switching=False))
    return model, follower, compressed_state(follower)


def test_past_the_pitchfork_the_wide_rod_slides_onto_us():
    """Rod M = 100 at W/L = 1/2 just past dW1 on the unstable U: the constrained branch (amplitude
    along the critical mode held) bends fast in the amplitude, so its next point is predicted by a
    quadratic through three solved points; the slide brackets the multiplier's root and lands on a
    stable US+ equilibrium instead of giving up to the pushes and descents of the fallback."""
    model, follower, state = compressed_follower(0.5, 100)
    L = model.strip.length
    state = follower.advance(state, 0.5 * L, 0.3542 * L)  # dW1/L = 0.3512
    assert not state.stable and phase_label(model, state.q, state.compression, state.shear) == "U"
    follower.options = ContinuationOptions()
    before = follower.iterations_by_phase["branch switching"]
    slid = follower._ensure_stable(state, 0)
    spent = follower.iterations_by_phase["branch switching"] - before
    assert slid is not None and slid.stable
    assert phase_label(model, slid.q, slid.compression, slid.shear) == "US+"
    assert scaled_residual(model, slid.evaluation.gradient) <= max(NewtonOptions().residual_tol,
                                                                   ROUNDOFF_STALL_FACTOR * model.residual_floor())
    # the bound lies between the slide that lands and the fallback after a slide that gives up
    # (about 50 and 240 iterations here, before and after the quadratic predictor: docs/findings/measured.md)
    assert spent < 110, f"{spent} Newton iterations to leave the saddle"


def test_a_descent_that_does_not_converge_is_not_repeated_from_the_same_state(monkeypatch):
    """Where every load step fails near a hard spot, the snap's energy descent from the last state
    runs once, not once per halving of the substep."""
    model, follower, state = compressed_follower(0.05, 20)
    follower.options = ContinuationOptions()
    descents = []

    def failing_descent(model_, q, options=None, *, minimize=False, evaluation=None):
        assert minimize
        descents.append(1)
        return NewtonResult(q, model_.evaluate(q), False, 3, 1.0, False, "no convergence")

    monkeypatch.setattr(follower, "_step", lambda *args, **kwargs: None)  # every load step fails
    monkeypatch.setattr(follower, "_across_fold", lambda *args, **kwargs: None)
    monkeypatch.setattr("ddg.solve.continuation.newton", failing_descent)
    with pytest.raises(ContinuationFailure):
        follower.advance(state, state.compression, 0.01 * model.strip.length)
    assert len(descents) == 1
