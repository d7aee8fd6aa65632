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

from ..energies.cross_section import (CrossSectionModes, add_pair_partials, add_torsion_warping_partials,
                                      field_density, modes_bending_terms, modes_curvature_form, torsion_warping,
                                      torsion_warping_stiffness)
from ..energies.rod_curvature import (STENCIL_SIZE, add_pair_cross_terms, add_stretched_stencil_terms,
                                      material_curvatures)
from ..energies.sadowsky import check_zeta
from ..energies.stencil_coupling import (add_local_terms, pair_blocks, stencil_strain_blocks, stencil_stretch,
                                         stencil_stretch_values)
from ..energies.trapeze import trapeze_coefficients, trapeze_density
from ..energies.wunderlich import POLE, wunderlich_pair_density
from ..geometry.strip import Strip
from ..limits import check_option
from .ribbon import RibbonModel
from .rod import RodModel
from .rod_assembly import CROSS_SECTION, PARTS, TRAPEZE, WUNDERLICH, width_terms
from .names import CROSS_SECTION_RIBBON, SANO_WADA_RIBBON, TRAPEZE_RIBBON, WUNDERLICH_RIBBON

#: The largest curvature-gradient length of CrossSectionRibbon, in widths: a length of several W
#: would make the term stiffer than the bending it regularises on any shape of the strip.
MAX_CURVATURE_GRADIENT = 10.0

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

    name = SANO_WADA_RIBBON

    def __init__(self, strip: Strip, nodes: int = 101):
        super().__init__(strip, nodes, zeta=sano_wada_zeta(strip))


class TrapezeRibbon(RodModel):
    """The DAR plus the trapeze term (ddg.energies.trapeze): the edges' stretching under twist."""

    name = TRAPEZE_RIBBON

    def __init__(self, strip: Strip, nodes: int = 101):
        super().__init__(strip, nodes)
        self.trapeze_coefficients = trapeze_coefficients(strip.young_modulus, strip.thickness, strip.width)

    energy_parts = PARTS[:3] + ("trapeze",)

    def width_terms(self):
        return width_terms(TRAPEZE, self.trapeze_coefficients)

    def coupled_terms(self, q, x, m1, m2, kappa_n, tau, grad, band, gradient, hessian):
        eps, eps_grad, eps_hess = stencil_stretch(x, self.rest_edge_lengths)
        energy, first, second = trapeze_density(eps, tau, self.voronoi_lengths, *self.trapeze_coefficients)
        if gradient:
            add_stretch_strain_terms(self, x, m1, m2, (eps_grad, eps_hess), (_TAU,), first, second, grad, band,
                                     hessian)
        return {"trapeze": float(energy.sum())}


class CrossSectionRibbon(RodModel):
    """The DAR plus its cross-section as a field (ddg.energies.cross_section, Eqs. X, X' and V):
    `modes` DOFs per edge after the twist angle (node_stride 4 + modes), zero on the clamped edges.
    `curvature_gradient` l > 0 adds B_k / 2 int kappa_n'^2, B_k = EI2 (l W)^2, over neighbouring
    stencils as Eq. V (without its clamp terms): a study option, zero by default; what it changes is
    measured in docs/findings/models.md (validation ribbon-reconciliation)."""

    name = CROSS_SECTION_RIBBON
    edge_fields = 2

    def __init__(self, strip: Strip, nodes: int = 101, modes: int | None = None, curvature_gradient: float = 0.0):
        length = check_option("CrossSectionRibbon", "curvature_gradient", curvature_gradient, "float", 0.0,
                              MAX_CURVATURE_GRADIENT)
        if modes is not None:
            self.edge_fields = modes
        super().__init__(strip, nodes)
        #: B_k = EI2 (l W)^2 of the normal curvature's gradient energy B_k / 2 int kappa_n'^2, l = curvature_gradient
        self.curvature_gradient_stiffness = strip.bending_stiffness * (length * strip.width) ** 2
        if self.curvature_gradient_stiffness > 0.0:
            self.energy_parts = type(self).energy_parts + ("curvature_gradient",)
        self.modes = CrossSectionModes(strip.width, strip.thickness, strip.young_modulus, strip.poisson_ratio,
                                       self.edge_fields)
        stride = self.node_stride
        # where the stencil's edges' modes sit in its block (after each edge's twist angle)
        n = self.edge_fields
        self._mode_place = np.r_[4 + np.arange(n), stride + 4 + np.arange(n)]
        # Eq. V: the torsion-warping of the cross-section, over pairs of stencils (3 stride + 3 DOFs)
        self.warping_stiffness = torsion_warping_stiffness(self.modes)
        self.pair_lengths = self.rest_edge_lengths[1:-1]
        self.bandwidth = 3 * stride + 2  # a pair of stencils spans x_{i-1} .. x_{i+2}: 3 stride + 3 DOFs
        # the modes' bending along the strip, a constant quadratic form in the DOFs (Eq. X')
        self._bending_form = modes_curvature_form(self.field_dofs, self.centerline.spacing, self.modes)

    fuses_stencil_terms = True
    energy_parts = PARTS[:3] + ("cross_section", "torsion_warping", "cross_section_bending")

    def width_terms(self):
        m = self.modes
        rows, cols, values = self._bending_form
        return width_terms(CROSS_SECTION, (m.membrane, m.plate, m.poisson_ratio, m.width, self.warping_stiffness,
                                           self.curvature_gradient_stiffness),
                           (self.pair_lengths, m.m, m.p, m.a, values), (m.S, m.P, m.Q, m.Psi, m.constant_hessian),
                           (self._mode_place, rows, cols), self.field_dofs)

    def fused_terms(self, q, x, m1, m2, kappa_n, kappa_g, tau, first, second, grad, band, gradient, hessian):
        """The rod's stencil densities (first, second: partials in (kappa_n, kappa_g, tau)), Eq. X
        and Eq. V in one compiled pass over the stencils (rod_curvature.add_stretched_stencil_terms),
        Eq. V's coupling of neighbouring twists in a second (add_pair_cross_terms); Eq. X' is a
        constant quadratic form."""
        c = q[self.field_dofs]
        eps = stencil_stretch_values(x, self.rest_edge_lengths)
        energy, f_u, f_uu = field_density(eps, kappa_n, kappa_g, tau, c[:-1], c[1:], self.voronoi_lengths,
                                          self.modes)
        pairs, pair_first, pair_second, ends, end_first, end_second = torsion_warping(
            tau, self.voronoi_lengths, self.pair_lengths, self.warping_stiffness)
        bending = modes_bending_terms(*self._bending_form, q, self.n_dof, gradient, hessian, grad, band)
        gradient_pairs, k_first, k_second, _, _, _ = torsion_warping(kappa_n, self.voronoi_lengths, self.pair_lengths,
                                                                     self.curvature_gradient_stiffness)
        if gradient:
            # u = (eps, kappa_n, kappa_g, tau, modes): the rod's own partials and Eq. V's per-twist parts join Eq. X's
            f_u[:, 1:4] += first
            f_uu[:, 1:4, 1:4] += second
            add_torsion_warping_partials(f_u, f_uu, pair_first, pair_second, end_first, end_second)
            add_pair_partials(f_u, f_uu, k_first, k_second, 1)
            strain_gradients = np.empty((len(tau) if hessian else 0, 4, STENCIL_SIZE))
            add_stretched_stencil_terms(x, m1, m2, self.rest_edge_lengths, f_u, f_uu, self.node_stride,
                                        self._mode_place, self.n_dof, grad, band, hessian, strain_gradients)
            if hessian:
                cross = np.zeros((len(tau) - 1, 2, 2))
                cross[:, 0, 0] = k_second[:, 0, 1]
                cross[:, 1, 1] = pair_second[:, 0, 1]
                add_pair_cross_terms(strain_gradients, cross, np.array([1, 3]), self.node_stride, self.n_dof, band)
        parts = {"cross_section": float(energy.sum()), "torsion_warping": float(pairs.sum() + ends.sum()),
                 "cross_section_bending": float(bending)}
        if self.curvature_gradient_stiffness > 0.0:
            parts["curvature_gradient"] = float(gradient_pairs.sum())
        return parts

    def residual_floor(self) -> float:
        """The rod's floor times (W / h)^2 / 25 where that is above 1: the modes' membrane terms
        cancel the centreline's stretching to about 1e-2 (eps = -W^2 tau^2 / 24), and their
        stiffness grows as (W / h)^2: with the rod's floor Newton stalled in round-off before the
        pitchfork (docs/findings/models.md)."""
        ratio = (self.strip.width / self.centerline.spacing) ** 2 / 25.0
        return super().residual_floor() * max(1.0, ratio)

    def resolution_indicators(self, q: np.ndarray) -> dict:
        """The rod's indicators plus W max |d kappa_n / ds| / max |kappa_n| (curvature_change_per_width):
        the largest change of the centreline's normal curvature within one width, relative to its
        largest value; above LONG_WAVELENGTH_LIMIT the model's expansion does not hold."""
        out = super().resolution_indicators(q)
        out["curvature_change_per_width"] = self._curvature_change(q)[0]
        return out

    def _curvature_change(self, q: np.ndarray) -> tuple[float, float]:
        """(W max |kappa_n'| / max |kappa_n|, s where kappa_n' is largest), kappa_n per unit length
        at the interior nodes and kappa_n' its difference between neighbours over their distance."""
        _, _, m1, m2, _ = self.frames(q)
        kappa = material_curvatures(q[self.node_dofs], m1, m2)[0] / self.voronoi_lengths
        largest = float(np.max(np.abs(kappa), initial=0.0))
        if largest == 0.0 or len(kappa) < 2:
            return 0.0, 0.0
        rate = np.abs(np.diff(kappa)) / self.pair_lengths
        worst = int(np.argmax(rate))
        where = 0.5 * (self.centerline.node_arclength[worst + 1] + self.centerline.node_arclength[worst + 2])
        return float(self.strip.width * rate[worst] / largest), float(where)

    def stop_note(self, q: np.ndarray) -> str | None:
        """Why a stopped path may have stopped: the last converged state's normal curvature changes
        by more than LONG_WAVELENGTH_LIMIT times its largest value within one width (measured: near
        dW_max an inflection of the twisted strip squeezed against a clamp, over one to three
        elements), where a fold the continuation finds may be the 1D expansion's, not the strip's;
        None otherwise."""
        change, where = self._curvature_change(q)
        if change <= LONG_WAVELENGTH_LIMIT:
            return None
        s, width = self.strip, self.strip.width
        from_clamp = min(where, s.length - where) / width
        return (f"at the last converged state the centreline's normal curvature changes by {change:.2g} times its "
                f"largest value within one width W, {from_clamp:.2g} W from a clamp (s/L = {where / s.length:.3f}): "
                f"beyond the long-wavelength expansion of this model (limit {LONG_WAVELENGTH_LIMIT:g}), so the fold "
                "where the path stopped may be the model's, not the strip's; a plate model resolves it")

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

    name = WUNDERLICH_RIBBON
    bandwidth = 14  # a pair of stencils spans 15 DOFs

    def __init__(self, strip: Strip, nodes: int = 101, zeta: float | None = None):
        super().__init__(strip, nodes, zeta=check_zeta(sano_wada_zeta(strip) if zeta is None else zeta))
        self.pair_lengths = self.rest_edge_lengths[1:-1]

    energy_parts = ("stretching", "bending", "twisting", "sadowsky", "wunderlich")

    def width_terms(self):
        return width_terms(WUNDERLICH, (self.strip.width,), (self.pair_lengths, self.voronoi_lengths / self.zeta))

    def pair_terms(self, kappa_n, tau):
        s = self.strip
        return wunderlich_pair_density(kappa_n, tau, self.voronoi_lengths, self.pair_lengths, s.width,
                                       s.bending_stiffness, s.twisting_stiffness, self.voronoi_lengths / self.zeta)

    def coupled_terms(self, q, x, m1, m2, kappa_n, tau, grad, band, gradient, hessian):
        energy, first, second, v = self.pair_terms(kappa_n, tau)
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


#: A model with a width along its centreline (CrossSectionRibbon) expands
#: the plate in strains that vary over lengths longer than the width W. Where the centreline's
#: normal curvature changes by more than this multiple of its largest value within one width
#: (W |d kappa_n / ds| / max |kappa_n| above 1: for a sinusoid, a wavelength below 2 pi W) the
#: expansion does not hold (path column `curvature_change_per_width`; ddg.protocol.validity).
LONG_WAVELENGTH_LIMIT = 1.0

#: A stopped Wunderlich path whose largest |W eta'| is above NEAR_POLE * 2 is said to stop at the barrier.
NEAR_POLE = 0.9

#: The models of this module by their --model names.
WIDE_RIBBONS = {cls.name: cls for cls in (SanoWadaRibbon, TrapezeRibbon, CrossSectionRibbon, WunderlichRibbon)}
