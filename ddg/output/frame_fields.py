"""What a ParaView frame shows of a model's state: the surface, its flat reference, and per-element
fields (written by ddg.output.frames.FrameWriter).

* Plate (any triangle mesh): the deformed triangles; per triangle `turn_angle_deg` (the largest
  angle between its normal and a neighbour's: where it exceeds 30 degrees the mesh stops
  resolving the shape, ddg.analysis.observables) and, for the paper's plate, the hinge bending
  energy density `bending_energy_density` (J/m^2: half of each of its hinges' energies, Eq. 11b,
  over its rest area).
* Rod and ribbons: drawn as the strip they stand for, a ribbon of width W along the centreline,
  spanned by the material frame's in-plane director (-m2, +y at rest; the normal m1 is +z), two
  triangles per edge, so that they render like the plates; per triangle the curvatures of the
  centreline at the edge (mean of its end nodes' values, ddg.analysis.curvatures.rod_curvatures):
  `k1_L` geodesic, `k2_L` normal (bending), `tau_L` twist, in units of 1/L.

Every frame's points are the deformed positions; the flat reference is the point array
`flat_position` (not a displacement: ParaView's Warp By Vector would deform the shape twice).
"""
from __future__ import annotations

import numpy as np


def ribbon_triangles(nodes: int) -> np.ndarray:
    """Two triangles per edge of a centreline of `nodes` nodes, over the points 2i (side -W/2) and
    2i + 1 (side +W/2) of node i."""
    j = np.arange(nodes - 1)
    lower = np.stack([2 * j, 2 * j + 2, 2 * j + 1], axis=1)
    upper = np.stack([2 * j + 1, 2 * j + 2, 2 * j + 3], axis=1)
    return np.stack([lower, upper], axis=1).reshape(-1, 3).astype(np.int64)


def _ribbon_points(centre: np.ndarray, director: np.ndarray, width: float) -> np.ndarray:
    points = np.empty((2 * len(centre), 3))
    points[0::2] = centre - 0.5 * width * director
    points[1::2] = centre + 0.5 * width * director
    return points


def _node_directors(edge_directors: np.ndarray) -> np.ndarray:
    """Unit vectors at the nodes from those of the edges (mean of the two adjacent edges)."""
    nodes = np.empty((len(edge_directors) + 1, 3))
    nodes[0], nodes[-1] = edge_directors[0], edge_directors[-1]
    nodes[1:-1] = edge_directors[:-1] + edge_directors[1:]
    return nodes / np.linalg.norm(nodes, axis=1, keepdims=True)


def frame_cells(model) -> tuple[np.ndarray, np.ndarray]:
    """(triangles (C, 3), flat reference positions (N, 3)) of the model's frames."""
    if hasattr(model, "mesh"):
        mesh = model.mesh
        return np.asarray(mesh.triangles, dtype=np.int64), np.column_stack([mesh.nodes, np.zeros(mesh.node_count)])
    rest = model.rest_state()[model.node_dofs]
    director = np.tile([0.0, 1.0, 0.0], (len(rest), 1))
    return ribbon_triangles(len(rest)), _ribbon_points(rest, director, model.strip.width)


def frame_content(model, q: np.ndarray) -> tuple[np.ndarray, dict]:
    """(deformed points (N, 3), cell fields {name: (C,) array}) of the state q."""
    if hasattr(model, "mesh"):
        return _plate_content(model, q)
    return _rod_content(model, q)


def _plate_content(model, q):
    from ..energies.hinge_bending import hinge_bending_energy, triangle_normals

    mesh = model.mesh
    x = model.positions(q)
    triangles = np.asarray(mesh.triangles)
    hinges = np.asarray(mesh.hinge_triangles).reshape(-1, 2)
    normals, _ = triangle_normals(x, triangles)
    angle = np.degrees(np.arccos(np.clip(np.einsum("hi,hi->h", normals[hinges[:, 0]], normals[hinges[:, 1]]),
                                         -1.0, 1.0)))
    turn = np.zeros(len(triangles))
    for side in (0, 1):
        np.maximum.at(turn, hinges[:, side], angle)
    fields = {"turn_angle_deg": turn}
    stiffness = getattr(model, "hinge_stiffness", None)
    if stiffness is not None:
        energy = hinge_bending_energy(x, triangles, hinges, stiffness, gradient=False, hessian=False)[0]
        per_triangle = np.zeros(len(triangles))
        for side in (0, 1):
            np.add.at(per_triangle, hinges[:, side], 0.5 * energy)
        rest = mesh.nodes[triangles]
        area = 0.5 * np.abs((rest[:, 1, 0] - rest[:, 0, 0]) * (rest[:, 2, 1] - rest[:, 0, 1])
                            - (rest[:, 1, 1] - rest[:, 0, 1]) * (rest[:, 2, 0] - rest[:, 0, 0]))
        fields["bending_energy_density"] = per_triangle / area
    return x, fields


def _rod_content(model, q):
    from ..analysis.rod_strains import rod_curvatures

    x = model.positions(q)
    _, _, _, m2, _ = model.frames(q)
    points = _ribbon_points(x, _node_directors(-np.asarray(m2)), model.strip.width)
    profile = rod_curvatures(model, q)
    fields = {}
    for name in ("k1_L", "k2_L", "tau_L"):
        interior = np.asarray(profile[name], dtype=float)
        at_nodes = np.concatenate([[interior[0]], interior, [interior[-1]]])   # clamp nodes: their neighbour's
        per_edge = 0.5 * (at_nodes[:-1] + at_nodes[1:])
        fields[name] = np.repeat(per_edge, 2)
    return points, fields
