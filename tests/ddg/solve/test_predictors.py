"""The continuation predictors (ddg.solve.extrapolation): polynomial extrapolation of a branch from
its last equilibria, a cubic in the load for the recorded path, a quartic in arclength for branch
tracing. A branch that is itself such a polynomial is predicted exactly."""
import numpy as np
import pytest

import ddg
from ddg.models.rod import RodModel
from ddg.solve.continuation import PathFollower
from ddg.solve.extrapolation import (ARCLENGTH_PREDICTOR_POINTS, LOAD_PREDICTOR_POINTS, extrapolate,
                                     lagrange_weights)
from ddg.solve.state import State


@pytest.mark.parametrize("points", [2, 3, 4, 5])
def test_the_weights_reproduce_a_polynomial_of_one_degree_less_than_the_points(points):
    rng = np.random.default_rng(points)
    nodes = np.sort(rng.uniform(-1.0, 0.0, points))
    coefficients = rng.standard_normal(points)
    for target in (0.3, 1.0, -0.5):
        predicted = extrapolate(nodes, np.polyval(coefficients, nodes), target)
        # exact up to round-off: measured at most 2.3e-12 (five points, extrapolated to 1.0)
        assert predicted == pytest.approx(np.polyval(coefficients, target), rel=1e-11, abs=1e-11)
    assert lagrange_weights(nodes, 0.7).sum() == pytest.approx(1.0, abs=1e-11)  # reproduces constants


def test_extrapolation_works_on_arrays():
    nodes = [0.0, 1.0, 2.0]
    values = [np.array([0.0, 1.0]), np.array([1.0, 2.0]), np.array([4.0, 5.0])]  # t^2, t^2 + 1
    assert np.allclose(extrapolate(nodes, values, 3.0), [9.0, 10.0])


def test_the_load_path_predicts_a_cubic_branch_exactly():
    """Four equilibria of a branch whose DOFs are cubic in dW give the fifth exactly."""
    assert LOAD_PREDICTOR_POINTS == 4 and ARCLENGTH_PREDICTOR_POINTS == 5
    model = RodModel(ddg.Strip.from_ratios(0.05, 0.5), 10)
    follower = PathFollower(model)
    rng = np.random.default_rng(1)
    c = rng.standard_normal((4, model.n_dof))

    def q_at(w):
        return c[0] + w * c[1] + w**2 * c[2] + w**3 * c[3]

    for k, w in enumerate([0.0, 0.1, 0.15, 0.3]):
        follower.remember(State(q_at(w), None, 0.5, w, True), restart=(k == 0))
    assert np.allclose(follower._extrapolate(0.5, 0.42), q_at(0.42), rtol=1e-10, atol=1e-10)
