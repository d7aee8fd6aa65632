"""Deformed shapes for ParaView: one VTU file per recorded step and a `frames.pvd` collection.

Each `frame_NNNNN.vtu` holds the deformed node positions (N, 3) as its points, the cells
(triangles: the plate mesh, or the ribbon a rod stands for, ddg.output.frame_fields; or line
segments), the point array `flat_position` (the flat reference; not a displacement, which Warp
By Vector would add to the already deformed points), any extra per-node and per-cell arrays
(e.g. turn_angle_deg and bending_energy_density of the plate, k1_L, k2_L, tau_L of the rod), and
field data `TimeValue`, `step` (the step index), `dL_over_L`, `dW_over_L` and `stage` (the stage
name as UTF-8 byte codes; VTK string arrays would make the file unreadable to meshio).
`frames.pvd` lists the frames with timestep = the frame's time (ddg.simulate gives dW/L on the
shear, and dL/L - dL_end/L <= 0 on the compression, so that ParaView's time axis reads the shear
directly and the whole protocol stays monotone) and carries step, dL_over_L, dW_over_L and stage
as attributes; it is rewritten after every frame, and every file is written atomically, so an
interrupted run leaves a valid collection of complete frames. meshio is imported lazily (Debian
python3-meshio).
"""
from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from ..limits import InputError
from .io import atomic_path, atomic_write_text

#: Nodes per cell of the supported cell types.
CELL_NODES = {"triangle": 3, "line": 2}

COLLECTION_NAME = "frames.pvd"
#: The point array holding the flat reference positions.
REFERENCE_ARRAY = "flat_position"


def _import_meshio():
    try:
        import meshio
    except ImportError:
        raise InputError(
            "writing VTU frames needs meshio, which is not installed; "
            "pip install 'ddg-strips[io]' (or Debian's python3-meshio)"
        ) from None
    return meshio


def polyline_cells(node_count: int) -> np.ndarray:
    """Line cells (node_count - 1, 2) joining consecutive nodes of a rod's centerline."""
    i = np.arange(node_count - 1)
    return np.stack([i, i + 1], axis=1)


def _as_points(array, name: str) -> np.ndarray:
    points = np.asarray(array, dtype=float)
    if points.ndim != 2 or points.shape[1] not in (2, 3):
        raise InputError(f"{name} have shape {points.shape}; expected (N, 3) or (N, 2)")
    if points.shape[1] == 2:
        points = np.column_stack([points, np.zeros(len(points))])
    return points


class FrameWriter:
    """Write `directory/frame_NNNNN.vtu` per step and keep `directory/frames.pvd` up to date.

    mesh_or_cells: a PlateMesh (triangles; the flat mesh is the reference) or integer cells
    (C, 3) / (C, 2) with cell_type "triangle" / "line" (inferred from the shape when omitted)
    and optional flat reference positions (N, 2|3), written as the point array flat_position.
    """

    def __init__(self, directory, mesh_or_cells, *, reference=None, cell_type: str | None = None,
                 prefix: str = "frame"):
        self._meshio = _import_meshio()
        if hasattr(mesh_or_cells, "triangles") and hasattr(mesh_or_cells, "nodes"):
            cells = np.asarray(mesh_or_cells.triangles)
            if reference is None:
                reference = mesh_or_cells.nodes
            cell_type = cell_type or "triangle"
        else:
            cells = np.asarray(mesh_or_cells)
        if cells.ndim != 2 or len(cells) == 0 or not np.issubdtype(cells.dtype, np.integer):
            raise InputError(f"cells have shape {cells.shape} and dtype {cells.dtype}; expected integer (C, 3) or (C, "
                             f"2), C > 0")
        if cell_type is None:
            cell_type = {3: "triangle", 2: "line"}.get(cells.shape[1])
        if cell_type not in CELL_NODES:
            raise InputError(f"cell_type = {cell_type!r} must be one of {sorted(CELL_NODES)}")
        if cells.shape[1] != CELL_NODES[cell_type]:
            raise InputError(f"{cell_type} cells need {CELL_NODES[cell_type]} nodes each; got shape {cells.shape}")
        if cells.min() < 0:
            raise InputError("cells index negative node numbers")
        self.directory = Path(directory)
        self.directory.mkdir(parents=True, exist_ok=True)
        self.cells = cells.astype(np.int64)
        self.cell_type = cell_type
        self.reference = None if reference is None else _as_points(reference, "reference positions")
        self.prefix = prefix
        self._entries: dict[int, dict] = {}
        self._closed = False

    @property
    def collection_path(self) -> Path:
        return self.directory / COLLECTION_NAME

    @property
    def files(self) -> list[Path]:
        """The frames written so far, in step order."""
        return [self.directory / self._entries[s]["file"] for s in sorted(self._entries)]

    def write(self, positions, *, step: int | None = None, dL_over_L: float = math.nan,
              dW_over_L: float = math.nan, stage: str = "", point_data: dict | None = None,
              cell_data: dict | None = None, time: float | None = None) -> Path:
        """Write one frame (deformed positions (N, 3) or (N, 2)) and rewrite the collection.

        step defaults to one past the last step written; writing a step again replaces it.
        cell_data: {name: (C,) or (C, k) array} per cell; time: the frame's time value in the
        collection and the file (default the step index).
        """
        if self._closed:
            raise RuntimeError("FrameWriter is closed")
        points = _as_points(positions, "positions")
        n = len(points)
        if self.cells.max() >= n:
            raise InputError(f"positions hold {n} nodes but the cells index node {int(self.cells.max())}")
        if step is None:
            step = max(self._entries, default=-1) + 1
        if isinstance(step, bool) or not isinstance(step, (int, np.integer)) or step < 0:
            raise InputError(f"step = {step!r} must be a non-negative integer")
        step = int(step)

        time = float(step) if time is None else float(time)
        if not math.isfinite(time):
            raise InputError(f"time = {time!r} must be a finite number")
        data = {}
        if self.reference is not None:
            if len(self.reference) != n:
                raise InputError(f"positions hold {n} nodes but the reference holds {len(self.reference)}")
            data[REFERENCE_ARRAY] = self.reference
        for name, values in (point_data or {}).items():
            values = np.asarray(values)
            if name in data:
                raise InputError(f"point array name {name!r} is reserved")
            if values.ndim not in (1, 2) or len(values) != n:
                raise InputError(f"point array {name!r} has shape {values.shape}; expected ({n},) or ({n}, k)")
            data[name] = values
        cells = {}
        for name, values in (cell_data or {}).items():
            values = np.asarray(values, dtype=float)
            if values.ndim not in (1, 2) or len(values) != len(self.cells):
                raise InputError(f"cell array {name!r} has shape {values.shape}; expected ({len(self.cells)},) or "
                                 f"({len(self.cells)}, k)")
            cells[name] = [values]

        name = f"{self.prefix}_{step:05d}.vtu"
        mesh = self._meshio.Mesh(points, [(self.cell_type, self.cells)], point_data=data, cell_data=cells)
        field = {"TimeValue": time, "step": step, "dL_over_L": float(dL_over_L),
                 "dW_over_L": float(dW_over_L), "stage": str(stage)}
        self._write_vtu(self.directory / name, mesh, field)
        self._entries[step] = {"file": name, "time": time, "dL_over_L": float(dL_over_L),
                               "dW_over_L": float(dW_over_L), "stage": str(stage)}
        self._write_collection()
        return self.directory / name

    def close(self) -> None:
        if not self._closed:
            self._write_collection()
            self._closed = True

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    # ------------------------------------------------------------------ files
    def _write_vtu(self, path: Path, mesh, field: dict) -> None:
        with atomic_path(path, suffix=".vtu") as tmp:
            self._meshio.write(tmp, mesh, file_format="vtu")
            with open(tmp, encoding="utf-8") as fh:
                text = fh.read()
            # meshio's VTU writer drops field_data, so the block is added to its output here
            if "<UnstructuredGrid>" not in text:
                raise RuntimeError("unexpected VTU layout from meshio: no <UnstructuredGrid> tag")
            text = text.replace("<UnstructuredGrid>", "<UnstructuredGrid>\n" + _field_data_xml(field), 1)
            with open(tmp, "w", encoding="utf-8") as fh:
                fh.write(text)

    def _write_collection(self) -> None:
        root = ET.Element("VTKFile", type="Collection", version="0.1", byte_order="LittleEndian")
        root.append(ET.Comment(" ddg frames: timestep = the frame's time (ddg.simulate: dW/L on the shear, "
                               "dL/L - dL_end/L on the compression); step, dL_over_L, dW_over_L and stage "
                               "are given per frame "))
        collection = ET.SubElement(root, "Collection")
        for step in sorted(self._entries):
            entry = self._entries[step]
            attributes = {"timestep": repr(entry["time"]), "step": str(step), "group": "", "part": "0",
                          "file": entry["file"]}
            for key in ("dL_over_L", "dW_over_L"):
                if math.isfinite(entry[key]):
                    attributes[key] = repr(entry[key])
            if entry["stage"]:
                attributes["stage"] = entry["stage"]
            ET.SubElement(collection, "DataSet", attributes)
        ET.indent(root)
        atomic_write_text(self.collection_path,
                          '<?xml version="1.0"?>\n' + ET.tostring(root, encoding="unicode") + "\n")


def _field_data_xml(field: dict) -> str:
    """VTK FieldData block, ascii; non-finite numbers and an empty stage are left out."""
    def array(vtk_type: str, name: str, values: list) -> str:
        return (f'<DataArray type="{vtk_type}" Name="{name}" NumberOfTuples="{len(values)}" format="ascii">\n'
                + " ".join(values) + "\n</DataArray>\n")

    parts = [array("Float64", "TimeValue", [repr(field["TimeValue"])]), array("Int64", "step", [str(field["step"])])]
    for key in ("dL_over_L", "dW_over_L"):
        if math.isfinite(field[key]):
            parts.append(array("Float64", key, [repr(field[key])]))
    if field["stage"]:
        parts.append(array("UInt8", "stage", [str(b) for b in field["stage"].encode("utf-8")]))
    return "<FieldData>\n" + "".join(parts) + "</FieldData>\n"


def read_frame(path) -> tuple[np.ndarray, dict, dict]:
    """Positions (N, 3), point and cell arrays (cell arrays under "cell:<name>") and metadata
    (step, time, dL_over_L, dW_over_L, stage) of one frame."""
    meshio = _import_meshio()
    mesh = meshio.read(path, file_format="vtu")
    field = mesh.field_data
    meta = {"step": int(field["step"][0]) if "step" in field else None,
            "time": float(field["TimeValue"][0]) if "TimeValue" in field else math.nan,
            "dL_over_L": float(field["dL_over_L"][0]) if "dL_over_L" in field else math.nan,
            "dW_over_L": float(field["dW_over_L"][0]) if "dW_over_L" in field else math.nan,
            "stage": bytes(np.asarray(field.get("stage", []), dtype=np.uint8)).decode("utf-8")}
    arrays = dict(mesh.point_data)
    arrays.update({f"cell:{name}": np.asarray(blocks[0]) for name, blocks in mesh.cell_data.items()})
    return np.asarray(mesh.points), arrays, meta
