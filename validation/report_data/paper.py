"""The figures after the paper's Figs. 9a, 9b, 10, A.11 and A.12-14 from their committed data
(data/paper_figures): the centreline approximation (Eqs. 12-13), the Sadowsky ribbon's paths and the
curvature profiles."""
from __future__ import annotations

from pathlib import Path

from ..table import FigureData, records_figure


def fig9a_figure(folder: Path) -> FigureData | None:
    """Fig. 9a from its files under `folder` (the paper figures' data folder, with fig9a/ written by
    validation/paper_figures.py: write_shapes): the rows are the plate's
    deformed nodes and the centreline stations with their m2; the meshes' triangles are marks.
    None without any finished width."""
    from ddg.output.io import read_numeric_rows

    from ..paper_figures import FIG9_WIDTHS, shape_files

    columns = ["kind", "W_over_L", "dW_over_L", "index", "x_over_L", "y_over_L", "z_over_L", "m2_x", "m2_y", "m2_z"]
    rows, triangles = [], {}
    for width in FIG9_WIDTHS:
        files = shape_files(folder, width)
        if not files["centerline"].exists():
            continue
        w = round(width, 6)
        triangles[w] = [[int(r["i"]), int(r["j"]), int(r["k"])] for r in read_numeric_rows(files["triangles"])]
        rows += [["plate node", w, r["dW_over_L"], int(r["node"]), r["x_over_L"], r["y_over_L"], r["z_over_L"],
                  None, None, None] for r in read_numeric_rows(files["nodes"])]
        rows += [["centreline", w, r["dW_over_L"], k, r["x_over_L"], r["y_over_L"], r["z_over_L"], r["m2_x"],
                  r["m2_y"], r["m2_z"]] for k, r in enumerate(read_numeric_rows(files["centerline"]))]
    if not rows:
        return None
    return FigureData(
        "deformed_plates", "deformed_plates",
        "Deformed plates and their centreline rendering (paper Fig. 9a): the plate on 2000 triangles (blue mesh) "
        "and the centreline with, at 12 stations, the line x + w m2 across the width that Eq. (12) builds from it "
        "(red), at dL/L = 1/2; rows W/L, columns dW/L; equal axes. Fig. 9b gives the distance between the two "
        "(`python -m validation.paper_figures`, data/paper_figures/fig9a).", columns, rows, {"triangles": triangles})


def paper_figures(folder: Path | None = None) -> list[FigureData]:
    """The figures after the paper's Figs. 9a, 9b and 10 (the centreline approximation, Eqs. 12-13),
    A.11 and A.12-14 (curvature profiles) from their committed data (data/paper_figures/generate.sh),
    in that order; the ones whose data are missing are left out."""
    from ddg.output.io import read_numeric_rows

    from ..reference import ROOT

    folder = Path(folder) if folder is not None else ROOT / "data" / "paper_figures"
    out = []
    shapes = fig9a_figure(folder)
    if shapes is not None:
        out.append(shapes)
    fields = []
    for path in sorted((folder / "fig9").glob("W*.csv")) if (folder / "fig9").is_dir() else []:
        fields += read_numeric_rows(path)
    if fields:
        out.append(records_figure(
            "centerline_error_field", "centerline_error_field",
            "The centreline approximation over the plate (paper Fig. 9b): delta(s, w) of Eq. (13), the distance from "
            "each deformed plate node to where the centreline and its material frame put it (Eq. 12), in % of L, "
            "on the flat strip (s, w); rows W/L, columns dW/L; plate on 2000 triangles, dL/L = 1/2 "
            "(`python -m validation.paper_figures`, data/paper_figures/fig9).", fields))
    errors = folder / "centerline_error" / "centerline_error.csv"
    if errors.exists():
        rows = [{k: r[k] for k in ("L_over_W", "W_over_L", "dW_over_L", "mean_error", "max_error", "phase")}
                for r in read_numeric_rows(errors)]
        out.append(records_figure(
            "centerline_error", "centerline_error",
            "The plate's centreline against the best centreline of a rod (paper Fig. 10, Eq. 13): mean and largest "
            "deviation delta in % of L against L/W on a log axis (L/W = 20 at the right), one line per dW/L; "
            "plate on 2000 triangles, dL/L = 1/2 (`python -m ddg centerline-error`, data/paper_figures).", rows))
    profiles = []
    for model in ("rod", "ribbon", "plate"):
        path = folder / f"curvatures_{model}" / "curvatures.csv"
        if path.exists():
            profiles += read_numeric_rows(path)
    a11 = []
    for folder_w in sorted((folder / "a11").glob("W*")) if (folder / "a11").is_dir() else []:
        width = float(folder_w.name[1:])
        if abs(1 / width - round(1 / width)) < 0.01:   # W0.1667 is 1/6 written to 4 digits
            width = 1 / round(1 / width)
        for run in sorted(p for p in folder_w.iterdir() if (p / "path.csv").exists()):
            a11 += [{"model": run.name, "width_ratio": width, "dW_over_L": r["dW_over_L"],
                     "H_mid_over_L": r["H_mid_over_L"]}
                    for r in read_numeric_rows(run / "path.csv") if r["stage"] == "shear"]
    if a11:
        out.append(records_figure(
            "sadowsky_a11", "sadowsky_a11",
            "H_mid/L against dW/L at dL/L = 1/2 (paper Fig. A.11): the rod (M = 100), the plate (2000 triangles), "
            "the Sadowsky ribbon from the flat strip (ribbon_direct) and relaxed from each rod equilibrium "
            "(ribbon_rod, the paper's DAR-Sadowsky), one panel per W/L (data/paper_figures/a11).", a11))
    if profiles:
        out.append(records_figure(
            "curvature_profiles", "curvature_profiles",
            "Curvature profiles along the strip (paper Figs. A.12-14): geodesic k1, normal k2 and twist tau (times "
            "L) of the rod, the Sadowsky ribbon and the plate's centreline at W/L = 1/20, dL/L = 1/2, one column per "
            "dW/L (`python -m ddg curvatures`, data/paper_figures).", profiles))
    return out

