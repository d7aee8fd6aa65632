"""Discrete Anisotropic Rod (DAR), paper section 3.1.

DOF vector q = [x_0, theta^0, x_1, theta^1, ..., theta^{M-2}, x_{M-1}] (Eq. 1), 4M - 1
entries (a model with `edge_fields` more DOFs per edge puts them after each theta^j:
node_stride = 4 + edge_fields, ddg.models.wide_ribbons.CrossSectionRibbon). Energy: stretching
(Eq. 6a), bending with both material curvatures (Eqs. 3-4, 6b)
and twisting with reference twist (Eqs. 5, 6c). Clamps (section 4): x_0, theta^0, x_1 and
x_{M-2}, theta^{M-2}, x_{M-1} are prescribed, 14 DOFs; the clamped edges straddle the clamp
points (see ddg.geometry.centerline) so the free length is exactly L. The material frame
starts with m1 = +z (the strip normal), t = +x, m2 = t x m1 = -y.
"""
from __future__ import annotations

import numpy as np
from scipy.optimize import brentq

from ..energies.rod_bending import bending_density
from ..energies.rod_curvature import add_stencil_terms, material_curvatures
from ..energies.rod_twist import discrete_twist, twisting_density
from ..energies.stretch import add_edge_terms
from ..geometry.centerline import Centerline
from ..geometry.frames import rod_frames
from ..geometry.strip import Strip
from .base import BandedModel, Evaluation
from .rod_assembly import PARTS, loops_of, rod_energy, width_terms
from .names import ROD

__all__ = ["RodModel", "Evaluation"]

class RodModel(BandedModel):
    """The DAR of a Strip on a Centerline of M nodes, with its reference-frame state."""

    name = ROD
    bandwidth = 10
    edge_fields = 0  # DOFs per edge beyond the twist angle (the rod has none)

    def __init__(self, strip: Strip, nodes: int = 100):
        self.strip = strip
        self.centerline = Centerline(strip.length, nodes)
        m = nodes
        self.nodes = m
        stride = self.node_stride = 4 + self.edge_fields
        self.n_dof = stride * (m - 1) + 3
        self.node_dofs = stride * np.arange(m)[:, None] + np.arange(3)[None, :]
        self.theta_dofs = stride * np.arange(m - 1) + 3
        self.field_dofs = stride * np.arange(m - 1)[:, None] + 4 + np.arange(self.edge_fields)[None, :]
        clamped = self.clamped_per_end = stride + 3  # x_0, theta^0 (and its fields), x_1
        h = self.centerline.spacing
        self.rest_edge_lengths = np.full(m - 1, h)
        self.voronoi_lengths = 0.5 * (self.rest_edge_lengths[:-1] + self.rest_edge_lengths[1:])
        self.stretch_stiffness = strip.stretching_stiffness / self.rest_edge_lengths  # Eq. (6a)
        self.constrained = np.r_[np.arange(clamped), np.arange(self.n_dof - clamped, self.n_dof)]
        self.free = slice(clamped, self.n_dof - clamped)
        self._edge_nodes = np.stack([np.arange(m - 1), np.arange(1, m)], axis=1)
        self.reset()

    # ------------------------------------------------------------------ state
    def rest_state(self) -> np.ndarray:
        q = np.zeros(self.n_dof)
        q[self.node_dofs] = self.centerline.rest_positions()
        return q

    def reset(self) -> np.ndarray:
        """Back to the flat, straight rest configuration; returns its DOF vector."""
        m = self.nodes
        self._tangents = np.tile([1.0, 0.0, 0.0], (m - 1, 1))
        self._d1 = np.tile([0.0, 0.0, 1.0], (m - 1, 1))
        self._ref_twist = np.zeros(m - 2)
        return self.rest_state()

    def positions(self, q: np.ndarray) -> np.ndarray:
        return q[self.node_dofs]

    def frames(self, q: np.ndarray):
        """Tangents, reference d1 (transported in time from the committed state), m1, m2, m_ref."""
        return rod_frames(q[self.node_dofs], self._tangents, self._d1, q[self.theta_dofs], self._ref_twist)

    def commit(self, q: np.ndarray, evaluation: Evaluation | None = None) -> None:
        """Adopt q's frames as the reference from which the next trial states are transported."""
        if evaluation is not None and evaluation.frames is not None:
            t, d1, m_ref = evaluation.frames
        else:
            t, d1, _, _, m_ref = self.frames(q)
        self._tangents, self._d1, self._ref_twist = t, d1, m_ref

    def save_frames(self):
        return (self._tangents.copy(), self._d1.copy(), self._ref_twist.copy())

    def restore_frames(self, saved) -> None:
        self._tangents, self._d1, self._ref_twist = (a.copy() for a in saved)

    # ------------------------------------------------------------------ clamps
    def clamp_values(self, compression: float, shear: float) -> np.ndarray:
        """Prescribed values of the clamped DOFs (14 for the rod) for clamp displacement (-dL, dW, 0):
        the clamped edges' positions move, their angles (and edge fields) keep their rest values."""
        rest = self.rest_state()
        values = rest[self.constrained].copy()
        n = self.clamped_per_end
        shift = np.zeros(n)
        shift[0:3] = shift[n - 3:n] = (-compression, shear, 0.0)
        values[n:] += shift
        return values

    def midpoint(self, q: np.ndarray) -> np.ndarray:
        """Centerline point at rest arclength s = L/2 (linear along the edge, O(h^2))."""
        return self.centerline.interpolate_at(q[self.node_dofs], 0.5 * self.strip.length)

    def centerline_positions(self, q: np.ndarray, stations: int = 101) -> tuple[np.ndarray, np.ndarray]:
        """Deformed centerline positions (stations, 3) at rest arclengths s = 0 .. L, and s."""
        s = np.linspace(0.0, self.strip.length, stations)
        x = q[self.node_dofs]
        sn = self.centerline.node_arclength
        return np.stack([np.interp(s, sn, x[:, k]) for k in range(3)], axis=1), s

    def symmetry_partners(self) -> tuple[np.ndarray, np.ndarray]:
        """Node i sits at s = (i - 1/2) h, its mirror node M - 1 - i at L - s."""
        i = np.arange(self.nodes)
        return i, i[::-1]

    def half_turn(self, q: np.ndarray, frames, compression: float, shear: float):
        """The state the scene's half turn makes of (q, frames) at the clamp displacement
        (compression, shear): (q', frames'), or None where the model has edge fields (their parity
        under the turn is not defined here).

        The turn is R = diag(-1, -1, 1) about the vertical axis through the midpoint c between the
        clamp points; node i goes to node M - 1 - i, x' = R (x - c) + c, and edge j to edge M - 2 - j
        with the tangent reversed, t' = -R t. The material frame turns with the body, m1' = R m1,
        and m2' = -R m2 keeps it right-handed about t'; with the reference director turned the same
        way, d1' = R d1, the twist angle changes sign, theta' = -theta, and the reference twist
        between two edges is kept, in reverse order. The clamps map onto each other and their
        angles (zero) onto zero. An equilibrium maps onto an equilibrium (the callers check its
        residual)."""
        if self.edge_fields:
            return None
        turn = np.array([-1.0, -1.0, 1.0])
        c = np.array([0.5 * (self.strip.length - compression), 0.5 * shear, 0.0])
        out = np.empty_like(q)
        x = q[self.node_dofs]
        out[self.node_dofs] = (turn * (x - c) + c)[::-1]
        out[self.theta_dofs] = -q[self.theta_dofs][::-1]
        tangents, d1, ref_twist = frames
        return out, (-(turn * tangents)[::-1], (turn * d1)[::-1], ref_twist[::-1].copy())

    def resolution_indicators(self, q: np.ndarray) -> dict:
        """Largest turning angle between neighbouring edges (degrees) and largest edge strain."""
        x = q[self.node_dofs]
        edges = x[1:] - x[:-1]
        lengths = np.linalg.norm(edges, axis=1)
        t = edges / lengths[:, None]
        cosine = np.clip(np.einsum("ij,ij->i", t[:-1], t[1:]), -1.0, 1.0)
        return {"max_turn_angle_deg": float(np.degrees(np.arccos(cosine.min()))),
                "max_strain": float(np.max(np.abs(lengths / self.rest_edge_lengths - 1.0)))}

    def mode_sign(self, mode: np.ndarray, direction: int) -> float:
        """Sign convention of a mode: +1 raises the midpoint (direction=1) or the first half
        of the strip against the second (direction=0, the '+' branches US+ and S+)."""
        z = mode[self.node_dofs][:, 2]

        def at(frac):
            return float(self.centerline.interpolate_at(z, frac * self.strip.length))

        return at(0.5) if direction else at(0.25) - at(0.75)

    def clamp_force(self, gradient: np.ndarray) -> np.ndarray:
        """Force (N) the moving clamp at s = L applies to the strip: dE/d(clamp translation)."""
        g = gradient[self.node_dofs]
        return g[-2] + g[-1]

    # ------------------------------------------------------------------ energy
    def evaluate(self, q: np.ndarray, gradient: bool = True, hessian: bool = True) -> Evaluation:
        """Energy (Eq. 6), gradient and banded Hessian at q, frames transported from the committed
        state: compiled passes over the edges (Eq. 6a) and the stencils (Eqs. 6b, 6c, or the
        ribbon's), written straight into the gradient and the band."""
        args = self.assembly_args()
        hessian = hessian and gradient
        if args is None:
            return self.evaluate_piecewise(q, gradient, hessian)
        grad, band = self._accumulators(gradient, hessian)
        parts, frames = rod_energy(np.ascontiguousarray(q, dtype=float), self.committed_frames(), args,
                                   gradient, hessian, grad, band)
        return self.compiled_evaluation(parts, grad, band, frames, gradient, hessian)

    def evaluate_piecewise(self, q: np.ndarray, gradient: bool = True, hessian: bool = True) -> Evaluation:
        """evaluate() composed in Python of the same compiled pieces, one call per piece (the
        strains, the densities, the chain rules of ddg.energies): the reference the one-call
        assembly is tested against (tests/ddg/solve/test_compiled_newton.py), and what a model without a
        one-call assembly (assembly_args None) evaluates."""
        hessian = hessian and gradient
        x = q[self.node_dofs]
        theta = q[self.theta_dofs]
        t, d1, m1, m2, m_ref = rod_frames(x, self._tangents, self._d1, theta, self._ref_twist)
        kappa_n, kappa_g = material_curvatures(x, m1, m2)
        tau = discrete_twist(theta, m_ref)
        parts, first, second = self.stencil_density(kappa_n, kappa_g, tau)
        n = self.n_dof
        grad, band = self._accumulators(gradient, hessian)
        stretching = add_edge_terms(x, self._edge_nodes, self.rest_edge_lengths, self.stretch_stiffness,
                                    self.node_stride, n, grad, band, gradient, hessian)
        if self.fuses_stencil_terms:
            parts.update(self.fused_terms(q, x, m1, m2, kappa_n, kappa_g, tau, first, second, grad, band, gradient,
                                          hessian))
        else:
            if gradient:
                add_stencil_terms(x, m1, m2, first, second, self.node_stride, n, grad, band, hessian)
            parts.update(self.coupled_terms(q, x, m1, m2, kappa_n, tau, grad, band, gradient, hessian))
        return self._evaluation({"stretching": float(stretching), **parts}, grad, band, gradient, hessian,
                                frames=(t, d1, m_ref))

    #: The parts of the energy that rod_assembly.rod_energy computes for this class (names of PARTS).
    energy_parts = PARTS[:3]

    def assembly_args(self):
        """The constants of the one-call assembly (ddg.models.rod_assembly.rod_energy) where the
        model's energy is the rod's, Eq. (6), or a ribbon's whose terms beyond it rod_energy
        computes (`width_terms` overridden), and evaluate is not overridden (the compiled Newton
        loop calls rod_energy, not evaluate); else None (the model is assembled piece by piece,
        below). Cached on the model."""
        cached = getattr(self, "_assembly_args", None)
        if cached is None:
            cls = type(self)
            own_terms = cls.width_terms is not RodModel.width_terms
            if cls.evaluate is not RodModel.evaluate or not own_terms and (
                    cls.stencil_density is not cls._one_call_density or cls.coupled_terms is not RodModel.coupled_terms
                    or cls.fuses_stencil_terms):
                cached = ()
            else:
                s = self.strip
                cached = (self.node_stride, self._edge_nodes, self.rest_edge_lengths, self.stretch_stiffness,
                          self.voronoi_lengths, float(s.bending_stiffness), float(s.geodesic_bending_stiffness),
                          float(s.twisting_stiffness), float(self.quartic_zeta()), self.width_terms())
            self._assembly_args = cached
        return cached or None

    def width_terms(self):
        """The terms beyond Eqs. (6) / (A.5) that rod_energy adds for this model
        (ddg.models.rod_assembly.width_terms): none for the rod. A subclass with terms of its own
        (coupled_terms, fused_terms) overrides this with their constants, or is assembled piecewise."""
        return width_terms()

    def compiled_energy(self):
        """The constants of rod_energy for the compiled Newton loop and corrector
        (ddg.solve.compiled_newton), or None where the model is assembled piece by piece."""
        return self.assembly_args()

    def compiled_loops(self):
        """The compiled Newton step and corrector bound to this model's energy
        (ddg.solve.compiled_newton.CompiledLoops), for the solvers where compiled_energy() is not None."""
        return loops_of(self.compiled_energy())

    def compiled_evaluation(self, parts, grad, band, frames, gradient: bool = True, hessian: bool = True) -> Evaluation:
        """The Evaluation of rod_energy's output (its parts by name, energy their sum)."""
        named = {name: float(parts[PARTS.index(name)]) for name in self.energy_parts}
        return self._evaluation(named, grad, band, gradient, hessian, frames=frames)

    def quartic_zeta(self) -> float:
        """zeta of the Sadowsky term in the one-call assembly (0: no such term)."""
        return 0.0

    def committed_frames(self):
        """The committed (tangents, d1, m_ref) from which trial states' frames are transported."""
        return (self._tangents, self._d1, self._ref_twist)

    #: A model whose energies beyond the rod's share the stencils' chain rule with the rod's own
    #: (`fused_terms` instead of add_stencil_terms and `coupled_terms`: one pass over the stencils).
    fuses_stencil_terms = False

    def coupled_terms(self, q, x, m1, m2, kappa_n, tau, grad, band, gradient: bool, hessian: bool) -> dict:
        """Energies beyond the per-stencil densities (the ribbons with width: the trapeze term's
        stretch-twist coupling, Wunderlich's pairs of stencils): adds their gradient and Hessian
        into grad and band (ddg.energies.stencil_coupling) and returns their totals by part. The
        rod has none."""
        return {}

    def stencil_density(self, kappa_n: np.ndarray, kappa_g: np.ndarray, tau: np.ndarray):
        """Bending (Eq. 6b) and twisting (Eq. 6c) of the interior nodes as functions of the strains:
        totals per part, partials (n, 3) and second partials (n, 3, 3) in (kappa_n, kappa_g, tau)
        (the ribbon overrides it)."""
        s = self.strip
        e_b, f_b, s_b = bending_density(kappa_n, kappa_g, self.voronoi_lengths, s.bending_stiffness,
                                        s.geodesic_bending_stiffness)
        e_t, f_t, s_t = twisting_density(tau, self.voronoi_lengths, s.twisting_stiffness)
        return {"bending": float(e_b.sum()), "twisting": float(e_t.sum())}, f_b + f_t, s_b + s_t

    # ------------------------------------------------------------------ linear algebra
    def eigenvalue_metric(self) -> tuple[np.ndarray, float]:
        """Lumped metric D of the free DOFs and the unit of the normalised eigenvalue.

        lambda_min is the lowest eigenvalue of K v = lambda D v with D = h per position DOF and
        h W^2 / 12 per twist angle (the cross-section's rotational inertia per unit area), in
        units of EI2 / L^4: lambda L^4 / EI2 approximates the continuum Rayleigh quotient and
        so does not depend on M. The plate uses area / W per node, making the two comparable.
        """
        h = self.centerline.spacing
        metric = np.full(self.n_dof, h)
        metric[self.theta_dofs] = h * self.strip.width**2 / 12.0
        return metric[self.free], self.strip.bending_stiffness / self.strip.length**4

    # ------------------------------------------------------------------ helpers
    def residual_scale(self) -> np.ndarray:
        """Per-DOF force/moment units: EI2 / L^2 for positions, EI2 / L for twist angles."""
        s = self.strip
        scale = np.full(self.n_dof, s.bending_stiffness / s.length**2)
        scale[self.theta_dofs] = s.bending_stiffness / s.length
        return scale

    def residual_floor(self) -> float:
        """Scaled residual that round-off alone produces: stretching forces EA L / h times the
        machine epsilon, in units of EI2 / L^2, times a safety factor of 10."""
        s = self.strip
        floor = np.finfo(float).eps * s.stretching_stiffness * s.length / self.centerline.spacing
        return 10.0 * floor / (s.bending_stiffness / s.length**2)

    def length_scale(self) -> np.ndarray:
        """Per-DOF size used in step tolerances: L for positions, 1 rad for angles."""
        scale = np.full(self.n_dof, self.strip.length)
        scale[self.theta_dofs] = 1.0
        return scale

    def buckled_guess(self, compression: float, direction: int = 1) -> np.ndarray:
        """An inextensible first-mode shape with chord L - dL, used to start the compression.

        Tangent angles phi_e = phi0 sin(2 pi s_e / L) at the edge stations s_e = e h, with phi0
        solved so the chord between the clamp points is exactly L - dL; the shape lies in the
        x-z plane, rising towards +z for direction = +1.
        """
        cl = self.centerline
        h = cl.spacing
        s_e = cl.edge_arclength
        shape = np.sin(2.0 * np.pi * s_e / cl.length)

        def chord_error(phi0):
            c = np.cos(phi0 * shape)
            return h * (0.5 * c[0] + c[1:-1].sum() + 0.5 * c[-1]) - (cl.length - compression)

        phi0 = brentq(chord_error, 0.0, 2.4) if compression > 0 else 0.0
        phi = direction * phi0 * shape
        tangents = np.stack([np.cos(phi), np.zeros_like(phi), np.sin(phi)], axis=1)
        x = np.zeros((self.nodes, 3))
        x[0] = [-0.5 * h, 0.0, 0.0]
        x[1:] = x[0] + h * np.cumsum(tangents, axis=0)
        q = self.rest_state()
        q[self.node_dofs] = x
        return q

    def mass(self) -> np.ndarray:
        """Lumped masses for the dynamic option (Eq. 7): rho A dl per node, rho I_p dl per edge."""
        s = self.strip
        h = self.centerline.spacing
        mass = np.full(self.n_dof, s.density * s.width * s.thickness * h)
        polar = s.density * s.width * s.thickness * (s.width**2 + s.thickness**2) / 12.0
        mass[self.theta_dofs] = polar * h
        return mass


RodModel._one_call_density = RodModel.stencil_density
