"""The error map's two figures as data, drawn by validation.figures: OUT/speed_accuracy.png (per
width, each run's wall time against its combined error, the paper's L/b only) and
OUT/enough_map.png (per dL/L and tolerance of TOLERANCES, the cheapest model measured within the
tolerance on all three quantities at each map scene over W/L and L/b, held-out scenes open)."""
from __future__ import annotations

import sys
from pathlib import Path

from ddg.advise import QUANTITIES
from ddg.output.io import finite_float

from ..figures import draw, save_png
from ..table import FigureData
from .held_out import TOLERANCES
from .readme_writer import scene_order
from .rows import cheapest_within, combined_error

#: The figures' resolution (dots per inch).
DPI = 90


def on_paper_strip(row: dict) -> bool:
    """The row is on the paper's strip (b = 0.127 mm: L/b 1181 at dL/L = 1/2, 787 at 1/4)."""
    import ddg

    default = ddg.Strip.from_ratios(float(row["width_ratio"]), float(row["compression_ratio"])).slenderness
    return abs(float(row["slenderness"]) - default) < 1e-6 * default


def speed_accuracy_data(rows: list[dict], tolerance: float = 0.01) -> FigureData:
    """Per row on the paper's strip with a wall time: model, dL/L, W/L, wall time and combined error
    (validation.error_map.rows.combined_error; None where a quantity is missing); the panels are
    every width of the map, the colours follow the models' order in the rows."""
    widths = sorted({round(float(r["width_ratio"]), 6) for r in rows})
    models = list(dict.fromkeys(r["model"] for r in rows))
    points = [[r["model"], float(r["compression_ratio"]), float(r["width_ratio"]), finite_float(r["wall_time_s"]),
               combined_error(r)] for r in rows
              if finite_float(r.get("wall_time_s")) is not None and on_paper_strip(r)]
    return FigureData("speed_accuracy", "map_speed_accuracy", "",
                      ["model", "compression_ratio", "width_ratio", "wall_time_s", "combined_error"], points,
                      {"widths": widths, "models": models, "tolerance": tolerance})


def enough_data(rows: list[dict]) -> FigureData:
    """Per dL/L, tolerance of TOLERANCES and scene: the cheapest DDG model within the tolerance on
    all three quantities, else the cheapest of any (the FEM's meshes), None where none is."""
    names, first = scene_order(rows)
    compressions = sorted({float(r["compression_ratio"]) for r in rows}, reverse=True)
    points = []
    for c in compressions:
        for tol in TOLERANCES:
            for n in names:
                f = first[n]
                if abs(float(f["compression_ratio"]) - c) > 1e-9:
                    continue
                mine = [r for r in rows if r["scene"] == n]   # a DDG model if one is enough, else the FEM
                best = cheapest_within(mine, tol, QUANTITIES, runnable_only=True) or cheapest_within(mine, tol)
                points.append([c, tol, n, float(f["width_ratio"]), float(f["slenderness"]), f.get("role"),
                               None if best is None else best["model"],
                               None if best is None else best["resolution_label"]])
    return FigureData("enough_map", "enough_map", "",
                      ["compression_ratio", "tolerance", "scene", "width_ratio", "slenderness", "role", "model",
                       "resolution_label"], points,
                      {"compressions": compressions, "tolerances": list(TOLERANCES),
                       "models": list(dict.fromkeys(r["model"] for r in rows))})


def figures(rows: list[dict], out: Path, tolerance: float = 0.01) -> list[str]:
    """OUT/speed_accuracy.png (`tolerance` dashed) and OUT/enough_map.png, drawn by
    validation.figures; their file names, or [] with one line naming the extra if matplotlib is
    missing."""
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        print("figures skipped: matplotlib is missing (pip install 'ddg-strips[plot]')", file=sys.stderr)
        return []
    names = []
    for data in (speed_accuracy_data(rows, tolerance), enough_data(rows)):
        save_png(draw(data), Path(out) / f"{data.name}.png", DPI)
        names.append(f"{data.name}.png")
    return names
