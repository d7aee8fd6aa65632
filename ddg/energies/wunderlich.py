"""Wunderlich's finite-width developable ribbon, Eq. (A.2), on pairs of the rod's stencils.

Eq. (A.2) (Wunderlich 1962; Starostin and van der Heijden 2007, 2015; Dias and Audoly 2015)
multiplies Sadowsky's density (A.4) by the ruling factor

    g(v) = (1 / v) log((1 + v / 2) / (1 - v / 2)) = 2 artanh(v / 2) / v,   v = W eta',

eta = tau / k2 the ruling slope and eta' its arclength derivative: g = 1 + v^2 / 12 + v^4 / 80
+ ... tends to 1 (Sadowsky) as W -> 0 and is a log barrier at |v| = 2, where the rulings of a
finite-width developable strip would cross at an edge. At an inflection point k2 -> 0 and eta
diverges: there the model is singular (the paper's Appendix A); we regularise as Eq. (A.5) does,

    Sadowsky part:  EI2 k2^2 + GJ tau^2 + EI2 tau^4 / (k2^2 + 1/zeta^2)        (Eq. A.5)
    ruling slope:   eta = tau k2 / (k2^2 + 1/zeta^2)                           (-> tau / k2)

so that zeta -> infinity is Eq. (A.2) itself (with GJ = 2 EI2, nu = 0: (1 + eta^2)^2 k2^2 =
k2^2 + 2 tau^2 + tau^4 / k2^2) and a finite zeta caps |eta| at zeta |tau| / 2. The effect of
zeta is measured (validation/ribbon_regularisation.py).

Discretisation. S_i is the Sadowsky density of interior node i (the rod's integrated strains,
ddg.energies.sadowsky), eta_i the ruling slope there, and between neighbouring nodes i, i + 1 at
distance h the factor g_p = g(W (eta_{i+1} - eta_i) / h). Each node's density takes the mean of
g over its one or two pairs, so the energy is sum_i S_i + sum_p (a_p S_i + b_p S_{i+1}) (g_p - 1)
with weights 1/2 (1 at the first and last interior node). The first sum is the Sadowsky ribbon
(rod_curvature.add_stencil_terms); this module gives the pair terms, functions of the four strains
(k2_i, tau_i, k2_{i+1}, tau_{i+1}), assembled by stencil_coupling.add_local_terms (bandwidth 14) in
the model's piecewise composition and by rod_curvature.add_pair_cross_terms in the one-call
assembly (ddg.models.rod_assembly). Compiled (numba): both call the same kernels.
Where |v| >= 2 the energy is +inf: Newton's line search rejects such a step.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from .sadowsky import quartic

#: Below this |v| the ruling factor and its derivatives are summed as series (to v^12), which is
#: exact to round-off there; above it the closed forms lose at most ~1e-13 to cancellation.
SERIES_BELOW = 0.1
#: Pole of the ruling factor: |W eta'| = 2 puts an edge where neighbouring rulings cross.
POLE = 2.0


#: Coefficients of the series g(v) = sum_k v^(2k) / ((2k + 1) 4^k), k = 0 .. 6.
_SERIES = np.array([1.0 / ((2 * k + 1) * 4.0**k) for k in range(7)])


@njit(cache=True)
def _ruling_factor_at(v):
    """g(v), g'(v), g''(v) at one v (ruling_factor)."""
    if abs(v) >= POLE:
        return math.inf, math.nan, math.nan
    if abs(v) < SERIES_BELOW:
        g, g1, g2 = 0.0, 0.0, 0.0
        for k in range(_SERIES.shape[0]):
            c = _SERIES[k]
            g += c * v ** (2 * k)
            if k >= 1:
                g1 += 2 * k * c * v ** (2 * k - 1)
                g2 += 2 * k * (2 * k - 1) * c * v ** (2 * k - 2)
        return g, g1, g2
    a = math.atanh(0.5 * v)
    a1 = 2.0 / (4.0 - v * v)
    a2 = 4.0 * v / (4.0 - v * v) ** 2
    return (2.0 * a / v, 2.0 * a1 / v - 2.0 * a / v**2,
            2.0 * a2 / v - 4.0 * a1 / v**2 + 4.0 * a / v**3)


@njit(cache=True)
def _ruling_factor_array(v):
    g, g1, g2 = np.empty_like(v), np.empty_like(v), np.empty_like(v)
    for i in range(v.shape[0]):
        g[i], g1[i], g2[i] = _ruling_factor_at(v[i])
    return g, g1, g2


def ruling_factor(v):
    """g(v) = 2 artanh(v/2) / v and its first two derivatives (arrays like v); inf beyond |v| >= 2
    (series to v^12 below SERIES_BELOW, closed forms above)."""
    v = np.asarray(v, dtype=float)
    g, g1, g2 = _ruling_factor_array(np.ascontiguousarray(v.ravel()))
    return g.reshape(v.shape), g1.reshape(v.shape), g2.reshape(v.shape)


@njit(cache=True)
def ruling_slope(kappa_n, tau, regularisation):
    """eta = tau k / (k^2 + r^2) and its partials (eta_k, eta_t, eta_kk, eta_kt, eta_tt) at one stencil."""
    r2 = regularisation * regularisation
    d = kappa_n * kappa_n + r2
    r2_minus_k2 = r2 - kappa_n * kappa_n
    return (tau * kappa_n / d, tau * r2_minus_k2 / (d * d), kappa_n / d,
            -2.0 * kappa_n * tau * (3.0 * r2 - kappa_n * kappa_n) / (d * d * d), r2_minus_k2 / (d * d), 0.0)


@njit(cache=True)
def sadowsky_part(kappa_n, tau, voronoi_length, bending_stiffness, twisting_stiffness, regularisation):
    """S = (EI2 k^2 + GJ tau^2 + EI2 tau^4 / (k^2 + r^2)) / (2 dl) at one stencil and its partials
    (S_k, S_t, S_kk, S_kt, S_tt): the out-of-plane and twist part of Eq. (A.5)."""
    half = 0.5 / voronoi_length
    q, q_k, q_t, q_kk, q_kt, q_tt = quartic(kappa_n, tau, regularisation)
    b, t = bending_stiffness, twisting_stiffness
    return (half * (b * kappa_n * kappa_n + t * tau * tau + b * q), half * (2.0 * b * kappa_n + b * q_k),
            half * (2.0 * t * tau + b * q_t), half * (2.0 * b + b * q_kk), half * b * q_kt, half * (2.0 * t + b * q_tt))


@njit(cache=True)
def pair_weights(n_stencils: int) -> tuple[np.ndarray, np.ndarray]:
    """(a_p, b_p) of the pairs p = (i, i + 1): each node's S is weighted by the mean of g over its
    pairs, 1/2 per pair, 1 where a node has one pair (the first and last interior node)."""
    a = np.full(n_stencils - 1, 0.5)
    b = np.full(n_stencils - 1, 0.5)
    a[0] = 1.0
    b[-1] = 1.0
    return a, b


@njit(cache=True)
def wunderlich_pair_density(kappa_n, tau, voronoi_lengths, pair_lengths, width, bending_stiffness,
                            twisting_stiffness, regularisation):
    """The pair terms (a S_i + b S_{i+1}) (g(v) - 1), v = W (eta_{i+1} - eta_i) / h, over the n - 1
    pairs of the n stencils: values (n - 1,), partials (n - 1, 4) and second partials
    (n - 1, 4, 4) in the strain order (k_i, tau_i, k_{i+1}, tau_{i+1}); and v (n - 1,). Past the
    pole (|v| >= 2) the pair's energy is inf and its derivatives nan.

    kappa_n, tau: the stencils' integrated strains; regularisation r = dl / zeta per stencil;
    pair_lengths h: the rest distance between the two nodes (the rest edge length)."""
    n = kappa_n.shape[0]
    w = np.empty((12, n))
    s, s_k, s_t, s_kk, s_kt, s_tt = w[0], w[1], w[2], w[3], w[4], w[5]
    eta, e_k, e_t, e_kk, e_kt, e_tt = w[6], w[7], w[8], w[9], w[10], w[11]
    for i in range(n):
        s[i], s_k[i], s_t[i], s_kk[i], s_kt[i], s_tt[i] = sadowsky_part(
            kappa_n[i], tau[i], voronoi_lengths[i], bending_stiffness, twisting_stiffness, regularisation[i])
        eta[i], e_k[i], e_t[i], e_kk[i], e_kt[i], e_tt[i] = ruling_slope(kappa_n[i], tau[i], regularisation[i])
    a, b = pair_weights(kappa_n.shape[0])
    m = kappa_n.shape[0] - 1
    energy = np.empty(m)
    first = np.empty((m, 4))
    second = np.empty((m, 4, 4))
    v = np.empty(m)
    ds = np.empty(4)
    dv = np.empty(4)
    dds = np.zeros((4, 4))
    ddv = np.zeros((4, 4))
    for p in range(m):
        i, j = p, p + 1
        scale = width / pair_lengths[p]
        v[p] = scale * (eta[j] - eta[i])
        g, g1, g2 = _ruling_factor_at(v[p])
        big_s = a[p] * s[i] + b[p] * s[j]
        # the four strains (k_i, t_i, k_j, t_j)
        ds[0], ds[1], ds[2], ds[3] = a[p] * s_k[i], a[p] * s_t[i], b[p] * s_k[j], b[p] * s_t[j]
        dds[0, 0], dds[0, 1], dds[1, 1] = a[p] * s_kk[i], a[p] * s_kt[i], a[p] * s_tt[i]
        dds[2, 2], dds[2, 3], dds[3, 3] = b[p] * s_kk[j], b[p] * s_kt[j], b[p] * s_tt[j]
        dds[1, 0], dds[3, 2] = dds[0, 1], dds[2, 3]
        dv[0], dv[1], dv[2], dv[3] = -scale * e_k[i], -scale * e_t[i], scale * e_k[j], scale * e_t[j]
        ddv[0, 0], ddv[0, 1], ddv[1, 1] = -scale * e_kk[i], -scale * e_kt[i], -scale * e_tt[i]
        ddv[2, 2], ddv[2, 3], ddv[3, 3] = scale * e_kk[j], scale * e_kt[j], scale * e_tt[j]
        ddv[1, 0], ddv[3, 2] = ddv[0, 1], ddv[2, 3]
        gm1 = g - 1.0
        energy[p] = big_s * gm1
        for r in range(4):
            first[p, r] = ds[r] * gm1 + big_s * g1 * dv[r]
            for c in range(4):
                second[p, r, c] = (dds[r, c] * gm1 + g1 * (ds[r] * dv[c] + ds[c] * dv[r])
                                   + big_s * g2 * dv[r] * dv[c] + big_s * g1 * ddv[r, c])
    return energy, first, second, v
