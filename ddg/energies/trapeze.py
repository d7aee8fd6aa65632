"""The trapeze term: stretching of a twisted strip's edges, on the rod's stencils.

A twisted strip of width W lengthens its fibres at distance y from the centreline by the helix
factor: the axial strain of the fibre is eps + tau^2 y^2 / 2 (eps the centreline stretch, tau the
twist per unit length; Green 1937, Buckley and Hutchinson's "trapeze effect", Audoly and Pomeau
2010 ch. 5; the non-developable ribbon with this term is Dias and Audoly 2015's extension of
Sadowsky to finite stretching). Integrating the membrane energy over the width,

    (E b / 2) int_{-W/2}^{W/2} (eps + tau^2 y^2 / 2)^2 dy
        = E b W eps^2 / 2  +  E b W^3 eps tau^2 / 24  +  E b W^5 tau^4 / 640,

whose first term is the rod's stretching (Eq. 6a, EA = E b W) and the other two are this
module's, per unit length: the coupling (a tension T = EA eps adds T W^2 / 12 to GJ) and the
quartic twist stiffness. For tau W^2 / b small next to 1 the quartic term is small next to the
twisting energy GJ tau^2 / 2 (ratio (1 + nu) tau^2 W^4 / (213 b^2)) and the model is the rod; for
W^2 tau / b of order one it sees the width. Under compression alone tau = 0 and both terms and
their first derivatives vanish: the U is the rod's (and the elastica's).

Discretely (integrated strains as in the rod, tau -> tau_i / dl_i, eps -> the Voronoi mean
stretch eps_i of ddg.energies.stencil_coupling.stencil_stretch), per interior node

    E_i = C3 eps_i tau_i^2 / dl_i + C5 tau_i^4 / dl_i^3,   C3 = E b W^3 / 24,  C5 = E b W^5 / 640.
"""
from __future__ import annotations

import numpy as np
from numba import njit


def trapeze_coefficients(young_modulus: float, thickness: float, width: float) -> tuple[float, float]:
    """(C3, C5) = (E b W^3 / 24, E b W^5 / 640): the eps tau^2 coupling and the tau^4 stiffness."""
    return (young_modulus * thickness * width**3 / 24.0, young_modulus * thickness * width**5 / 640.0)


@njit(cache=True)
def trapeze_density(eps, tau, voronoi_lengths, coupling, quartic):
    """E_i per stencil (n,), partials in (eps, tau) (n, 2) and second partials (n, 2, 2).

    eps: the stencils' centreline stretch; tau: their integrated twist (Eq. 5); coupling, quartic:
    C3, C5 of trapeze_coefficients. Compiled (the one-call assembly, ddg.models.rod_assembly, calls it)."""
    n = eps.shape[0]
    energy = np.empty(n)
    first = np.empty((n, 2))
    second = np.empty((n, 2, 2))
    for i in range(n):
        dl, t, e = voronoi_lengths[i], tau[i], eps[i]
        t2 = t * t
        dl3 = dl * dl * dl
        energy[i] = coupling * e * t2 / dl + quartic * t2 * t2 / dl3
        first[i, 0] = coupling * t2 / dl
        first[i, 1] = 2.0 * coupling * e * t / dl + 4.0 * quartic * t * t2 / dl3
        second[i, 0, 0] = 0.0
        second[i, 0, 1] = second[i, 1, 0] = 2.0 * coupling * t / dl
        second[i, 1, 1] = 2.0 * coupling * e / dl + 12.0 * quartic * t2 / dl3
    return energy, first, second
