"""The rod's bending energy, Eq. (6b), vectorised over interior nodes.

E_b = 1/2 sum 1/dl_i [EI2 (kappa_n)^2 + EI1 (kappa_g)^2] for a naturally straight strip,
with kappa_n (out of plane) and kappa_g (geodesic) from rod_curvature; dl_i is the
undeformed Voronoi length.
"""
from __future__ import annotations

import numpy as np

from .rod_curvature import StencilGeometry, curvature_derivatives


def bending_energy(g: StencilGeometry, voronoi_lengths, bending_stiffness, geodesic_bending_stiffness,
                   *, gradient=True, hessian=True):
    """E_b per node, stencil gradient (n, 11) and symmetric Hessian (n, 11, 11)."""
    (kn, gn, hn), (kg, gg, hg) = curvature_derivatives(g, hessian=hessian and gradient)
    a = bending_stiffness / voronoi_lengths
    c = geodesic_bending_stiffness / voronoi_lengths
    energy = 0.5 * (a * kn**2 + c * kg**2)
    if not gradient:
        return energy, None, None
    grad = (a * kn)[:, None] * gn + (c * kg)[:, None] * gg
    if not hessian:
        return energy, grad, None
    hess = a[:, None, None] * (gn[:, :, None] * gn[:, None, :] + kn[:, None, None] * hn) + c[:, None, None] * (
        gg[:, :, None] * gg[:, None, :] + kg[:, None, None] * hg
    )
    hess = 0.5 * (hess + hess.transpose(0, 2, 1))
    return energy, grad, hess
