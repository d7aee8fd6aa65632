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
    return a[:, :, None] * b[:, None, :]


def _skew(v):
    n = v.shape[0]
    out = np.zeros((n, 3, 3))
    out[:, 0, 1] = -v[:, 2]
    out[:, 0, 2] = v[:, 1]
    out[:, 1, 0] = v[:, 2]
    out[:, 1, 2] = -v[:, 0]
    out[:, 2, 0] = -v[:, 1]
    out[:, 2, 1] = v[:, 0]
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
    """[(kappa, gradient (n, 11), StencilHessian)] for kappa_n and kappa_g."""
    n = g.e.shape[0]
    kappa_n, kappa_g = material_curvatures(g)
    chi = g.chi
    inv_e = 1.0 / g.norm_e
    inv_f = 1.0 / g.norm_f
    tt = g.tilde_t
    d1t = (g.m1e + g.m1f) / chi[:, None]
    d2t = (g.m2e + g.m2f) / chi[:, None]

    # the two curvatures differ by the director used (d2 vs d1) and a few signs
    # kappa, its tilde director, sign of the cross terms, directors in d kappa / d theta,
    # directors in d2 kappa / de2 (and d2 kappa / d theta2)
    spec = (
        (kappa_n, d2t, +1.0, (g.m1e, g.m1f), g.m2e, g.m2f),
        (kappa_g, d1t, -1.0, (g.m2e, g.m2f), g.m1e, g.m1f),
    )
    out = []
    for kappa, dt, sgn, ga, me, mf in spec:
        grad = np.zeros((n, 11))
        dke = inv_e[:, None] * (-kappa[:, None] * tt + sgn * cross(g.tf, dt))
        dkf = inv_f[:, None] * (-kappa[:, None] * tt - sgn * cross(g.te, dt))
        _scatter_edges(dke, dkf, grad)
        # d kappa / d theta: d m1/d theta = m2, d m2/d theta = -m1
        grad[:, TE] = -0.5 * rowdot(g.kb, ga[0])
        grad[:, TF] = -0.5 * rowdot(g.kb, ga[1])
        if not hessian:
            out.append((kappa, grad, None))
            continue
        k3 = kappa[:, None, None]
        chi3 = chi[:, None, None]
        tt_tt = _outer(tt, tt)
        tf_c = cross(g.tf, dt)
        te_c = cross(g.te, dt)
        inv_e2 = (inv_e**2)[:, None, None]
        inv_f2 = (inv_f**2)[:, None, None]
        h_ee = inv_e2 * (2.0 * k3 * tt_tt - sgn * (_outer(tf_c, tt) + _outer(tt, tf_c))
                         - k3 / chi3 * (_EYE - _outer(g.te, g.te))
                         + 0.25 * sgn * (_outer(g.kb, me) + _outer(me, g.kb)))
        h_ff = inv_f2 * (2.0 * k3 * tt_tt + sgn * (_outer(te_c, tt) + _outer(tt, te_c))
                         - k3 / chi3 * (_EYE - _outer(g.tf, g.tf))
                         + 0.25 * sgn * (_outer(g.kb, mf) + _outer(mf, g.kb)))
        h_ef = (inv_e * inv_f)[:, None, None] * (
            -k3 / chi3 * (_EYE + _outer(g.te, g.tf))
            + 2.0 * k3 * tt_tt - sgn * _outer(tf_c, tt) + sgn * _outer(tt, te_c) - sgn * _skew(dt)
        )
        # position-twist: d2 kappa / de dtheta and d2 kappa / df dtheta
        kb_m = np.stack([rowdot(g.kb, ga[0]), rowdot(g.kb, ga[1])], axis=1)  # (n, 2)
        e_theta = np.empty((n, 3, 2))
        f_theta = np.empty((n, 3, 2))
        for c, m in enumerate(ga):
            e_theta[:, :, c] = inv_e[:, None] * (0.5 * kb_m[:, c, None] * tt - cross(g.tf, m) / chi[:, None])
            f_theta[:, :, c] = inv_f[:, None] * (0.5 * kb_m[:, c, None] * tt + cross(g.te, m) / chi[:, None])
        theta_theta = -sgn * 0.5 * np.stack([rowdot(g.kb, me), rowdot(g.kb, mf)], axis=1)
        hess = StencilHessian(h_ee, h_ef, h_ff, e_theta, f_theta, theta_theta)
        out.append((kappa, grad, hess))
    return out
