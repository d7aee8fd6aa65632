"""One-dimensional ribbon models that carry the width (paper section 4.3 and Appendix A).

All three live on the rod's centreline and frame (Eq. 1: the same DOFs, clamps, reference
frames, outputs, continuation, stability, thresholds and branch tracing as the DAR); each adds to
or replaces the rod's bending and twisting (Eqs. 6b, 6c) with a ribbon energy of its own module:

- `ribbon-sano-wada` (SanoWadaRibbon): Eq. (A.5) with Sano and Wada's (2019) width-dependent
  regularisation zeta^2 = (1 - nu) W^4 / (60 b^2) (ddg.energies.sadowsky). zeta / L =
  sqrt((1 - nu) / 60) W^2 / (b L) interpolates between the Kirchhoff rod (zeta -> 0, the quartic
  term cut off) and Sadowsky's developable ribbon (zeta -> infinity) through W^2 / (b L).
- `ribbon-trapeze` (TrapezeRibbon): the rod (Eqs. 6a-c) plus the stretching of the edges under
  twist (ddg.energies.trapeze): E b W^3 eps tau^2 / 24 + E b W^5 tau^4 / 640 per unit length.
  It keeps the rod's twist stiffness GJ, so it is exact for small W, and sees the width where
  W^2 tau / b is of order one.
- `ribbon-cross-section` (CrossSectionRibbon): the rod plus its cross-section as a field: two
  modes of the transverse deflection per edge (DOFs after each twist angle), which bend to relieve
  the edges' stretching under twist (ddg.energies.cross_section, after Audoly and Neukirch 2021):
  the rod for a narrow strip, the trapeze ribbon where the cross-section cannot bend, Sadowsky's
  ribbon for a wide one; and the torsion-warping of its rotation, with zero twist at the clamps
  (Eq. V). It has more DOFs than the rod (6M - 3 against 4M - 1): the cross-section's shape
  changes along the strip over about 0.4 W, which a density of the rod's strains alone cannot
  hold (ddg.energies.cross_section, "Why a field").
- `ribbon-wunderlich` (WunderlichRibbon): Wunderlich's finite-width developable ribbon, Eq. (A.2),
  regularised at inflection points as (A.5) is (ddg.energies.wunderlich); zeta defaults to the
  Sano-Wada value, and its effect is measured (validation/ribbon_regularisation.py).
"""
from __future__ import annotations

import math

import numpy as np

from ..energies.cross_section import (CrossSectionModes, field_density, modes_curvature_form, torsion_warping,
                                      torsion_warping_stiffness)
from ..energies.rod_curvature import material_curvatures, stencil_place
from ..energies.sadowsky import check_zeta
from ..energies.stencil_coupling import (add_local_terms, add_placed_terms, pair_blocks, stencil_strain_blocks,
                                         stencil_stretch)
from ..energies.trapeze import trapeze_coefficients, trapeze_density
from ..energies.wunderlich import POLE, wunderlich_pair_density
from ..geometry.strip import Strip
from .ribbon import RibbonModel
from .rod import RodModel

__all__ = ["SanoWadaRibbon", "TrapezeRibbon", "CrossSectionRibbon", "WunderlichRibbon", "sano_wada_zeta",
           "WIDE_RIBBONS"]

#: Strain indices of rod_curvature's (kappa_n, kappa_g, tau) order used here.
_KAPPA_N, _TAU = 0, 2


def add_stretch_strain_terms(model, x, m1, m2, eps_derivatives, components, first, second, grad, band,
                             hessian) -> None:
    """Adds per-stencil terms of (the Voronoi mean stretch, the rod strains `components`) to grad
    and (hessian) band: eps_derivatives = stencil_stretch's (gradients, Hessians); first (n, k)
    and second (n, k, k) the density's partials in that order."""
    eps_grad, eps_hess = eps_derivatives
    grads, hessians = stencil_strain_blocks(x, m1, m2)
    n = len(eps_grad)
    local_grads = np.concatenate([eps_grad[:, None], grads[:, list(components)]], axis=1)
    local_hess = np.concatenate([eps_hess[:, None], hessians[:, list(components)]], axis=1)
    add_local_terms(4 * np.arange(n), local_grads, local_hess, first, second, model.n_dof, grad, band, hessian)


def sano_wada_zeta(strip: Strip) -> float:
    """zeta = sqrt((1 - nu) / 60) W^2 / b (m), Sano and Wada (2019), the paper's Eq. (A.5)."""
    return math.sqrt((1.0 - strip.poisson_ratio) / 60.0) * strip.width**2 / strip.thickness


class SanoWadaRibbon(RibbonModel):
    """Eq. (A.5) with zeta from the strip: sqrt((1 - nu) / 60) W^2 / b (Sano and Wada 2019)."""

    name = "ribbon-sano-wada"

    def __init__(self, strip: Strip, nodes: int = 101):
        super().__init__(strip, nodes, zeta=sano_wada_zeta(strip))


class TrapezeRibbon(RodModel):
    """The DAR plus the trapeze term (ddg.energies.trapeze): the edges' stretching under twist."""

    name = "ribbon-trapeze"

    def __init__(self, strip: Strip, nodes: int = 101):
        super().__init__(strip, nodes)
        self.trapeze_coefficients = trapeze_coefficients(strip.young_modulus, strip.thickness, strip.width)

    def coupled_terms(self, q, x, m1, m2, kappa_n, tau, grad, band, gradient, hessian):
        eps, eps_grad, eps_hess = stencil_stretch(x, self.rest_edge_lengths)
        energy, first, second = trapeze_density(eps, tau, self.voronoi_lengths, *self.trapeze_coefficients)
        if gradient:
            add_stretch_strain_terms(self, x, m1, m2, (eps_grad, eps_hess), (_TAU,), first, second, grad, band,
                                     hessian)
        return {"trapeze": float(energy.sum())}


def _symmetric_csr(rows, cols, values, n: int):
    """The symmetric sparse matrix whose lower triangle is (rows, cols, values), rows >= cols."""
    from scipy.sparse import coo_matrix

    lower = coo_matrix((values, (rows, cols)), shape=(n, n)).tocsr()
    diagonal = coo_matrix((values * (rows == cols), (rows, cols)), shape=(n, n)).tocsr()
    return (lower + lower.T - diagonal).tocsr()


class CrossSectionRibbon(RodModel):
    """The DAR plus its cross-section as a field (ddg.energies.cross_section, Eqs. X, X' and V):
    `modes` DOFs per edge after the twist angle (node_stride 4 + modes), zero on the clamped edges."""

    name = "ribbon-cross-section"
    edge_fields = 2

    def __init__(self, strip: Strip, nodes: int = 101, modes: int | None = None):
        if modes is not None:
            self.edge_fields = modes
        super().__init__(strip, nodes)
        self.modes = CrossSectionModes(strip.width, strip.thickness, strip.young_modulus, strip.poisson_ratio,
                                       self.edge_fields)
        stride = self.node_stride
        # where the stencil's rod strains (over the rod's 11 DOFs) and its edges' modes sit in its block
        self._rod_place = stencil_place(11, stride)
        n = self.edge_fields
        self._mode_place = np.r_[4 + np.arange(n), stride + 4 + np.arange(n)]
        # Eq. V: the torsion-warping of the cross-section, over pairs of stencils (3 stride + 3 DOFs)
        self.warping_stiffness = torsion_warping_stiffness(self.modes)
        self.pair_lengths = self.rest_edge_lengths[1:-1]
        self._pair_place = stencil_place(15, stride)
        self.bandwidth = 3 * stride + 2  # a pair of stencils spans x_{i-1} .. x_{i+2}: 3 stride + 3 DOFs
        # the modes' bending along the strip, a constant quadratic form in the DOFs (Eq. X')
        rows, cols, values = modes_curvature_form(self.field_dofs, self.centerline.spacing, self.modes)
        self._curvature_band = ((rows - cols) * self.n_dof + cols, values)  # distinct entries of the band
        self._curvature_matrix = _symmetric_csr(rows, cols, values, self.n_dof)

    def coupled_terms(self, q, x, m1, m2, kappa_n, tau, grad, band, gradient, hessian):
        c = q[self.field_dofs]
        eps, eps_grad, eps_hess = stencil_stretch(x, self.rest_edge_lengths)
        _, kappa_g = material_curvatures(x, m1, m2)
        energy, first, second = field_density(eps, kappa_n, kappa_g, tau, c[:-1], c[1:], self.voronoi_lengths,
                                              self.modes)
        if gradient:
            grads, hessians = stencil_strain_blocks(x, m1, m2)
            strain_grads = np.concatenate([eps_grad[:, None], grads], axis=1)
            strain_hess = np.concatenate([eps_hess[:, None], hessians], axis=1)
            add_placed_terms(self.node_stride * np.arange(len(eps)), self._rod_place, strain_grads, strain_hess,
                             self._mode_place, first, second, self.n_dof, grad, band, hessian)
        pairs, pair_first, pair_second, ends, end_first, end_second = torsion_warping(
            tau, self.voronoi_lengths, self.pair_lengths, self.warping_stiffness)
        if gradient:
            none = np.empty(0, dtype=np.int64)
            pg, ph = pair_blocks(grads, hessians, (_TAU,))
            add_placed_terms(self.node_stride * np.arange(len(pairs)), self._pair_place, pg, ph, none,
                             pair_first, pair_second, self.n_dof, grad, band, hessian)
            last = len(eps) - 1
            add_placed_terms(self.node_stride * np.array([0, last]), self._rod_place,
                             np.ascontiguousarray(grads[[0, last]][:, [_TAU]]),
                             np.ascontiguousarray(hessians[[0, last]][:, [_TAU]]), none,
                             end_first[:, None], end_second[:, None, None], self.n_dof, grad, band, hessian)
        curvature_force = self._curvature_matrix @ q
        if gradient:
            grad += curvature_force
            if hessian:
                where, values = self._curvature_band
                band[where] += values
        return {"cross_section": float(energy.sum()), "torsion_warping": float(pairs.sum() + ends.sum()),
                "cross_section_bending": 0.5 * float(q @ curvature_force)}

    def residual_floor(self) -> float:
        """The rod's floor times (W / h)^2 / 25 where that is above 1: the modes' membrane terms
        cancel the centreline's stretching to about 1e-2 (eps = -W^2 tau^2 / 24), and their
        stiffness grows as (W / h)^2; measured at W/L = 1/12, M = 201 (W / h = 17): residual noise
        3-5e-5 against the rod's floor 9.3e-6, so Newton stalled before the pitchfork."""
        ratio = (self.strip.width / self.centerline.spacing) ** 2 / 25.0
        return super().residual_floor() * max(1.0, ratio)

    def cross_section(self, q: np.ndarray) -> np.ndarray:
        """The modes c^e (M - 1, n) of each edge's cross-section (c_1: transverse curvature, 1/m)."""
        return q[self.field_dofs]

    # the modes' units in the metric, residuals, steps and masses: c_j W^(2j - 1) is an angle
    def _mode_units(self) -> np.ndarray:
        return self.strip.width ** (2 * np.arange(1, self.edge_fields + 1) - 1)

    def eigenvalue_metric(self):
        """The rod's metric plus h int (w_j - mean w_j)^2 dy / W per mode (the cross-section's
        inertia, as the twist angle's h W^2 / 12)."""
        metric, unit = super().eigenvalue_metric()
        full = np.zeros(self.n_dof)
        full[self.free] = metric
        variance = np.diag(self.modes.S)[1:] / self.strip.width  # the modes are centred (Eq. X)
        full[self.field_dofs] = self.centerline.spacing * variance[None, :]
        return full[self.free], unit

    def residual_scale(self) -> np.ndarray:
        scale = super().residual_scale()
        scale[self.field_dofs] = (self.strip.bending_stiffness / self.strip.length * self._mode_units())[None, :]
        return scale

    def length_scale(self) -> np.ndarray:
        scale = super().length_scale()
        scale[self.field_dofs] = (1.0 / self._mode_units())[None, :]
        return scale

    def mass(self) -> np.ndarray:
        """The rod's masses plus rho b h int w_j^2 dy per mode."""
        mass = super().mass()
        s = self.strip
        mass[self.field_dofs] = (s.density * s.thickness * self.centerline.spacing * np.diag(self.modes.S)[1:])[None, :]
        return mass


class WunderlichRibbon(RibbonModel):
    """Eq. (A.2) regularised as (A.5): the Sadowsky ribbon (RibbonModel) with GJ from the strip,
    each node's density times the mean ruling factor g(W eta') of its pairs of stencils."""

    name = "ribbon-wunderlich"
    bandwidth = 14  # a pair of stencils spans 15 DOFs

    def __init__(self, strip: Strip, nodes: int = 101, zeta: float | None = None):
        super().__init__(strip, nodes, zeta=check_zeta(sano_wada_zeta(strip) if zeta is None else zeta))
        self.pair_lengths = self.rest_edge_lengths[1:-1]
        self.largest_ruling_rate = 0.0  # max |W eta'| of the last evaluated state (2 is the pole)

    def pair_terms(self, kappa_n, tau):
        s = self.strip
        return wunderlich_pair_density(kappa_n, tau, self.voronoi_lengths, self.pair_lengths, s.width,
                                       s.bending_stiffness, s.twisting_stiffness, self.voronoi_lengths / self.zeta)

    def coupled_terms(self, q, x, m1, m2, kappa_n, tau, grad, band, gradient, hessian):
        energy, first, second, v = self.pair_terms(kappa_n, tau)
        self.largest_ruling_rate = float(np.max(np.abs(v))) if len(v) else 0.0
        total = float(energy.sum()) if np.all(np.isfinite(energy)) else math.inf
        if gradient and math.isfinite(total):
            grads, hessians = stencil_strain_blocks(x, m1, m2)
            pg, ph = pair_blocks(grads, hessians, (_KAPPA_N, _TAU))
            add_local_terms(4 * np.arange(len(v)), pg, ph, first, second, self.n_dof, grad, band, hessian)
        elif gradient:
            grad[:] = np.nan
        return {"wunderlich": total}

    def resolution_indicators(self, q: np.ndarray) -> dict:
        """The rod's indicators plus the largest |W eta'| (the ruling factor's pole is at 2)."""
        out = super().resolution_indicators(q)
        x = q[self.node_dofs]
        t, _, m1, m2, m_ref = self.frames(q)
        from ..energies.rod_twist import discrete_twist

        kappa_n, _ = material_curvatures(x, m1, m2)
        tau = discrete_twist(q[self.theta_dofs], m_ref)
        v = self.pair_terms(kappa_n, tau)[3]
        out["max_ruling_rate"] = float(np.max(np.abs(v))) if len(v) else 0.0
        return out


    def stop_note(self, q: np.ndarray) -> str | None:
        """Why a stopped path may have stopped: |W eta'| within NEAR_POLE of the ruling factor's
        pole at 2 (the log barrier of Eq. A.2), where a fold found by the continuation may be the
        barrier rather than a limit point of the ribbon; None otherwise."""
        rate = self.resolution_indicators(q)["max_ruling_rate"]
        if rate < NEAR_POLE * POLE:
            return None
        return (f"the last converged state has |W eta'| = {rate:.3f}, near the pole of Wunderlich's ruling factor "
                f"at 2 (Eq. A.2): the fold where the path stopped may be that log barrier, not a limit point of the "
                f"ribbon (zeta = {self.zeta / self.strip.length:.3g} L regularises eta)")


#: A stopped Wunderlich path whose largest |W eta'| is above NEAR_POLE * 2 is said to stop at the barrier.
NEAR_POLE = 0.9

#: The models of this module by their --model names.
WIDE_RIBBONS = {cls.name: cls for cls in (SanoWadaRibbon, TrapezeRibbon, CrossSectionRibbon, WunderlichRibbon)}
