"""The rod's and ribbons' centreline curvatures at a state, from their own discrete strains (the
profile that ddg.analysis.curvatures plots and the ParaView frames carry per element)."""
from __future__ import annotations

import numpy as np

from ..energies.rod_curvature import material_curvatures


def rod_curvatures(model, q: np.ndarray) -> dict:
    """Curvatures of the rod or ribbon at q (frames transported from the model's committed state):
    s/L of the interior nodes and k1 L (geodesic), k2 L (bending), tau L (twist)."""
    x = model.positions(q)
    _, _, m1, m2, m_ref = model.frames(q)
    kappa_n, kappa_g = material_curvatures(x, m1, m2)
    theta = q[model.theta_dofs]
    tau = theta[1:] - theta[:-1] + m_ref
    L = model.strip.length
    scale = L / model.voronoi_lengths
    return {"s_over_L": model.centerline.node_arclength[1:-1] / L, "k1_L": kappa_g * scale, "k2_L": kappa_n * scale,
            "tau_L": tau * scale}
