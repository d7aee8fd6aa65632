"""Structured triangle mesh of the flat strip [0, L] x [-W/2, W/2] with gmsh's Python API.

The mesh is in units of L (x in [0, 1]); the two clamped edges x = 0 and x = 1 are physical
groups (tags CLAMP_START, CLAMP_END), the node counts nx, ny are even so that the centre
(L/2, 0) is a mesh vertex, and the alternating diagonals make the mesh invariant under the
half-turn (x, y) -> (1 - x, -y) and the mirror y -> -y: the symmetric U branch stays exactly
symmetric, and +dW and -dW give mirror images.
"""
from __future__ import annotations

import math
import signal
import sys
import threading
from dataclasses import dataclass

import numpy as np

from .elements import DEFAULT_ELEMENT, ELEMENTS, check_element

CLAMP_START = 1  # physical tag of the edge x = 0
CLAMP_END = 2  # physical tag of the edge x = L
SURFACE = 10

#: Fewest elements across the width: a 60-element-long mesh's count (10 for W/L = 1/6, 30 for
#: W/L = 1/2); coarser across-width meshes put dW2 off by several hundredths (issue 5).
MIN_ELEMENTS_ALONG_FOR_WIDTH = 60

#: Bounds of the element counts, checked before any FEM import (checked_spec):
#: - along L at least 4: 2 elements on each side of the centre vertex (odd counts are rounded up
#:   to even so that (L/2, 0) is a vertex); fewer cannot hold the clamped buckle at all;
#: - along L at most 400: a path's time. Whole paths took 291 s on 60 x 10 elements (16k unknowns)
#:   and 1312 s on 120 x 20 (64k; fem_reference/README.md): time ~ unknowns^1.1. At 400 elements
#:   W/L = 1/6 has 713k unknowns (~5 h a path), W/L = 1/2 2.1M (~17 h, and more memory than most
#:   machines allow, see below); finer meshes are nothing a user can wait for, and 60-120 already
#:   give the thresholds to ~1e-3 L (gold.py);
#: - across W at least 2 (rounded up to even: the centre vertex sits on y = 0) and at most 400,
#:   the near-isotropic count of the widest strip ddg allows (W = L) at the largest resolution.
MIN_RESOLUTION, MAX_RESOLUTION = 4, 400
MIN_ACROSS, MAX_ACROSS = 2, 400

#: Memory of a run, from measured peak resident memory (dolfinx 0.5.2, PETSc 3.18, MUMPS, one
#: process) while building the model and holding the three L D L^T factorisations a path uses at
#: once (Newton, inertia, SLEPc shift-invert): W/L = 1/2 on 48 x 30, 96 x 48 and 144 x 72
#: elements (38k, 121k and 272k unknowns) took 0.34, 1.05 and 2.38 GB above the 0.14 GB of the
#: bare interpreter, i.e. 8.8 kB per unknown at every size. The estimate takes 12 kB per unknown
#: (a third more, for the path's saved states and fill growing like n log n with nested
#: dissection beyond the measured sizes, scaled by log n / log 2.7e5 there) plus the process.
BYTES_PER_DOF = 12e3
FACTOR_FILL_REFERENCE_DOFS = 2.7e5
PROCESS_BYTES = 0.25 * 2.0**30


@dataclass(frozen=True)
class MeshSpec:
    """nx elements along L, ny across W (both even); width_ratio = W/L."""

    nx: int
    ny: int
    width_ratio: float
    #: the shell's finite element on this mesh (fem_reference.elements.ELEMENTS)
    element: str = DEFAULT_ELEMENT

    @classmethod
    def from_resolution(cls, resolution: int, width_ratio: float, across: int | None = None,
                        element: str = DEFAULT_ELEMENT) -> "MeshSpec":
        """resolution elements along L; across W near-isotropic (nx W/L) but never fewer than
        MIN_ELEMENTS_ALONG_FOR_WIDTH * W/L, and at least 2; both rounded up to even counts."""
        nx = 2 * math.ceil(resolution / 2)
        if across is None:
            across = max(math.ceil(nx * width_ratio - 1e-9),
                         math.ceil(MIN_ELEMENTS_ALONG_FOR_WIDTH * width_ratio - 1e-9), 2)
        ny = 2 * math.ceil(across / 2)
        return cls(nx, ny, float(width_ratio), element)

    @property
    def n_dof(self) -> int:
        """Unknowns of the Naghdi discretisation (shell.NaghdiStrip) with this spec's element
        (elements.ShellElement.n_dof): for the default u in [P2 + B3]^3, theta in [P2]^2, the
        structured mesh has (2 nx + 1)(2 ny + 1) P2 nodes and 2 nx ny bubbles."""
        return ELEMENTS[self.element].n_dof(self.nx, self.ny)

    def estimated_memory_bytes(self) -> float:
        """Peak memory of a run on this mesh (see BYTES_PER_DOF)."""
        n = self.n_dof
        fill = max(1.0, math.log(n) / math.log(FACTOR_FILL_REFERENCE_DOFS))
        return PROCESS_BYTES + BYTES_PER_DOF * n * fill

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


def checked_spec(resolution, width_ratio: float, across=None, name: str = "--resolution",
                 across_name: str = "--across", element: str = DEFAULT_ELEMENT,
                 element_name: str = "element") -> MeshSpec:
    """The MeshSpec of `resolution` elements along L (and `across` across W) with the shell
    `element`, refused with a one-line ddg InputError before any FEM work when the element is
    unknown (elements.check_element), a count is outside its bounds (MIN/MAX_RESOLUTION,
    MIN/MAX_ACROSS) or the mesh needs more memory than this machine allows (ddg.limits.check_memory
    with MeshSpec.estimated_memory_bytes)."""
    from ddg.limits import check_integer, check_memory

    check_element(element, element_name)

    resolution = check_integer(name, resolution, MIN_RESOLUTION, MAX_RESOLUTION,
                               f"elements along L: at least {MIN_RESOLUTION} to hold the buckle, at most "
                               f"{MAX_RESOLUTION} (a path there takes 5-17 hours); odd counts are rounded up to even")
    if across is not None:
        across = check_integer(across_name, across, MIN_ACROSS, MAX_ACROSS,
                               f"elements across W: at least {MIN_ACROSS}, an even count (odd ones are rounded up) "
                               f"so that a vertex sits at the centre (L/2, 0); at most {MAX_ACROSS}")
    spec = MeshSpec.from_resolution(resolution, width_ratio, across, element)
    if spec.ny > MAX_ACROSS:
        check_integer(f"elements across W (from {name} {resolution} and W/L = {width_ratio:.4g})", spec.ny,
                      MIN_ACROSS, MAX_ACROSS)
    label = name if across is None else f"{name}, {across_name}"
    value = f"{resolution}" if across is None else f"{resolution}, {across}"
    check_memory(label, f"{value} (a {spec.nx} x {spec.ny} mesh, {spec.n_dof} unknowns)",
                 spec.estimated_memory_bytes())
    return spec


def keep_python_sigint(handler) -> None:
    """Put back the Python SIGINT handler that gmsh replaced.

    gmsh.py (Debian python3-gmsh 4.8) sets SIGINT to SIG_DFL when it is imported (dolfinx.io.gmshio
    imports it) and restores the handler of that moment only in gmsh.finalize(): in between,
    Ctrl-C would kill the process with nothing written. `handler` is the one in force before
    (a default, ignored or C-level one is replaced by Python's KeyboardInterrupt handler unless
    it was SIG_IGN). Main thread only (elsewhere signals cannot be set and do not arrive)."""
    if threading.current_thread() is not threading.main_thread():
        return
    wanted = handler if (callable(handler) or handler == signal.SIG_IGN) else signal.default_int_handler
    if signal.getsignal(signal.SIGINT) is not wanted:
        signal.signal(signal.SIGINT, wanted)


def import_gmsh():
    """The gmsh module, imported without its SIGINT reset.

    gmsh.py sets SIGINT to SIG_DFL as its first action on import, before it loads libgmsh (a
    large library, tenths of a second): a Ctrl-C in that window would kill the process silently,
    so signal.signal ignores that one call while gmsh is imported (main thread only; gmsh then
    records the handler in force as the one gmsh.finalize() restores). Off the main thread (a
    Dask worker runs its tasks in a thread), where a signal handler cannot be set at all, the call
    is skipped alike and gmsh is left no handler to restore, so that finalize() does not fail."""
    if "gmsh" in sys.modules:
        import gmsh

        return gmsh
    original = signal.signal

    def keep_sigint(signum, handler):
        if signum == signal.SIGINT and handler == signal.SIG_DFL:
            return signal.getsignal(signal.SIGINT)
        return original(signum, handler)

    signal.signal = keep_sigint
    try:
        import gmsh
    finally:
        signal.signal = original
    if threading.current_thread() is not threading.main_thread():
        gmsh.oldsig = None  # gmsh.finalize() restores SIGINT only if it has a handler to restore
    return gmsh


def build_gmsh_model(spec: MeshSpec):
    """Create the strip mesh in the current gmsh model (units of L); returns the gmsh module."""
    handler = signal.getsignal(signal.SIGINT)
    gmsh = import_gmsh()
    gmsh.initialize()
    keep_python_sigint(handler)  # Ctrl-C while meshing raises KeyboardInterrupt once gmsh returns
    try:
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
    except BaseException:
        gmsh.finalize()
        keep_python_sigint(handler)
        raise
    return gmsh


def create_mesh(spec: MeshSpec):
    """dolfinx mesh and facet tags (CLAMP_START, CLAMP_END) of the strip, units of L."""
    from mpi4py import MPI

    handler = signal.getsignal(signal.SIGINT)
    import_gmsh()  # before gmshio imports it: see there
    from dolfinx.io import gmshio

    keep_python_sigint(handler)
    gmsh = build_gmsh_model(spec)
    try:
        mesh, _cell_tags, facet_tags = gmshio.model_to_mesh(gmsh.model, MPI.COMM_WORLD, 0, gdim=2)
    finally:
        gmsh.model.remove()
        gmsh.finalize()  # restores the handler of gmsh's import, not necessarily ours
        keep_python_sigint(handler)
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
