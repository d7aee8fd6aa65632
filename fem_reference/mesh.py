"""Structured triangle mesh of the flat strip [0, L] x [-W/2, W/2] with gmsh's Python API.

The mesh is in units of L (x in [0, 1]); the two clamped edges x = 0 and x = 1 are physical
groups (tags CLAMP_START, CLAMP_END), the node counts nx, ny are even so that the centre
(L/2, 0) is a mesh vertex, and the alternating diagonals make the mesh invariant under the
half-turn (x, y) -> (1 - x, -y) and the mirror y -> -y: the symmetric U branch stays exactly
symmetric, and +dW and -dW give mirror images.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

CLAMP_START = 1  # physical tag of the edge x = 0
CLAMP_END = 2  # physical tag of the edge x = L
SURFACE = 10

#: Fewest elements across the width: a 60-element-long mesh's count (10 for W/L = 1/6, 30 for
#: W/L = 1/2); coarser across-width meshes put dW2 off by several hundredths (issue 5).
MIN_ELEMENTS_ALONG_FOR_WIDTH = 60


@dataclass(frozen=True)
class MeshSpec:
    """nx elements along L, ny across W (both even); width_ratio = W/L."""

    nx: int
    ny: int
    width_ratio: float

    @classmethod
    def from_resolution(cls, resolution: int, width_ratio: float, across: int | None = None) -> "MeshSpec":
        """resolution elements along L; across W near-isotropic (nx W/L) but never fewer than
        MIN_ELEMENTS_ALONG_FOR_WIDTH * W/L, and at least 2; both rounded up to even counts."""
        nx = 2 * math.ceil(resolution / 2)
        if across is None:
            across = max(math.ceil(nx * width_ratio - 1e-9),
                         math.ceil(MIN_ELEMENTS_ALONG_FOR_WIDTH * width_ratio - 1e-9), 2)
        ny = 2 * math.ceil(across / 2)
        return cls(nx, ny, float(width_ratio))

    @property
    def n_triangles(self) -> int:
        return 2 * self.nx * self.ny

    @property
    def h_along(self) -> float:
        return 1.0 / self.nx

    @property
    def h_across(self) -> float:
        return self.width_ratio / self.ny

    def as_dict(self) -> dict:
        return {
            "generator": "gmsh transfinite rectangle, alternating diagonals",
            "elements_along_L": self.nx,
            "elements_across_W": self.ny,
            "triangles": self.n_triangles,
            "h_along_over_L": self.h_along,
            "h_across_over_L": self.h_across,
            "centre_vertex": [0.5, 0.0],
        }


def build_gmsh_model(spec: MeshSpec):
    """Create the strip mesh in the current gmsh model (units of L); returns the gmsh module."""
    import gmsh

    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add("strip")
    half = 0.5 * spec.width_ratio
    occ = gmsh.model.geo
    p = [occ.addPoint(0.0, -half, 0.0), occ.addPoint(1.0, -half, 0.0), occ.addPoint(1.0, half, 0.0),
         occ.addPoint(0.0, half, 0.0)]
    lines = [occ.addLine(p[0], p[1]), occ.addLine(p[1], p[2]), occ.addLine(p[2], p[3]), occ.addLine(p[3], p[0])]
    loop = occ.addCurveLoop(lines)
    surface = occ.addPlaneSurface([loop])
    for line, count in zip(lines, (spec.nx, spec.ny, spec.nx, spec.ny)):
        occ.mesh.setTransfiniteCurve(line, count + 1)
    occ.mesh.setTransfiniteSurface(surface, "Alternate", p)
    occ.synchronize()
    gmsh.model.addPhysicalGroup(2, [surface], SURFACE)
    gmsh.model.addPhysicalGroup(1, [lines[3]], CLAMP_START)
    gmsh.model.addPhysicalGroup(1, [lines[1]], CLAMP_END)
    gmsh.model.mesh.generate(2)
    return gmsh


def create_mesh(spec: MeshSpec):
    """dolfinx mesh and facet tags (CLAMP_START, CLAMP_END) of the strip, units of L."""
    from mpi4py import MPI

    from dolfinx.io import gmshio

    gmsh = build_gmsh_model(spec)
    try:
        mesh, _cell_tags, facet_tags = gmshio.model_to_mesh(gmsh.model, MPI.COMM_WORLD, 0, gdim=2)
    finally:
        gmsh.model.remove()
        gmsh.finalize()
    check_symmetric(mesh.geometry.x[:, :2], spec)
    return mesh, facet_tags


def check_symmetric(points: np.ndarray, spec: MeshSpec, tol: float = 1e-10) -> None:
    """Assert that the vertices are invariant under (x, y) -> (1 - x, -y) and contain (1/2, 0)."""
    from scipy.spatial import cKDTree

    tree = cKDTree(points)
    dist, _ = tree.query(np.column_stack([1.0 - points[:, 0], -points[:, 1]]))
    if dist.max() > tol:
        raise RuntimeError(f"mesh {spec} is not half-turn symmetric ({dist.max():.2e})")
    if tree.query([0.5, 0.0])[0] > tol:
        raise RuntimeError(f"mesh {spec} has no vertex at the centre (L/2, 0)")
