"""Discrete material curvatures of a framed centerline and their derivatives (Eqs. 3-4).

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

Local DOF order of a stencil (11 entries, contiguous in the rod's DOF vector of Eq. 1):
    [x_{i-1} (0:3), theta^{i-1} (3), x_i (4:7), theta^i (7), x_{i+1} (8:11)].
Derivatives are those of the energy with reference frames carried by parallel transport in
time from the current configuration (Bergou et al. 2010; Jawed et al. 2018 primer); the
Hessian is the symmetric part of the derivative of the gradient, which is the exact second
derivative along straight lines in DOF space.
"""
from __future__ import annotations

import numpy as np

from ..geometry.frames import cross, rowdot

# positions of the blocks in the 11-DOF stencil
XE, TE, XI, TF, XF = slice(0, 3), 3, slice(4, 7), 7, slice(8, 11)
_NODE = (slice(0, 3), slice(4, 7), slice(8, 11))
# d(edge)/d(node): e = x_i - x_{i-1}, f = x_{i+1} - x_i
_EDGE_SIGN = np.array([[-1.0, 0.0], [1.0, -1.0], [0.0, 1.0]])


_EYE = np.eye(3)


def _outer(a, b):
    """Row-wise outer products (..., 3) x (..., 3) -> (..., 3, 3)."""
    return a[..., :, None] * b[..., None, :]


def _swap(m):
    return np.swapaxes(m, -1, -2)


def _skew(v):
    """Cross-product matrices [v]x of row vectors (..., 3) -> (..., 3, 3)."""
    out = np.zeros(v.shape + (3,))
    out[..., 0, 1] = -v[..., 2]
    out[..., 0, 2] = v[..., 1]
    out[..., 1, 0] = v[..., 2]
    out[..., 1, 2] = -v[..., 0]
    out[..., 2, 0] = -v[..., 1]
    out[..., 2, 1] = v[..., 0]
    return out


def _scatter_edges(grad_e, grad_f, out):
    """Write d/de, d/df (n, 3) into the node blocks of an (n, 11) stencil gradient."""
    out[:, XE] = -grad_e
    out[:, XI] = grad_e - grad_f
    out[:, XF] = grad_f


class StencilHessian:
    """Second derivatives of a stencil quantity in edge form, before mapping to the 11 DOFs.

    ee, ef, ff: (n, 3, 3) blocks d2/de2, d2/de df, d2/df2; e_theta, f_theta: (n, 3, 2)
    mixed blocks with (theta^{i-1}, theta^i); theta_theta: (n, 2) diagonal twist block.
    Linear combinations are formed in this compact form and mapped to (n, 11, 11) once.
    """

    __slots__ = ("ee", "ef", "ff", "e_theta", "f_theta", "theta_theta")

    def __init__(self, ee, ef, ff, e_theta, f_theta, theta_theta):
        self.ee, self.ef, self.ff = ee, ef, ff
        self.e_theta, self.f_theta, self.theta_theta = e_theta, f_theta, theta_theta

    def scaled_sum(self, weights, others=()):
        """sum_k w_k H_k with weights (n,) arrays: self * weights[0] + others[k] * weights[k+1]."""
        terms = [(self, weights[0])] + [(h, w) for h, w in zip(others, weights[1:])]
        out = []
        for name in self.__slots__:
            acc = 0.0
            for h, w in terms:
                value = getattr(h, name)
                if value is None:
                    continue
                acc = acc + w.reshape((-1,) + (1,) * (value.ndim - 1)) * value
            out.append(acc)
        return StencilHessian(*out)

    def to_stencil(self) -> np.ndarray:
        """The (n, 11, 11) Hessian in stencil DOF order (e = x_i - x_{i-1}, f = x_{i+1} - x_i)."""
        n = self.ee.shape[0]
        ee, ef, ff = self.ee, self.ef, self.ff
        fe = ef.transpose(0, 2, 1)
        hess = np.empty((n, 11, 11))
        hess[:, XE, XE] = ee
        hess[:, XE, XI] = ef - ee
        hess[:, XE, XF] = -ef
        hess[:, XI, XE] = fe - ee
        hess[:, XI, XI] = ee - ef - fe + ff
        hess[:, XI, XF] = ef - ff
        hess[:, XF, XE] = -fe
        hess[:, XF, XI] = fe - ff
        hess[:, XF, XF] = ff
        for col, c in ((TE, 0), (TF, 1)):
            e_t, f_t = self.e_theta[:, :, c], self.f_theta[:, :, c]
            hess[:, XE, col] = -e_t
            hess[:, XI, col] = e_t - f_t
            hess[:, XF, col] = f_t
            hess[:, col, XE] = -e_t
            hess[:, col, XI] = e_t - f_t
            hess[:, col, XF] = f_t
        hess[:, TE, TE] = self.theta_theta[:, 0]
        hess[:, TF, TF] = self.theta_theta[:, 1]
        hess[:, TE, TF] = 0.0
        hess[:, TF, TE] = 0.0
        return hess


class StencilGeometry:
    """Per-node quantities shared by the bending and twisting energies (vectorised)."""

    def __init__(self, x_prev, x_node, x_next, m1e, m2e, m1f, m2f):
        self.e = x_node - x_prev
        self.f = x_next - x_node
        self.norm_e = np.sqrt(rowdot(self.e, self.e))
        self.norm_f = np.sqrt(rowdot(self.f, self.f))
        self.te = self.e / self.norm_e[:, None]
        self.tf = self.f / self.norm_f[:, None]
        self.chi = 1.0 + rowdot(self.te, self.tf)
        self.kb = 2.0 * cross(self.te, self.tf) / self.chi[:, None]
        self.tilde_t = (self.te + self.tf) / self.chi[:, None]
        self.m1e, self.m2e, self.m1f, self.m2f = m1e, m2e, m1f, m2f


def material_curvatures(g: StencilGeometry) -> tuple[np.ndarray, np.ndarray]:
    """(kappa_n, kappa_g) at each interior node, Eq. (4)."""
    kappa_n = 0.5 * rowdot(g.kb, g.m2e + g.m2f)
    kappa_g = -0.5 * rowdot(g.kb, g.m1e + g.m1f)
    return kappa_n, kappa_g


def curvature_derivatives(g: StencilGeometry, hessian: bool = True):
    """[(kappa, gradient (n, 11), StencilHessian)] for kappa_n and kappa_g.

    The two curvatures differ only in the director (d2~ for kappa_n, d1~ for kappa_g), the
    directors in their twist derivatives and a few signs; both are computed at once on arrays
    with a leading axis of length 2, which halves the number of numpy calls.
    """
    n = g.e.shape[0]
    kappa = np.stack(material_curvatures(g))                              # (2, n)
    chi = g.chi
    inv_e = 1.0 / g.norm_e
    inv_f = 1.0 / g.norm_f
    tt = g.tilde_t
    dt = np.stack([g.m2e + g.m2f, g.m1e + g.m1f]) / chi[None, :, None]  # (2, n, 3)
    sgn = np.array([1.0, -1.0])[:, None, None]
    # directors of d kappa / d theta^{e,f}: (curvature, edge, n, 3); d m1/dtheta = m2, d m2/dtheta = -m1
    ga = np.stack([np.stack([g.m1e, g.m1f]), np.stack([g.m2e, g.m2f])])
    # directors of the kb (x) m terms and of d2 kappa / d theta2: (curvature, edge, n, 3)
    mm = np.stack([np.stack([g.m2e, g.m2f]), np.stack([g.m1e, g.m1f])])
    k1 = kappa[:, :, None]
    tf_c = cross(g.tf, dt)
    te_c = cross(g.te, dt)
    grad = np.zeros((2, n, 11))
    dke = inv_e[:, None] * (-k1 * tt + sgn * tf_c)
    dkf = inv_f[:, None] * (-k1 * tt - sgn * te_c)
    grad[:, :, XE] = -dke
    grad[:, :, XI] = dke - dkf
    grad[:, :, XF] = dkf
    kb_ga = rowdot(g.kb, ga)                                               # (2, 2, n)
    grad[:, :, TE] = -0.5 * kb_ga[:, 0]
    grad[:, :, TF] = -0.5 * kb_ga[:, 1]
    if not hessian:
        return [(kappa[c], grad[c], None) for c in range(2)]
    k3 = kappa[:, :, None, None]
    chi3 = chi[:, None, None]
    tt_tt = _outer(tt, tt)
    inv_e2 = (inv_e**2)[:, None, None]
    inv_f2 = (inv_f**2)[:, None, None]
    kb_me = _outer(g.kb, mm[:, 0])
    kb_mf = _outer(g.kb, mm[:, 1])
    tfc_tt = _outer(tf_c, tt)
    tec_tt = _outer(te_c, tt)
    h_ee = inv_e2 * (2.0 * k3 * tt_tt - sgn[..., None] * (tfc_tt + _swap(tfc_tt))
                     - k3 / chi3 * (_EYE - _outer(g.te, g.te))
                     + 0.25 * sgn[..., None] * (kb_me + _swap(kb_me)))
    h_ff = inv_f2 * (2.0 * k3 * tt_tt + sgn[..., None] * (tec_tt + _swap(tec_tt))
                     - k3 / chi3 * (_EYE - _outer(g.tf, g.tf))
                     + 0.25 * sgn[..., None] * (kb_mf + _swap(kb_mf)))
    h_ef = (inv_e * inv_f)[:, None, None] * (
        -k3 / chi3 * (_EYE + _outer(g.te, g.tf))
        + 2.0 * k3 * tt_tt + sgn[..., None] * (_swap(tec_tt) - tfc_tt - _skew(dt))
    )
    # position-twist blocks d2 kappa / de dtheta, d2 kappa / df dtheta: (2, n, 3, edge)
    half_kb_tt = 0.5 * kb_ga[..., None] * tt                              # (2, 2, n, 3)
    chi4 = chi[:, None]
    e_theta = inv_e[:, None] * (half_kb_tt - cross(g.tf, ga) / chi4)
    f_theta = inv_f[:, None] * (half_kb_tt + cross(g.te, ga) / chi4)
    e_theta = np.moveaxis(e_theta, 1, -1)
    f_theta = np.moveaxis(f_theta, 1, -1)
    theta_theta = -sgn * 0.5 * np.moveaxis(rowdot(g.kb, mm), 1, -1)  # (2, n, 2)
    return [(kappa[c], grad[c], StencilHessian(h_ee[c], h_ef[c], h_ff[c], e_theta[c], f_theta[c], theta_theta[c]))
            for c in range(2)]
