"""The regularised discrete Sadowsky energy of a narrow ribbon, Eq. (A.5), on the rod's stencils.

Eq. (A.5) (Sano and Wada 2019) adds to the rod's energy (A.1) the quartic twist term of
Sadowsky's functional (A.4) with a regularised denominator,

    E = 1/2 int [EI1 k1^2 + EI2 k2^2 + GJ tau^2 + EI2 tau^4 / (1/zeta^2 + k2^2)] ds,

written with the factor 1/2 of the rod's Eq. (6) (A.5 omits it on every term alike). With
GJ = 2 EI2 (nu = 0) and zeta -> infinity the out-of-plane and twist part is Sadowsky's
EI2 (k2^2 + tau^2)^2 / k2^2 / 2 (A.4). Discretely the curvatures kappa_n (the paper's k2),
kappa_g (k1) and the twist tau are the rod's integrated, dimensionless stencil quantities
(ddg.energies.rod_curvature, rod_twist), k ds -> kappa / dl, so per interior node

    E_i = 1/(2 dl_i) [EI2 kn^2 + EI1 kg^2 + GJ tau^2 + EI2 tau^4 / (kn^2 + (dl_i / zeta)^2)].

zeta is a length (m): 1/zeta is the curvature below which the quartic term is cut off. With
tau = 0 the energy is the rod's bending energy (Eq. 6b), its out-of-plane part alone when EI1 = 0.
"""
from __future__ import annotations

import numpy as np

from ..geometry.strip import InputError
from .rod_curvature import StencilGeometry, curvature_derivatives
from .rod_twist import twist_derivatives


ZETA_RANGE = (1e-9, 1e15)


def check_zeta(zeta) -> float:
    """zeta (m) within ZETA_RANGE, else InputError. 1/zeta^2 must stay a nonzero normal float,
    so the denominator of the quartic term never vanishes where k2 = 0 (zeta = 1e300 makes it
    0), and finite: 1e-9 m to 1e15 m (the paper's 1e8; results stop changing from zeta ~ 10 L)."""
    low, high = ZETA_RANGE
    if isinstance(zeta, bool):
        raise InputError(f"zeta = {zeta!r} is a bool; allowed: a length in [{low:g}, {high:g}] m")
    try:
        value = float(zeta)
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"zeta = {zeta!r} is not a number; allowed: a length in [{low:g}, {high:g}] m") from None
    if not (np.isfinite(value) and low <= value <= high):
        raise InputError(f"zeta = {zeta!r} outside the allowed range [{low:g}, {high:g}] m")
    return value


def quartic_twist_term(kappa_n, tau, regularisation):
    """Q = tau^4 / (kn^2 + r^2) and its first and second partial derivatives in (kn, tau).

    Returns Q, Q_k, Q_t, Q_kk, Q_kt, Q_tt, arrays over stencils (r = dl / zeta, Eq. A.5)."""
    d = kappa_n**2 + regularisation**2
    t2 = tau**2
    t4 = t2 * t2
    q = t4 / d
    q_k = -2.0 * kappa_n * t4 / d**2
    q_t = 4.0 * tau * t2 / d
    q_kk = t4 * (6.0 * kappa_n**2 - 2.0 * regularisation**2) / d**3
    q_kt = -8.0 * kappa_n * tau * t2 / d**2
    q_tt = 12.0 * t2 / d
    return q, q_k, q_t, q_kk, q_kt, q_tt


def sadowsky_energy(g: StencilGeometry, tau, voronoi_lengths, bending_stiffness, geodesic_bending_stiffness,
                    twisting_stiffness, zeta, *, gradient=True, hessian=True):
    """Per-stencil energy of Eq. (A.5), its parts, the (n, 11) gradient and (n, 11, 11) Hessian.

    Returns (energy, parts, grad, hess); parts is a dict of per-stencil arrays 'bending'
    (EI2 kn^2 + EI1 kg^2), 'twisting' (GJ tau^2) and 'sadowsky' (the quartic term), each with
    its 1/(2 dl). tau: the discrete twist (Eq. 5) of each stencil; stiffnesses in N m^2.
    """
    zeta = check_zeta(zeta)
    want_hessian = hessian and gradient
    (kn, gn, hn), (kg, gg, hg) = curvature_derivatives(g, hessian=want_hessian)
    a = bending_stiffness / voronoi_lengths
    c = geodesic_bending_stiffness / voronoi_lengths
    k = twisting_stiffness / voronoi_lengths
    q, q_k, q_t, q_kk, q_kt, q_tt = quartic_twist_term(kn, tau, voronoi_lengths / zeta)
    parts = {"bending": 0.5 * (a * kn**2 + c * kg**2), "twisting": 0.5 * k * tau**2, "sadowsky": 0.5 * a * q}
    energy = parts["bending"] + parts["twisting"] + parts["sadowsky"]
    if not gradient:
        return energy, parts, None, None
    g_tau, h_tau = twist_derivatives(g, hessian=want_hessian)
    # first derivatives of E_i with respect to kn, kg and tau
    e_k = a * (kn + 0.5 * q_k)
    e_g = c * kg
    e_t = k * tau + 0.5 * a * q_t
    grad = e_k[:, None] * gn + e_g[:, None] * gg + e_t[:, None] * g_tau
    if not want_hessian:
        return energy, parts, grad, None
    hess = hn.scaled_sum([e_k, e_g, e_t], [hg, h_tau]).to_stencil()
    e_kk = a * (1.0 + 0.5 * q_kk)
    e_kt = 0.5 * a * q_kt
    e_tt = k + 0.5 * a * q_tt
    outer = lambda u, v: u[:, :, None] * v[:, None, :]  # noqa: E731
    cross_kt = outer(gn, g_tau)
    hess += (e_kk[:, None, None] * outer(gn, gn) + c[:, None, None] * outer(gg, gg)
             + e_tt[:, None, None] * outer(g_tau, g_tau)
             + e_kt[:, None, None] * (cross_kt + np.swapaxes(cross_kt, 1, 2)))
    return energy, parts, grad, hess
