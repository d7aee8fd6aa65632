"""The rod's bending energy, Eq. (6b), as a function of the stencil strains.

E_b = 1/2 sum 1/dl_i [EI2 (kappa_n)^2 + EI1 (kappa_g)^2] for a naturally straight strip,
with kappa_n (out of plane) and kappa_g (geodesic) from rod_curvature; dl_i is the
undeformed Voronoi length. The chain rule to the DOFs is rod_curvature.add_stencil_terms.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from .rod_curvature import KAPPA_G, KAPPA_N


@njit(cache=True)
def bending_density(kappa_n, kappa_g, voronoi_lengths, bending_stiffness, geodesic_bending_stiffness):
    """E_b per stencil (n,), its partials in (kappa_n, kappa_g, tau) (n, 3) and second partials (n, 3, 3)."""
    a = bending_stiffness / voronoi_lengths
    c = geodesic_bending_stiffness / voronoi_lengths
    energy = 0.5 * (a * kappa_n**2 + c * kappa_g**2)
    first = np.zeros((len(energy), 3))
    first[:, KAPPA_N] = a * kappa_n
    first[:, KAPPA_G] = c * kappa_g
    second = np.zeros((len(energy), 3, 3))
    second[:, KAPPA_N, KAPPA_N] = a
    second[:, KAPPA_G, KAPPA_G] = c
    return energy, first, second
