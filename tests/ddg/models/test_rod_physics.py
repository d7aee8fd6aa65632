"""The rod against exact solutions and the paper: elastica, Euler load, symmetry, thresholds."""

import numpy as np
import pytest
from scipy.optimize import brentq

import ddg
from ddg.analysis.analytic import (EULER_ANTISYMMETRIC, EULER_SYMMETRIC, clamped_elastica_force,
                          clamped_elastica_midpoint_height)
from ddg.models.rod import RodModel
from ddg.solve.newton import NewtonOptions
from ddg.solve.stability import lowest_modes


def compress(width_ratio, compression_ratio, nodes, steps=20):
    strip = ddg.Strip.from_ratios(width_ratio, compression_ratio)
    protocol = ddg.LoadingProtocol(compression_ratio, shear_ratio=0.0, compression_steps=steps)
    result = ddg.simulate(strip, protocol, model="rod", resolution=nodes)
    assert result.converged, result.summary["message"]
    return result


@pytest.mark.parametrize("compression_ratio", [0.25, 0.5])
def test_compressed_midpoint_height_matches_clamped_elastica(compression_ratio):
    result = compress(0.05, compression_ratio, 100)
    exact = clamped_elastica_midpoint_height(compression_ratio)
    error = abs(result.summary["H_mid_over_L_compressed"] - exact) / exact
    assert error < 2e-3


def test_elastica_error_falls_as_h_squared():
    nodes = np.array([24, 48, 96])
    exact = clamped_elastica_midpoint_height(0.5)
    errors = np.array([abs(compress(0.05, 0.5, m, steps=10).summary["H_mid_over_L_compressed"] - exact) for m in nodes])
    spacing = 1.0 / (nodes - 2)
    slope = np.polyfit(np.log(spacing), np.log(errors), 1)[0]
    assert 1.7 < slope < 2.3, (errors, slope)
    assert errors[-1] < 1e-3 * exact


def test_midpoint_height_depends_only_on_compression():
    """Inextensible limit: H_mid/L is independent of width, thickness and modulus (section 4.1)."""
    a = compress(0.05, 0.25, 60).summary["H_mid_over_L_compressed"]
    strip = ddg.Strip.from_ratios(0.2, 0.25, slenderness=600, young_modulus=3e9)
    b = ddg.simulate(strip, ddg.LoadingProtocol(0.25, shear_ratio=0.0, compression_steps=20), "rod", 60)
    # measured 2.1e-6 (the two strips' different extensibility at M = 60): 1e-5 is 4.8 times that
    assert abs(a - b.summary["H_mid_over_L_compressed"]) < 1e-5


def _straight_lowest_eigenvalues(rod, strain, count):
    """Lowest normalised eigenvalues of the uniformly compressed straight rod (an exact equilibrium)."""
    rod.reset()
    q = rod.rest_state()
    q[rod.node_dofs] *= 1.0 - strain
    ev = rod.evaluate(q)
    assert np.max(np.abs(ev.gradient[rod.free])) < 1e-6 * rod.strip.euler_load  # round-off of EA-sized terms
    return lowest_modes(rod, ev.hessian, count)


def test_straight_strip_loses_stability_at_clamped_euler_loads():
    """lambda_min crosses zero at P L^2/EI = 4 pi^2; the second eigenvalue at 80.763 (antisymmetric)."""
    strip = ddg.Strip.from_ratios(0.05, 0.5)
    rod = RodModel(strip, 100)
    ea, ei, L = strip.stretching_stiffness, strip.bending_stiffness, strip.length
    unit = ei / L**2 / ea  # strain at which P = EI / L^2

    def crossing(index):
        def f(p):
            return _straight_lowest_eigenvalues(rod, p * unit, index + 1)[index]

        return brentq(f, 0.5 * [EULER_SYMMETRIC, EULER_ANTISYMMETRIC][index],
                      1.5 * [EULER_SYMMETRIC, EULER_ANTISYMMETRIC][index], xtol=1e-6)

    # P = EA * strain exactly for the discrete straight rod. Measured -3.4e-4 and -6.3e-4 at M = 100
    # (the O(h^2) discretisation error; brentq's xtol 1e-6 is far below): bounds 4 times those
    assert abs(crossing(0) / EULER_SYMMETRIC - 1.0) < 1.5e-3
    assert abs(crossing(1) / EULER_ANTISYMMETRIC - 1.0) < 2.5e-3


def test_clamp_force_at_onset_of_buckling_is_euler_load():
    """On the buckled branch the compressive clamp force follows the elastica, P -> 4 pi^2 EI/L^2."""
    paper = ddg.Strip.from_ratios(0.05, 0.5)
    strip = ddg.Strip(length=paper.length, width=paper.width, thickness=paper.thickness)  # any dL/L may load it
    protocol = ddg.LoadingProtocol(0.01, shear_ratio=0.0, compression_steps=2)
    result = ddg.simulate(strip, protocol, "rod", 100)
    row = result.rows[-1]
    force = row["F_axial_norm"] * strip.force_unit * strip.length**2 / strip.bending_stiffness
    # measured -3.0e-4 against the exact elastica at M = 100 (discretisation): 1.2e-3 is 4 times that
    assert abs(force / clamped_elastica_force(row["dL_over_L"]) - 1.0) < 1.2e-3
    # measured +4.7e-3: the elastica's force at dL/L = 0.01 is above the onset load; 2e-2 is 4.2 times that
    assert abs(force / EULER_SYMMETRIC - 1.0) < 2e-2


def test_compression_alone_causes_no_lateral_motion():
    result = compress(0.05, 0.5, 40, steps=10)
    x = result.model.positions(result.final_state.q)
    assert np.max(np.abs(x[:, 1])) < 1e-12 * result.model.strip.length
    assert all(abs(r["F_shear_norm"]) < 1e-9 for r in result.rows)


def test_shearing_the_other_way_gives_the_mirror_image():
    strip = ddg.Strip.from_ratios(0.05, 0.5)
    shapes = []
    for sign in (1, -1):
        protocol = ddg.LoadingProtocol(0.5, shear_ratio=0.2, compression_steps=10, shear_steps=10, shear_sign=sign)
        result = ddg.simulate(strip, protocol, "rod", 40)
        assert result.converged
        shapes.append(result.model.positions(result.final_state.q))
    mirrored = shapes[1] * np.array([1.0, -1.0, 1.0])
    assert np.max(np.abs(shapes[0] - mirrored)) < 1e-9 * strip.length


def test_narrow_strip_passes_U_to_US_near_036_and_US_to_S_near_052():
    """Paper section 4.2, W/L = 1/20, dL/L = 1/2: dW1/L ~ 0.36, dW2/L ~ 0.52 (loose here)."""
    strip = ddg.Strip.from_ratios(0.05, 0.5)
    protocol = ddg.LoadingProtocol(0.5, shear_ratio=0.6, compression_steps=20, shear_steps=60)
    result = ddg.simulate(strip, protocol, "rod", 100)
    assert result.converged, result.summary["message"]
    shear = [r for r in result.rows if r["stage"] == "shear"]
    dw = np.array([r["dW_over_L"] for r in shear])
    h = np.array([r["H_mid_over_L"] for r in shear])
    switched = np.array([r["branch_switched"] for r in shear])
    assert all(r["stable"] for r in shear)
    dW1 = dw[np.argmax(switched)]
    assert switched.any() and abs(dW1 - 0.36) < 0.03
    # US -> S: the midpoint reaches the inflection (H_mid = 0) and stays there
    dW2 = dw[np.argmax(np.abs(h) < 1e-4 * 1.0)]
    assert abs(dW2 - 0.52) < 0.03
    # H = 0 on S by symmetry, to within Newton's step_tol (1e-10 L: a smaller correction at a residual
    # at round-off ends the solve): measured 7e-12 (9e-15 while round-off convergence took 3 more steps)
    assert np.all(np.abs(h[dw > dW2 + 0.01]) < NewtonOptions().step_tol)
    # before dW1 the midpoint barely drops; between the thresholds it falls to zero
    assert h[dw < 0.3].min() > 0.3 and h[(dw > dW1) & (dw < dW2)].max() < h[0]


def test_compression_lands_on_the_stable_buckled_branch_from_either_side():
    """The start guess only selects the side: buckling down is the exact mirror z -> -z of buckling up."""
    from ddg.solve.continuation import PathFollower

    strip = ddg.Strip.from_ratios(0.05, 0.25)
    heights = []
    for direction in (1, -1):
        rod = RodModel(strip, 50)
        state = PathFollower(rod).start_compression(0.02 * strip.length, direction)
        assert state.stable
        heights.append(rod.midpoint(state.q)[2])
    assert heights[0] > 0 and abs(heights[0] + heights[1]) < 1e-12 * strip.length
    # the straight state at the same compression is an equilibrium but unstable
    straight = _straight_lowest_eigenvalues(RodModel(strip, 50), 0.02, 1)
    assert straight[0] < 0


def test_the_eigenpairs_of_an_unstable_state_are_solved_once(monkeypatch):
    """An unstable state's lowest eigenpair, computed once for its lambda_min, is reused by a later
    request for the eigenvector on the same Hessian (branch switching, issue 31 item 2): one
    shift-invert Lanczos, the same eigenvalue and vector; a request for more eigenvalues solves
    again."""
    from ddg.solve.banded import SymmetricBanded

    rod = RodModel(ddg.Strip.from_ratios(0.05, 0.5), 60)
    ea, ei, L = rod.strip.stretching_stiffness, rod.strip.bending_stiffness, rod.strip.length
    q = rod.rest_state()
    q[rod.node_dofs] *= 1.0 - 60.0 * ei / L**2 / ea   # past the first Euler load 4 pi^2: unstable
    ev = rod.evaluate(q)
    calls = []
    solve = SymmetricBanded.lowest_eigenpairs
    monkeypatch.setattr(SymmetricBanded, "lowest_eigenpairs",
                        lambda self, *a, **k: calls.append(1) or solve(self, *a, **k))
    lam = lowest_modes(rod, ev.hessian, 1)
    assert lam[0] < 0 and len(calls) == 1
    again, vectors = lowest_modes(rod, ev.hessian, 1, vectors=True)
    assert len(calls) == 1 and again[0] == lam[0] and vectors.shape == (rod.free.stop - rod.free.start, 1)
    fresh = rod.evaluate(q)   # another evaluation: nothing kept on it
    w, v = lowest_modes(rod, fresh.hessian, 1, vectors=True)
    assert len(calls) == 2 and w[0] == lam[0] and np.array_equal(np.abs(v), np.abs(vectors))
    assert len(lowest_modes(rod, ev.hessian, 2)) == 2 and len(calls) == 3
