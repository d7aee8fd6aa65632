"""Figures' data of the path: the compressed midpoint height against the exact elastica, H_mid/L and
the clamp force against dW/L per scene, convergence with resolution, the Poisson ratio's effect
(paper Figs. 5b, 6, 7, C.16, E.18, G.20)."""
from __future__ import annotations

import numpy as np

from ddg.analysis.analytic import clamped_elastica_midpoint_height

from .. import claims as C
from ..estimates import load_study
from ..reference import paper_value
from ..studies import COMPRESSIONS
from ..table import FigureData, fraction
from .runs import MODELS, compression_values, find_run, shear_values


def elastica_figure(results, profile, golds) -> FigureData:
    """Midpoint height under compression, models and FEM against the exact clamped elastica."""
    rows = []
    for model, width in (("rod", 1 / 20), ("plate", 1 / 6), ("plate", 1 / 20), ("ribbon", 1 / 20)):
        run = find_run(results, model, 0.5, width, profile.models.get(model))
        if run is None:
            continue
        dl, h = compression_values(run, "dL_over_L"), compression_values(run, "H_mid_over_L")
        rows += [[model, width, a, b, clamped_elastica_midpoint_height(a) if a > 0 else 0.0] for a, b in zip(dl, h)]
    gold = golds.get((0.5, 1 / 6))
    if gold is not None:
        dl, h = gold.column("dL_over_L", "compression"), gold.column("H_mid_over_L", "compression")
        rows += [["fem", 1 / 6, a, b, clamped_elastica_midpoint_height(a) if a > 0 else 0.0] for a, b in zip(dl, h)]
    exact = [(x, clamped_elastica_midpoint_height(x)) for x in np.linspace(1e-3, 0.6, 200)]
    return FigureData("elastica", "elastica",
                      "Midpoint height under compression (paper Fig. 5b): models against the exact clamped elastica.",
                      ["model", "width_ratio", "dL_over_L", "H_mid_over_L", "exact_H_mid_over_L"], rows,
                      {"exact": exact})


def shear_column(results, profile, golds, compression, width, column) -> tuple[list[list], list[dict]]:
    """`column` against dW/L on the shear stage for every model run of the scene and the FEM gold:
    the rows [model, dL/L, W/L, dW/L, value] and each model run's dW1/L and dW2/L (for its lines)."""
    rows, thresholds = [], []
    curves = [(model, find_run(results, model, compression, width, profile.models.get(model)))
              for model in MODELS] + [("fem", golds.get((compression, width)))]
    for model, run in curves:
        if run is None:
            continue
        dw, y = shear_values(run, "dW_over_L"), shear_values(run, column)
        thresholds.append({"model": model, "compression_ratio": compression, "width_ratio": width,
                           **{k: (getattr(run, "summary", None) or {}).get(k)
                              for k in ("dW1_over_L", "dW2_over_L", "resolved_up_to_dW_over_L")}})
        rows += [[model, compression, width, a, b] for a, b in zip(dw, y)]
    return rows, thresholds


def shear_curve_figures(results, profile, golds) -> list[FigureData]:
    """H_mid/L against dW/L, one figure per compression, one panel per width (paper Figs. 6, 7)."""
    figures = []
    for compression in COMPRESSIONS:
        scenes = [w for c, w in profile.shear_curves if c == compression]
        if not scenes:
            continue
        rows, thresholds, paper = [], [], []
        for width in scenes:
            r, t = shear_column(results, profile, golds, compression, width, "H_mid_over_L")
            rows += r
            thresholds += t
            paper += [{"width_ratio": width, "key": key, "value": paper_value(compression, width, key)}
                      for key in ("dW1", "dW2") if paper_value(compression, width, key) is not None]
        figures.append(FigureData(
            f"hmid_vs_dW_dL{compression:g}", "shear_curves",
            f"H_mid/L against dW/L at dL/L = {fraction(compression)} (paper Figs. 6, 7); dotted: dW1, dashed: "
            "dW2 of each model (from stability; the FEM's in black); red triangles: the paper's quoted thresholds; "
            "a model's curve past the last state its mesh resolves (turns above 30 degrees) is drawn faint.",
            ["model", "compression_ratio", "width_ratio", "dW_over_L", "H_mid_over_L"], rows,
            {"panels": [(compression, w) for w in scenes], "thresholds": thresholds, "paper": paper}))
    return figures


#: The scenes of the force figure (paper Fig. E.18: dL/L = 1/2, W/L = 1/20, 1/12, 1/6, 1/2)
FORCE_SCENES = tuple((0.5, w) for w in (1 / 20, 1 / 12, 1 / 6, 1 / 2))


def shear_force_figure(results, profile, golds, load=None) -> FigureData | None:
    """Lateral clamp force against dW/L on the paper's Fig. E.18 scenes the profile runs, with
    the converged force of the FEM and plate mesh studies where they exist (rows of model "fem
    (converged)", "plate (converged)" with their error_bar; `load(model, dL/L, W/L)`, default
    validation.estimates.load_study)."""
    load = load or load_study
    scenes = [s for s in FORCE_SCENES if s in profile.shear_curves]
    if not scenes:
        return None
    rows, thresholds = [], []
    for compression, width in scenes:
        r, t = shear_column(results, profile, golds, compression, width, "F_shear_norm")
        rows += [row + [None] for row in r]
        thresholds += t
        for model in ("fem", "plate"):
            study = load(model, compression, width)
            if study is not None and study.force is not None:
                f = study.force
                rows += [[f"{model} (converged)", compression, width, float(x), float(v), float(e)]
                         for x, v, e in zip(f.dw, f.value, f.error_bar)]
    return FigureData(
        "shear_force", "shear_force",
        "Lateral clamp force against dW/L (paper Fig. E.18), on a symlog axis (linear for |F| L/(E b^3) < 1, "
        "logarithmic beyond: the force grows without bound as dW approaches dW_max); dotted: dW1, dashed: dW2 of "
        "each model (from stability); shaded: the converged force of the FEM and plate mesh studies with its error "
        "bar, up to where all their meshes reached (claims plate_vs_fem_force, plate_vs_fem_own_material_force). "
        "tests/ddg/models/test_shear_force.py checks the force against the derivative of the energy along the path.",
        ["model", "compression_ratio", "width_ratio", "dW_over_L", "F_shear_norm", "error_bar"], rows,
        {"panels": scenes, "thresholds": thresholds})


def convergence_data(results, study_specs) -> list[dict]:
    """Per model and resolution: the compressed height's error, the H_mid curve against the finest run."""
    data = []
    by_model: dict[str, list] = {}
    for spec in study_specs:
        if spec in results:
            by_model.setdefault(spec.model, []).append((spec, results[spec]))
    for model, runs in by_model.items():
        runs.sort(key=lambda t: t[0].resolution)
        finest = runs[-1][1]
        for spec, run in runs:
            data.append({
                "model": model, "resolution": spec.resolution, "width_ratio": spec.width_ratio,
                "elastica_rel_error": C.elastica_error(run),
                "curve_error_vs_finest": (C.curve_difference_away_from_thresholds(run, finest)
                                          if run is not finest else None),
                "dW1_over_L": run.summary.get("dW1_over_L"), "dW2_over_L": run.summary.get("dW2_over_L"),
                "wall_time_s": run.summary.get("wall_time_s"),
            })
    return data


def poisson_data(results, study_specs) -> tuple[FigureData, dict[float, dict]]:
    """The rod's H_mid curve per Poisson ratio, and each curve's and dW1's difference from nu = 0."""
    rows, curves = [], {}
    for spec in study_specs:
        run = results.get(spec)
        if run is None:
            continue
        dw, h = shear_values(run, "dW_over_L"), shear_values(run, "H_mid_over_L")
        curves[spec.poisson_ratio] = run
        rows += [[spec.poisson_ratio, a, b] for a, b in zip(dw, h)]
    spread = {}
    if 0.0 in curves:
        for nu, run in curves.items():
            if nu != 0.0:
                spread[nu] = {"max_H_difference_over_L": C.curve_difference_away_from_thresholds(run, curves[0.0]),
                              "dW1_difference": C.threshold_difference(run, curves[0.0])}
    figure = FigureData("poisson", "poisson",
                        "Rod, W/L = 1/20, dL/L = 1/2: the Poisson ratio enters only GJ (paper Fig. G.20).",
                        ["poisson_ratio", "dW_over_L", "H_mid_over_L"], rows)
    return figure, spread

