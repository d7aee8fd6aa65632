"""The validation's figures, each drawn from its data alone: draw(FigureData) -> matplotlib figure.

A drawing function takes the figure's rows (the rows of its CSV, as dicts) and its marks
(validation.table.FigureData), never a run; so every number a figure shows is in its data, and a
figure can be drawn from hand-made rows. One module per family: the path (paths), the runs'
convergence, cost and failures (diagnostics), the deformed strip (shapes), the error map
(error_map); the shared colours and helpers in style. matplotlib is imported lazily (the `report`
and `plot` extras).
"""
from __future__ import annotations

from pathlib import Path

from ..table import FigureData, fraction
from .diagnostics import (STABILITY_CATEGORIES, STABILITY_COLORS, convergence, pareto, speed_accuracy,
                          stability_category, stability_map)
from .error_map import FAMILY_MARKERS, enough_map, family_marker, map_speed_accuracy
from .paths import (A11_STYLES, BAND_COLORS, PHASE_SHADES, elastica, poisson, sadowsky_a11, shear_curves, shear_force,
                    thresholds, wide_ribbons)
from .shapes import centerline_error, centerline_error_field, curvature_profiles, deformed_plates, snapshots
from .style import COLORS, MARKERS, pyplot

__all__ = ["A11_STYLES", "BAND_COLORS", "COLORS", "DRAW", "FAMILY_MARKERS", "MARKERS", "PHASE_SHADES",
           "STABILITY_CATEGORIES", "STABILITY_COLORS", "centerline_error", "centerline_error_field", "convergence",
           "curvature_profiles", "deformed_plates", "draw", "elastica", "enough_map", "family_marker", "fraction",
           "map_speed_accuracy", "pareto", "poisson", "sadowsky_a11", "save", "save_png", "shear_curves",
           "shear_force", "snapshots", "speed_accuracy", "stability_category", "stability_map", "thresholds",
           "wide_ribbons"]

DRAW = {"elastica": elastica, "centerline_error": centerline_error, "curvature_profiles": curvature_profiles,
        "sadowsky_a11": sadowsky_a11, "centerline_error_field": centerline_error_field,
        "deformed_plates": deformed_plates, "shear_curves": shear_curves, "shear_force": shear_force,
        "thresholds": thresholds,
        "convergence": convergence, "poisson": poisson, "speed_accuracy": speed_accuracy,
        "stability_map": stability_map, "snapshots": snapshots, "wide_ribbons": wide_ribbons,
        "map_speed_accuracy": map_speed_accuracy, "enough_map": enough_map}


def draw(data: FigureData):
    """The matplotlib figure of `data`, from its rows and marks only."""
    return DRAW[data.kind](data.records(), **data.marks)


def save(fig, directory: Path, name: str) -> bytes:
    """DIR/<name>.png (110 dpi) and .pdf, byte-stable (ddg.output.io.save_figure); the figure is
    closed; returns the PNG bytes."""
    from ddg.output.io import save_figure

    plt = pyplot()
    directory = Path(directory)
    png = save_figure(fig, directory / f"{name}.png", dpi=110, bbox_inches="tight").read_bytes()
    save_figure(fig, directory / f"{name}.pdf", bbox_inches="tight")
    plt.close(fig)
    return png


def save_png(fig, path: Path, dpi: int) -> Path:
    """`path` as a PNG of the whole figure at `dpi`, byte-stable (ddg.output.io.save_figure); the
    figure is closed."""
    from ddg.output.io import save_figure

    path = save_figure(fig, Path(path), dpi=dpi)
    pyplot().close(fig)
    return path
