"""The rod's bending energy, Eq. (6b), vectorised over interior nodes.

E_b = 1/2 sum 1/dl_i [EI2 (kappa_n)^2 + EI1 (kappa_g)^2] for a naturally straight strip,
with kappa_n (out of plane) and kappa_g (geodesic) from rod_curvature; dl_i is the
undeformed Voronoi length.
"""
from __future__ import annotations


from .rod_curvature import StencilGeometry, curvature_derivatives


def bending_energy(g: StencilGeometry, voronoi_lengths, bending_stiffness, geodesic_bending_stiffness,
                   *, gradient=True, hessian=True):
    """E_b per node, stencil gradient (n, 11) and symmetric Hessian (n, 11, 11).

    The Hessian is 1/dl [EI2 (grad kn grad kn^T + kn hess kn) + EI1 (same for kg)].
    """
    (kn, gn, hn), (kg, gg, hg) = curvature_derivatives(g, hessian=hessian and gradient)
    a = bending_stiffness / voronoi_lengths
    c = geodesic_bending_stiffness / voronoi_lengths
    energy = 0.5 * (a * kn**2 + c * kg**2)
    if not gradient:
        return energy, None, None
    grad = (a * kn)[:, None] * gn + (c * kg)[:, None] * gg
    if not hessian:
        return energy, grad, None
    hess = curvature_hessian_terms(hn, hg, a * kn, c * kg)
    hess += a[:, None, None] * (gn[:, :, None] * gn[:, None, :]) + c[:, None, None] * (gg[:, :, None] * gg[:, None, :])
    return energy, grad, hess


def curvature_hessian_terms(hn, hg, weight_n, weight_g):
    """weight_n Hess(kappa_n) + weight_g Hess(kappa_g), mapped to the 11x11 stencil."""
    return hn.scaled_sum([weight_n, weight_g], [hg]).to_stencil()
