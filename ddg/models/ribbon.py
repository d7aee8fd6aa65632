"""Discrete Sadowsky ribbon (paper Appendix A): the rod with bending and twisting replaced by
the regularised Sadowsky energy of Eq. (A.5).

Same DOFs (Eq. 1), clamps, reference frames and outputs as the DAR (ddg.models.rod); only the
bending and twisting energies (Eqs. 6b, 6c) give way to ddg.energies.sadowsky, which adds the
quartic twist term EI2 tau^4 / (1/zeta^2 + k2^2). That term makes twist expensive where the
out-of-plane curvature k2 is small: at an inflection point of a developable ribbon the twist
must vanish.
"""
from __future__ import annotations

import numpy as np

from ..energies.sadowsky import check_zeta, sadowsky_density
from ..geometry.strip import Strip
from .rod import RodModel
from .names import RIBBON, ROD

__all__ = ["RibbonModel", "DEFAULT_ZETA_OVER_L", "RIBBON_INITS"]

#: How a ribbon run is started (ddg.protocol): "direct" follows the ribbon itself from the flat
#: strip (the paper's Direct-Sadowsky); "rod" relaxes each recorded state of the rod under the
#: ribbon's energy (DAR-Sadowsky).
RIBBON_INITS = ("direct", ROD)

#: Default regularisation length zeta / L of Eq. (A.5). At W/L = 1/20, dL/L = 1/2, M = 101 the
#: shear path (H_mid up to dW/L = 0.5, direct and rod-initialised) differs from zeta / L = 1e8 by
#: 1.7e-6 L at zeta / L = 10, 1.7e-8 L at 100 and less beyond (measured; tests/ddg/models/test_ribbon.py);
#: the Sano-Wada value W^2 / (b sqrt 60) = 0.38 L shifts it by ~1e-3 L. The paper sets zeta = 1e8.
DEFAULT_ZETA_OVER_L = 1e4


class RibbonModel(RodModel):
    """The DAR's DOFs and clamps with the Sadowsky energy (A.5); zeta in metres (default 1e4 L).

    Choose M not a multiple of 4: the clamped elastica's inflection points sit at s = L/4 and
    3L/4, on node (M - 2)/4 + 1/2 when M = 0 mod 4, where kappa^(2) = 0 makes the quartic term a
    maximum in kappa^(2) (Q_kk = -2 tau^4 / r^4), so that the symmetric U is a saddle from the
    first shear step and the path leaves it for a slightly asymmetric state
    (docs/findings/models.md). The default resolution is 101.
    """

    name = RIBBON

    def __init__(self, strip: Strip, nodes: int = 100, zeta: float | None = None):
        super().__init__(strip, nodes)
        self.zeta = check_zeta(DEFAULT_ZETA_OVER_L * strip.length if zeta is None else zeta)

    energy_parts = ("stretching", "bending", "twisting", "sadowsky")

    def quartic_zeta(self) -> float:
        return self.zeta

    def stencil_density(self, kappa_n: np.ndarray, kappa_g: np.ndarray, tau: np.ndarray):
        """The Sadowsky energy (Eq. A.5): the rod's bending and twisting plus the quartic term."""
        parts, first, second = super().stencil_density(kappa_n, kappa_g, tau)
        e_q, f_q, s_q = sadowsky_density(kappa_n, tau, self.voronoi_lengths, self.strip.bending_stiffness, self.zeta)
        return {**parts, "sadowsky": float(e_q.sum())}, first + f_q, second + s_q


RibbonModel._one_call_density = RibbonModel.stencil_density
