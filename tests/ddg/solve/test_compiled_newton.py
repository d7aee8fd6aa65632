"""The compiled Newton load step (ddg.solve.compiled_newton, issue 31 item 1) is ddg.solve.newton's
loop run in one compiled call: same iterations to the same states, same failures with the same
messages; and its pieces, the one-call assembly of the rod's energy (ddg.models.rod_assembly) and
LAPACK's band routines called from compiled code (ddg.solve.lapack), agree with what they replace."""
import re

import numpy as np
import pytest
import scipy.linalg as sla

import ddg
from ddg.models.ribbon import RibbonModel
from ddg.models.rod import RodModel
from ddg.models.wide_ribbons import CrossSectionRibbon, SanoWadaRibbon, TrapezeRibbon, WunderlichRibbon
from ddg.solve.compiled_newton import _solve_indefinite
from ddg.solve.lapack import band_cholesky, band_cholesky_solve, band_lu_solve
from ddg.solve.newton import NewtonOptions, newton

SCENE = ddg.Strip.from_ratios(0.05, 0.5)


def _random_band(rng, n, bandwidth, shift):
    """Lower band storage (bandwidth + 1, n) of a symmetric band matrix, and the dense matrix."""
    a = rng.standard_normal((n, n))
    a = a + a.T
    a[np.abs(np.subtract.outer(np.arange(n), np.arange(n))) > bandwidth] = 0.0
    a += shift * np.eye(n)
    band = np.zeros((bandwidth + 1, n))
    for d in range(bandwidth + 1):
        band[d, : n - d] = np.diagonal(a, -d)
    return band, a


def test_lapack_band_cholesky_and_solve_match_scipy():
    rng = np.random.default_rng(0)
    band, a = _random_band(rng, 60, 5, 40.0)
    t = np.ascontiguousarray(band.T)
    assert band_cholesky(t)
    assert np.allclose(t.T, sla.cholesky_banded(band, lower=True), rtol=1e-13, atol=1e-13)
    b = rng.standard_normal(60)
    x = b.copy()
    band_cholesky_solve(t, x)
    assert np.abs(a @ x - b).max() < 1e-12 * np.abs(b).max()


def test_lapack_band_cholesky_refuses_an_indefinite_matrix_and_lu_solves_it():
    rng = np.random.default_rng(1)
    band, a = _random_band(rng, 50, 4, 0.0)
    assert np.linalg.eigvalsh(a)[0] < 0
    assert not band_cholesky(np.ascontiguousarray(band.T))
    b = rng.standard_normal(50)
    x, ok = band_lu_solve(np.ascontiguousarray(band.T), b)
    assert ok and np.allclose(x, np.linalg.solve(a, b), rtol=1e-10, atol=1e-12)
    y, ok = _solve_indefinite(np.ascontiguousarray(band.T), np.column_stack([b, 2 * b]))
    assert ok and np.allclose(y[:, 0], np.linalg.solve(a, b), rtol=1e-10, atol=1e-12)
    assert np.allclose(y[:, 1], 2 * y[:, 0], rtol=1e-12, atol=1e-14)


def test_a_singular_band_is_reported_not_solved():
    band = np.zeros((3, 6))
    x, ok = band_lu_solve(np.ascontiguousarray(band.T), np.ones(6))
    assert not ok


def _curvature_gradient_cross_section(strip, nodes):
    return CrossSectionRibbon(strip, nodes, curvature_gradient=0.3)


@pytest.mark.parametrize("cls", [RodModel, RibbonModel, SanoWadaRibbon, TrapezeRibbon, WunderlichRibbon,
                                 CrossSectionRibbon, _curvature_gradient_cross_section])
def test_the_one_call_assembly_is_the_piecewise_one(cls):
    """Energy, gradient, Hessian and frames of rod_energy against the model's composition of the
    same pieces (evaluate_piecewise, the path checked against finite differences in
    tests/ddg/models/test_wide_ribbons.py and tests/ddg/energies/test_cross_section.py) at a random
    deformed state, frames transported from another: equal to the summation's round-off (measured 4e-16 relative for the
    rod; the wide ribbons sum their terms in another order)."""
    rng = np.random.default_rng(2)
    model = cls(SCENE, 41)
    # Wunderlich's energy is finite only below the pole |W eta'| = 2: a smaller perturbation
    noise = 1e-5 if cls is WunderlichRibbon else 1e-3
    q = model.buckled_guess(0.5 * SCENE.length) + noise * rng.standard_normal(model.n_dof)
    model.commit(q)
    q += noise * rng.standard_normal(model.n_dof)
    one = model.evaluate(q)
    assert np.isfinite(one.energy)
    pieces = model.evaluate_piecewise(q)
    assert one.parts.keys() == pieces.parts.keys()
    assert one.energy == pytest.approx(pieces.energy, rel=1e-14)
    scale = np.abs(pieces.gradient).max()
    assert np.abs(one.gradient - pieces.gradient).max() <= 1e-14 * scale
    assert np.abs(one.hessian.band - pieces.hessian.band).max() <= 1e-14 * np.abs(pieces.hessian.band).max()
    for a, b in zip(one.frames, pieces.frames):
        assert np.array_equal(a, b)


def test_a_model_with_terms_the_assembly_does_not_know_is_assembled_piecewise():
    """A model adding energies beyond Eq. (6) / (A.5) without their width terms must not take the
    rod's one-call assembly; every model of the package has one (issue 31 item 1)."""
    class Extra(RodModel):
        def coupled_terms(self, *args):
            return {"extra": 0.0}

    assert Extra(SCENE, 41).compiled_energy() is None
    for cls in (RodModel, RibbonModel, SanoWadaRibbon, TrapezeRibbon, WunderlichRibbon, CrossSectionRibbon):
        assert cls(SCENE, 41).compiled_energy() is not None


def _run(model_name, compiled, resolution):
    options = ddg.ContinuationOptions(newton=NewtonOptions(compiled=compiled))
    return ddg.simulate(SCENE, ddg.LoadingProtocol(0.5), model=model_name, resolution=resolution, options=options)


@pytest.mark.parametrize("model_name, resolution", [("rod", 60), ("ribbon", 61), ("ribbon-trapeze", 61)])
def test_the_compiled_loop_takes_the_same_path_as_the_python_loop(model_name, resolution):
    """The whole default path with its thresholds and branches: the same Newton iterations in every
    phase of the path, the same thresholds and H_mid.

    The load steps do the same arithmetic (measured: identical states). The corrector's inner
    product sums in another order than numpy's pairwise sum, so its states differ by round-off
    (measured 1e-15 L away from folds, 1e-11 L at the fold that gives dW2), and at the fold one
    convergence test may fall the other way: threshold location took 135 against 136 iterations
    at M = 60 (110 both at M = 100). Bounds: 1e-9 L on the thresholds (a thousand times the
    measured 1e-12, a millionth of dW2's bracket) and 2 % on the threshold iterations."""
    compiled, python = _run(model_name, True, resolution), _run(model_name, False, resolution)
    a, b = compiled.summary, python.summary
    assert a["status"] == b["status"] == "complete"
    # The fold snaps run the corrector, and the load steps after them start from its states, so a
    # step's decision (halve or not) may fall the other way on the round-off: the counts are compared
    # within 2 % (at least one iteration), as the threshold location's. Measured equal in every phase
    # with OpenBLAS's Cooperlake and Prescott kernels (the rod's whole path 771 and 770 iterations on
    # them: the counts move with the CPU, not with the loop).
    def close(x, y):
        return abs(x - y) <= max(1, 0.02 * y)

    assert close(a["newton_iterations"], b["newton_iterations"]), (a["newton_iterations"], b["newton_iterations"])
    by_a, by_b = a["newton_iterations_by_phase"], b["newton_iterations_by_phase"]
    assert by_a.keys() == by_b.keys() and all(close(by_a[k], by_b[k]) for k in by_b), (by_a, by_b)
    assert abs(a["threshold_newton_iterations"] - b["threshold_newton_iterations"]) <= \
        0.02 * b["threshold_newton_iterations"]
    for key in ("dW1_over_L", "dW2_over_L"):  # the Sadowsky ribbon stays on U here: both None
        assert (a[key] is None) == (b[key] is None)
        assert a[key] is None or abs(a[key] - b[key]) < 1e-9
    h_a, h_b = compiled.column("H_mid_over_L"), python.column("H_mid_over_L")
    assert len(h_a) == len(h_b) and np.abs(np.asarray(h_a) - np.asarray(h_b)).max() < 1e-9
    assert len(compiled.branch_rows) == len(python.branch_rows)


@pytest.fixture(scope="module")
def compressed_rod():
    r = ddg.simulate(SCENE, ddg.LoadingProtocol(0.5, 1e-4, compression_steps=10, shear_steps=1), model="rod",
                     resolution=40, thresholds=False, branches=False)
    return r.model, r.final_state


def _ending(result):
    """How a solve ended: converged or not, the test that ended it (its message without the measured
    ratio) and that ratio, if any."""
    ratio = re.search(r" \(ratio ([^)]*)\)", result.message)
    return result.converged, re.sub(r" \(ratio [^)]*\)", "", result.message), ratio and float(ratio.group(1))


def assert_ends_the_same_way(a, b, length_scale, state_bound, energy_bound, minimisation=False):
    """Two solves of one step, on the compiled and the Python loop (or assembly): the same ending and,
    where they took the same decisions, the same iterations, line-search trials and state (within the
    bounds, in Newton's units, model.length_scale).

    A converged load step is well conditioned: it must take the same decisions. A step that diverges
    amplifies any round-off difference between the two sides' sums (none where both call the same
    kernels and BLAS, as the rod's do: measured identical states), and so does a minimisation through
    indefinite Hessians (its shifts are found by trial factorisations): there a line search or a
    trial may decide the other way (issue 47: no exact count of a diverging or ill-conditioned
    computation across code paths). Then a load step must still give up on both sides, and a
    minimisation still converge on both to the same minimum, whose energy is second order in the
    state's error (to 1e-12 relative, as when the decisions agree)."""
    same_decisions = (a.iterations, a.line_search_trials) == (b.iterations, b.line_search_trials)
    assert a.converged == b.converged, (a.message, b.message)
    if same_decisions or (a.converged and not minimisation):
        assert same_decisions, (a.iterations, a.line_search_trials, b.iterations, b.line_search_trials)
        (_, ends_a, ratio_a), (_, ends_b, ratio_b) = _ending(a), _ending(b)
        assert ends_a == ends_b and a.positive_definite == b.positive_definite, (a.message, b.message)
        # the ratio printed to 3 digits, from states that may differ by the bound: compared, not matched
        assert (ratio_a is None) == (ratio_b is None) and (ratio_a is None or abs(ratio_a - ratio_b) <= 0.01 * ratio_b)
        assert np.abs((a.q - b.q) / length_scale).max() <= state_bound
        assert a.evaluation.energy == pytest.approx(b.evaluation.energy, rel=energy_bound)
    elif a.converged:
        assert a.message == b.message and a.evaluation.energy == pytest.approx(b.evaluation.energy, rel=1e-12)


@pytest.mark.parametrize("shear_ratio, limit, give_up", [(1e-3, 0.5, 4), (0.2, 0.5, 4), (0.2, None, 4),
                                                          (0.2, None, None), (0.05, None, 2)])
def test_a_load_step_ends_the_same_way_in_both_loops(compressed_rod, shear_ratio, limit, give_up):
    """Converged, not contracting, no progress, no convergence or a failed line search: the same
    outcome, message, iterations and state, and the same committed frames afterwards. Both loops do
    the same arithmetic here (measured: identical states with four OpenBLAS kernels, even after the
    15 diverging iterations), so the bounds are round-off's; assert_ends_the_same_way says what is
    asserted where a platform's two loops did not."""
    model, state = compressed_rod
    q = model.apply_clamps(state.q, state.compression, shear_ratio * SCENE.length)
    results, frames = [], []
    for compiled in (True, False):
        saved = model.save_frames()
        options = NewtonOptions(contraction_limit=limit, give_up_after=give_up, compiled=compiled)
        results.append(newton(model, q, options))
        frames.append(model.save_frames())
        model.restore_frames(saved)
    a, b = results
    assert_ends_the_same_way(a, b, SCENE.length, 1e-12, 1e-12)
    if (a.iterations, a.line_search_trials) == (b.iterations, b.line_search_trials):
        for x, y in zip(*frames):
            assert np.abs(x - y).max() <= 1e-12


@pytest.mark.parametrize("model_name", ["ribbon-trapeze", "ribbon-wunderlich", "ribbon-cross-section"])
def test_the_wide_ribbons_load_steps_are_the_same_in_both_loops(model_name):
    """The ribbons with width take the compiled loop too (their terms in rod_energy): a load step
    from the compressed U, small (converges) and large (gives up, not contracting, in the three
    models), ends with the same outcome, iterations and state as the Python loop on the piecewise
    composition (assert_ends_the_same_way)."""
    r = ddg.simulate(SCENE, ddg.LoadingProtocol(0.5, 1e-4, compression_steps=10, shear_steps=1), model=model_name,
                     resolution=31, thresholds=False, branches=False)
    model, state = r.model, r.final_state
    converged = []
    for shear_ratio in (2e-4, 0.05):   # from the final state at 1e-4 L: a tenth of a shear step, and a jump
        q = model.apply_clamps(state.q, state.compression, shear_ratio * SCENE.length)
        results = []
        for compiled in (True, False):
            saved = model.save_frames()
            model._assembly_args = None if compiled else ()   # None: rebuilt; (): the piecewise composition
            results.append(newton(model, q, NewtonOptions(compiled=compiled)))
            model.restore_frames(saved)
        a, b = results
        converged.append(a.converged)
        # the two assemblies sum in different orders (1e-16 relative: converged states measured
        # within 4.4e-16 and energies 5.6e-16, bounds 1e-12 as the rod's loops above); a solve that
        # gives up ends after iterations that amplify that: measured up to 1.5e-10 in Newton's units
        # (model.length_scale: L for positions, 1 for angles) and 3.7e-10 relative in the energy
        # (the Wunderlich ribbon, over OpenBLAS's Cooperlake, Haswell, Prescott and Atom kernels:
        # the amplified round-off moves with the CPU); bounds 1e-9 and 2e-9, 6.7 and 5.4 times those
        state_bound, energy_bound = (1e-12, 1e-12) if a.converged else (1e-9, 2e-9)
        assert_ends_the_same_way(a, b, model.length_scale(), state_bound, energy_bound)
    assert converged[0]   # the small step converges; the large one may give up (the contraction test)


@pytest.mark.parametrize("model_name", ["rod", "ribbon-trapeze", "ribbon-wunderlich", "ribbon-cross-section"])
def test_a_minimisation_ends_the_same_way_on_both_assemblies(model_name):
    """newton(minimize=True), the trust-region descent of the fold snaps and branch switching (a
    Python loop, ddg.solve.trust_region), on the one-call assembly and on the piecewise composition:
    from the compressed U sheared by a jump (the step the load steps give up on) and from the U
    pushed off at random (1e-5 L), the same outcome, iterations, refused steps and state
    (assert_ends_the_same_way)."""
    r = ddg.simulate(SCENE, ddg.LoadingProtocol(0.5, 1e-4, compression_steps=10, shear_steps=1), model=model_name,
                     resolution=31, thresholds=False, branches=False)
    model, state = r.model, r.final_state
    rng = np.random.default_rng(4)
    pushed = state.q.copy()
    pushed[model.free] += 1e-5 * SCENE.length * rng.standard_normal(model.free.stop - model.free.start)
    for q in (model.apply_clamps(state.q, state.compression, 0.05 * SCENE.length), pushed):
        results = []
        for compiled in (True, False):
            saved = model.save_frames()
            model._assembly_args = None if compiled else ()
            results.append(newton(model, q, NewtonOptions(compiled=compiled), minimize=True))
            model.restore_frames(saved)
        a, b = results
        assert a.converged
        # the wide ribbons' two assemblies sum in different orders (1e-16 relative), which the
        # descent's 26-30 iterations amplify: measured with the trust-region descent 4.5e-12, 2.7e-13
        # and 0 (trapeze, Wunderlich, cross-section, in the units of Newton's corrections,
        # model.length_scale: L for positions, 1 for angles; the Levenberg-Marquardt loop before it
        # gave 1.7e-13, 6.0e-13 and 8.5e-14); bound 1.5e-11, 3.4 times the largest. The rod's
        # assemblies agree to 4e-16 (measured 0): 1e-12
        bound = 1e-12 if model_name == "rod" else 1.5e-11
        assert_ends_the_same_way(a, b, model.length_scale(), bound, 1e-12, minimisation=True)


def test_the_factor_made_by_the_loop_is_the_stability_tests(compressed_rod):
    """The converged state's free Hessian carries the Cholesky factor the loop made (item 1: the
    stability test from the factorisation already made), equal to scipy's."""
    model, state = compressed_rod
    q = model.apply_clamps(state.q, state.compression, 1e-3 * SCENE.length)
    saved = model.save_frames()
    result = newton(model, q, NewtonOptions())
    model.restore_frames(saved)
    assert result.converged and result.positive_definite
    block = model.free_matrix(result.evaluation.hessian)
    assert block._cholesky_tried and block._cholesky is not None
    reference = sla.cholesky_banded(block.band, lower=True)
    assert np.abs(block._cholesky - reference).max() <= 1e-12 * np.abs(reference).max()
