"""The regularised discrete Sadowsky energy (Eq. A.5): finite-difference checks of its gradient
and Hessian at generic deformed, twisted states, and its reduction to the rod's bending energy
where the twist vanishes.

Conventions as in tests/ddg/energies/test_rod_energies.py: q is committed first, so reference frames are
transported from q; the Hessian matches the symmetrised FD Jacobian of the gradient. DOFs are
scaled to natural units (h for positions, 1 rad for angles).
"""
from __future__ import annotations

import numpy as np
import pytest

from ddg import Strip
from ddg.energies.rod_bending import bending_density
from ddg.energies.rod_curvature import material_curvatures
from ddg.energies.rod_twist import discrete_twist, twisting_density
from ddg.energies.sadowsky import quartic_twist_term, sadowsky_density
from ddg.geometry.strip import InputError
from ddg.models.ribbon import RibbonModel
from ddg.models.rod import RodModel
from rod_states import twisted_rod_state

# a strip with moderate stiffness contrast (as in test_rod_energies) so no term dominates
STRIP = Strip(length=0.1, width=0.01, thickness=0.002, young_modulus=1e9, poisson_ratio=0.0)
SEEDS = (0, 1, 2)
REL_STEP = 1e-6
RTOL = 1e-6


def rel_err(approx, exact) -> float:
    return float(np.linalg.norm(np.asarray(approx) - exact) / np.linalg.norm(exact))






def stencil_state(model, q):
    """Curvatures (kappa_n, kappa_g) and twist tau at q (frames transported from the committed state)."""
    x = model.positions(q)
    _, _, m1, m2, m_ref = model.frames(q)
    kn, kg = material_curvatures(x, m1, m2)
    return kn, kg, discrete_twist(q[model.theta_dofs], m_ref)


def sadowsky_energy(kn, kg, tau, dl, ei2, ei1, gj, zeta):
    """Eq. (A.5) per stencil, its parts and its partials in (kappa_n, kappa_g, tau): the rod's
    densities plus the quartic term, as RibbonModel.stencil_density sums them."""
    e_b, f_b, s_b = bending_density(kn, kg, dl, ei2, ei1)
    e_t, f_t, s_t = twisting_density(tau, dl, gj)
    e_q, f_q, s_q = sadowsky_density(kn, tau, dl, ei2, zeta)
    return e_b + e_t + e_q, {"bending": e_b, "twisting": e_t, "sadowsky": e_q}, f_b + f_t + f_q, s_b + s_t + s_q


def test_quartic_term_partials_match_finite_differences():
    """Q = tau^4 / (kn^2 + r^2): its five partials against central differences, including kn near 0."""
    rng = np.random.default_rng(4)
    kn = np.r_[rng.uniform(-0.3, 0.3, 6), 1e-3, -2e-3]
    tau = rng.uniform(-0.2, 0.2, kn.size)
    r = np.full(kn.size, 0.02)   # the regularisation dl / zeta per stencil
    q, q_k, q_t, q_kk, q_kt, q_tt = quartic_twist_term(kn, tau, r)
    assert q == pytest.approx(tau**4 / (kn**2 + r**2), rel=1e-14)
    eps = 1e-7
    f = lambda a, b: quartic_twist_term(a, b, r)  # noqa: E731
    assert rel_err((f(kn + eps, tau)[0] - f(kn - eps, tau)[0]) / (2 * eps), q_k) < RTOL
    assert rel_err((f(kn, tau + eps)[0] - f(kn, tau - eps)[0]) / (2 * eps), q_t) < RTOL
    assert rel_err((f(kn + eps, tau)[1] - f(kn - eps, tau)[1]) / (2 * eps), q_kk) < RTOL
    assert rel_err((f(kn, tau + eps)[1] - f(kn, tau - eps)[1]) / (2 * eps), q_kt) < RTOL
    assert rel_err((f(kn, tau + eps)[2] - f(kn, tau - eps)[2]) / (2 * eps), q_tt) < RTOL


@pytest.mark.parametrize("seed", SEEDS)
def test_zero_twist_reduces_to_the_rod_bending_energy(seed):
    """With tau = 0 the energy and its partials of Eq. (A.5) equal the rod's bending energy (Eq. 6b),
    with EI1 = 0 its out-of-plane part alone; the second partials differ only by the twist's GJ / dl
    (the quartic term has zero second derivatives at tau = 0)."""
    model = RodModel(STRIP, 12)
    q = twisted_rod_state(model, seed)
    model.commit(q)
    kn, kg, tau = stencil_state(model, q)
    zero = np.zeros_like(tau)
    dl = model.voronoi_lengths
    s = STRIP
    for ei1 in (s.geodesic_bending_stiffness, 0.0):
        e_rod, f_rod, s_rod = bending_density(kn, kg, dl, s.bending_stiffness, ei1)
        e, parts, f, sec = sadowsky_energy(kn, kg, zero, dl, s.bending_stiffness, ei1, s.twisting_stiffness,
                                           zeta=1e-3 * s.length)
        assert np.max(np.abs(e - e_rod)) <= 1e-14 * np.max(e_rod)
        assert np.all(parts["sadowsky"] == 0.0) and np.all(parts["twisting"] == 0.0)
        assert rel_err(f, f_rod) < 1e-13
        expected = s_rod.copy()
        expected[:, 2, 2] += s.twisting_stiffness / dl
        assert rel_err(sec, expected) < 1e-13
    # and at the actual (non-zero) twist the quartic term is what distinguishes the two
    e, parts, _, _ = sadowsky_energy(kn, kg, tau, dl, s.bending_stiffness, s.geodesic_bending_stiffness,
                                     s.twisting_stiffness, zeta=s.length)
    expected = 0.5 * s.bending_stiffness / dl * tau**4 / (kn**2 + (dl / s.length) ** 2)
    assert parts["sadowsky"] == pytest.approx(expected, rel=1e-13)


@pytest.mark.parametrize("seed", SEEDS)
def test_density_partials_match_finite_differences(seed):
    """The partials of Eq. (A.5) in (kappa_n, kappa_g, tau) that the compiled chain rule uses:
    first partials = central differences of the energy, second = of the first."""
    model = RodModel(STRIP, 12)
    q = twisted_rod_state(model, seed)
    model.commit(q)
    strains = np.stack(stencil_state(model, q), axis=1)
    dl = model.voronoi_lengths
    s = STRIP
    args = (dl, s.bending_stiffness, s.geodesic_bending_stiffness, s.twisting_stiffness, 0.5 * s.length)
    _, _, first, second = sadowsky_energy(*strains.T, *args)
    eps = 1e-7
    for c in range(3):
        step = np.zeros_like(strains)
        step[:, c] = eps
        ep, _, fp, _ = sadowsky_energy(*(strains + step).T, *args)
        em, _, fm, _ = sadowsky_energy(*(strains - step).T, *args)
        assert rel_err((ep - em) / (2 * eps), first[:, c]) < RTOL
        assert rel_err((fp - fm) / (2 * eps), second[:, :, c]) < RTOL


def test_sadowsky_limit_with_gj_equal_2ei2():
    """nu = 0 (GJ = 2 EI2), zeta -> inf: E_i = EI2 / (2 dl) (kn^2 + tau^2)^2 / kn^2 + EI1 kg^2 / (2 dl), Eq. (A.4)."""
    model = RodModel(STRIP, 12)
    q = twisted_rod_state(model, 1)
    model.commit(q)
    kn, kg, tau = stencil_state(model, q)
    dl = model.voronoi_lengths
    s = STRIP
    assert s.twisting_stiffness == pytest.approx(2 * s.bending_stiffness, rel=1e-14)
    e, _, _, _ = sadowsky_energy(kn, kg, tau, dl, s.bending_stiffness, s.geodesic_bending_stiffness,
                                 s.twisting_stiffness, zeta=1e12)
    expected = 0.5 / dl * (s.bending_stiffness * (kn**2 + tau**2) ** 2 / kn**2 + s.geodesic_bending_stiffness * kg**2)
    assert e == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("bad", (0.0, -1.0, float("inf"), float("nan"), "big"))
def test_bad_zeta_is_a_one_line_input_error(bad):
    with pytest.raises(InputError, match="zeta"):
        RibbonModel(STRIP, 9, zeta=bad)
