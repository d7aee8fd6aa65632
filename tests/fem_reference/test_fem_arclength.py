"""Pseudo-arclength in the shear for the shell (fem_reference.solver.Solver.arclength_correct,
shear_tangent) and the trace across a fold (fem_reference.continuation.trace_across_fold, issue 31
item 4): the corrector's states are the equilibria natural continuation finds at their dW, the
tangent is the branch's derivative, and a trace that does not end in a snap leaves the model where
it started. Skipped where dolfinx is not installed (CI installs it)."""
from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("dolfinx", reason="fem_reference needs dolfinx (Debian python3-dolfinx, scripts/setup.sh)")
pytest.importorskip("slepc4py", reason="fem_reference needs slepc4py (Debian python3-slepc4py, scripts/setup.sh)")

from test_fem_reference import _compress, _model  # noqa: E402

COMPRESSION, SHEAR = 0.5, 0.05


@pytest.fixture(scope="module")
def sheared():
    """W/L = 1/6, dL/L = 1/2, dW/L = 0.05 on the fast tests' mesh (24 x 10), on U (stable)."""
    model, solver, stepper = _model(1 / 6, COMPRESSION)
    _compress(model, solver, stepper, COMPRESSION)
    stepper.advance((COMPRESSION, SHEAR))
    return model, solver, stepper, model.get_state()


def _newton_at(model, solver, state, shear):
    model.set_state(state)
    model.set_clamp(COMPRESSION, shear)
    solver.newton()
    return model.get_state()


def test_the_corrector_lands_on_the_equilibrium_newton_finds_at_its_shear(sheared):
    """Measured: 5 corrections, the state within 5e-9 L of Newton's at the same dW (each converged
    to a correction below 1e-10 L; bound 10 times the measured difference)."""
    model, solver, stepper, state = sheared
    weight = 1.0 / state.size
    model.set_state(state)
    model.set_clamp(COMPRESSION, SHEAR)
    t_q, t_w = solver.shear_tangent(COMPRESSION, SHEAR, weight)
    ds = 0.01
    model.set_state(state + ds * t_q)
    iterations, shear = solver.arclength_correct(COMPRESSION, SHEAR + ds * t_w, state, SHEAR, (t_q, t_w), ds, weight)
    traced = model.get_state()
    assert iterations <= 8
    arc = weight * np.dot(traced - state, t_q) + (shear - SHEAR) * t_w
    assert arc == pytest.approx(ds, rel=1e-8)
    assert shear > SHEAR  # oriented with dW > 0
    assert np.max(np.abs(traced - _newton_at(model, solver, state, shear))) < 5e-8


def test_the_tangent_is_the_derivative_of_the_branch(sheared):
    """dq/dW from K dq = -dR/dW against central differences of Newton's states at dW +- 1e-4 L
    (their error O(h^2) ~ 1e-8 relative; bound 1e-4 of the derivative's size)."""
    model, solver, stepper, state = sheared
    weight = 1.0 / state.size
    model.set_state(state)
    model.set_clamp(COMPRESSION, SHEAR)
    t_q, t_w = solver.shear_tangent(COMPRESSION, SHEAR, weight)
    h = 1e-4
    plus, minus = _newton_at(model, solver, state, SHEAR + h), _newton_at(model, solver, state, SHEAR - h)
    derivative = (plus - minus) / (2 * h)
    assert np.max(np.abs(t_q / t_w - derivative)) < 1e-4 * np.max(np.abs(derivative))


def test_a_trace_that_does_not_snap_leaves_the_model_where_it_started(sheared):
    """Along a stable branch with no fold the trace finds no stable state after an unstable one:
    it gives up after its states, and the model is back at its start, state and clamp."""
    import fem_reference.continuation as continuation

    model, solver, stepper, state = sheared
    stepper.restore((COMPRESSION, SHEAR), state)
    saved = continuation.FOLD_TRACE_POINTS
    continuation.FOLD_TRACE_POINTS = 3
    try:
        assert continuation.trace_across_fold(stepper, (COMPRESSION, SHEAR + 0.02)) is None
    finally:
        continuation.FOLD_TRACE_POINTS = saved
    record = stepper.fold_traces[-1]
    assert record["states"] == 3 and "without a stable state" in record["outcome"]
    assert np.array_equal(model.get_state(), state) and model.clamp == (COMPRESSION, SHEAR)


def test_a_failed_fold_trace_is_not_retried_next_to_where_it_failed(sheared):
    """The shell on 96 x 12 at L/b = 4000 started 8 traces of up to 200 states within 1e-4 L, one
    per tiny converged substep: after a trace finds no snap, none starts within FOLD_TRACE_RETRY
    (1e-3 L, dW2's bracket) of it, nor twice from one state."""
    from fem_reference.continuation import FOLD_TRACE_RETRY

    model, solver, stepper, state = sheared
    stepper._fold_trace_failed_at, stepper._fold_traced_from = None, None
    assert stepper.may_trace_fold((COMPRESSION, SHEAR))
    stepper._fold_traced_from = (COMPRESSION, SHEAR)
    assert not stepper.may_trace_fold((COMPRESSION, SHEAR))
    stepper._fold_trace_failed_at = SHEAR
    assert not stepper.may_trace_fold((COMPRESSION, SHEAR + 0.5 * FOLD_TRACE_RETRY))
    assert stepper.may_trace_fold((COMPRESSION, SHEAR + 2.0 * FOLD_TRACE_RETRY))
    stepper._fold_trace_failed_at, stepper._fold_traced_from = None, None


def test_a_residual_stalled_at_round_off_is_convergence(sheared):
    """Newton with the residual and correction tests off (atol = rtol = dx_tol = 0) can only end by
    the round-off acceptance (Solver._at_roundoff, needed next to singular tangents at L/b = 4000):
    from the state at a neighbouring dW it ends within the floor, on the equilibrium the usual tests find
    (measured: 1.1e-12 L apart, the stall at 9e-8 within the floor 3e-7; bound 1e-11 L, ten times
    the measured: both states are round-off apart); with the floor set below the stall
    the same solve fails after max_iterations instead of accepting."""
    import dataclasses

    from fem_reference.solver import NewtonFailure

    model, solver, stepper, state = sheared
    usual = solver.options
    shear = SHEAR + 1e-3
    try:
        expected = _newton_at(model, solver, state, shear)
        solver.options = dataclasses.replace(usual, atol=0.0, rtol=0.0, dx_tol=0.0)
        accepted = solver.roundoff_convergences
        found = _newton_at(model, solver, state, shear)
        assert solver.roundoff_convergences == accepted + 1
        assert np.linalg.norm(solver.assemble_residual().array) <= solver.residual_floor
        assert np.max(np.abs(found - expected)) < 1e-11
        floor, solver.residual_floor = solver.residual_floor, 0.0
        try:
            with pytest.raises(NewtonFailure, match="no convergence"):
                _newton_at(model, solver, state, shear)
        finally:
            solver.residual_floor = floor
    finally:
        solver.options = usual
        model.set_state(state)
        model.set_clamp(COMPRESSION, SHEAR)
