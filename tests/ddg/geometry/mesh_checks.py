"""Helpers shared by the mesh tests of this folder: the L x W strip of the mesh-file tests, the check
of a one-line error, and a mesh's signed areas, edge lengths and boundary edges."""
from __future__ import annotations

import numpy as np

#: The strip of the mesh-file tests (test_read_mesh.py, test_gmsh_mesh.py, test_frame_writer.py): W/L = 1/6.
L, W = 0.075, 0.075 / 6


def signed_areas(points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    p = points[triangles]
    d1, d2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    return 0.5 * (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])


def edge_lengths(mesh, edges) -> np.ndarray:
    return np.linalg.norm(mesh.nodes[edges[:, 1]] - mesh.nodes[edges[:, 0]], axis=1)


def boundary_edges(mesh) -> np.ndarray:
    """Edges of one triangle only: those not shared by a hinge."""
    interior = np.zeros(len(mesh.edges), dtype=bool)
    interior[mesh.hinge_edges] = True
    return ~interior


def one_line_error(excinfo, *fragments):
    message = str(excinfo.value)
    assert "\n" not in message
    for fragment in fragments:
        assert fragment in message, message
