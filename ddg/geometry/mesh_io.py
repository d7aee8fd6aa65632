"""Unstructured triangle meshes of the strip: read from a file (meshio) or generate (gmsh).

Both return a `PlateMesh` in the convention of `plate_mesh`: the mesh covers
[-c, L + c] x [-W/2, W/2] and the nodes in the band [-c, c] around the clamp line x = 0
(and [L - c, L + c] around x = L) move rigidly with the fixed (moving) clamp; the rigid
triangles straddle the clamp lines, so the free plate between them is exactly L long.
A file gives no c: the band at each end is the mesh's first layer of triangles, 2c deep, and
the mesh must be L + 2c long (plate_mesh.mesh_from_arrays), so a mesh of the wrong length is
refused rather than clamped deeper. Sizes are bounded by MAX_TRIANGLES and by the memory a
plate run needs (plate_mesh.plate_memory_estimate_bytes).
meshio and gmsh are optional (Debian python3-meshio, python3-gmsh) and imported lazily.
"""
from __future__ import annotations

import contextlib
import io
import math
import os
import signal
import threading
from pathlib import Path

import numpy as np

from ..limits import check_integer
from .plate_mesh import (DEFAULT_TRIANGLES, MAX_TRIANGLES, PlateMesh, check_mesh_memory, check_plate_size,
                         mesh_from_arrays)
from ..limits import InputError

#: Cells a mesh file may hold besides its triangles (gmsh's boundary lines and corner points);
#: any other cell (quads, quadratic triangles, polygons, volumes) would be silently dropped.
_IGNORED_CELLS = frozenset({"vertex", "line", "line3"})

#: Frontal-Delaunay: near-equilateral triangles (minimum angle ~40 degrees at 2000 triangles).
_GMSH_ALGORITHM = 6


def _first_line(error: BaseException) -> str:
    text = str(error).strip() or type(error).__name__
    return text.splitlines()[0]


def _check_lengths(length, width) -> None:
    for name, value in (("length", length), ("width", width)):
        if isinstance(value, bool) or not (isinstance(value, (int, float, np.integer, np.floating))
                                           and math.isfinite(value) and value > 0):
            raise InputError(f"{name} = {value!r} must be a positive finite number of metres")


def _import_meshio():
    try:
        import meshio
    except ImportError:
        raise InputError(
            "reading or writing meshes needs meshio, which is not installed; "
            "pip install 'ddg-strips[io]' (or Debian's python3-meshio)"
        ) from None
    return meshio


def _in_file(path: Path, error: InputError) -> InputError:
    """The error of mesh_from_arrays ("mesh has ...") as one naming the file ("mesh file 'x' has ...")."""
    text = str(error)
    if text.startswith("mesh "):
        return InputError(f"mesh file {str(path)!r} {text[len('mesh '):]}")
    return InputError(f"mesh file {str(path)!r}: {text}")


def read_mesh(path, length: float, width: float) -> PlateMesh:
    """Read a flat triangle mesh of the strip from any format meshio reads (.msh, .vtu, .obj, ...).

    The mesh must be one flat piece of linear triangles covering the rectangle L + 2c by W
    (any offset), its clamp zone at each end being its first layer of triangles, 2c deep: the
    nodes within 2c of each end (the band [-c, c] around each clamp line) are clamped. Cells
    other than triangles may only be boundary lines and points (ignored, as gmsh writes them);
    z must be constant; every node must belong to a triangle. Every defect (see
    mesh_from_arrays) and a size beyond MAX_TRIANGLES or the machine's memory raises a one-line
    InputError naming the file, before any work.
    """
    _check_lengths(length, width)
    if not isinstance(path, (str, os.PathLike)):
        raise InputError(f"mesh = {path!r} must be the path of a mesh file (str or os.PathLike), "
                         f"not {type(path).__name__}")
    meshio = _import_meshio()
    path = Path(path)
    if not path.is_file():
        raise InputError(f"mesh file {str(path)!r} does not exist or is not a file")
    if path.stat().st_size == 0:
        raise InputError(f"mesh file {str(path)!r} is empty (0 bytes)")
    # meshio prints each failed format attempt and calls sys.exit(1) when none reads the file,
    # so its output is captured and SystemExit turned into our error
    chatter = io.StringIO()
    try:
        with contextlib.redirect_stdout(chatter), contextlib.redirect_stderr(chatter):
            data = meshio.read(path)
    except (Exception, SystemExit) as error:  # ReadError, KeyError, ValueError, ... by format
        reason = str(error).strip() if isinstance(error, Exception) else ""
        reason = reason.splitlines()[0] if reason else ""
        if not reason:
            reason = next((line.strip() for line in chatter.getvalue().splitlines() if line.strip()),
                          "not a mesh format meshio can read").removeprefix("Error:").strip()
        if "need at least one array to concatenate" in reason:  # meshio's VTU reader on a file without cells
            reason = "it holds no cells (an empty mesh?)"
        raise InputError(f"cannot read mesh file {str(path)!r}: {reason}") from None
    blocks = [np.asarray(block.data) for block in data.cells if block.type == "triangle"]
    if not blocks:
        found = sorted({block.type for block in data.cells}) or ["none"]
        raise InputError(
            f"mesh file {str(path)!r} has no triangle cells (found: {', '.join(found)}); "
            "give a linear triangle mesh of the strip"
        )
    others = sorted({block.type for block in data.cells} - _IGNORED_CELLS - {"triangle"})
    if others:
        raise InputError(f"mesh file {str(path)!r} has {', '.join(others)} cells besides its triangles; "
                         "give a mesh of linear triangles only (those cells would be ignored)")
    count = sum(len(block) for block in blocks)
    try:
        check_integer("triangles", count, 1, MAX_TRIANGLES, "a plate run of more would not fit in memory")
    except InputError as error:
        raise InputError(f"mesh file {str(path)!r}: {error}") from None
    try:
        mesh = mesh_from_arrays(data.points, np.concatenate(blocks), length, width, allow_unused_nodes=False)
        check_mesh_memory(mesh)
    except InputError as error:
        raise _in_file(path, error) from None
    return mesh


def _gmsh_initialized(gmsh) -> bool:
    probe = getattr(gmsh, "isInitialized", None)  # gmsh >= 4.9
    if probe is not None:
        return bool(probe())
    try:  # gmsh 4.8 (Debian 12): the version string is empty before initialize, raises after finalize
        return bool(gmsh.option.getString("General.Version"))
    except Exception:
        return False


def gmsh_mesh(length: float, width: float, triangles: int = DEFAULT_TRIANGLES,
              clamp_depth: float | None = None) -> PlateMesh:
    """Unstructured frontal-Delaunay mesh of [-c, L + c] x [-W/2, W/2] with gmsh.

    The element size h is set from the area of an equilateral triangle, sqrt(3)/4 h^2, so that
    about `triangles` triangles lie between the clamp lines (one calibration pass corrects the
    boundary excess; within a few percent). The domain is three rectangles sharing the edges
    x = +-c and L -+ c of the clamped bands, so those are mesh lines; the bands are meshed
    structured and the plate centre (L/2, 0) is a node. The clamp depth c defaults to half the
    height of an equilateral triangle, sqrt(3)/4 h, so that, as on the structured mesh (half a
    column spacing), each band is one layer of rigid triangles straddling its clamp line.
    Deterministic (fixed seed, one thread, no config files); gmsh is initialised only if it is
    not already, and left as it was found.
    `triangles` is an integer in [16, MAX_TRIANGLES] whose plate run fits in memory
    (plate_mesh.check_plate_size), checked before gmsh is called. Note: a clamp_depth of more
    than one layer makes the clamped bands several layers deep; the last rigid layer then
    clamps the slope at about c - h/2, so the free plate is about L - 2c + h long, not L (and
    read_mesh, which takes the first layer as the clamp zone, refuses such a mesh in a file).
    """
    _check_lengths(length, width)
    triangles = check_plate_size(length, width, triangles, unstructured=True)
    if clamp_depth is not None and not (
        isinstance(clamp_depth, (int, float, np.floating)) and math.isfinite(clamp_depth)
        and 0 < clamp_depth < 0.5 * length
    ):
        raise InputError(f"clamp_depth = {clamp_depth!r} must be a number in (0, L/2 = {0.5 * length:g}) metres")
    nodes, tris, c = _gmsh_session(length, width, triangles, clamp_depth)
    mesh = mesh_from_arrays(nodes, tris, length, width, clamp_depth=c)
    check_mesh_memory(mesh)  # the estimate above took the band of a typical unstructured mesh
    return mesh


def _gmsh_session(length: float, width: float, triangles: int, clamp_depth: float | None):
    """gmsh imported, initialised (unless it is already), the strip meshed twice (the calibration
    pass) and gmsh left as it was found: nodes (N, 2), triangles (T, 3) and the clamp depth. Called
    by gmsh_mesh once its inputs are checked; everything gmsh does happens here."""
    try:
        # importing Debian's gmsh 4.8 resets SIGINT to the default (kill) until finalize;
        # keep the caller's handler (and never touch signals off the main thread)
        main_thread = threading.current_thread() is threading.main_thread()
        sigint = signal.getsignal(signal.SIGINT) if main_thread else None
        import gmsh
    except ImportError:
        raise InputError(
            "generating meshes needs gmsh's Python API, which is not installed; "
            "install it with `apt-get install python3-gmsh` (Debian) or `pip install gmsh`"
        ) from None
    except ValueError:  # gmsh's import-time signal call outside the main thread
        raise InputError("gmsh must first be imported from the main thread (it installs a signal handler)") from None

    area = length * width
    h = math.sqrt(area / triangles / (0.25 * math.sqrt(3.0)))
    owner = not _gmsh_initialized(gmsh)
    saved: dict[str, float] = {}
    previous_model = None
    try:
        if owner:
            gmsh.initialize([], readConfigFiles=False)
        else:
            previous_model = gmsh.model.getCurrent()
        options = {"General.Terminal": 0, "General.NumThreads": 1, "Mesh.MaxNumThreads2D": 1,
                   "Mesh.RandomSeed": 1, "Mesh.Algorithm": _GMSH_ALGORITHM, "Mesh.ElementOrder": 1,
                   "Mesh.RecombineAll": 0, "Mesh.MeshSizeFromCurvature": 0,
                   "Mesh.MeshSizeMin": h, "Mesh.MeshSizeMax": h}  # sizes reset per pass below
        for name, value in options.items():
            saved[name] = gmsh.option.getNumber(name)
            gmsh.option.setNumber(name, value)
        # the boundary rows add triangles beyond the area estimate; one rescaled pass fixes it
        nodes, tris, c = _gmsh_generate(gmsh, length, width, h, clamp_depth)
        h *= math.sqrt(max(_count_between_clamps(nodes, tris, length), 1) / triangles)
        nodes, tris, c = _gmsh_generate(gmsh, length, width, h, clamp_depth)
    except Exception as error:  # gmsh raises bare Exception with its last logged error
        raise InputError(f"gmsh failed to mesh the strip (L = {length:g}, W = {width:g}, "
                         f"h = {h:.3g} m): {_first_line(error)}") from None
    finally:
        if owner:
            try:
                gmsh.finalize()
            except Exception:
                pass
        else:
            for name, value in saved.items():
                gmsh.option.setNumber(name, value)
            if previous_model is not None:
                gmsh.model.setCurrent(previous_model)
        if main_thread and sigint is not None:
            signal.signal(signal.SIGINT, sigint)
    return nodes, tris, c


def _count_between_clamps(nodes: np.ndarray, tris: np.ndarray, length: float) -> int:
    centroid_x = nodes[tris, 0].mean(axis=1)
    return int(np.count_nonzero((centroid_x > 0) & (centroid_x < length)))


def _gmsh_generate(gmsh, length: float, width: float, h: float, clamp_depth: float | None):
    """Mesh once with element size h in a fresh model; return nodes (N, 2), triangles (T, 3)
    and the clamp depth."""
    c = 0.25 * math.sqrt(3.0) * h if clamp_depth is None else float(clamp_depth)
    gmsh.model.add("ddg_strip")
    try:
        gmsh.option.setNumber("Mesh.MeshSizeMin", h)
        gmsh.option.setNumber("Mesh.MeshSizeMax", h)
        geo = gmsh.model.geo
        xs = (-c, c, length - c, length + c)
        bottom = [geo.addPoint(x, -0.5 * width, 0.0, h) for x in xs]
        top = [geo.addPoint(x, 0.5 * width, 0.0, h) for x in xs]
        lower = [geo.addLine(bottom[i], bottom[i + 1]) for i in range(len(xs) - 1)]
        upper = [geo.addLine(top[i], top[i + 1]) for i in range(len(xs) - 1)]
        across = [geo.addLine(bottom[i], top[i]) for i in range(len(xs))]
        surfaces = [geo.addPlaneSurface([geo.addCurveLoop([lower[i], across[i + 1], -upper[i], -across[i]])])
                    for i in range(len(xs) - 1)]
        # the clamped bands are structured: at the default c one layer of rigid triangles
        # straddling the clamp line (left to the frontal mesher, a band 2c ~ 0.87 h wide gets
        # a middle column of nodes); a deeper band gets layers about an equilateral row high
        rows = max(1, round(width / h))
        layers = max(1, round(2.0 * c / (0.5 * math.sqrt(3.0) * h)))
        for band in (0, 2):
            for curve in (across[band], across[band + 1]):
                geo.mesh.setTransfiniteCurve(curve, rows + 1)
            for curve in (lower[band], upper[band]):
                geo.mesh.setTransfiniteCurve(curve, layers + 1)
            geo.mesh.setTransfiniteSurface(surfaces[band], "Alternate")
        centre = geo.addPoint(0.5 * length, 0.0, 0.0, h)
        geo.synchronize()
        gmsh.model.mesh.embed(0, [centre], 2, surfaces[1])
        gmsh.model.mesh.generate(2)
        tags, coords, _ = gmsh.model.mesh.getNodes()
        _, connectivity = gmsh.model.mesh.getElementsByType(2)  # 3-node triangles
    finally:
        gmsh.model.remove()
    tags = tags.astype(np.int64)
    index = np.full(int(tags.max()) + 1, -1, dtype=np.int64)
    index[tags] = np.arange(len(tags))
    nodes = coords.reshape(-1, 3)[:, :2].copy()
    tris = index[connectivity.astype(np.int64).reshape(-1, 3)]
    return nodes, tris, c
