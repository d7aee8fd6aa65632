"""FEniCSx (dolfinx 0.5.2) finite-element reference for the sheared pre-buckled strip.

A geometrically exact nonlinear Naghdi shell (fem_reference.shell) on gmsh meshes
(fem_reference.mesh), solved by Newton continuation with stability, threshold location and
branch switching (fem_reference.solver, fem_reference.continuation); the same outputs as the
DDG models (fem_reference.api). dolfinx is imported lazily: `import fem_reference` works
without it, `fem_reference.simulate` needs it.
"""
from __future__ import annotations

__version__ = "0.1.0"


def simulate(*args, **kwargs):
    """fem_reference.api.simulate (imports dolfinx)."""
    from .api import simulate as _simulate

    return _simulate(*args, **kwargs)
