"""The report's tables from the committed error map (data/error_map): the 1D models with width against
the FEM study on the paper's scenes, and the cheapest model within each tolerance per map scene."""
from __future__ import annotations

from pathlib import Path

from ddg.output.io import finite_float

from ..error_map.rows import cheapest_within, combined_error, read_table
from ..reference import ROOT
from ..studies import COMPRESSIONS, WIDTHS_GOLD
from ..table import FigureData

#: The 1D models of the "1D models with width" section and the resolution shown for each (the
#: ribbons' default M = 101, the rod's paper M = 100); the plate at its study's finest mesh.
WIDE_MODELS = (("rod", "M100"), ("ribbon", "M101"), ("ribbon-sano-wada", "M101"), ("ribbon-trapeze", "M101"),
               ("ribbon-cross-section", "M101"), ("ribbon-wunderlich", "M101"))
WIDE_COLUMNS = ["compression_ratio", "width_ratio", "model", "resolution", "dW1_over_L", "dW2_over_L",
                "ref_dW1", "ref_dW2", "dW1_error", "dW2_error", "H_mid_error", "wall_time_s", "reason"]
#: Tolerance (units of L) of the "cheapest model within" table: 1 % of L.
ENOUGH_TOLERANCE = 0.01
#: The further tolerances of the "which model is enough" table (the map per tolerance).
ENOUGH_MORE_TOLERANCES = (0.02, 0.05)


def enough_column(tolerance: float) -> str:
    """The enough table's column of the cheapest model within `tolerance` on all three quantities."""
    return f"on_all_three_{tolerance:g}".replace(".", "_")


ENOUGH_COLUMNS = ["compression_ratio", "width_ratio", "slenderness", "on_dW1", "on_dW1_bound", "on_all_three",
                  "on_all_three_bound", "wall_time_s"] + [enough_column(t) for t in ENOUGH_MORE_TOLERANCES]


def error_map_rows(path: Path | None = None) -> list[dict]:
    """The committed error map (data/error_map/error_map.csv, validation/error_map/), [] if absent."""
    path = Path(path) if path is not None else ROOT / "data" / "error_map" / "error_map.csv"
    return read_table(path) if path.exists() else []


def _paper_scene(row: dict) -> tuple[float, float] | None:
    """(dL/L, W/L) of a map row on one of the paper's ten scenes at the paper's strip, else None."""
    from ddg.geometry.strip import Strip

    for compression in COMPRESSIONS:
        for width in WIDTHS_GOLD:
            if abs(float(row["compression_ratio"]) - compression) < 1e-9 and \
                    abs(float(row["width_ratio"]) - width) < 1e-6 * width:
                lb = Strip.from_ratios(width, compression).slenderness
                if abs(float(row["slenderness"]) - lb) < 1e-6 * lb:
                    return compression, width
    return None


def wide_ribbon_table(rows: list[dict]) -> list[dict]:
    """Per paper scene: dW1/L, dW2/L and the errors against the FEM study (error map rows) of the
    rod, the ribbons (WIDE_MODELS) and the plate on its study's finest mesh."""
    out = []
    scenes = sorted({s for s in (_paper_scene(r) for r in rows) if s is not None}, key=lambda s: (-s[0], s[1]))
    for compression, width in scenes:
        mine = [r for r in rows if _paper_scene(r) == (compression, width)]
        picks = [r for model, label in WIDE_MODELS for r in mine
                 if r["model"] == model and r["resolution_label"] == label]
        plates = [r for r in mine if r["model"] == "plate"]
        if plates:
            picks.append(max(plates, key=lambda r: int(float(r["resolution"]))))
        for r in picks:
            out.append({"compression_ratio": compression, "width_ratio": width, "model": r["model"],
                        "resolution": r["resolution_label"], "dW1_over_L": finite_float(r["dW1"]),
                        "dW2_over_L": finite_float(r["dW2"]), "ref_dW1": finite_float(r["ref_dW1"]),
                        "ref_dW2": finite_float(r["ref_dW2"]),
                        "dW1_error": finite_float(r["dW1_error"]), "dW2_error": finite_float(r["dW2_error"]),
                        "H_mid_error": finite_float(r["H_mid_error"]), "wall_time_s": finite_float(r["wall_time_s"]),
                        "reason": r.get("reason", "")})
    return out


def _cheapest_label(row: dict | None) -> str:
    return "none" if row is None else f"{row['model']} {row['resolution_label']} ({float(row['wall_time_s']):.3g} s)"


def enough_table(rows: list[dict], tolerance: float = ENOUGH_TOLERANCE) -> list[dict]:
    """Per map scene: the cheapest model ddg runs (the FEM left out) whose error plus the
    reference's error bar is within `tolerance` on dW1 alone and on dW1, dW2 and H_mid together
    (validation.error_map.cheapest_within), with its bound and wall time; "none" where none is; and
    the cheapest on all three at each of ENOUGH_MORE_TOLERANCES (columns enough_column(tolerance):
    on_all_three_0_02, ...)."""
    out = []
    keys = sorted({(float(r["compression_ratio"]), float(r["width_ratio"]), float(r["slenderness"])) for r in rows},
                  key=lambda k: (-k[0], k[1], k[2]))
    for compression, width, slenderness in keys:
        mine = [r for r in rows if (float(r["compression_ratio"]), float(r["width_ratio"]),
                                    float(r["slenderness"])) == (compression, width, slenderness)]
        dw1 = cheapest_within(mine, tolerance, ("dW1",), runnable_only=True)
        all3 = cheapest_within(mine, tolerance, runnable_only=True)
        out.append({"compression_ratio": compression, "width_ratio": width, "slenderness": round(slenderness),
                    "on_dW1": f"{dw1['model']} {dw1['resolution_label']}" if dw1 else "none",
                    "on_dW1_bound": finite_float(dw1["dW1_bound"]) if dw1 else None,
                    "on_all_three": f"{all3['model']} {all3['resolution_label']}" if all3 else "none",
                    "on_all_three_bound": combined_error(all3) if all3 else None,
                    "wall_time_s": finite_float(all3["wall_time_s"]) if all3 else None}
                   | {enough_column(t): _cheapest_label(cheapest_within(mine, t, runnable_only=True))
                      for t in ENOUGH_MORE_TOLERANCES})
    return out


def wide_ribbon_figure(table: list[dict]) -> FigureData:
    """dW1/L and dW2/L against W/L of the rod, the ribbons and the plate, with the FEM study's
    extrapolated values (the error map's reference)."""
    rows = [[r["model"], r["compression_ratio"], r["width_ratio"], r["dW1_over_L"], r["dW2_over_L"]] for r in table]
    seen = set()
    for r in table:
        if (r["compression_ratio"], r["width_ratio"]) not in seen:
            seen.add((r["compression_ratio"], r["width_ratio"]))
            rows.append(["fem (extrapolated)", r["compression_ratio"], r["width_ratio"], r["ref_dW1"], r["ref_dW2"]])
    return FigureData(
        "ribbons_vs_width", "wide_ribbons",
        "1D models with width: dW1/L (circles) and dW2/L (squares) against W/L of the rod (M = 100), the ribbons "
        "(M = 101) and the plate (finest mesh of its study) beside the FEM study's extrapolated values; a missing "
        "marker is a threshold the model does not reach (reason in the table).",
        ["model", "compression_ratio", "width_ratio", "dW1_over_L", "dW2_over_L"], rows,
        {"compressions": list(COMPRESSIONS)})

