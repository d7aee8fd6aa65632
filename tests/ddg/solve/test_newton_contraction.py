"""Newton's optional fail-fast on contraction (NewtonOptions.contraction_limit, issue 31 item 2):
a load step outside Newton's basin is given up as soon as its corrections stop contracting,
instead of after the full iteration budget; inside the basin nothing changes."""
import numpy as np
import pytest

import ddg
from ddg.geometry.strip import InputError
from ddg.solve.newton import NewtonOptions, newton

SCENE = ddg.Strip.from_ratios(0.05, 0.5)


@pytest.fixture(scope="module")
def compressed_rod():
    """The rod (M = 40) compressed to dL/L = 1/2, on U."""
    r = ddg.simulate(SCENE, ddg.LoadingProtocol(0.5, 1e-4, compression_steps=10, shear_steps=1), model="rod",
                     resolution=40, thresholds=False, branches=False)
    return r.model, r.final_state


def _solve_at_shear(model, state, shear_ratio, limit):
    """Newton at dW = shear_ratio L from the compressed state itself (no predictor)."""
    saved = model.save_frames()
    q = model.apply_clamps(state.q, state.compression, shear_ratio * SCENE.length)
    try:
        return newton(model, q, NewtonOptions(contraction_limit=limit))
    finally:
        model.restore_frames(saved)


#: Without the contraction test a jump outside the basin spends at least this many iterations before
#: it is given up: twice the 4 the test allows. Measured 15 (the whole budget, "no convergence") at
#: every jump on the AMD EPYC the suite was written on; on an Intel Xeon, and here with
#: OPENBLAS_CORETYPE=Prescott, the jump to dW = 0.1 L fails its line search at the 14th instead: a
#: diverging iteration amplifies the BLAS kernels' round-off, so its count is not asserted.
MANY_ITERATIONS = 8


@pytest.mark.parametrize("shear_ratio", [0.05, 0.1, 0.2, 0.3])
def test_a_step_far_outside_the_basin_is_given_up_within_four_iterations(compressed_rod, shear_ratio):
    """With the test the jumps stop after 1-4 iterations (measured on five OpenBLAS kernels; the
    contraction ratios that stop them, 0.78-1.22, are far from the limit 0.5, so round-off does not
    move the decision); without it the same jumps run on, until the iteration budget or a failed
    line search ends them."""
    model, state = compressed_rod
    without = _solve_at_shear(model, state, shear_ratio, None)
    with_test = _solve_at_shear(model, state, shear_ratio, 0.5)
    assert not with_test.converged and with_test.iterations <= 4
    assert "not contracting" in with_test.message
    assert not without.converged and "not contracting" not in without.message
    assert without.iterations >= MANY_ITERATIONS, without.message


def test_a_step_inside_the_basin_is_the_same_with_and_without_the_test(compressed_rod):
    """Exact equality on purpose: a converging step on the same code path, and the test only reads
    the corrections' norms, so both solves do the same arithmetic on any CPU."""
    model, state = compressed_rod
    without = _solve_at_shear(model, state, 1e-3, None)
    with_test = _solve_at_shear(model, state, 1e-3, 0.5)
    assert without.converged and with_test.converged
    assert with_test.iterations == without.iterations
    assert np.array_equal(with_test.q, without.q)


def test_the_rods_path_with_the_test_has_the_same_thresholds_for_fewer_iterations():
    """Measured (M = 100, default scene): path 779 -> 698 iterations, threshold location 110 both
    (the fold that gives dW2 is found by pseudo-arclength, which the test does not touch); dW1
    moves by about 4e-9 L. Bound: issue 31's "results unchanged to 1e-6 L for the rod"."""
    def run(limit):
        options = ddg.ContinuationOptions(newton=NewtonOptions(contraction_limit=limit))
        return ddg.simulate(SCENE, ddg.LoadingProtocol(0.5), model="rod", resolution=100, options=options,
                            branches=False).summary

    off, on = run(None), run(0.5)
    assert on["status"] == off["status"] == "complete"
    assert on["dW1_over_L"] == pytest.approx(off["dW1_over_L"], abs=1e-6)
    assert on["dW2_over_L"] == pytest.approx(off["dW2_over_L"], abs=1e-6)
    assert on["newton_iterations"] < off["newton_iterations"]
    # threshold location does not use the test; it took 110 iterations both ways until the corrector
    # was compiled (issue 31 item 1), whose sums round differently at the fold: 110 against 109 since
    # (bound restated after that measurement: within 2 %, as tests/ddg/solve/test_compiled_newton.py).
    # Since round-off convergence is taken at the first tiny correction (issue 49) location takes
    # 56 and 58 iterations: the two paths' states differ at round-off, and one iteration more or less
    # in a bracketing solve is 2-4 % of so few; bound restated after that measurement: 2 % or 3.
    assert on["threshold_newton_iterations"] <= max(1.02 * off["threshold_newton_iterations"],
                                                    off["threshold_newton_iterations"] + 3)


@pytest.mark.parametrize("value", [0.0, -0.5, 1.5, float("nan"), True, "x"])
def test_a_bad_contraction_limit_is_refused_in_one_line(value):
    with pytest.raises(InputError, match="contraction_limit"):
        NewtonOptions(contraction_limit=value)


def test_the_default_is_on():
    assert NewtonOptions().contraction_limit == 0.5


def test_a_path_that_would_stop_with_the_test_retries_without_it(monkeypatch):
    """Before a path is given up the follower switches the fail-fast off and retries: here every
    solve that has the test on fails at once, and the path still completes, equal to a run with the
    test off (measured: identical; bound 1e-9 L, Newton's residual tolerance in the scaled units)."""
    import ddg.solve.continuation as continuation
    from ddg.solve.newton import NewtonResult

    real = continuation.newton
    refused, retried = [], []
    patient = 2 * NewtonOptions().max_iterations

    def refusing(model, q, options=None, **kwargs):
        load_step = not kwargs.get("minimize")
        if load_step and options.contraction_limit is None and options.max_iterations < patient:
            retried.append(1)  # a load step without the test and not patient: the retry
        elif not retried and (load_step or refused):
            # after the first buckled state every solve fails until the follower retries without the test
            refused.append(1)
            return NewtonResult(q, None, False, 1, float("inf"), None, "Newton corrections not contracting")
        return real(model, q, options, **kwargs)

    protocol = ddg.LoadingProtocol(0.5, 0.2, compression_steps=10, shear_steps=10)
    off = ddg.simulate(SCENE, protocol, model="rod", resolution=40, branches=False, thresholds=False,
                       options=ddg.ContinuationOptions(newton=NewtonOptions(contraction_limit=None)))
    monkeypatch.setattr(continuation, "newton", refusing)
    on = ddg.simulate(SCENE, protocol, model="rod", resolution=40, branches=False, thresholds=False)
    assert refused and retried and on.summary["status"] == "complete"
    assert on.summary["H_mid_over_L_compressed"] == pytest.approx(off.summary["H_mid_over_L_compressed"], abs=1e-9)
    assert on.rows[-1]["H_mid_over_L"] == pytest.approx(off.rows[-1]["H_mid_over_L"], abs=1e-9)
