"""Discrete Elastic Plate (DEP), paper section 3.2.

DOF vector q = [x_0, x_1, ..., x_{N-1}] (Eq. 10), 3N entries, nodes of a flat triangle mesh
of the strip (ddg.geometry.plate_mesh). Energy: edge springs (Eq. 11a) and hinge bending from
neighbouring triangle normals (Eq. 11b).

Stiffnesses (derived in ddg.energies.hinge_bending and tested):
- stretching: k_e = E b (A_a + A_b) / |e_bar|^2 per edge (sum of the reference areas of the
  triangles sharing it). On interior edges of an equilateral mesh this is Eq. (11a)'s
  sqrt(3)/2 E b; the continuum limit is an isotropic membrane of 2D modulus E b and Poisson
  ratio 1/3 (boundary edges carry half, so the membrane is uniform up to the edge).
- bending: c_h = D |e_bar|^2 / (2 (A_a + A_b)) per hinge with D = E b^3 / 12: on equilateral
  triangles exactly Eq. (11b)'s E b^3 / (12 sqrt(3)), whose continuum limit has the plate
  bending stiffness D (Seung and Nelson 1988) and a Gaussian modulus of -4/3 D, i.e. a
  bending Poisson ratio nu_b = -1/3 (measured in tests/ddg/energies/test_plate_energies.py). Consequences
  for a strip, compared with the rod at nu = 0: a narrow plate bends as a beam of stiffness
  D (1 - nu_b^2) W = 8/9 EI2 (its Euler loads, tested) and twists with GJ = 2 D (1 - nu_b) W,
  4/3 of the rod's E W b^3 / 6; the stiffness ratio that sets the thresholds differs by 3/2.

Clamps (section 4): the two node columns at each end (every node within half a column
spacing of a clamp line, ddg.geometry.plate_mesh) move rigidly with their clamp; they
straddle the clamp lines so the free plate is exactly L.
"""
from __future__ import annotations

import math

import numpy as np

from ..energies.hinge_bending import add_hinge_terms, hinge_stiffness, triangle_normals
from ..energies.stretch import add_edge_terms
from ..geometry.centerline import first_mode_profile
from ..geometry.plate_mesh import DEFAULT_TRIANGLES, PlateMesh, structured_mesh
from ..limits import InputError
from ..geometry.strip import Strip
from .base import BandedModel, Evaluation
from .names import PLATE



class PlateModel(BandedModel):
    """The DEP of a Strip on a triangle mesh (structured with ~`triangles` triangles by default)."""

    name = PLATE

    def __init__(self, strip: Strip, triangles: int = DEFAULT_TRIANGLES, *, mesh: PlateMesh | None = None):
        self.strip = strip
        if mesh is None:
            mesh = structured_mesh(strip.length, strip.width, triangles)
        elif not (math.isclose(mesh.length, strip.length, rel_tol=1e-9)
                  and math.isclose(mesh.width, strip.width, rel_tol=1e-9)):
            raise InputError(f"mesh is {mesh.length:g} x {mesh.width:g} m but the strip is "
                             f"{strip.length:g} x {strip.width:g} m; they must agree")
        self.mesh = mesh
        n_nodes = mesh.node_count
        self.n_dof = 3 * n_nodes
        self.node_dofs = 3 * np.arange(n_nodes)[:, None] + np.arange(3)[None, :]
        left, right = np.flatnonzero(mesh.clamped_left), np.flatnonzero(mesh.clamped_right)
        if not (np.array_equal(left, np.arange(len(left)))
                and np.array_equal(right, np.arange(n_nodes - len(right), n_nodes))):
            raise InputError("mesh nodes must be ordered along x (build meshes with mesh_from_arrays)")
        self.left_nodes, self.right_nodes = left, right
        self.free = slice(3 * len(left), 3 * (n_nodes - len(right)))
        self.constrained = np.r_[np.arange(self.free.start), np.arange(self.free.stop, self.n_dof)]

        E, b = strip.young_modulus, strip.thickness
        rest = mesh.nodes
        self.rest_edge_lengths = np.linalg.norm(rest[mesh.edges[:, 1]] - rest[mesh.edges[:, 0]], axis=1)
        self.stretch_stiffness = E * b * mesh.edge_triangle_areas / self.rest_edge_lengths**2
        hinge_edges = mesh.hinge_edges
        self.hinge_stiffness = hinge_stiffness(self.rest_edge_lengths[hinge_edges],
                                               mesh.edge_triangle_areas[hinge_edges], E * b**3 / 12.0)

        self.bandwidth = 3 * mesh.bandwidth_nodes() + 2
        # connectivity as the compiled kernels take it (int64, contiguous), built once per mesh
        self._edges = np.ascontiguousarray(mesh.edges, dtype=np.int64)
        self._triangles = np.ascontiguousarray(mesh.triangles, dtype=np.int64)
        self._hinge_triangles = np.ascontiguousarray(mesh.hinge_triangles, dtype=np.int64).reshape(-1, 2)
        self._centre = mesh.interpolation_matrix(np.array([[0.5 * strip.length, 0.0]]))
        quarter = np.array([[0.25 * strip.length, 0.0], [0.75 * strip.length, 0.0]])
        self._quarters = mesh.interpolation_matrix(quarter)

    # ------------------------------------------------------------------ state
    def rest_state(self) -> np.ndarray:
        q = np.zeros(self.n_dof)
        q[self.node_dofs[:, :2]] = self.mesh.nodes
        return q

    def reset(self) -> np.ndarray:
        return self.rest_state()

    def positions(self, q: np.ndarray) -> np.ndarray:
        return q[self.node_dofs]

    # the plate has no frames to carry between states
    def commit(self, q: np.ndarray, evaluation: Evaluation | None = None) -> None:
        pass

    def save_frames(self):
        return None

    def restore_frames(self, saved) -> None:
        pass

    # ------------------------------------------------------------------ clamps
    def clamp_values(self, compression: float, shear: float) -> np.ndarray:
        """Clamped DOFs for clamp displacement (-dL, dW, 0) of the nodes with x >= L."""
        values = self.rest_state()[self.constrained].copy()
        right = self.node_dofs[self.right_nodes] - (self.free.stop - self.free.start)
        values[right[:, 0]] -= compression
        values[right[:, 1]] += shear
        return values

    def clamp_force(self, gradient: np.ndarray) -> np.ndarray:
        """Force (N) the moving clamp applies to the plate: dE/d(clamp translation) (App. E)."""
        return gradient[self.node_dofs[self.right_nodes]].sum(axis=0)

    # ------------------------------------------------------------------ observables
    def _interpolate(self, q: np.ndarray, where) -> np.ndarray:
        nodes, weights = where
        return np.einsum("qk,qkc->qc", weights, q[self.node_dofs][nodes])

    def midpoint(self, q: np.ndarray) -> np.ndarray:
        """Position of the plate's centre point (L/2, 0) (a node of the structured mesh)."""
        return self._interpolate(q, self._centre)[0]

    def mode_sign(self, mode: np.ndarray, direction: int) -> float:
        """+1 raises the centre (direction=1) or the first half against the second (direction=0)."""
        if direction:
            return float(self._interpolate(mode, self._centre)[0, 2])
        z = self._interpolate(mode, self._quarters)[:, 2]
        return float(z[0] - z[1])

    def centerline_positions(self, q: np.ndarray, stations: int = 101) -> tuple[np.ndarray, np.ndarray]:
        """Deformed positions (stations, 3) of the material line w = 0 at s = 0 .. L, and s."""
        s = np.linspace(0.0, self.strip.length, stations)
        where = self.mesh.interpolation_matrix(np.stack([s, np.zeros_like(s)], axis=1))
        return self._interpolate(q, where), s

    def symmetry_partners(self) -> tuple[np.ndarray, np.ndarray]:
        """Nodes whose reference point (x, y) has a node at (L - x, -y), with that node; the
        structured mesh pairs every node, other meshes whichever nodes match to 1e-9 L."""
        cached = getattr(self, "_partners", None)
        if cached is None:
            L = self.strip.length
            nodes = self.mesh.nodes
            key = np.round(nodes / (1e-9 * L)).astype(np.int64)
            image = np.round(np.stack([L - nodes[:, 0], -nodes[:, 1]], axis=1) / (1e-9 * L)).astype(np.int64)
            order = np.lexsort((key[:, 1], key[:, 0]))
            sorted_keys = key[order]
            # position of each image among the sorted node keys (lexicographic search by x, then y)
            at = np.searchsorted(sorted_keys[:, 0] * (2**31) + sorted_keys[:, 1], image[:, 0] * (2**31) + image[:, 1])
            at = np.minimum(at, len(order) - 1)
            match = np.all(sorted_keys[at] == image, axis=1)
            cached = self._partners = (np.flatnonzero(match), order[at[match]])
        return cached

    def resolution_indicators(self, q: np.ndarray) -> dict:
        """Largest angle between neighbouring triangle normals (degrees) and largest edge strain."""
        mesh = self.mesh
        x = q[self.node_dofs]
        normals, _ = triangle_normals(x, mesh.triangles)
        ht = mesh.hinge_triangles
        cosine = np.clip(np.einsum("hi,hi->h", normals[ht[:, 0]], normals[ht[:, 1]]), -1.0, 1.0)
        lengths = np.linalg.norm(x[mesh.edges[:, 1]] - x[mesh.edges[:, 0]], axis=1)
        return {"max_turn_angle_deg": float(np.degrees(np.arccos(cosine.min()))),
                "max_strain": float(np.max(np.abs(lengths / self.rest_edge_lengths - 1.0)))}

    # ------------------------------------------------------------------ energy
    def evaluate(self, q: np.ndarray, gradient: bool = True, hessian: bool = True) -> Evaluation:
        """Energy (Eq. 11), gradient and banded Hessian at q: compiled passes over the edges (Eq. 11a)
        and the triangles and hinges (Eq. 11b), written straight into the gradient and the band."""
        x = q.reshape(-1, 3)
        hessian = hessian and gradient
        n = self.n_dof
        grad, band = self._accumulators(gradient, hessian)
        stretching = add_edge_terms(x, self._edges, self.rest_edge_lengths, self.stretch_stiffness, 3, n,
                                    grad, band, gradient, hessian)
        bending = add_hinge_terms(x, self._triangles, self._hinge_triangles, self.hinge_stiffness, n,
                                  grad, band, gradient, hessian)
        parts = {"stretching": float(stretching), "bending": float(bending)}
        return self._evaluation(parts, grad, band, gradient, hessian)

    # ------------------------------------------------------------------ metrics and scales
    def eigenvalue_metric(self) -> tuple[np.ndarray, float]:
        """Lumped metric (node area / W per coordinate) and the unit EI2 / L^4, as the rod's
        (h per position): a mode uniform across the width has the rod's Rayleigh quotient."""
        metric = np.repeat(self.mesh.node_areas / self.strip.width, 3)
        return metric[self.free], self.strip.bending_stiffness / self.strip.length**4

    def _typical_spacing(self) -> float:
        return math.sqrt(4.0 * float(np.mean(self.mesh.triangle_areas)) / math.sqrt(3.0))

    def residual_scale(self) -> np.ndarray:
        """Per-node force unit: EI2 / L^2 times the node's share of a rod node of the same
        spacing (node area / (W h)), so tolerances mean what they mean for the rod."""
        s = self.strip
        share = self.mesh.node_areas / (s.width * self._typical_spacing())
        return np.repeat(s.bending_stiffness / s.length**2 * share, 3)

    def residual_floor(self) -> float:
        """Scaled residual that round-off alone produces: spring forces k_e L eps summed over a
        node's six edges, in the residual units, times a safety factor of 10."""
        floor = 6.0 * np.finfo(float).eps * float(self.stretch_stiffness.max()) * self.strip.length
        return 10.0 * floor / float(self.residual_scale()[self.free].min())

    def length_scale(self) -> np.ndarray:
        return np.full(self.n_dof, self.strip.length)

    def buckled_guess(self, compression: float, direction: int = 1) -> np.ndarray:
        """The inextensible first-mode shape (uniform across the width) with chord L - dL."""
        L = self.strip.length
        x0 = self.mesh.nodes[:, 0]
        X, Z = first_mode_profile(L, compression, np.clip(x0, 0.0, L), direction)
        X = X + np.minimum(x0, 0.0) + np.maximum(x0 - L, 0.0)
        q = self.rest_state()
        q[self.node_dofs[:, 0]] = X
        q[self.node_dofs[:, 2]] = Z
        return q
