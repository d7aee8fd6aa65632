"""3D pictures of a run's recorded frames (pyvista, off-screen): a PNG per state, a grid of
states in one PNG, and interactive HTML scenes.

A run folder written with frames (`python -m ddg simulate ... --frames`, `ddg.simulate(...,
frames=True)`) holds frames/frame_NNNNN.vtu per recorded step (ddg.output.frames), whose step
index is the row of path.csv that gives the state's phase (U, US+, S-, ...). The plate is drawn
as its triangle surface, the rod as a tube whose diameter is the strip width W (its frames carry
the centerline only, not the material frame a ribbon of width W would need). Coordinates are
shown in units of the free length L, read from the frame's reference positions, which span
[-c, L + c] with the clamped bands [-c, c] and [L - c, L + c]; those bands are drawn as grey
clamp jaws. The camera is fixed: one view direction and a parallel projection fitted to every
state drawn together, so shapes and sizes compare across pictures.

pyvista (and vtk) are an optional extra, imported only here and only when drawing. Off-screen
rendering needs no display: the vtk wheels (>= 9.4) fall back to EGL (Mesa's llvmpipe on a
machine without a GPU); with no DISPLAY the EGL window is requested directly, which skips the
X attempt and its warning. The HTML scene goes through pyvista's trame exporter
(trame-pyvista), which starts a local trame server and patches asyncio (nest_asyncio2), so it
runs in a child interpreter, never in the caller's process.
"""
from __future__ import annotations

import json
import math
import os
import subprocess
import tempfile
import sys
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..limits import InputError
from .io import atomic_path

RENDER_EXTRA_MESSAGE = "install the 'render' extra: pip install ddg-strips[render]"
HTML_EXTRA_MESSAGE = ("the HTML scene needs trame-pyvista and nest_asyncio2 besides the 'render' extra: "
                      "pip install trame-pyvista nest_asyncio2")

#: Camera direction from the focal point: azimuth -60 deg, elevation 25 deg (the report's matplotlib
#: view_init(elev=25, azim=-60)): the arch of U is seen from the side, the shear offset in y and the
#: S shape's two lobes in perspective.
VIEW_AZIMUTH_DEG = -60.0
VIEW_ELEVATION_DEG = 25.0
WINDOW_SIZE = (1000, 700)
COLORMAP = "viridis"
#: Clamp jaws drawn (units of L): how far they reach out of the strip, their thickness, and how
#: far they stand out of the strip's edges.
JAW_LENGTH, JAW_THICKNESS, JAW_MARGIN = 0.06, 0.025, 0.15
#: Tube diameter of a rod frame (units of L) when the strip width is not known.
ROD_DIAMETER_DEFAULT = 0.02
#: Fraction of the view's height and width the strip may fill (the rest: the title above, the colour
#: bar below, a margin).
FIT_HEIGHT, FIT_WIDTH = 0.70, 0.92
#: Colours: white background, dark text and clamps.
BACKGROUND, FOREGROUND, CLAMP_COLOR = "white", "black", "dimgray"


# --------------------------------------------------------------------------- optional imports
def import_pyvista():
    """pyvista, or an InputError naming the extra to install."""
    try:
        import pyvista
    except ImportError:
        raise InputError(RENDER_EXTRA_MESSAGE) from None
    if not os.environ.get("DISPLAY") and not os.environ.get("WAYLAND_DISPLAY"):
        # without a display vtk tries X, warns "bad X server connection", then uses EGL anyway
        os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    return pyvista


def _importable(name: str) -> bool:
    import importlib.util

    if name in sys.modules:  # None there blocks the import (and makes find_spec raise)
        return sys.modules[name] is not None
    return importlib.util.find_spec(name) is not None


def html_unavailable() -> str | None:
    """Why an HTML scene cannot be exported here (one line), or None if it can."""
    if not _importable("pyvista"):
        return RENDER_EXTRA_MESSAGE
    return None if _importable("trame_pyvista") and _importable("nest_asyncio2") else HTML_EXTRA_MESSAGE


# --------------------------------------------------------------------------- run folders
@dataclass
class RunFrames:
    """The frames of a run folder: step -> VTU file, and what path.csv and summary.json say."""
    directory: Path
    files: dict[int, Path]
    rows: list[dict] = field(default_factory=list)
    summary: dict = field(default_factory=dict)

    @property
    def steps(self) -> list[int]:
        return sorted(self.files)

    def row(self, step: int) -> dict:
        return self.rows[step] if 0 <= step < len(self.rows) else {}

    def phase(self, step: int) -> str:
        return str(self.row(step).get("phase") or "")

    @property
    def strip_width(self) -> float | None:
        """W in metres from summary.json (the rod's frames do not carry it)."""
        scene = self.summary.get("scene")
        width = scene.get("width") if isinstance(scene, dict) else None
        ok = isinstance(width, (int, float)) and not isinstance(width, bool) and math.isfinite(width) and width > 0
        return float(width) if ok else None

    def describe_steps(self) -> str:
        """'0 to 160', or '0 to 160 (158 frames)' when some steps have no frame."""
        steps = self.steps
        gaps = len(steps) != steps[-1] - steps[0] + 1
        return f"{steps[0]} to {steps[-1]}" + (f" ({len(steps)} frames)" if gaps else "")


def _frame_files(frames_dir: Path) -> dict[int, Path]:
    pvd = frames_dir / "frames.pvd"
    files = {}
    if pvd.is_file():
        try:
            for d in ET.parse(pvd).getroot().iter("DataSet"):   # "step" (timestep is dW/L; older files: the step)
                step = d.get("step") if d.get("step") is not None else d.get("timestep")
                files[int(step)] = frames_dir / d.get("file")
        except (ET.ParseError, TypeError, ValueError):
            files = {}
    if not files:  # no collection (or a broken one): the frame files by name
        for path in frames_dir.glob("frame_*.vtu"):
            try:
                files[int(path.stem.split("_")[-1])] = path
            except ValueError:
                continue
    return {step: path for step, path in files.items() if path.is_file()}


def open_run(run_dir) -> RunFrames:
    """The frames of `run_dir`, checked: a one-line InputError if it is not a run folder with frames."""
    from .io import read_path_csv

    if run_dir is None or isinstance(run_dir, bool) or not isinstance(run_dir, (str, os.PathLike)):
        raise InputError(f"run folder = {run_dir!r} must be a directory path")
    directory = Path(run_dir)
    if not directory.is_dir():
        raise InputError(f"run folder {str(directory)!r} does not exist or is not a directory; "
                         "give the --out folder of `python -m ddg simulate ... --frames`")
    frames_dir = directory / "frames"
    if not any((directory / name).exists() for name in ("frames", "summary.json", "path.csv")):
        raise InputError(f"{str(directory)!r} is not a run folder (no frames/, summary.json or path.csv); "
                         "give the --out folder of `python -m ddg simulate ... --frames`")
    if not frames_dir.is_dir():
        raise InputError(f"run folder {str(directory)!r} has no frames/ folder; "
                         "run `python -m ddg simulate ... --frames --out DIR` to record frames")
    files = _frame_files(frames_dir)
    if not files:
        raise InputError(f"{str(frames_dir)!r} holds no frame_NNNNN.vtu files; "
                         "run `python -m ddg simulate ... --frames --out DIR` to record frames")
    rows, summary = [], {}
    if (directory / "path.csv").is_file():
        try:
            rows = read_path_csv(directory / "path.csv")
        except (OSError, ValueError, UnicodeDecodeError):
            rows = []
    if (directory / "summary.json").is_file():
        try:
            summary = json.loads((directory / "summary.json").read_text())
        except (OSError, ValueError, UnicodeDecodeError):
            summary = {}
    return RunFrames(directory, files, rows, summary if isinstance(summary, dict) else {})


def default_steps(run: RunFrames) -> list[int]:
    """A few recorded steps spanning the shear stage: per phase (U, US, S, signs ignored) in the
    order the path meets them, the middle step of its first stretch of consecutive shear frames
    (near the report's choice: U at dW1/2, US between dW1 and dW2, S past dW2); without phases in
    path.csv, the first, middle and last recorded shear (or any) steps."""
    shear = [s for s in run.steps if run.row(s).get("stage") == "shear"] or run.steps
    stretches: dict[str, list[int]] = {}
    current = None
    for step in shear:
        phase = run.phase(step).rstrip("+-")
        if phase and phase not in stretches:
            stretches[phase] = [step]
        elif phase and phase == current:
            stretches[phase].append(step)
        current = phase if phase and stretches[phase][-1] == step else None
    if stretches:
        return [s[len(s) // 2] for s in stretches.values()]
    return sorted({shear[0], shear[len(shear) // 2], shear[-1]})


def check_steps(run: RunFrames, steps) -> list[int]:
    """The requested steps (ints; None for default_steps), each one a recorded frame."""
    if steps is None:
        return default_steps(run)
    if isinstance(steps, (int, np.integer)) and not isinstance(steps, bool):
        steps = [steps]
    out = []
    for step in steps:
        if isinstance(step, bool) or not isinstance(step, (int, np.integer)):
            raise InputError(f"step {step!r} must be an integer; this run's frames hold steps {run.describe_steps()}")
        if int(step) not in run.files:
            raise InputError(f"step {int(step)} has no frame; this run's frames hold steps {run.describe_steps()}")
        if int(step) not in out:
            out.append(int(step))
    if not out:
        raise InputError(f"no steps given; this run's frames hold steps {run.describe_steps()}")
    return out


# --------------------------------------------------------------------------- one frame
@dataclass
class Frame:
    """One recorded state, in units of the free length L (x along the clamps' axis)."""
    points: np.ndarray            # (N, 3) deformed positions / L
    cells: np.ndarray             # (C, 3) triangles or (C, 2) segments
    kind: str                     # "plate" (triangles) or "rod" (polyline)
    length: float                 # L in metres
    clamped: tuple[np.ndarray, np.ndarray] | None  # node masks of the two clamped bands
    clamp_depth: float            # c / L: the clamped band is [-c, c] around each clamp line
    width: float | None           # W / L, when known
    point_data: dict              # arrays of the frame (displacement in units of L)
    step: int | None = None
    stage: str = ""
    dL_over_L: float = math.nan
    dW_over_L: float = math.nan


def clamp_bands(reference: np.ndarray) -> tuple[float, float, np.ndarray, np.ndarray]:
    """(L, c, left, right) from reference positions spanning [-c, L + c] along x: the free length,
    the half-depth of the clamped bands and the masks of the nodes in [-c, c] and [L - c, L + c]
    (the rod's clamped end edges, the plate's clamped node columns; ddg.geometry.centerline)."""
    x = reference[:, 0]
    xmin, xmax = float(x.min()), float(x.max())
    depth = max(-xmin, 0.0)
    length = xmax - depth
    if not length > 0:
        raise InputError(f"frame reference spans x in [{xmin:g}, {xmax:g}]; expected [-c, L + c] with L > 0")
    tol = 1e-6 * length
    return length, depth, x <= depth + tol, x >= length - depth - tol


def read_frame(path, *, strip_width: float | None = None) -> Frame:
    """One VTU frame read with pyvista: positions, cells, arrays and the step's metadata."""
    pv = import_pyvista()
    try:
        grid = pv.read(str(path))
    except Exception as exc:  # noqa: BLE001  (vtk's readers raise assorted errors)
        raise InputError(f"{str(path)!r} is not a readable VTU frame: {exc}") from None
    points = np.asarray(grid.points, dtype=float)
    if points.ndim != 2 or len(points) == 0:
        raise InputError(f"{str(path)!r} holds no points")
    cells, kind = _cells(grid, path)
    data = {name: np.asarray(grid.point_data[name]) for name in grid.point_data.keys()}
    clamped, depth = None, 0.0
    if "flat_position" in data and data["flat_position"].shape == points.shape:
        data["displacement"] = points - data.pop("flat_position")   # coloured by |displacement|
    if "displacement" in data and data["displacement"].shape == points.shape:
        reference = points - data["displacement"]
        length, depth, left, right = clamp_bands(reference)
        clamped = (left, right)
        if strip_width is None and kind == "plate":  # the flat plate spans [-W/2, W/2] across
            strip_width = float(np.ptp(reference[:, 1])) or None
    else:  # no reference: no clamps, lengths in units of the x extent
        length = float(np.ptp(points[:, 0])) or 1.0
    field_data = grid.field_data

    def number(name):
        return float(np.asarray(field_data[name]).ravel()[0]) if name in field_data.keys() else math.nan

    stage = ""
    if "stage" in field_data.keys():
        stage = bytes(np.asarray(field_data["stage"], dtype=np.uint8).ravel()).decode("utf-8", "replace")
    step = int(number("step")) if "step" in field_data.keys() else None
    scaled = {k: (v / length if k == "displacement" else v) for k, v in data.items()}
    return Frame(points / length, cells, kind, length, clamped, depth / length,
                 None if strip_width is None else strip_width / length, scaled, step, stage,
                 number("dL_over_L"), number("dW_over_L"))


def _cells(grid, path) -> tuple[np.ndarray, str]:
    types = np.asarray(grid.celltypes)
    conn = np.asarray(grid.cell_connectivity)
    if len(types) and np.all(types == 5):  # VTK_TRIANGLE
        return conn.reshape(-1, 3), "plate"
    if len(types) and np.all(types == 3):  # VTK_LINE
        return conn.reshape(-1, 2), "rod"
    raise InputError(f"{str(path)!r} holds cells of VTK types {sorted(set(types.tolist()))}; "
                     "expected triangles (plate) or line segments (rod)")


def scalars_of(frame: Frame, color_by: str) -> tuple[np.ndarray, str]:
    """Per-node values to colour by and their label: "z" (height / L), or a point array of the
    frame (vectors by their length)."""
    if color_by == "z":
        return frame.points[:, 2], "z / L"
    if color_by not in frame.point_data:
        raise InputError(f"colour = {color_by!r} is not in this frame; choose from {colour_choices(frame)}")
    values = np.asarray(frame.point_data[color_by], dtype=float)
    if values.ndim == 2:
        values = np.linalg.norm(values, axis=1)
    label = f"|{color_by}| / L" if color_by == "displacement" else color_by
    return values, label


def colour_choices(frame: Frame) -> list[str]:
    return ["z", *sorted(frame.point_data)]


def clamp_boxes(frame: Frame) -> list[tuple[float, float, float, float, float, float]]:
    """Bounds (xmin, xmax, ymin, ymax, zmin, zmax), units of L, of the two clamp jaws: around the
    clamped band's deformed nodes, reaching JAW_LENGTH out of the strip along x."""
    if frame.clamped is None:
        return []
    half_width = 0.5 * (frame.width or ROD_DIAMETER_DEFAULT) * (1 + JAW_MARGIN)
    boxes = []
    for mask, outward in zip(frame.clamped, (-1.0, 1.0)):
        if not mask.any():
            continue
        centre = frame.points[mask].mean(axis=0)
        inner = centre[0] - outward * frame.clamp_depth
        outer = centre[0] + outward * (frame.clamp_depth + JAW_LENGTH)
        boxes.append((min(inner, outer), max(inner, outer), centre[1] - half_width, centre[1] + half_width,
                      centre[2] - 0.5 * JAW_THICKNESS, centre[2] + 0.5 * JAW_THICKNESS))
    return boxes


def extent_points(frame: Frame, limit: int = 4000) -> np.ndarray:
    """Points (units of L) the camera must show for this frame: the strip's nodes (at most
    `limit`, evenly picked) and the clamp jaws' corners."""
    points = frame.points[:: max(1, math.ceil(len(frame.points) / limit))]
    corners = [[x, y, z] for box in clamp_boxes(frame) for x in box[0:2] for y in box[2:4] for z in box[4:6]]
    return np.vstack([points, np.reshape(corners, (-1, 3))])


def _as_fit_points(fit_to) -> np.ndarray:
    """(K, 3) points from (K, 3) points or (6,) bounds (xmin, xmax, ymin, ymax, zmin, zmax)."""
    a = np.asarray(fit_to, dtype=float)
    if a.shape == (6,):
        return np.array([[x, y, z] for x in a[0:2] for y in a[2:4] for z in a[4:6]])
    if a.ndim != 2 or a.shape[1] != 3 or len(a) == 0 or not np.isfinite(a).all():
        raise InputError(f"fit_to has shape {a.shape}; expected (K, 3) finite points or (6,) bounds")
    return a


def title_of(frame: Frame, phase: str = "", model: str = "") -> str:
    """'plate W/L = 0.167 · step 95 (shear)' over 'dL/L = 0.500, dW/L = 0.392 · US+'."""
    first = " ".join(p for p in (model or frame.kind, f"W/L = {frame.width:.3g}" if frame.width else "") if p)
    if frame.step is not None:
        first += f" · step {frame.step}" + (f" ({frame.stage})" if frame.stage else "")
    second = ", ".join(f"{name} = {value:.3f}" for name, value in (("dL/L", frame.dL_over_L), ("dW/L", frame.dW_over_L))
                       if math.isfinite(value))
    if phase:
        second += f" · {phase}" if second else phase
    return first + ("\n" + second if second else "")


# --------------------------------------------------------------------------- drawing
def _view_vectors():
    az, el = math.radians(VIEW_AZIMUTH_DEG), math.radians(VIEW_ELEVATION_DEG)
    direction = np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])
    up = np.array([0.0, 0.0, 1.0])
    up = up - direction * (up @ direction)
    return direction, up / np.linalg.norm(up)


def _fit_camera(renderer, points: np.ndarray, aspect: float, pad: float = 0.0) -> None:
    """Parallel projection along the fixed view direction, scaled and centred so the projected
    `points` (grown by `pad`) fill the band of the view between the title and the colour bar."""
    direction, up = _view_vectors()
    right = np.cross(up, direction)
    along = [points @ axis for axis in (right, up, direction)]
    lo = np.array([a.min() for a in along]) - pad
    hi = np.array([a.max() for a in along]) + pad
    mid = 0.5 * (lo + hi)
    half_w, half_h = 0.5 * (hi[0] - lo[0]), 0.5 * (hi[1] - lo[1])
    scale = max(half_h / FIT_HEIGHT, half_w / (FIT_WIDTH * aspect), 1e-3)
    centre = mid[0] * right + mid[1] * up + mid[2] * direction
    camera = renderer.camera
    distance = 4.0 * max(hi[2] - lo[2], half_w, half_h, 1e-3)
    camera.focal_point = tuple(centre)
    camera.position = tuple(centre + distance * direction)
    camera.up = tuple(up)
    camera.parallel_projection = True
    camera.parallel_scale = scale
    renderer.reset_camera_clipping_range()


def _add_state(plotter, frame: Frame, *, color_by: str, clim, show_edges: bool, scalar_bar: bool) -> None:
    pv = import_pyvista()
    values, label = scalars_of(frame, color_by)
    if frame.kind == "plate":
        faces = np.hstack([np.full((len(frame.cells), 1), 3), frame.cells]).ravel()
        mesh = pv.PolyData(frame.points, faces)
        mesh.point_data[label] = values
        mesh = mesh.compute_normals(auto_orient_normals=False, split_vertices=False)
    else:
        # one polyline cell through the nodes in order (segments as separate cells would give a
        # tube of capped pieces, striped)
        order = _polyline_order(frame.cells, len(frame.points))
        line = pv.PolyData(frame.points[order], lines=np.concatenate([[len(order)], np.arange(len(order))]))
        line.point_data[label] = values[order]
        mesh = line.tube(radius=0.5 * (frame.width or ROD_DIAMETER_DEFAULT), n_sides=24, capping=True)
    bar = dict(title=label, vertical=False, position_x=0.3, position_y=0.06, height=0.08, width=0.4,
               title_font_size=16, label_font_size=14, color=FOREGROUND, fmt="%.2f", n_labels=5) if scalar_bar else None
    plotter.add_mesh(mesh, scalars=label, cmap=COLORMAP, clim=clim, smooth_shading=True, show_edges=show_edges,
                     edge_color="#595959", line_width=0.5, ambient=0.15, diffuse=0.85,
                     show_scalar_bar=scalar_bar, scalar_bar_args=bar)
    if scalar_bar:  # labels under the bar, so they do not run into its title above it
        plotter.scalar_bars[label].SetTextPositionToPrecedeScalarBar()
    for box in clamp_boxes(frame):
        plotter.add_mesh(pv.Box(bounds=box), color=CLAMP_COLOR)


def _polyline_order(segments: np.ndarray, count: int) -> np.ndarray:
    """Node indices along a chain of segments (a rod's centerline, ddg.output.frames.polyline_cells)."""
    if len(segments) == count - 1 and (segments[:, 1] - segments[:, 0] == 1).all() and segments[0, 0] == 0:
        return np.arange(count)
    nxt = {int(a): int(b) for a, b in segments}
    start = (set(nxt) - set(nxt.values()) or {int(segments[0, 0])}).pop()
    order = [start]
    while order[-1] in nxt and len(order) <= count:
        order.append(nxt[order[-1]])
    return np.asarray(order)


def _screenshot(plotter) -> np.ndarray:
    image = np.asarray(plotter.screenshot(None, return_img=True))
    plotter.close()
    flat = image.reshape(-1, image.shape[-1])
    if (flat == flat[0]).all():
        raise RuntimeError("off-screen rendering produced a uniform image: no working OpenGL (vtk >= 9.4 uses EGL "
                           "without a display; install Mesa's libegl1 and libegl-mesa0, or run under Xvfb)")
    return image


def _write_png(image: np.ndarray, png_path) -> Path:
    from PIL import Image  # pillow: a dependency of pyvista

    png_path = Path(png_path)
    with atomic_path(png_path, suffix=".png") as tmp:
        Image.fromarray(image).save(tmp, format="PNG")
    return png_path


def _clim(frames, color_by: str):
    values = np.concatenate([scalars_of(f, color_by)[0] for f in frames])
    lo, hi = float(values.min()), float(values.max())
    return (lo, hi) if hi > lo else (lo - 0.5, hi + 0.5)


#: Modules after whose import an in-process EGL render aborts the interpreter.
_UNSAFE_FOR_EGL = ("dolfinx", "petsc4py")


def _draw_in_child(panels, timeout: float = 300.0, **options) -> np.ndarray:
    """draw() in a fresh interpreter: the panels and options pickled to it, the image back."""
    import pickle

    package_root = str(Path(__file__).resolve().parents[2])
    env = dict(os.environ)
    env["PYTHONPATH"] = package_root + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
    with tempfile.TemporaryDirectory(prefix="ddg-render-") as tmp:
        job, image = Path(tmp) / "job.pickle", Path(tmp) / "image.npy"
        job.write_bytes(pickle.dumps((panels, options, str(image))))
        child = "import sys; from ddg.output.render import _draw_child; _draw_child(sys.argv[1])"
        proc = subprocess.run([sys.executable, "-c", child, str(job)], capture_output=True, text=True, env=env,
                              timeout=timeout)
        if proc.returncode != 0 or not image.exists():
            lines = [ln for ln in proc.stderr.splitlines() if ln.strip() and "WARN|" not in ln]
            raise RuntimeError(f"rendering failed: {lines[-1] if lines else f'exit code {proc.returncode}'}")
        return np.load(image)


def _draw_child(job_path: str) -> None:
    """Child side of _draw_in_child."""
    import pickle

    panels, options, image = pickle.loads(Path(job_path).read_bytes())
    np.save(image, draw(panels, **options))


def draw(frames_and_titles, *, columns: int | None = None, window_size=None, color_by: str = "z",
         fit_to=None, clim=None, show_edges: bool = False) -> np.ndarray:
    """RGB image (H, W, 3) of one or more states in a grid of `columns` panels, each with its title,
    all seen by the same fixed camera fitted to all of them (or to `fit_to`: (K, 3) points or (6,)
    bounds, units of L), colours on one scale (`clim`, default the range over all panels). A panel
    whose frame is None stays empty (keeps the grid's rows aligned).

    In a process that has loaded dolfinx/PETSc (the FEM reference, or a test session that ran
    it), vtk's off-screen EGL context aborts the interpreter (measured: SIGABRT in
    vtkRenderWindow::Render); there the drawing is done in a child interpreter."""
    panels = list(frames_and_titles)
    if any(name in sys.modules for name in _UNSAFE_FOR_EGL):
        return _draw_in_child(panels, columns=columns, window_size=window_size, color_by=color_by, fit_to=fit_to,
                              clim=clim, show_edges=show_edges)
    pv = import_pyvista()
    count = len(panels)
    columns = count if columns is None else max(1, min(int(columns), count))
    rows = math.ceil(count / columns)
    if window_size is None:
        window_size = (WINDOW_SIZE[0], WINDOW_SIZE[1]) if count == 1 else (560 * columns, 420 * rows)
    frames = [f for f, _ in panels if f is not None]
    if not frames:
        raise InputError("nothing to draw: every panel is empty")
    fit = np.vstack([extent_points(f) for f in frames]) if fit_to is None else _as_fit_points(fit_to)
    pad = max(0.5 * (f.width or ROD_DIAMETER_DEFAULT) if f.kind == "rod" else 0.0 for f in frames)
    clim = _clim(frames, color_by) if clim is None else clim
    plotter = pv.Plotter(off_screen=True, shape=(rows, columns), window_size=list(window_size), border=False,
                         lighting="three lights")
    plotter.set_background(BACKGROUND)
    aspect = (window_size[0] / columns) / (window_size[1] / rows)
    last = max(k for k, (frame, _) in enumerate(panels) if frame is not None)
    for k, (frame, title) in enumerate(panels):
        if frame is None:
            continue
        plotter.subplot(k // columns, k % columns)
        _add_state(plotter, frame, color_by=color_by, clim=clim, show_edges=show_edges, scalar_bar=(k == last))
        plotter.add_text(title, position="upper_left", font_size=11 if count > 1 else 13, color=FOREGROUND)
        plotter.add_axes(color=FOREGROUND, line_width=2, labels_off=False)
        _fit_camera(plotter.renderer, fit, aspect, pad)
    return _screenshot(plotter)


def render_frame(vtu_path, png_path, *, phase: str | None = None, title: str | None = None, color_by: str = "z",
                 strip_width: float | None = None, fit_to=None, clim=None, window_size=WINDOW_SIZE,
                 show_edges: bool = False) -> Path:
    """Draw one frame to `png_path`: the plate's surface or the rod's tube coloured by `color_by`
    ("z" or a point array of the frame), the clamps, and a title with dL/L, dW/L and the phase.
    When the frame sits in a run folder (DIR/frames/frame_NNNNN.vtu), the phase comes from
    DIR/path.csv and the strip width (the rod's tube diameter) from DIR/summary.json unless given.
    fit_to ((K, 3) points or (6,) bounds, units of L) fixes what the camera frames, clim the colour
    range (defaults: this frame's)."""
    vtu_path = Path(vtu_path)
    if not vtu_path.is_file():
        raise InputError(f"frame {str(vtu_path)!r} does not exist")
    run = None
    if vtu_path.parent.name == "frames" and (phase is None or strip_width is None):
        try:
            run = open_run(vtu_path.parent.parent)
        except InputError:
            run = None
    frame = read_frame(vtu_path, strip_width=strip_width if strip_width is not None else (run and run.strip_width))
    if phase is None:
        phase = run.phase(frame.step) if run is not None and frame.step is not None else ""
    model = str((run.summary if run is not None else {}).get("model") or "")
    text = title if title is not None else title_of(frame, phase, model)
    image = draw([(frame, text)], window_size=window_size, color_by=color_by, fit_to=fit_to, clim=clim,
                 show_edges=show_edges)
    return _write_png(image, png_path)


def render_grid(panels, png_path=None, *, columns: int | None = None, color_by: str = "z",
                strip_widths=None, window_size=None, show_edges: bool = False):
    """Several frames in one picture, filled row by row, `columns` wide, one camera and one colour
    scale: panels are (vtu_path, title) pairs (title None: the default title) or None for an empty
    panel. strip_widths (metres, per panel) size a rod's tube; a plate's comes from its frame.
    Writes `png_path` and returns its path, or returns the RGB image (H, W, 3) when png_path is None."""
    pairs = list(panels)
    if not pairs:
        raise InputError("render_grid needs at least one (vtu_path, title) panel")
    widths = list(strip_widths) if strip_widths is not None else [None] * len(pairs)
    loaded = []
    for pair, width in zip(pairs, widths):
        if pair is None:
            loaded.append((None, ""))
            continue
        path, title = pair
        frame = read_frame(path, strip_width=width)
        loaded.append((frame, title if title is not None else title_of(frame)))
    image = draw(loaded, columns=columns, window_size=window_size, color_by=color_by, show_edges=show_edges)
    return image if png_path is None else _write_png(image, png_path)


def render_run(run_dir, out_dir=None, steps=None, *, color_by: str = "z", html: bool = False,
               window_size=WINDOW_SIZE, show_edges: bool = False) -> list[Path]:
    """Draw chosen steps of a run folder: out_dir/step_NNNNN.png each (default out_dir:
    run_dir/render), and out_dir/step_NNNNN.html interactive scenes if html. steps: frame step
    indices (default default_steps: one state per phase of the shear stage). One fixed camera and
    one colour scale for all of them. Returns the files written."""
    run = open_run(run_dir)
    chosen = check_steps(run, steps)
    import_pyvista()
    if html and (reason := html_unavailable()) is not None:
        raise InputError(reason)
    out = Path(out_dir) if out_dir is not None else run.directory / "render"
    from .io import check_output_directory

    check_output_directory(out, "out")
    frames = {s: read_frame(run.files[s], strip_width=run.strip_width) for s in chosen}
    fit = np.vstack([extent_points(f) for f in frames.values()])
    clim = _clim(frames.values(), color_by)
    model = str(run.summary.get("model") or "")
    written = []
    for step, frame in frames.items():
        image = draw([(frame, title_of(frame, run.phase(step), model))], window_size=window_size,
                     color_by=color_by, fit_to=fit, clim=clim, show_edges=show_edges)
        written.append(_write_png(image, out / f"step_{step:05d}.png"))
    if html:
        jobs = [{"vtu": str(run.files[s]), "html": str(out / f"step_{s:05d}.html"), "strip_width": run.strip_width,
                 "color_by": color_by, "fit_to": fit.tolist(), "clim": list(clim)} for s in chosen]
        written += export_html(jobs)
    return written


# --------------------------------------------------------------------------- HTML
def export_html(jobs: list[dict], timeout: float = 300.0) -> list[Path]:
    """Interactive HTML scenes (vtk.js, self-contained) of frames, exported by pyvista's trame
    exporter in a child interpreter. Each job: vtu, html, and optional strip_width, color_by,
    fit_to, clim. Returns the HTML files."""
    reason = html_unavailable()
    if reason is not None:
        raise InputError(reason)
    package_root = str(Path(__file__).resolve().parents[2])
    env = dict(os.environ)
    env["PYTHONPATH"] = package_root + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
    child = "from ddg.output.render import _export_html_child; _export_html_child()"
    proc = subprocess.run([sys.executable, "-c", child], input=json.dumps(jobs), capture_output=True, text=True,
                          env=env, timeout=timeout)
    if proc.returncode != 0:
        lines = [ln for ln in proc.stderr.splitlines() if ln.strip() and "WARN|" not in ln]
        raise RuntimeError(f"HTML export failed: {lines[-1] if lines else f'exit code {proc.returncode}'}")
    return [Path(job["html"]) for job in jobs]


def _export_html_child() -> None:
    """Child side of export_html: jobs as JSON on stdin."""
    import warnings

    jobs = json.loads(sys.stdin.read())
    pv = import_pyvista()
    for job in jobs:
        frame = read_frame(job["vtu"], strip_width=job.get("strip_width"))
        plotter = pv.Plotter(off_screen=True, window_size=list(WINDOW_SIZE), lighting="three lights")
        plotter.set_background(BACKGROUND)
        color_by = job.get("color_by", "z")
        clim = job.get("clim") or _clim([frame], color_by)
        _add_state(plotter, frame, color_by=color_by, clim=clim, show_edges=False, scalar_bar=True)
        fit = _as_fit_points(job["fit_to"]) if job.get("fit_to") else extent_points(frame)
        _fit_camera(plotter.renderer, fit, WINDOW_SIZE[0] / WINDOW_SIZE[1])
        try:
            with atomic_path(Path(job["html"]), suffix=".html") as tmp, warnings.catch_warnings():
                warnings.simplefilter("ignore")  # pyvista >= 0.48 deprecates Plotter.export_html for .trame's
                component = getattr(plotter, "trame", None)
                (component.export_html if component is not None else plotter.export_html)(str(tmp))
        finally:
            plotter.close()
