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
from numba import njit

from ..limits import InputError
from .rod_curvature import KAPPA_N, TAU


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


@njit(cache=True)
def quartic(kappa_n, tau, regularisation):
    """Q = tau^4 / (kn^2 + r^2) and its first and second partial derivatives in (kn, tau) at one
    stencil: Q, Q_k, Q_t, Q_kk, Q_kt, Q_tt (r = dl / zeta, Eq. A.5)."""
    r2 = regularisation * regularisation
    d = kappa_n * kappa_n + r2
    t2 = tau * tau
    t4 = t2 * t2
    return (t4 / d, -2.0 * kappa_n * t4 / (d * d), 4.0 * tau * t2 / d,
            t4 * (6.0 * kappa_n * kappa_n - 2.0 * r2) / (d * d * d), -8.0 * kappa_n * tau * t2 / (d * d), 12.0 * t2 / d)


@njit(cache=True)
def quartic_twist_term(kappa_n, tau, regularisation):
    """`quartic` over stencils: arrays Q, Q_k, Q_t, Q_kk, Q_kt, Q_tt (n,) of arrays kappa_n, tau and
    the regularisation r (n,)."""
    n = kappa_n.shape[0]
    out = np.empty((6, n))
    for i in range(n):
        q, q_k, q_t, q_kk, q_kt, q_tt = quartic(kappa_n[i], tau[i], regularisation[i])
        out[0, i], out[1, i], out[2, i], out[3, i], out[4, i], out[5, i] = q, q_k, q_t, q_kk, q_kt, q_tt
    return out[0], out[1], out[2], out[3], out[4], out[5]


def sadowsky_density(kappa_n, tau, voronoi_lengths, bending_stiffness, zeta):
    """The quartic term of Eq. (A.5) per stencil, EI2 tau^4 / (kn^2 + (dl / zeta)^2) / (2 dl): its
    values (n,), partials in (kappa_n, kappa_g, tau) (n, 3) and second partials (n, 3, 3). Added to
    the rod's bending and twisting densities (rod_bending, rod_twist) it is the whole of Eq. (A.5);
    the chain rule to the DOFs is rod_curvature.add_stencil_terms. zeta is checked (check_zeta)."""
    return sadowsky_terms(kappa_n, tau, voronoi_lengths, bending_stiffness, check_zeta(zeta))


@njit(cache=True)
def sadowsky_terms(kappa_n, tau, voronoi_lengths, bending_stiffness, zeta):
    """sadowsky_density for a zeta already checked (the compiled assembly calls it)."""
    n = kappa_n.shape[0]
    energy = np.empty(n)
    first = np.zeros((n, 3))
    second = np.zeros((n, 3, 3))
    for i in range(n):
        half_a = 0.5 * bending_stiffness / voronoi_lengths[i]
        q, q_k, q_t, q_kk, q_kt, q_tt = quartic(kappa_n[i], tau[i], voronoi_lengths[i] / zeta)
        energy[i] = half_a * q
        first[i, KAPPA_N] = half_a * q_k
        first[i, TAU] = half_a * q_t
        second[i, KAPPA_N, KAPPA_N] = half_a * q_kk
        second[i, KAPPA_N, TAU] = second[i, TAU, KAPPA_N] = half_a * q_kt
        second[i, TAU, TAU] = half_a * q_tt
    return energy, first, second
