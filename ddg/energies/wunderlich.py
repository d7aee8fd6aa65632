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
(k2_i, tau_i, k2_{i+1}, tau_{i+1}), assembled by stencil_coupling.add_local_terms (bandwidth 14).
Where |v| >= 2 the energy is +inf: Newton's line search rejects such a step.
"""
from __future__ import annotations

import numpy as np

from .sadowsky import quartic_twist_term

#: Below this |v| the ruling factor and its derivatives are summed as series (to v^12), which is
#: exact to round-off there; above it the closed forms lose at most ~1e-13 to cancellation.
SERIES_BELOW = 0.1
#: Pole of the ruling factor: |W eta'| = 2 puts an edge where neighbouring rulings cross.
POLE = 2.0


def ruling_factor(v):
    """g(v) = 2 artanh(v/2) / v and its first two derivatives (arrays like v); inf beyond |v| >= 2."""
    v = np.asarray(v, dtype=float)
    g = np.empty_like(v)
    g1 = np.empty_like(v)
    g2 = np.empty_like(v)
    small = np.abs(v) < SERIES_BELOW
    pole = np.abs(v) >= POLE
    big = ~small & ~pole
    # g = sum_k v^(2k) / ((2k + 1) 4^k)
    vs = v[small]
    coefficients = [1.0 / ((2 * k + 1) * 4.0**k) for k in range(7)]
    g[small] = sum(c * vs**(2 * k) for k, c in enumerate(coefficients))
    g1[small] = sum(2 * k * c * vs**(2 * k - 1) for k, c in enumerate(coefficients) if k >= 1)
    g2[small] = sum(2 * k * (2 * k - 1) * c * vs**(2 * k - 2) for k, c in enumerate(coefficients) if k >= 1)
    vb = v[big]
    a = np.arctanh(0.5 * vb)
    a1 = 2.0 / (4.0 - vb * vb)
    a2 = 4.0 * vb / (4.0 - vb * vb) ** 2
    g[big] = 2.0 * a / vb
    g1[big] = 2.0 * a1 / vb - 2.0 * a / vb**2
    g2[big] = 2.0 * a2 / vb - 4.0 * a1 / vb**2 + 4.0 * a / vb**3
    g[pole], g1[pole], g2[pole] = np.inf, np.nan, np.nan
    return g, g1, g2


def ruling_slope(kappa_n, tau, regularisation):
    """eta = tau k / (k^2 + r^2) and its partials (eta_k, eta_t, eta_kk, eta_kt, eta_tt)."""
    d = kappa_n**2 + regularisation**2
    r2_minus_k2 = regularisation**2 - kappa_n**2
    eta = tau * kappa_n / d
    eta_k = tau * r2_minus_k2 / d**2
    eta_t = kappa_n / d
    eta_kk = -2.0 * kappa_n * tau * (3.0 * regularisation**2 - kappa_n**2) / d**3
    eta_kt = r2_minus_k2 / d**2
    eta_tt = np.zeros_like(eta)
    return eta, eta_k, eta_t, eta_kk, eta_kt, eta_tt


def sadowsky_part(kappa_n, tau, voronoi_lengths, bending_stiffness, twisting_stiffness, regularisation):
    """S = (EI2 k^2 + GJ tau^2 + EI2 tau^4 / (k^2 + r^2)) / (2 dl) per stencil and its partials
    (S_k, S_t, S_kk, S_kt, S_tt): the out-of-plane and twist part of Eq. (A.5)."""
    half = 0.5 / voronoi_lengths
    q, q_k, q_t, q_kk, q_kt, q_tt = quartic_twist_term(kappa_n, tau, regularisation)
    b, t = bending_stiffness, twisting_stiffness
    s = half * (b * kappa_n**2 + t * tau**2 + b * q)
    return (s, half * (2.0 * b * kappa_n + b * q_k), half * (2.0 * t * tau + b * q_t),
            half * (2.0 * b + b * q_kk), half * b * q_kt, half * (2.0 * t + b * q_tt))


def pair_weights(n_stencils: int) -> tuple[np.ndarray, np.ndarray]:
    """(a_p, b_p) of the pairs p = (i, i + 1): each node's S is weighted by the mean of g over its
    pairs, 1/2 per pair, 1 where a node has one pair (the first and last interior node)."""
    a = np.full(n_stencils - 1, 0.5)
    b = np.full(n_stencils - 1, 0.5)
    a[0] = 1.0
    b[-1] = 1.0
    return a, b


def wunderlich_pair_density(kappa_n, tau, voronoi_lengths, pair_lengths, width, bending_stiffness,
                            twisting_stiffness, regularisation):
    """The pair terms (a S_i + b S_{i+1}) (g(v) - 1), v = W (eta_{i+1} - eta_i) / h, over the n - 1
    pairs of the n stencils: values (n - 1,), partials (n - 1, 4) and second partials
    (n - 1, 4, 4) in the strain order (k_i, tau_i, k_{i+1}, tau_{i+1}); and v (n - 1,).

    kappa_n, tau: the stencils' integrated strains; regularisation r = dl / zeta per stencil;
    pair_lengths h: the rest distance between the two nodes (the rest edge length)."""
    s, s_k, s_t, s_kk, s_kt, s_tt = sadowsky_part(kappa_n, tau, voronoi_lengths, bending_stiffness,
                                                  twisting_stiffness, regularisation)
    eta, e_k, e_t, e_kk, e_kt, e_tt = ruling_slope(kappa_n, tau, regularisation)
    a, b = pair_weights(len(kappa_n))
    scale = width / pair_lengths
    v = scale * (eta[1:] - eta[:-1])
    g, g1, g2 = ruling_factor(v)
    m = len(v)
    # the four strains (k_i, t_i, k_j, t_j), j = i + 1
    big_s = a * s[:-1] + b * s[1:]
    ds = np.stack([a * s_k[:-1], a * s_t[:-1], b * s_k[1:], b * s_t[1:]], axis=1)
    dds = np.zeros((m, 4, 4))
    dds[:, 0, 0], dds[:, 0, 1], dds[:, 1, 1] = a * s_kk[:-1], a * s_kt[:-1], a * s_tt[:-1]
    dds[:, 2, 2], dds[:, 2, 3], dds[:, 3, 3] = b * s_kk[1:], b * s_kt[1:], b * s_tt[1:]
    dds[:, 1, 0], dds[:, 3, 2] = dds[:, 0, 1], dds[:, 2, 3]
    dv = scale[:, None] * np.stack([-e_k[:-1], -e_t[:-1], e_k[1:], e_t[1:]], axis=1)
    ddv = np.zeros((m, 4, 4))
    ddv[:, 0, 0], ddv[:, 0, 1], ddv[:, 1, 1] = -e_kk[:-1], -e_kt[:-1], -e_tt[:-1]
    ddv[:, 2, 2], ddv[:, 2, 3], ddv[:, 3, 3] = e_kk[1:], e_kt[1:], e_tt[1:]
    ddv[:, 1, 0], ddv[:, 3, 2] = ddv[:, 0, 1], ddv[:, 2, 3]
    ddv *= scale[:, None, None]
    gm1 = g - 1.0
    energy = big_s * gm1
    with np.errstate(invalid="ignore"):  # past the pole: energy inf, derivatives nan
        first = ds * gm1[:, None] + (big_s * g1)[:, None] * dv
        cross = g1[:, None, None] * ds[:, :, None] * dv[:, None, :]
        second = (dds * gm1[:, None, None] + cross + np.transpose(cross, (0, 2, 1))
                  + (big_s * g2)[:, None, None] * dv[:, :, None] * dv[:, None, :]
                  + (big_s * g1)[:, None, None] * ddv)
    return energy, first, second, v
