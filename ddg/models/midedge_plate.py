"""The mid-edge plate (`plate-midedge`): a discrete Kirchhoff plate with the material's Poisson ratio.

The paper's plate (Eq. 11, ddg.models.plate) is kept as `plate`. This second plate model has
the same kinematics for the nodes but its own energies, chosen so that the plate converges at
second order with the mesh and its continuum limit is the Kirchhoff plate of the strip's
material (Young's modulus E, Poisson ratio nu for both membrane and bending):

- membrane: constant-strain triangles (ddg.energies.membrane), plane-stress St Venant-Kirchhoff,
  by default mixed as the shell's partial selective reduced integration: alpha = b^2 / h^2 of
  them and 1 - alpha of their node-smoothed strains (ddg.energies.smoothed_membrane), against
  membrane locking (what it removes: docs/findings/benchmark.md; `membrane="full"`: all CST);
- bending: mid-edge normals (ddg.energies.midedge_bending): one angle DOF per edge, the
  triangle's second fundamental form from its three mid-edge normals (Morley's element when
  linearised), density D/2 [nu tr(M)^2 + (1 - nu) tr(M^2)] with D = E b^3 / (12 (1 - nu^2)).

A narrow strip of this plate bends like the rod, EI2 = D (1 - nu^2) W = E W b^3 / 12, and twists
with GJ = 2 D (1 - nu) W = E W b^3 / (6 (1 + nu)) (the paper's Eq. A.1), where the paper's
plate, with its bending Poisson ratio -1/3, twists 4/3 stiffer (tested in
tests/ddg/models/test_midedge_plate.py).

DOFs: the nodes' positions (3 each) and the edges' angles (1 each), ordered together by x (of
the node, of the edge's midpoint) so the Hessian is banded and the clamped DOFs come first and
last. Clamps (ddg.geometry.plate_mesh.ghost_clamp_mesh): the node columns at x = 0 and x = L
and one ghost column beyond each are clamped, with the angles of the edges between clamped
nodes (theta = 0: the director of a clamped edge is the clamp's normal); the free plate is
exactly [0, L].
"""
from __future__ import annotations

import numpy as np

from ..energies.membrane import add_membrane_terms, face_membrane_matrices
from ..energies.midedge_bending import ROLE_FIRST, ROLE_SECOND, add_midedge_terms, face_bending_matrices
from ..energies.smoothed_membrane import add_smoothed_membrane_terms, node_patches, plane_stress_matrix, strain_maps
from ..geometry.plate_mesh import DEFAULT_TRIANGLES, PlateMesh, ghost_clamp_mesh
from ..limits import InputError
from ..geometry.strip import Strip
from .base import Evaluation
from .plate import PlateModel
from .names import MIDEDGE_PLATE


#: Membrane discretisations: "psri", alpha = min(1, b^2 / h^2) of the constant-strain triangles and
#: the rest node-smoothed (ddg.energies.smoothed_membrane), the treatment of membrane locking as
#: the shell reference's partial selective reduced integration; "full", the constant-strain
#: triangles alone (locks on coarse thin plates: docs/findings/benchmark.md).
MEMBRANES = ("psri", "full")


def _bending_stencils(triangles, face_edges, roles, hinge_of_edge, hinges):
    """Each triangle's bending stencil for ddg.energies.midedge_bending.add_midedge_terms: (stencil
    (T, 6): its vertices, then the far vertices o_a of the hinges it is second on, each once, -1
    after them; hinge_slots (T, 3, 4): the stencil rows of (v0, v1, o_a, o_b) of the hinge of edge
    i where the triangle is the hinge's second triangle b = (v1, v0, o_b), -1 where it is first)."""
    count = len(triangles)
    second = roles == ROLE_SECOND
    rows = hinges[np.maximum(hinge_of_edge[face_edges], 0)]  # (T, 3, 4)
    stencil = np.full((count, 6), -1, dtype=np.int64)
    stencil[:, :3] = triangles
    slots = np.full((count, 3, 4), -1, dtype=np.int64)
    size = np.full(count, 3)
    for i in range(3):
        on = second[:, i]
        far, v0 = rows[:, i, 2], rows[:, i, 0]
        if (on & (rows[:, i, 3] != triangles[:, i])).any():
            raise InputError("a hinge's second triangle is not opposite its own vertex o_b")
        slot = size.copy()
        for j in range(i):
            same = on & second[:, j] & (far == rows[:, j, 2])
            slot[same] = slots[same, j, 2]
        new = on & (slot == size)
        stencil[new, size[new]] = far[new]
        size += new
        after, before = (i + 1) % 3, (i + 2) % 3
        slot_v0 = np.where(triangles[:, after] == v0, after, before)
        slots[on, i] = np.stack([slot_v0, after + before - slot_v0, slot, np.full(count, i)], axis=1)[on]
    return np.ascontiguousarray(stencil), np.ascontiguousarray(slots)


class MidedgePlateModel(PlateModel):
    """The mid-edge plate of a Strip on a ghost-clamp structured mesh of ~`triangles` triangles
    (or `rows` rows across W, or a given ghost_clamp_mesh). membrane_alpha (with "psri"): the
    constant-strain share instead of b^2 / h^2, e.g. 0 for the node-smoothed membrane alone."""

    name = MIDEDGE_PLATE

    def __init__(self, strip: Strip, triangles: int = DEFAULT_TRIANGLES, *, rows: int | None = None,
                 mesh: PlateMesh | None = None, membrane: str = "psri", membrane_alpha: float | None = None):
        if membrane not in MEMBRANES:
            raise InputError(f"membrane = {membrane!r} must be one of {', '.join(MEMBRANES)}")
        if membrane_alpha is not None and not (membrane == "psri" and 0.0 <= membrane_alpha <= 1.0):
            raise InputError(f"membrane_alpha = {membrane_alpha!r} must lie in [0, 1], with membrane 'psri'")
        self.strip = strip
        self.membrane = membrane
        if mesh is None:
            mesh = ghost_clamp_mesh(strip.length, strip.width, triangles, rows=rows)
        elif mesh.clamp_depth != 0.0:
            raise InputError("the mid-edge plate needs a mesh whose clamp lines are node columns "
                             "(ddg.geometry.plate_mesh.ghost_clamp_mesh)")
        self.mesh = mesh
        nodes, tris, edges = mesh.nodes, mesh.triangles, mesh.edges
        n_nodes, n_edges = len(nodes), len(edges)
        clamped = mesh.clamped_left | mesh.clamped_right
        edge_clamped = clamped[edges[:, 0]] & clamped[edges[:, 1]]
        rigid = clamped[tris].all(axis=1)

        # DOF numbering: nodes and edges ordered together by x (clamped ones first and last)
        key = np.r_[nodes[:, 0], 0.5 * (nodes[edges[:, 0], 0] + nodes[edges[:, 1], 0])]
        kind = np.r_[np.zeros(n_nodes, dtype=np.int64), np.ones(n_edges, dtype=np.int64)]
        index = np.r_[np.arange(n_nodes), np.arange(n_edges)]
        order = np.lexsort((index, kind, key))
        width = np.where(kind[order] == 0, 3, 1)
        start = np.r_[0, np.cumsum(width)[:-1]]
        self.n_dof = int(width.sum())
        node_start = np.empty(n_nodes, dtype=np.int64)
        edge_start = np.empty(n_edges, dtype=np.int64)
        is_node = kind[order] == 0
        node_start[index[order][is_node]] = start[is_node]
        edge_start[index[order][~is_node]] = start[~is_node]
        self.node_dofs = node_start[:, None] + np.arange(3)[None, :]
        self.edge_dofs = edge_start
        constrained_entity = np.r_[clamped, edge_clamped][order]
        free_entities = np.flatnonzero(~constrained_entity)
        first, last = free_entities[0], free_entities[-1]
        if constrained_entity[first:last + 1].any():
            raise InputError("mesh clamps are not at its ends (the mid-edge plate orders DOFs by x)")
        self.free = slice(int(start[first]), int(start[last] + width[last]))
        self.constrained = np.r_[np.arange(self.free.start), np.arange(self.free.stop, self.n_dof)]
        self.left_nodes, self.right_nodes = np.flatnonzero(mesh.clamped_left), np.flatnonzero(mesh.clamped_right)

        # connectivity: each triangle's edges (opposite vertex i), its role on them, the hinges
        # with the first triangle a (a rigid ghost triangle where there is one)
        key_edges = edges[:, 0].astype(np.int64) * n_nodes + edges[:, 1]
        face_edges = np.empty_like(tris)
        for i in range(3):
            a, b = tris[:, (i + 1) % 3], tris[:, (i + 2) % 3]
            key_faces = np.minimum(a, b).astype(np.int64) * n_nodes + np.maximum(a, b)
            face_edges[:, i] = np.searchsorted(key_edges, key_faces)
        hinges = mesh.hinges.copy()
        pair = mesh.hinge_triangles.copy()
        swap = rigid[pair[:, 1]] & ~rigid[pair[:, 0]]
        hinges[swap] = hinges[swap][:, [1, 0, 3, 2]]
        pair[swap] = pair[swap][:, ::-1]
        hinge_of_edge = np.full(n_edges, -1, dtype=np.int64)
        hinge_of_edge[mesh.hinge_edges] = np.arange(len(hinges))
        second_of_edge = np.full(n_edges, -1, dtype=np.int64)
        second_of_edge[mesh.hinge_edges] = pair[:, 1]
        roles = np.where(second_of_edge[face_edges] == np.arange(len(tris))[:, None], ROLE_SECOND, ROLE_FIRST)

        E, b, nu = strip.young_modulus, strip.thickness, strip.poisson_ratio
        self._membrane, self._abar = face_membrane_matrices(nodes, tris, E, b, nu)
        self._bending = face_bending_matrices(nodes, tris, E, b, nu)
        self._strain_T, areas = strain_maps(nodes, tris)
        self._patches = node_patches(tris, areas, active=~rigid)
        self._plane_stress = plane_stress_matrix(E, b, nu)
        #: share of the full constant-strain membrane; the rest is the node-smoothed one
        self.membrane_alpha = min(1.0, (b / self._typical_spacing()) ** 2) if membrane == "psri" else 1.0
        if membrane_alpha is not None:  # a fixed share, the same on every mesh (mesh studies)
            self.membrane_alpha = float(membrane_alpha)
        self._triangles = np.ascontiguousarray(tris, dtype=np.int64)
        self._face_edges = np.ascontiguousarray(face_edges, dtype=np.int64)
        #: the hinges (v0, v1, o_a, o_b) with a their first triangle, and each edge's row in them (-1: free edge)
        self._hinges, self._hinge_of_edge = np.ascontiguousarray(hinges, dtype=np.int64), hinge_of_edge
        self._stencil, self._hinge_slots = _bending_stencils(tris, face_edges, roles, hinge_of_edge, hinges)
        # the per-triangle passes visit the triangles by their lowest DOF, so that the band entries
        # they add into stay in a window of the band's columns (the mesh numbers them row by row)
        lowest = np.where(self._stencil >= 0, self.node_dofs[np.maximum(self._stencil, 0), 0], self.n_dof).min(axis=1)
        by_x = np.argsort(lowest, kind="stable")
        self._by_x = {name: np.ascontiguousarray(array[by_x]) for name, array in (
            ("triangles", self._triangles), ("membrane", self.membrane_alpha * self._membrane),
            ("abar", self._abar), ("stencil", self._stencil), ("hinge_slots", self._hinge_slots),
            ("face_edges", self._face_edges), ("bending", self._bending))}
        self._node_dofs = np.ascontiguousarray(self.node_dofs, dtype=np.int64)
        self._edge_dofs = np.ascontiguousarray(self.edge_dofs, dtype=np.int64)

        # bandwidth: the widest stencil (a triangle, the far vertices of its hinges, its edges)
        far = np.where(roles == ROLE_SECOND, hinges[np.maximum(hinge_of_edge[face_edges], 0), 2], tris)
        stencil = np.concatenate([self.node_dofs[tris].reshape(len(tris), -1),
                                  self.node_dofs[far].reshape(len(tris), -1), self.edge_dofs[face_edges]], axis=1)
        self.bandwidth = int((stencil.max(axis=1) - stencil.min(axis=1)).max())
        # the smoothed membrane couples the nodes of each patch (the triangles around a node)
        pointer, patch_faces = self._patches[0], self._patches[1]
        patch_dofs = self.node_dofs[tris[patch_faces]].reshape(len(patch_faces), -1)
        starts = pointer[:-1]
        span = np.maximum.reduceat(patch_dofs.max(axis=1), starts) - np.minimum.reduceat(patch_dofs.min(axis=1), starts)
        self.bandwidth = max(self.bandwidth, int(span.max()))

        self.rest_edge_lengths = np.linalg.norm(nodes[edges[:, 1]] - nodes[edges[:, 0]], axis=1)
        self.stretch_stiffness = E * b * mesh.edge_triangle_areas / self.rest_edge_lengths**2 / (1.0 - nu * nu)
        self._centre = mesh.interpolation_matrix(np.array([[0.5 * strip.length, 0.0]]))
        quarter = np.array([[0.25 * strip.length, 0.0], [0.75 * strip.length, 0.0]])
        self._quarters = mesh.interpolation_matrix(quarter)

    # ------------------------------------------------------------------ energy
    def evaluate(self, q: np.ndarray, gradient: bool = True, hessian: bool = True) -> Evaluation:
        """Energy (membrane + mid-edge bending), gradient and banded Hessian at q."""
        x = np.ascontiguousarray(q[self._node_dofs])
        theta = np.ascontiguousarray(q[self._edge_dofs])
        hessian = hessian and gradient
        n = self.n_dof
        grad, band = self._accumulators(gradient, hessian)
        alpha = self.membrane_alpha
        t = self._by_x
        stretching = add_membrane_terms(x, t["triangles"], t["membrane"], t["abar"], self._node_dofs, n,
                                        grad, band, gradient, hessian)
        if alpha < 1.0:
            stretching += add_smoothed_membrane_terms(x, self._triangles, self._strain_T, self._abar, *self._patches,
                                                      self._plane_stress, 1.0 - alpha, self._node_dofs, n,
                                                      grad, band, gradient, hessian)
        bending = add_midedge_terms(x, theta, t["stencil"], t["hinge_slots"], t["face_edges"], t["bending"],
                                    self._node_dofs, self._edge_dofs, n, grad, band, gradient, hessian)
        parts = {"stretching": float(stretching), "bending": float(bending)}
        return self._evaluation(parts, grad, band, gradient, hessian)

    # ------------------------------------------------------------------ metrics and scales
    def _edge_areas(self) -> np.ndarray:
        return self.mesh.edge_triangle_areas / 3.0

    def eigenvalue_metric(self) -> tuple[np.ndarray, float]:
        """Lumped metric as the paper's plate's (node area / W per coordinate), and for an edge
        angle its area share / W times h^2 / 12 (the rod's h W^2 / 12 for its twist angle)."""
        metric = np.empty(self.n_dof)
        metric[self.node_dofs] = (self.mesh.node_areas / self.strip.width)[:, None]
        h = self._typical_spacing()
        metric[self.edge_dofs] = self._edge_areas() / self.strip.width * h * h / 12.0
        return metric[self.free], self.strip.bending_stiffness / self.strip.length**4

    def residual_scale(self) -> np.ndarray:
        """Per-node force unit as the paper's plate's; an edge angle's moment unit is the force
        unit of its area share times the spacing h (an angle error delta weighs as a
        displacement delta h)."""
        s = self.strip
        h = self._typical_spacing()
        unit = s.bending_stiffness / s.length**2 / (s.width * h)
        scale = np.empty(self.n_dof)
        scale[self.node_dofs] = (unit * self.mesh.node_areas)[:, None]
        scale[self.edge_dofs] = unit * self._edge_areas() * h
        return scale

    def length_scale(self) -> np.ndarray:
        """L for positions, 1 rad for edge angles."""
        scale = np.full(self.n_dof, self.strip.length)
        scale[self.edge_dofs] = 1.0
        return scale

    def residual_floor(self) -> float:
        floor = 6.0 * np.finfo(float).eps * float(self.stretch_stiffness.max()) * self.strip.length
        return 10.0 * floor / float(self.residual_scale()[self.node_dofs[~(self.mesh.clamped_left
                                                                            | self.mesh.clamped_right)]].min())

