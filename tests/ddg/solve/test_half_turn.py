"""The scene's half turn (about the vertical axis through the midpoint between the clamps) maps an
equilibrium onto an equilibrium: US+ onto US-, which branch tracing then takes instead of tracing
US- (ddg.models.rod.RodModel.half_turn, ddg.solve.branches.half_turn_branch)."""
import numpy as np
import pytest

import ddg
from ddg.api import make_model
from ddg.solve.branches import Branch, half_turn_branch
from ddg.solve.continuation import ContinuationOptions, PathFollower
from ddg.solve.newton import scaled_residual
from ddg.solve.state import phase_label
from rod_states import compressed_state


@pytest.fixture(scope="module", params=["rod", "ribbon-trapeze"])
def us_plus(request):
    """A stable US+ equilibrium (W/L = 1/20, dL/L = 1/2, dW/L = 0.4, 41 nodes) and its model."""
    strip = ddg.Strip.from_ratios(0.05, 0.5)
    L = strip.length
    model = make_model(request.param, strip, 41)
    follower = PathFollower(model, ContinuationOptions())
    state = compressed_state(follower)
    for k in range(1, 9):
        state = follower.advance(state, 0.5 * L, 0.05 * L * k)
    state.frames = model.save_frames()
    assert phase_label(model, state.q, state.compression, state.shear) == "US+"
    return model, state


def test_the_half_turn_of_US_plus_is_an_equilibrium_on_US_minus_with_the_same_energy(us_plus):
    model, state = us_plus
    q, frames = model.half_turn(state.q, state.frames, state.compression, state.shear)
    model.restore_frames(frames)
    image = model.evaluate(q)
    assert phase_label(model, q, state.compression, state.shear) == "US-"
    # the map permutes the same terms of the energy: equal up to the round-off of their sums
    assert image.energy == pytest.approx(state.evaluation.energy, rel=1e-12)
    # as converged as the original (measured equal to 2 digits: the map permutes the same terms)
    assert scaled_residual(model, image.gradient) < 10 * scaled_residual(model, state.evaluation.gradient) + 1e-12
    assert model.midpoint(q)[2] == pytest.approx(model.midpoint(state.q)[2], abs=1e-12)
    model.restore_frames(state.frames)


def test_turning_twice_is_the_identity(us_plus):
    model, state = us_plus
    once = model.half_turn(state.q, state.frames, state.compression, state.shear)
    q, frames = model.half_turn(*once, state.compression, state.shear)
    # exact but for the round-off of x -> c - (x - c) done twice (a few eps times L)
    assert np.max(np.abs(q - state.q)) < 1e-15 * model.strip.length + 1e-15
    for a, b in zip(frames, state.frames):
        assert np.max(np.abs(a - b)) < 1e-15


def test_an_image_that_is_not_an_equilibrium_is_refused(us_plus, monkeypatch):
    """half_turn_branch checks every image; one that is off (here the twist not reversed) makes it
    return None, and trace_branches then traces US- by pseudo-arclength."""
    model, state = us_plus
    assert half_turn_branch(model, ContinuationOptions(), Branch("US+", [state])) is not None
    turn = type(model).half_turn

    def wrong(self, q, frames, compression, shear):
        out, turned = turn(self, q, frames, compression, shear)
        out[self.theta_dofs] *= -1.0
        return out, turned

    monkeypatch.setattr(type(model), "half_turn", wrong)
    assert half_turn_branch(model, ContinuationOptions(), Branch("US+", [state])) is None
    model.restore_frames(state.frames)


def test_models_with_edge_fields_have_no_map():
    model = make_model("ribbon-cross-section", ddg.Strip.from_ratios(0.05, 0.5), 41)
    q = model.reset()
    assert model.half_turn(q, model.save_frames(), 0.0, 0.0) is None
