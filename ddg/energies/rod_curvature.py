"""The rod's discrete strains at an interior node and their derivatives (Eqs. 3-5), compiled.

At interior node i, with incoming edge e = x_i - x_{i-1} and outgoing edge f = x_{i+1} - x_i,
the curvature binormal is kb = 2 e x f / (|e||f| + e.f) (Eq. 3) and the two material
curvatures are the Bergou et al. (2010) pair

    kappa_n = 1/2 (m2^e + m2^f) . kb    (bending towards m1, the strip normal)
    kappa_g = -1/2 (m1^e + m1^f) . kb   (bending in the plane of the strip, geodesic)

The paper's Eq. (4) writes the same two expressions as kappa^(1), kappa^(2) while calling
m1 the surface normal and pairing kappa^(1) with the stiff E b W^3 / 12; those three
statements cannot all hold. We keep m1 as the normal and pair each curvature with the
stiffness of the bending it measures: kappa_n (the paper's kappa^(2), out of plane) with
EI2 = E W b^3 / 12 and kappa_g (the paper's kappa^(1), geodesic) with EI1 = E b W^3 / 12.
The third strain is the discrete twist tau = theta^i - theta^{i-1} + m_ref (Eq. 5), with
d m_ref / de = kb / (2 |e|) and d m_ref / df = kb / (2 |f|) for reference frames carried by
parallel transport in time (Bergou et al. 2010).

Local DOF order of a stencil (11 entries, contiguous in the rod's DOF vector of Eq. 1):
    [x_{i-1} (0:3), theta^{i-1} (3), x_i (4:7), theta^i (7), x_{i+1} (8:11)].
Derivatives are those of the energy with reference frames carried by parallel transport in
time from the current configuration (Bergou et al. 2010; Jawed et al. 2018 primer); the
Hessian is the symmetric part of the derivative of the gradient, which is the exact second
derivative along straight lines in DOF space.

Every rod-type energy (the rod's bending Eq. 6b and twisting Eq. 6c, the Sadowsky ribbon
Eq. A.5) is a function of these three strains per stencil, E_i = e(kappa_n, kappa_g, tau): its
module gives the partial derivatives of e, and `add_stencil_terms` applies the chain rule,

    grad E_i = sum_c e_c grad s_c,   hess E_i = sum_c e_c hess s_c + sum_cd e_cd grad s_c grad s_d^T,

in one compiled pass that writes straight into the assembled gradient and band. The first term,
sum_c e_c hess s_c, is formed directly (`_stencil` with weights e_c): the two curvatures' second
derivatives are sums of the same dyads, so their weighted sum costs one of them (what that saves:
docs/findings/measured.md). This module is the only implementation of the strains and their
derivatives.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit


#: Strain order in every (n, 3) array of this module: out-of-plane curvature, geodesic curvature, twist.
KAPPA_N, KAPPA_G, TAU = 0, 1, 2
STENCIL_SIZE = 11


@njit(cache=True, forceinline=True)
def _cross(a, b):
    """a x b of two 3-tuples."""
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@njit(cache=True, forceinline=True)
def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@njit(cache=True, forceinline=True)
def _combine(wa, a, wb, b):
    """wa a + wb b of two 3-tuples."""
    return (wa * a[0] + wb * b[0], wa * a[1] + wb * b[1], wa * a[2] + wb * b[2])


@njit(cache=True, forceinline=True)
def _scaled(w, a):
    """w a of a 3-tuple."""
    return (w * a[0], w * a[1], w * a[2])


@njit(cache=True, forceinline=True)
def _row(v, i):
    """Row i of an (n, 3) array as a 3-tuple (a tuple lives in registers; a row view would cost
    reference counts in the hottest loop, docs/findings/measured.md)."""
    return (v[i, 0], v[i, 1], v[i, 2])


@njit(cache=True, forceinline=True)
def _curvature(c, sgn, director, kb, tt, te, tf, chi, ie, jf, ge, gf):
    """One material curvature sgn kb . director / 2 (director = the sum of the two edges' m2 for
    kappa_n, sgn = 1, or m1 for kappa_g, sgn = -1) and its edge-form gradient into row c of ge, gf;
    returns (kappa, director / chi)."""
    kappa = sgn * 0.5 * _dot(kb, director)
    dt = _scaled(1.0 / chi, director)
    pf = _cross(tf, dt)
    pe = _cross(te, dt)
    for k in range(3):
        ge[c, k] = ie * (-kappa * tt[k] + sgn * pf[k])
        gf[c, k] = jf * (-kappa * tt[k] - sgn * pe[k])
    return kappa, dt


@njit(cache=True, forceinline=True)
def _stencil(x, m1, m2, i, w0, w1, w2, strain, ge, gf, gth, ee, ef, ff, eth, fth, thth):
    """Curvatures (strain[0:2]), the edge-form first derivatives of (kappa_n, kappa_g, tau) of one
    stencil, ge, gf (3 strains, 3) = d/de, d/df and gth (3, 2) = d/dtheta^{e,f}, and the weighted
    sum of their second derivatives, w0 d2 kappa_n + w1 d2 kappa_g + w2 d2 tau: ee, ef, ff (3, 3) in
    e and f, eth, fth (3, 2) mixed with the angles, thth (2,) the angles' diagonal. The two
    curvatures' second derivatives share their dyads, so the weighted sum is formed from weighted
    vectors (D = w0 dt_n - w1 dt_g, M = w0 m2 - w1 m1, G = w0 m1 + w1 m2) in one pass; unit weights
    give one strain's second derivatives (`_derivatives`). Stencil i of the centerline x (M, 3) and
    its edges' directors m1, m2 (M - 1, 3); the stencil's vectors are 3-tuples."""
    e = _combine(1.0, _row(x, i + 1), -1.0, _row(x, i))
    f = _combine(1.0, _row(x, i + 2), -1.0, _row(x, i + 1))
    ie = 1.0 / math.sqrt(_dot(e, e))
    jf = 1.0 / math.sqrt(_dot(f, f))
    te = _scaled(ie, e)
    tf = _scaled(jf, f)
    chi = 1.0 + _dot(te, tf)
    kb = _scaled(2.0 / chi, _cross(te, tf))
    tt = _combine(1.0 / chi, te, 1.0 / chi, tf)
    ie2, jf2, iej = ie * ie, jf * jf, ie * jf
    m1e, m1f, m2e, m2f = _row(m1, i), _row(m1, i + 1), _row(m2, i), _row(m2, i + 1)
    # kappa_n: directors m2, twist directors m1 (d m2/d theta = -m1); kappa_g: m1 and m2
    kappa_n, dt_n = _curvature(0, 1.0, _combine(1.0, m2e, 1.0, m2f), kb, tt, te, tf, chi, ie, jf, ge, gf)
    kappa_g, dt_g = _curvature(1, -1.0, _combine(1.0, m1e, 1.0, m1f), kb, tt, te, tf, chi, ie, jf, ge, gf)
    strain[0], strain[1] = kappa_n, kappa_g
    gth[0, 0], gth[0, 1] = -0.5 * _dot(kb, m1e), -0.5 * _dot(kb, m1f)
    gth[1, 0], gth[1, 1] = -0.5 * _dot(kb, m2e), -0.5 * _dot(kb, m2f)
    # twist: tau = theta^f - theta^e + m_ref, linear in theta
    for k in range(3):
        ge[2, k] = 0.5 * kb[k] * ie
        gf[2, k] = 0.5 * kb[k] * jf
    gth[2, 0], gth[2, 1] = -1.0, 1.0
    # the weighted vectors of the curvatures' dyads
    big_k = w0 * kappa_n + w1 * kappa_g
    big_d = _combine(w0, dt_n, -w1, dt_g)
    pe = _cross(tf, big_d)   # sum_c w_c sgn_c (tf x dt_c)
    pf = _cross(te, big_d)   # sum_c w_c sgn_c (te x dt_c)
    me = _combine(w0, m2e, -w1, m1e)
    mf = _combine(w0, m2f, -w1, m1f)
    ae = _combine(1.0, te, 1.0, tt)
    af = _combine(1.0, tf, 1.0, tt)
    for a in range(3):
        for b in range(3):
            eye = 1.0 if a == b else 0.0
            tt2 = 2.0 * big_k * tt[a] * tt[b]
            ee[a, b] = (ie2 * (tt2 - (pe[a] * tt[b] + tt[a] * pe[b]) - big_k / chi * (eye - te[a] * te[b])
                               + 0.25 * (kb[a] * me[b] + me[a] * kb[b]))
                        - 0.25 * w2 * ie2 * (kb[a] * ae[b] + ae[a] * kb[b]))
            ff[a, b] = (jf2 * (tt2 + (pf[a] * tt[b] + tt[a] * pf[b]) - big_k / chi * (eye - tf[a] * tf[b])
                               + 0.25 * (kb[a] * mf[b] + mf[a] * kb[b]))
                        - 0.25 * w2 * jf2 * (kb[a] * af[b] + af[a] * kb[b]))
            ef[a, b] = (iej * (-big_k / chi * (eye + te[a] * tf[b]) + tt2 + (tt[a] * pf[b] - pe[a] * tt[b]))
                        - 0.25 * w2 * iej * (kb[a] * tt[b] + tt[a] * kb[b]))
    # skew parts of the e-f block: + [D]x-like from the curvatures, - the twist's ([te]x + [tf]x) / 2 chi |e||f|
    s0 = iej * big_d[0] - w2 * (te[0] + tf[0]) * 0.5 * iej / chi
    s1 = iej * big_d[1] - w2 * (te[1] + tf[1]) * 0.5 * iej / chi
    s2 = iej * big_d[2] - w2 * (te[2] + tf[2]) * 0.5 * iej / chi
    ef[0, 1] += s2
    ef[0, 2] -= s1
    ef[1, 0] -= s2
    ef[1, 2] += s0
    ef[2, 0] += s1
    ef[2, 1] -= s0
    for j in range(2):
        g_j = _combine(w0, m1e, w1, m2e) if j == 0 else _combine(w0, m1f, w1, m2f)
        kb_g = _dot(kb, g_j)
        cross_f = _cross(tf, g_j)
        cross_e = _cross(te, g_j)
        for k in range(3):
            eth[k, j] = ie * (0.5 * kb_g * tt[k] - cross_f[k] / chi)
            fth[k, j] = jf * (0.5 * kb_g * tt[k] + cross_e[k] / chi)
    thth[0] = -0.5 * _dot(kb, me)
    thth[1] = -0.5 * _dot(kb, mf)


@njit(cache=True, forceinline=True)
def _stencil_gradient(ge, gf, gth, c, out, row):
    """Row `row` of out: the 11-entry stencil gradient of strain c from its edge form
    (e = x_i - x_{i-1}, f = x_{i+1} - x_i)."""
    for k in range(3):
        out[row, k] = -ge[c, k]
        out[row, 4 + k] = ge[c, k] - gf[c, k]
        out[row, 8 + k] = gf[c, k]
    out[row, 3] = gth[c, 0]
    out[row, 7] = gth[c, 1]


@njit(cache=True)
def _edge_form_to_stencil(ee, ef, ff, eth, fth, thth, out):
    """The (11, 11) stencil Hessian of an edge-form second derivative (blocks in e, f, theta)."""
    for a in range(3):
        for b in range(3):
            EE, EF, FE, FF = ee[a, b], ef[a, b], ef[b, a], ff[a, b]
            out[a, b] = EE
            out[a, 4 + b] = EF - EE
            out[a, 8 + b] = -EF
            out[4 + a, b] = FE - EE
            out[4 + a, 4 + b] = EE - EF - FE + FF
            out[4 + a, 8 + b] = EF - FF
            out[8 + a, b] = -FE
            out[8 + a, 4 + b] = FE - FF
            out[8 + a, 8 + b] = FF
    for j in range(2):
        col = 3 if j == 0 else 7
        for a in range(3):
            e_t, f_t = eth[a, j], fth[a, j]
            out[a, col] = out[col, a] = -e_t
            out[4 + a, col] = out[col, 4 + a] = e_t - f_t
            out[8 + a, col] = out[col, 8 + a] = f_t
    out[3, 3], out[7, 7] = thth[0], thth[1]
    out[3, 7] = out[7, 3] = 0.0


@njit(cache=True)
def _scratch():
    """Work arrays of one stencil: strains, ge, gf, gth. Allocated inside the compiled loops, because
    a tuple of arrays passed in from Python costs a dispatch per call (docs/findings/measured.md)."""
    return np.empty(3), np.empty((3, 3)), np.empty((3, 3)), np.empty((3, 2))


@njit(cache=True)
def curvature_rows(x, m1, m2):
    n = x.shape[0] - 2
    out = np.empty((n, 2))
    kb = np.empty(3)
    for i in range(n):
        e0, e1, e2 = x[i + 1, 0] - x[i, 0], x[i + 1, 1] - x[i, 1], x[i + 1, 2] - x[i, 2]
        f0, f1, f2 = x[i + 2, 0] - x[i + 1, 0], x[i + 2, 1] - x[i + 1, 1], x[i + 2, 2] - x[i + 1, 2]
        ne, nf = math.sqrt(e0 * e0 + e1 * e1 + e2 * e2), math.sqrt(f0 * f0 + f1 * f1 + f2 * f2)
        scale = 2.0 / (ne * nf + e0 * f0 + e1 * f1 + e2 * f2)
        kb[0] = scale * (e1 * f2 - e2 * f1)
        kb[1] = scale * (e2 * f0 - e0 * f2)
        kb[2] = scale * (e0 * f1 - e1 * f0)
        kn = 0.0
        kg = 0.0
        for k in range(3):
            kn += kb[k] * (m2[i, k] + m2[i + 1, k])
            kg -= kb[k] * (m1[i, k] + m1[i + 1, k])
        out[i, 0] = 0.5 * kn
        out[i, 1] = 0.5 * kg
    return out


def material_curvatures(x: np.ndarray, m1: np.ndarray, m2: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(kappa_n, kappa_g) at the M - 2 interior nodes of a centerline x (M, 3) with material
    directors m1, m2 (M - 1, 3) (Eq. 4); integrated, dimensionless (2 tan of half the turning angle)."""
    k = curvature_rows(np.ascontiguousarray(x, dtype=float), np.ascontiguousarray(m1, dtype=float),
                    np.ascontiguousarray(m2, dtype=float))
    return k[:, 0].copy(), k[:, 1].copy()


def turning_chi(x: np.ndarray) -> np.ndarray:
    """chi = 1 + t^e . t^f at the interior nodes (2 for a straight node, 0 for a reversal)."""
    t = np.diff(x, axis=0)
    t /= np.linalg.norm(t, axis=1)[:, None]
    return 1.0 + np.einsum("ij,ij->i", t[:-1], t[1:])


@njit(cache=True)
def _derivatives(x, m1, m2, strains, grads, hessians):
    strain, ge, gf, gth = _scratch()
    _, ee, ef, ff, eth, fth, thth = _contraction_scratch()
    for i in range(x.shape[0] - 2):
        for c in range(3):   # each strain's second derivatives: unit weights
            _stencil(x, m1, m2, i, 1.0 * (c == 0),
                     1.0 * (c == 1), 1.0 * (c == 2), strain, ge, gf, gth, ee, ef, ff, eth, fth, thth)
            _edge_form_to_stencil(ee, ef, ff, eth, fth, thth, hessians[i, c])
        strains[i, 0], strains[i, 1] = strain[0], strain[1]
        for c in range(3):
            _stencil_gradient(ge, gf, gth, c, grads[i], c)


def strain_derivatives(x: np.ndarray, m1: np.ndarray, m2: np.ndarray):
    """(kappa_n, kappa_g) (n, 2), stencil gradients (n, 3, 11) and Hessians (n, 3, 11, 11) of the
    three strains (kappa_n, kappa_g, tau) at the n = M - 2 interior nodes. The twist's value needs
    the twist angles and m_ref (rod_twist.discrete_twist); its derivatives need only the geometry.
    For tests and analysis: the models assemble with `add_stencil_terms` without forming these."""
    n = x.shape[0] - 2
    strains = np.empty((n, 2))
    grads = np.empty((n, 3, STENCIL_SIZE))
    hessians = np.empty((n, 3, STENCIL_SIZE, STENCIL_SIZE))
    _derivatives(np.ascontiguousarray(x, dtype=float), np.ascontiguousarray(m1, dtype=float),
                 np.ascontiguousarray(m2, dtype=float), strains, grads, hessians)
    return strains, grads, hessians


@njit(cache=True)
def stencil_place(size, node_stride):
    """Where the rod's DOFs of a block of `size` (11: a stencil, 15: a pair of stencils) sit in the
    block of a model with node_stride DOFs per node (the rod's 4, or 4 + its edge fields after each
    twist angle): local DOF a goes to a + (a // 4) (node_stride - 4)."""
    place = np.arange(size)
    return place + (place // 4) * (node_stride - 4)


@njit(cache=True, forceinline=True)
def _contraction_scratch():
    """Work arrays of the chain rule of one stencil: its 11 x 11 block and the weighted edge forms."""
    return (np.empty((STENCIL_SIZE, STENCIL_SIZE)), np.empty((3, 3)), np.empty((3, 3)), np.empty((3, 3)),
            np.empty((3, 2)), np.empty((3, 2)), np.empty(2))


@njit(cache=True, forceinline=True)
def _add_gradient_products(second, i, g, count, h11):
    """h11 += sum_cd second[i, c, d] g_c g_d^T over the first `count` strains (lower triangle only)."""
    for c in range(count):
        for d in range(count):
            coefficient = second[i, c, d]
            if coefficient != 0.0:
                for a in range(STENCIL_SIZE):
                    ga = coefficient * g[c, a]
                    for b in range(a + 1):
                        h11[a, b] += ga * g[d, b]


@njit(cache=True, forceinline=True)
def _scatter_lower(h11, place, node_stride, base, n_dof, band):
    """The stencil block's lower triangle into the flattened lower band: its DOFs are increasing in
    a, so entry (a, b), a >= b, lands at band[(place[a] - place[b]) * n_dof + base + place[b]]."""
    if node_stride == 4:   # the rod's own layout: place[a] = a, diagonal a - b of the band
        for a in range(STENCIL_SIZE):
            for b in range(a + 1):
                band[(a - b) * n_dof + base + b] += h11[a, b]
        return
    for a in range(STENCIL_SIZE):
        for b in range(a + 1):
            band[(place[a] - place[b]) * n_dof + base + place[b]] += h11[a, b]


@njit(cache=True)
def add_stencil_terms(x, m1, m2, first, second, node_stride, n_dof, grad, band, want_hessian):
    """Chain rule for an energy sum_i e(kappa_n, kappa_g, tau) of the stencils: adds its gradient
    to grad and (want_hessian) its Hessian to the flattened lower band of an n_dof matrix.

    first (n, 3): de/ds_c per stencil; second (n, 3, 3): d2e/ds_c ds_d; node j's position starts at
    DOF node_stride * j, edge j's twist angle follows it (the rod's layout, Eq. 1, has
    node_stride = 4; a model with more DOFs per edge, ddg.models.wide_ribbons.CrossSectionRibbon,
    puts them after the angle), so stencil i starts at DOF node_stride * i."""
    strain, ge, gf, gth = _scratch()
    g11 = np.empty((3, STENCIL_SIZE))
    h11, ee, ef, ff, eth, fth, thth = _contraction_scratch()
    place = stencil_place(STENCIL_SIZE, node_stride)  # the stencil's 11 DOFs within its block
    for i in range(x.shape[0] - 2):
        _stencil(x, m1, m2, i, first[i, 0], first[i, 1],
                 first[i, 2], strain, ge, gf, gth, ee, ef, ff, eth, fth, thth)
        base = node_stride * i
        for c in range(3):
            _stencil_gradient(ge, gf, gth, c, g11, c)
        for a in range(STENCIL_SIZE):
            grad[base + place[a]] += first[i, 0] * g11[0, a] + first[i, 1] * g11[1, a] + first[i, 2] * g11[2, a]
        if not want_hessian:
            continue
        _edge_form_to_stencil(ee, ef, ff, eth, fth, thth, h11)
        _add_gradient_products(second, i, g11, 3, h11)
        _scatter_lower(h11, place, node_stride, node_stride * i, n_dof, band)



@njit(cache=True)
def add_stretched_stencil_terms(x, m1, m2, rest_edge_lengths, first, second, node_stride, unit_place, n_dof, grad,
                                band, want_hessian, strain_gradients):
    """add_stencil_terms for a density e(eps, kappa_n, kappa_g, tau, u_1 .. u_k) per stencil: eps
    the stencil's Voronoi mean stretch (|e| + |f|) / (|e-bar| + |f-bar|) - 1 (Eq. 2's edges, as
    ddg.energies.stencil_coupling.stencil_stretch), whose edge form is d eps / de = t_e / R,
    d2 eps / de2 = (I - t_e t_e^T) / (|e| R) (likewise f; R = |e-bar| + |f-bar|), and u_j DOFs
    of the stencil's block themselves, at block positions unit_place (the cross-section model's
    modes, ddg.models.wide_ribbons.CrossSectionRibbon). first (n, 4 + k), second (n, 4 + k, 4 + k)
    in that order. The first-order parts of all four strains are contracted in edge form before
    the stencil's 11 x 11 block is formed (one pass, as add_stencil_terms). strain_gradients
    (n, 4, 11): filled with each stencil's gradients of (eps, kappa_n, kappa_g, tau) over its rod
    DOFs (for terms coupling neighbouring stencils' strains, `add_pair_cross_terms`), when it has
    n rows."""
    strain, ge, gf, gth = _scratch()
    g = np.empty((4, STENCIL_SIZE))
    h11, ee, ef, ff, eth, fth, thth = _contraction_scratch()
    mixed = np.empty(STENCIL_SIZE)
    place = stencil_place(STENCIL_SIZE, node_stride)
    units = unit_place.shape[0]
    keep = strain_gradients.shape[0] == x.shape[0] - 2
    for i in range(x.shape[0] - 2):
        _stencil(x, m1, m2, i, first[i, 1], first[i, 2],
                 first[i, 3], strain, ge, gf, gth, ee, ef, ff, eth, fth, thth)
        e = _combine(1.0, _row(x, i + 1), -1.0, _row(x, i))
        f = _combine(1.0, _row(x, i + 2), -1.0, _row(x, i + 1))
        ne, nf = math.sqrt(_dot(e, e)), math.sqrt(_dot(f, f))
        te, tf = _scaled(1.0 / ne, e), _scaled(1.0 / nf, f)
        rest = rest_edge_lengths[i] + rest_edge_lengths[i + 1]
        for k in range(3):
            g[0, k] = -te[k] / rest
            g[0, 4 + k] = (te[k] - tf[k]) / rest
            g[0, 8 + k] = tf[k] / rest
        g[0, 3] = 0.0
        g[0, 7] = 0.0
        for c in range(3):
            _stencil_gradient(ge, gf, gth, c, g, 1 + c)
        if keep:
            for c in range(4):
                for a in range(STENCIL_SIZE):
                    strain_gradients[i, c, a] = g[c, a]
        base = node_stride * i
        for a in range(STENCIL_SIZE):
            grad[base + place[a]] += (first[i, 0] * g[0, a] + first[i, 1] * g[1, a] + first[i, 2] * g[2, a]
                                      + first[i, 3] * g[3, a])
        for j in range(units):
            grad[base + unit_place[j]] += first[i, 4 + j]
        if not want_hessian:
            continue
        se, sf = first[i, 0] / (ne * rest), first[i, 0] / (nf * rest)   # the stretch's edge form
        for a in range(3):
            for b in range(3):
                eye = 1.0 if a == b else 0.0
                ee[a, b] += se * (eye - te[a] * te[b])
                ff[a, b] += sf * (eye - tf[a] * tf[b])
        _edge_form_to_stencil(ee, ef, ff, eth, fth, thth, h11)
        _add_gradient_products(second, i, g, 4, h11)
        _scatter_lower(h11, place, node_stride, base, n_dof, band)
        # the strains against the unit strains, and the unit strains among themselves
        for j in range(units):
            rj = unit_place[j]
            for a in range(STENCIL_SIZE):
                mixed[a] = (second[i, 0, 4 + j] * g[0, a] + second[i, 1, 4 + j] * g[1, a]
                            + second[i, 2, 4 + j] * g[2, a] + second[i, 3, 4 + j] * g[3, a])
                ra = place[a]
                if ra >= rj:
                    band[(ra - rj) * n_dof + base + rj] += mixed[a]
                else:
                    band[(rj - ra) * n_dof + base + ra] += mixed[a]
            for k in range(j + 1):
                rk = unit_place[k]
                value = second[i, 4 + j, 4 + k]
                if rj >= rk:
                    band[(rj - rk) * n_dof + base + rk] += value
                else:
                    band[(rk - rj) * n_dof + base + rj] += value


@njit(cache=True)
def add_pair_cross_terms(strain_gradients, cross, components, node_stride, n_dof, band):
    """The cross terms of an energy of neighbouring stencils' strains, sum_i E(s_i, s_{i+1}): adds
    sum_ab cross[i, a, b] (g_ia g_{i+1,b}^T + g_{i+1,b} g_ia^T) to the lower band, g_ia stencil i's
    gradient of strain components[a] (strain_gradients (n, 4, 11) in (eps, kappa_n, kappa_g, tau),
    from add_stretched_stencil_terms) and cross (n - 1, k, k) the mixed partials
    d2E / ds_ia ds_{i+1,b}. The other parts of the chain rule (the first partials and the second
    partials within one stencil) are per stencil and belong in add_stretched_stencil_terms'
    first/second. Used for Eq. V's neighbouring twists (the cross-section model) and Wunderlich's
    pairs (ddg.energies.wunderlich)."""
    place = stencil_place(STENCIL_SIZE, node_stride)
    k = components.shape[0]
    lo_g = np.empty(STENCIL_SIZE)
    for i in range(strain_gradients.shape[0] - 1):
        lo, hi = node_stride * i, node_stride * (i + 1)  # stencil i + 1 starts one node later
        for b_ in range(k):
            # h_b = sum_a cross[i, a, b] g_ia: stencil i's side of the products with g_{i+1,b}
            nonzero = False
            for c in range(STENCIL_SIZE):
                total = 0.0
                for a_ in range(k):
                    total += cross[i, a_, b_] * strain_gradients[i, components[a_], c]
                lo_g[c] = total
                nonzero = nonzero or total != 0.0
            if not nonzero:
                continue
            hi_g = strain_gradients[i + 1, components[b_]]
            for a in range(STENCIL_SIZE):
                ra = hi + place[a]
                for b in range(STENCIL_SIZE):
                    rb = lo + place[b]
                    value = hi_g[a] * lo_g[b]
                    if ra == rb:   # a DOF of both stencils: both products land on the diagonal
                        band[rb] += 2.0 * value
                    elif ra > rb:
                        band[(ra - rb) * n_dof + rb] += value
                    else:
                        band[(rb - ra) * n_dof + ra] += value
