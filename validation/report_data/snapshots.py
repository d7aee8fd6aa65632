"""3D snapshots of the plate runs: a U, a US and an S state of a narrow and a wide plate (paper Fig. 1),
from the frames the runs wrote."""
from __future__ import annotations

from pathlib import Path

from ..studies import SNAPSHOT_SCENES
from ..table import FigureData
from .data import Snapshots
from .runs import find_run


def _frame_index(frames_dir: Path) -> list[dict]:
    """The frames.pvd collection of a run: [{step, file, dW_over_L, stage}], or [] if absent."""
    import xml.etree.ElementTree as ET

    pvd = frames_dir / "frames.pvd"
    if not pvd.exists():
        return []
    # "step" (the pvd's timestep is the time, dW/L; frames written before it carried the step)
    return [{"step": int(d.get("step") if d.get("step") is not None else d.get("timestep")),
             "file": frames_dir / d.get("file"), "stage": d.get("stage"),
             "dW_over_L": float(d.get("dW_over_L"))} for d in ET.parse(pvd).getroot().iter("DataSet")]


def snapshot_states(run) -> list[tuple[str, float, Path]]:
    """(phase, dW/L, frame file) of a U, a US and an S state of a plate run: the recorded shear
    state nearest to dW1/2 on U, to (dW1 + dW2)/2 on US (dW2 -> dW_end if S is never reached) and to
    (dW2 + dW_end)/2 on S."""
    frames = [f for f in _frame_index(run.directory / "frames") if f["stage"] == "shear"]
    if not frames:
        return []
    s = run.summary
    shear = [r for r in run.rows if r["stage"] == "shear"]
    dw_end = max(float(r["dW_over_L"]) for r in shear)
    dw1, dw2 = s.get("dW1_over_L"), s.get("dW2_over_L")
    targets = {"U": 0.5 * dw1 if dw1 else 0.5 * dw_end,
               "US": 0.5 * (dw1 + (dw2 or dw_end)) if dw1 else None,
               "S": 0.5 * (dw2 + dw_end) if dw2 else None}
    out = []
    for phase, target in targets.items():
        if target is None:
            continue
        rows = [r for r in shear if str(r["phase"]).rstrip("+-") == phase]
        if not rows:
            continue
        row = min(rows, key=lambda r: abs(float(r["dW_over_L"]) - target))
        frame = min(frames, key=lambda f: abs(f["dW_over_L"] - float(row["dW_over_L"])))
        if abs(frame["dW_over_L"] - float(row["dW_over_L"])) < 1e-9:
            out.append((str(row["phase"]), float(row["dW_over_L"]), frame["file"]))
    return out


def snapshot_data(results, profile) -> tuple[FigureData | None, Snapshots]:
    """3D shapes of U, US and S plates, narrow and wide (paper Fig. 1), from the plate runs' frames:
    the nodes (in L) as rows, each panel's triangles as marks."""
    try:
        import meshio
    except ImportError:
        return None, Snapshots(skipped="no meshio")
    states = []
    for compression, width in SNAPSHOT_SCENES:
        run = find_run(results, "plate", compression, width, profile.models.get("plate"))
        if run is not None:
            states += [(compression, width, run, *state) for state in snapshot_states(run)]
    if not states:
        return None, Snapshots(skipped="no plate runs")
    rows, panels = [], []
    for width in sorted({s[1] for s in states}):
        for compression, _, run, phase, dw, path in [s for s in states if s[1] == width]:
            mesh = meshio.read(path)
            xyz = mesh.points / float(run.summary["scene"]["length"])
            panels.append({"compression_ratio": compression, "width_ratio": width, "phase": phase, "dW_over_L": dw,
                           "triangles": mesh.cells_dict["triangle"], "frame": str(path)})
            rows += [[compression, width, phase, dw, k, *map(float, p)] for k, p in enumerate(xyz)]
    figure = FigureData(
        "snapshots_3d", "snapshots",
        "Deformed plates (paper Fig. 1): U, US and S states of a narrow and a wide strip at dL/L = 1/2, "
        "from the plate runs' frames (U at dW1/2, US halfway between dW1 and dW2, S halfway from dW2 to "
        "the end of the shear).",
        ["compression_ratio", "width_ratio", "phase", "dW_over_L", "node", "x_over_L", "y_over_L", "z_over_L"], rows,
        {"panels": panels})
    return figure, Snapshots(shapes=len(panels))

