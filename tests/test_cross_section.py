"""The relaxed cross-section (ddg.energies.cross_section, issue 30): the least energy of a strip's
cross-section against a direct solution of its boundary value problem, its limits (the trapeze
ribbon at an inflection point or for a narrow strip, Sadowsky's ribbon for a wide one), its series
and closed form, and the convex envelope at the inflection points.
"""
from __future__ import annotations

import mpmath
import numpy as np
import pytest
from scipy.integrate import solve_bvp

from ddg.energies.cross_section import (SERIES_BELOW, cross_section_coefficients, cross_section_density,
                                        foundation_share, psi, relaxed_share, well_bottom)


def share_by_collocation(k: float) -> float:
    """Phi(k) from the cross-section problem itself: on eta in [0, 1/2] (the even half), h'''' +
    4 k^4 h = mu with h'(0) = h'''(0) = 0, h''(1/2) = -1, h'''(1/2) = 0 and zero mean fixing mu;
    Phi = int 4 k^4 h^2 + (h'' + 1)^2 over the width (scipy's collocation solver)."""
    def rhs(eta, y, p):
        return np.vstack([y[1], y[2], y[3], p[0] - 4.0 * k**4 * y[0], y[0]])

    def bc(ya, yb, p):
        return np.array([ya[1], ya[3], yb[2] + 1.0, yb[3], ya[4], yb[4]])

    eta = np.linspace(0.0, 0.5, 401)
    guess = np.zeros((5, eta.size))
    guess[0] = -eta**2 / 2 + 1.0 / 24.0
    guess[1], guess[2] = -eta, -1.0
    sol = solve_bvp(rhs, bc, eta, guess, p=[0.0], tol=1e-10, max_nodes=200000)
    assert sol.success, sol.message
    fine = np.linspace(0.0, 0.5, 20001)
    h, h2 = sol.sol(fine)[0], sol.sol(fine)[2]
    return 2.0 * np.trapz(4.0 * k**4 * h**2 + (h2 + 1.0) ** 2, fine)


@pytest.mark.parametrize("k", [0.8, 1.5, 3.0, 6.0, 12.0])
def test_closed_form_share_is_the_least_energy_of_the_cross_section(k):
    """Phi(k) = 1 - (2/k)(cosh k - cos k)/(sinh k + sin k) against the boundary value problem solved
    by collocation: measured relative differences 1e-9 .. 4e-8 (the quadrature of the solution)."""
    assert foundation_share(np.array([k]))[0][0] == pytest.approx(share_by_collocation(k), rel=2e-7)


def test_series_and_closed_form_agree_with_high_precision_arithmetic():
    """Psi(s) = Phi(s^1/4)/s evaluated with 40 digits (mpmath) against the series (s < 4) and the
    closed form (s >= 4): relative errors measured below 3e-15 and 2e-13; the two branches meet
    at SERIES_BELOW in value and both derivatives."""
    mpmath.mp.dps = 40

    def exact(s):
        k = mpmath.mpf(s) ** mpmath.mpf(0.25)
        return (1 - 2 / k * (mpmath.cosh(k) - mpmath.cos(k)) / (mpmath.sinh(k) + mpmath.sin(k))) / mpmath.mpf(s)

    for s in (1e-6, 0.01, 0.5, 2.0, 3.99, 4.0, 10.0, 300.0, 1e5, 1e9):
        value = psi(np.array([s]))[0][0]
        assert value == pytest.approx(float(exact(s)), rel=1e-12), s
    below, above = psi(np.array([SERIES_BELOW * (1 - 1e-12)])), psi(np.array([SERIES_BELOW]))
    for a, b in zip(below, above):
        assert a[0] == pytest.approx(b[0], rel=1e-10)


def test_psi_derivatives_match_finite_differences():
    s = np.array([0.3, 3.0, 4.5, 50.0, 1e4, 1e7])
    h = 1e-5 * s
    v0, d0, dd0 = psi(s)
    vp, dp, _ = psi(s + h)
    vm, dm, _ = psi(s - h)
    assert np.allclose((vp - vm) / (2 * h), d0, rtol=1e-7)
    assert np.allclose((dp - dm) / (2 * h), dd0, rtol=1e-6)


def test_narrow_limit_is_the_trapeze_and_wide_limit_is_sadowsky():
    """Psi(0) = 1/180: with the stretching coupling, E b W^5 tau^4 (1/1152 + 1/1440) = E b W^5
    tau^4 / 640, the trapeze ribbon's quartic term. Large k: Phi -> 1 - 2/k, and the density with
    eps relaxed tends to Sadowsky's (D W / 2)(kappa^2 + tau^2)^2 / kappa^2 (nu = 0: D W = E W b^3 / 12)."""
    assert psi(np.array([0.0]))[0][0] == pytest.approx(1 / 180, rel=1e-15)
    assert 1 / 1152 + 1 / 1440 == pytest.approx(1 / 640, rel=1e-15)
    for k in (50.0, 200.0, 1000.0):
        assert foundation_share(np.array([k]))[0][0] == pytest.approx(1 - 2 / k, abs=1e-12)
    e, b, w = 1e9, 1e-4, 0.02
    c3, c5, g0, c, nu = cross_section_coefficients(e, b, w, 0.0)
    dl = 1e-3
    kappa, tau = 200.0, 150.0  # k = (c kappa^2)^(1/4) = 170
    eps = -tau**2 * w**2 / 24.0  # the centreline stretch that relaxes the mean fibre strain
    energy = cross_section_density(np.array([eps]), np.array([kappa * dl]), np.array([tau * dl]), np.array([dl]),
                                   (c3, c5, g0, c, nu))[0][0] / dl
    stretch = 0.5 * e * b * w * eps**2
    rod = 0.5 * e * w * b**3 / 12 * kappa**2 + 0.5 * e * w * b**3 / 6 * tau**2
    sadowsky = 0.5 * e * w * b**3 / 12 * (kappa**2 + tau**2) ** 2 / kappa**2
    k = (c * kappa**2) ** 0.25
    # the share of the transverse bending forbidden is Phi, 1 - 2/k of Sadowsky's relief
    assert stretch + rod + energy == pytest.approx(sadowsky, rel=3.0 / k)
    assert stretch + rod + energy < sadowsky


@pytest.mark.parametrize("nu", [0.0, 0.3, 0.49])
def test_envelope_is_convex_and_continuous_at_the_well(nu):
    """Above the twist where K^2 + phi has a double well (T > 12.27 for nu = 0), the relaxed density
    is flat below K_m and meets the unrelaxed one at K_m with the same slope (0): the total K^2 + f
    is convex in K on a grid (second differences >= -1e-9 of its scale)."""
    for t in (5.0, 12.0, 13.0, 20.0, 60.0):
        k = np.linspace(-3 * t, 3 * t, 6001)
        tt = np.full_like(k, t)
        f = relaxed_share(k, tt, nu)[0]
        total = k**2 + f
        second = np.diff(total, 2)
        assert second.min() >= -1e-9 * np.abs(total).max(), (t, second.min())
    sm = well_bottom(np.array([5.0, 20.0]), nu)
    assert np.isnan(sm[0]) and sm[1] > 0
    km = np.sqrt(sm[1])
    below = relaxed_share(np.array([km * (1 - 1e-11)]), np.array([20.0]), nu)
    above = relaxed_share(np.array([km * (1 + 1e-11)]), np.array([20.0]), nu, relaxed=False)
    assert below[0][0] == pytest.approx(above[0][0], rel=1e-9)
    assert below[1][0] == pytest.approx(above[1][0], rel=1e-6)


def test_double_well_threshold_for_nu_zero():
    """nu = 0: the bending density K^2 + Psi(K^2) T^4 has curvature 2 - 2 T^4 / 22680 at K = 0, so
    the double well opens at T = 22680^(1/4) = 12.27."""
    threshold = 22680 ** 0.25
    sm = well_bottom(np.array([threshold * 0.999, threshold * 1.001]), 0.0)
    assert np.isnan(sm[0]) and np.isfinite(sm[1])


def test_relaxed_share_derivatives_match_finite_differences():
    """f and its partials in (K, T), inside and outside the flat region, against central differences."""
    rng = np.random.default_rng(3)
    for nu in (0.0, 0.3):
        k = rng.uniform(-30, 30, 200)
        t = rng.uniform(-30, 30, 200)
        f, fk, ft, fkk, fkt, ftt = relaxed_share(k, t, nu)
        h = 1e-6 * np.maximum(1.0, np.abs(k))
        g = 1e-6 * np.maximum(1.0, np.abs(t))
        fkp, fkm = relaxed_share(k + h, t, nu), relaxed_share(k - h, t, nu)
        ftp, ftm = relaxed_share(k, t + g, nu), relaxed_share(k, t - g, nu)
        scale = np.abs(f).max()
        assert np.allclose((fkp[0] - fkm[0]) / (2 * h), fk, atol=1e-6 * scale / 30)
        assert np.allclose((ftp[0] - ftm[0]) / (2 * g), ft, atol=1e-6 * scale / 30)
        # second partials away from the kink at |K| = K_m (the envelope is C1 there)
        sm = well_bottom(t, nu)
        away = ~(np.isfinite(sm) & (np.abs(k * k - np.nan_to_num(sm)) < 1e-3 * np.maximum(np.nan_to_num(sm), 1)))
        assert np.allclose(((fkp[1] - fkm[1]) / (2 * h))[away], fkk[away], atol=1e-5 * scale / 900)
        assert np.allclose(((ftp[2] - ftm[2]) / (2 * g))[away], ftt[away], atol=1e-5 * scale / 900)
        assert np.allclose(((ftp[1] - ftm[1]) / (2 * g))[away], fkt[away], atol=1e-5 * scale / 900)
