"""The validation report's data: one ReportData object computed from the runs, no rendering.

Every number the report states comes from here: the tables (claims, thresholds, speed-accuracy,
convergence, stability map) as rows, each figure as the rows of its CSV with the few marks it draws
besides (validation/figures.py draws a figure from these alone), the claims as rows
(validation/claims.py), the verdicts of the report's sentences (validation/verdicts.py), the
timings and the provenance. validation/report.py renders it (templates, CSV, summary.json).
"""
from __future__ import annotations

import base64
import dataclasses
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ddg.analysis.analytic import clamped_elastica_midpoint_height
from ddg.geometry.strip import shear_limit
from ddg.output.io import finite_float, read_json_object

from . import claims as C
from .estimates import Study, load_study, single_run_study, study_from_runs
from .reference import (FEM_FINE, FEM_GOLD, PAPER_DROPS_QUARTER, ROOT, GoldCurve, gold_name, load_dep_material,
                        load_gold, paper_value)
from .studies import COMPRESSIONS, SNAPSHOT_SCENES, SPEED_SCENE, WIDE_RIBBONS, WIDTHS_GOLD, Profile
from .verdicts import (PAPER_DISAGREEMENT, ClaimsVerdict, MaterialCheck, MeshTrend, PaperReading, paper_disagreements,
                       unusual_outcomes)

MODELS = ("rod", "plate", "ribbon") + WIDE_RIBBONS
CLAIM_COLUMNS = ["claim", "statement", "bound", "measured", "holds", "outcome", "reason", "difference",
                 "combined_error_bar", "in_error_bars", "needs"]
THRESHOLD_COLUMNS = ["model", "compression_ratio", "width_ratio", "dW1_over_L", "paper_dW1", "dW1_rel_diff_vs_paper",
                     "dW2_over_L", "paper_dW2", "dW2_rel_diff_vs_paper", "dW2_S_stable_over_L",
                     "dW1_drop_vs_W_1_20_percent", "paper_drop_percent", "dW_max_over_L", "resolved_up_to_dW_over_L"]


def fraction(x: float) -> str:
    """1/d for the ratios the paper uses (0.05 -> "1/20"), else 4 significant digits."""
    for d in (2, 2.5, 3, 4, 5, 6, 8, 10, 12, 16, 20):
        if abs(x - 1 / d) < 1e-6:
            return f"1/{d:g}"
    return f"{x:.4g}"


# ---------------------------------------------------------------------------- the data object
@dataclass
class Table:
    """Rows of one table (dicts keyed by column). `csv`: written as DIR/<name>.csv (the others'
    numbers are in their figure's CSV); `shown`: the columns the report prints (default all)."""
    name: str
    columns: list[str]
    rows: list[dict]
    csv: bool = False
    shown: list[str] | None = None

    @property
    def shown_columns(self) -> list[str]:
        return self.columns if self.shown is None else self.shown


@dataclass
class FigureData:
    """One figure: `rows` (in `columns` order) are its CSV and every number it plots from data;
    `marks` the reference lines and layout it draws besides (analytic curves, paper values,
    threshold lines, panels); `kind` names its drawing function in validation/figures.py.
    `png` is set once drawn (the HTML embeds it)."""
    name: str
    kind: str
    caption: str
    columns: list[str]
    rows: list[list]
    marks: dict = field(default_factory=dict)
    png: bytes | None = None

    @property
    def files(self) -> dict[str, str]:
        return {ext: f"figures/{self.name}.{ext}" for ext in ("png", "pdf", "csv")}

    @property
    def png_base64(self) -> str:
        return base64.b64encode(self.png or b"").decode()

    @property
    def png_size(self) -> tuple[int, int] | None:
        """(width, height) in pixels of the drawn PNG (its IHDR chunk), None before it is drawn: the
        HTML gives its image this size so the page is laid out before the image loads."""
        if not self.png or self.png[:8] != b"\x89PNG\r\n\x1a\n" or len(self.png) < 24:
            return None
        return int.from_bytes(self.png[16:20], "big"), int.from_bytes(self.png[20:24], "big")

    def records(self) -> list[dict]:
        return [dict(zip(self.columns, row)) for row in self.rows]


@dataclass
class Snapshots:
    """The 3D snapshots: how many shapes, or why there are none ("no meshio", "no plate runs")."""
    shapes: int = 0
    skipped: str | None = None


@dataclass
class Provenance:
    profile: str
    runs: int                   # runs with a result
    distinct_specs: int         # distinct runs the studies request
    specs: int                  # runs the studies request, a run shared by studies counted for each
    fem_gold_scenes: list[tuple[float, float]]
    missing_fem_gold: list[tuple[float, float]]

    @property
    def fem_gold_names(self) -> list[str]:
        return sorted(f"dL{c:g}_W{w:.4g}" for c, w in self.fem_gold_scenes)

    @property
    def missing_fem_gold_names(self) -> list[str]:
        return sorted(f"dL/L={fraction(c)} W/L={fraction(w)}" for c, w in self.missing_fem_gold)


@dataclass
class Timings:
    model_wall_time_s: float            # sum of the runs' own wall times (cached runs: when they ran)
    report_wall_time_s: float | None = None  # this report, runs to figures; set by build_report


@dataclass
class ReportData:
    """Everything the report states; the templates only lay it out."""
    provenance: Provenance
    claims: list[dict]                  # rows of validation.claims.evaluate
    tables: dict[str, Table]            # claims, thresholds, speed_accuracy, convergence, stability_map, benchmark
    speed_reference: str
    poisson: dict[float, dict]          # nu -> its curve's and dW1's difference from nu = 0
    material: MaterialCheck | None
    snapshots: Snapshots
    figures: list[FigureData]
    timings: Timings

    @property
    def claims_verdict(self) -> ClaimsVerdict:
        return ClaimsVerdict(self.claims)

    @property
    def paper_reading(self) -> PaperReading:
        return PaperReading.of(self.tables["thresholds"].rows)

    @property
    def paper_disagreement_limit(self) -> float:
        return PAPER_DISAGREEMENT

    @property
    def paper_disagreements(self) -> list[dict]:
        return paper_disagreements(self.tables["thresholds"].rows, self.paper_disagreement_limit)

    @property
    def unusual_outcomes(self) -> list[dict]:
        return unusual_outcomes(self.tables["stability_map"].rows)

    @property
    def disagreement_entries(self) -> int:
        """How many entries the list of disagreements has: the paper's, the unusual outcomes, the
        material check and its mesh trend (the templates fold a long list)."""
        material = 0 if self.material is None else 1 + (self.material.mesh_trend is not None)
        return len(self.paper_disagreements) + len(self.unusual_outcomes) + material

    @property
    def summary_figure(self) -> FigureData | None:
        """The figure the summary shows (SUMMARY_FIGURE), None where this report has none."""
        return next((f for f in self.figures if f.name == SUMMARY_FIGURE), None)

    @property
    def benchmark_summary(self) -> Table | None:
        """The benchmark in brief for the summary, None where this report has no benchmark."""
        return benchmark_summary(self.tables["benchmark"]) if "benchmark" in self.tables else None


#: The figure the report's summary shows beside the benchmark: the thresholds against W/L (paper Fig. 8).
SUMMARY_FIGURE = "thresholds_vs_width"
#: The benchmark's columns in the summary: (heading, column of the value; its bar is <column>_error_bar).
BENCHMARK_SUMMARY = (("FEM dW1/L", "fem_dW1"), ("FEM dW2/L", "fem_dW2"), ("plate dW1/L", "plate_dW1"),
                     ("plate dW2/L", "plate_dW2"))


def benchmark_summary(table: Table) -> Table:
    """The benchmark table (benchmark_table) in brief: per scene the FEM shell's and the plate's
    converged dW1/L and dW2/L, each with its error bar (validation.benchmark.with_bar)."""
    from .benchmark import with_bar

    rows = [{"dL/L": fraction(r["compression_ratio"]), "W/L": fraction(r["width_ratio"])}
            | {heading: with_bar(finite_float(r.get(key)), finite_float(r.get(f"{key}_error_bar")))
               for heading, key in BENCHMARK_SUMMARY} for r in table.rows]
    return Table("benchmark_summary", ["dL/L", "W/L"] + [heading for heading, _ in BENCHMARK_SUMMARY], rows)


# ---------------------------------------------------------------------------- reading runs
def _shear(run, key):
    return np.array([float(r[key]) for r in run.rows if r["stage"] == "shear"])


def _comp(run, key):
    return np.array([float(r[key]) for r in run.rows if r["stage"] == "compression"])


def find_run(results, model, compression, width, resolution=None, poisson=0.0):
    """The run of `results` ({RunSpec: run}) on a scene, or None."""
    for spec, run in results.items():
        if (spec.model == model and abs(spec.compression_ratio - compression) < 1e-9
                and abs(spec.width_ratio - width) < 1e-9 and spec.poisson_ratio == poisson
                and (resolution is None or spec.resolution == resolution)):
            return run
    return None


def load_golds(scenes, gold_root: Path | None = None) -> dict:
    """(dL/L, W/L) -> FEM gold curve, for the scenes that have one."""
    golds = {}
    for c, w in scenes:
        gold = load_gold(c, w) if gold_root is None else load_gold(c, w, gold_root)
        if gold is not None:
            golds[(c, w)] = gold
    return golds


# ---------------------------------------------------------------------------- figures' data
def elastica_figure(results, profile, golds) -> FigureData:
    """Midpoint height under compression, models and FEM against the exact clamped elastica."""
    rows = []
    for model, width in (("rod", 1 / 20), ("plate", 1 / 6), ("plate", 1 / 20), ("ribbon", 1 / 20)):
        run = find_run(results, model, 0.5, width, profile.models.get(model))
        if run is None:
            continue
        dl, h = _comp(run, "dL_over_L"), _comp(run, "H_mid_over_L")
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
        dw, y = _shear(run, "dW_over_L"), _shear(run, column)
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
        "tests/test_shear_force.py checks the force against the derivative of the energy along the path.",
        ["model", "compression_ratio", "width_ratio", "dW_over_L", "F_shear_norm", "error_bar"], rows,
        {"panels": scenes, "thresholds": thresholds})


FORCE_COLUMNS = ["reference", "compression_ratio", "width_ratio", "range", "points", "F_scale", "difference",
                 "combined_error_bar", "excess", "worst_at_dW_over_L"]


def force_table(dep6=None, load=None) -> list[dict]:
    """The plate study's clamp force against the FEM's on the scenes of claim plate_vs_fem_force
    (and against the shell with the plate's material, `dep6`, at W/L = 1/6), split by range: the
    whole compared path (0.02 from the thresholds, as the claim) and the U branch (up to 0.02 below
    the smaller dW1); figures relative to the FEM's largest |F| on the compared points. A scene
    without both studies is left out."""
    load = load or load_study
    pairs = [("FEM study", c, w, load("plate", c, w), load("fem", c, w))
             for c, w in [SPEED_SCENE, *C.NARROW_SCENES]]
    if dep6 is not None:
        pairs.append(("FEM, plate's material (90 el.)", *SPEED_SCENE, load("plate", *SPEED_SCENE), dep6))
    out = []
    for reference, c, w, plate, fem in pairs:
        if plate is None or fem is None or plate.force is None or fem.force is None:
            continue
        dw1 = min(x.value for x in (plate.dW1, fem.dW1) if x is not None) if plate.dW1 or fem.dW1 else None
        ranges = [("path, 0.02 from the thresholds", C.curve_agreement(plate, fem, quantity="force"))]
        if dw1 is not None:
            ranges.append(("U branch", C.curve_agreement(plate, fem, band=0.0, upto=dw1 - C.THRESHOLD_BAND,
                                                         quantity="force")))
        for name, a in ranges:
            if a is not None:
                out.append({"reference": reference, "compression_ratio": c, "width_ratio": w, "range": name,
                            "points": a.points, "F_scale": a.scale, "difference": a.difference,
                            "combined_error_bar": a.combined_error_bar, "excess": a.excess,
                            "worst_at_dW_over_L": a.at})
    return out


def threshold_table(results, profile, golds) -> list[dict]:
    """dW1, dW2, dW2_S_stable per model and scene, against the paper's quoted values and drops."""
    table = []
    widths = sorted({w for _, w in profile.shear_curves} | set(profile.phase_widths))
    for compression in COMPRESSIONS:
        for width in widths:
            entries = {}
            for model in MODELS:
                run = find_run(results, model, compression, width, profile.models.get(model))
                if run is not None:
                    entries[model] = run.summary
            gold = golds.get((compression, width))
            if gold is not None:
                entries["fem"] = gold.summary
            for model, s in entries.items():
                row = {"model": model, "compression_ratio": compression, "width_ratio": width,
                       "dW1_over_L": s.get("dW1_over_L"), "dW2_over_L": s.get("dW2_over_L"),
                       "dW2_S_stable_over_L": s.get("dW2_S_stable_over_L"),
                       "dW_max_over_L": shear_limit(1.0, width, compression),
                       "resolved_up_to_dW_over_L": s.get("resolved_up_to_dW_over_L")}
                for key in ("dW1", "dW2"):
                    paper = paper_value(compression, width, key)
                    row[f"paper_{key}"] = paper
                    ours = row[f"{key}_over_L"]
                    row[f"{key}_rel_diff_vs_paper"] = None if paper is None or ours is None else ours / paper - 1
                table.append(row)
    # percent drops of dW1 against W/L = 1/20, per model and compression
    for row in table:
        base = next((r for r in table if r["model"] == row["model"]
                     and r["compression_ratio"] == row["compression_ratio"] and abs(r["width_ratio"] - 1 / 20) < 1e-9),
                    None)
        row["dW1_drop_vs_W_1_20_percent"] = (
            None if base is None or base["dW1_over_L"] is None or row["dW1_over_L"] is None
            else 100 * (1 - row["dW1_over_L"] / base["dW1_over_L"]))
        paper_drop = PAPER_DROPS_QUARTER.get(min(PAPER_DROPS_QUARTER, key=lambda w: abs(w - row["width_ratio"])))
        close = any(abs(w - row["width_ratio"]) < 1e-9 for w in PAPER_DROPS_QUARTER)
        row["paper_drop_percent"] = paper_drop if close and row["compression_ratio"] == 0.25 else None
    return table


def thresholds_figure(table, benchmark: list[dict] | None = None) -> FigureData:
    """The threshold table against W/L per compression (paper Fig. 8 phase boundaries), with the
    converged FEM and plate thresholds and their error bars from the benchmark (data/benchmark)."""
    rows, dw_max, paper = [], {}, []
    for compression in COMPRESSIONS:
        dw_max[compression] = [(x, shear_limit(1.0, x, compression)) for x in np.linspace(1 / 20, 1 / 2, 100)]
        for model in MODELS + ("fem",):
            sel = sorted((r for r in table if r["model"] == model and r["compression_ratio"] == compression),
                         key=lambda r: r["width_ratio"])
            rows += [[model, compression, r["width_ratio"], r["dW1_over_L"], r["dW2_over_L"], r["dW_max_over_L"],
                      None, None] for r in sel]
        for prefix in ("fem", "plate"):
            for b in sorted((b for b in benchmark or () if abs(float(b["compression_ratio"]) - compression) < 1e-9),
                            key=lambda b: float(b["width_ratio"])):
                w = float(b["width_ratio"])
                rows.append([f"{prefix} (converged)", compression, w, b.get(f"{prefix}_dW1"), b.get(f"{prefix}_dW2"),
                             shear_limit(1.0, w, compression), b.get(f"{prefix}_dW1_error_bar"),
                             b.get(f"{prefix}_dW2_error_bar")])
        for width in sorted({r["width_ratio"] for r in table}):
            paper += [{"compression_ratio": compression, "width_ratio": width, "key": key,
                       "value": paper_value(compression, width, key)}
                      for key in ("dW1", "dW2") if paper_value(compression, width, key) is not None]
    return FigureData(
        "thresholds_vs_width", "thresholds",
        "Thresholds dW1/L (U to US) and dW2/L (US to S) against W/L (paper Fig. 8 phase boundaries), with the "
        "shear limit dW_max; the converged FEM and plate thresholds with their error bars (the benchmark, "
        "data/benchmark); shaded: U, US and S by the converged FEM thresholds.",
        ["model", "compression_ratio", "width_ratio", "dW1_over_L", "dW2_over_L", "dW_max_over_L",
         "dW1_error_bar", "dW2_error_bar"], rows,
        {"compressions": list(COMPRESSIONS), "dW_max": dw_max, "paper": paper})


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


def _records_figure(name: str, kind: str, caption: str, data: list[dict], marks: dict | None = None) -> FigureData:
    """A figure whose CSV is a table's rows."""
    return FigureData(name, kind, caption, list(data[0].keys()) if data else ["model"],
                      [list(d.values()) for d in data], marks or {})


def poisson_data(results, study_specs) -> tuple[FigureData, dict[float, dict]]:
    """The rod's H_mid curve per Poisson ratio, and each curve's and dW1's difference from nu = 0."""
    rows, curves = [], {}
    for spec in study_specs:
        run = results.get(spec)
        if run is None:
            continue
        dw, h = _shear(run, "dW_over_L"), _shear(run, "H_mid_over_L")
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


#: The speed-accuracy benchmark of the three plate models (benchmarks/speed_accuracy.py): its entries
#: join the chart, labelled "(benchmark)", with their idle-machine wall times.
SPEED_BENCHMARK = ROOT / "benchmarks" / "results" / "speed_accuracy.json"


def _speed_row(model, resolution, summary: dict, curve_error, dw1_error) -> dict:
    return {"model": model, "resolution": resolution, "wall_time_s": summary.get("wall_time_s"),
            "curve_error": curve_error, "dW1_error": dw1_error, "converged": summary.get("converged")}


def speed_accuracy(results, study_specs, golds, benchmark: Path = SPEED_BENCHMARK) -> tuple[list[dict], str]:
    """Wall time and error of each model and resolution on SPEED_SCENE; the FEM shell's stored meshes
    (its gold study and data/fem_fine) and the speed-accuracy benchmark's entries too. Returns
    (rows, reference).

    With the FEM's mesh study of the scene (issue 29: not a single run), the reference is its
    converged values: the dW1 error is the distance to the converged dW1, the curve error the
    largest distance to the converged H_mid/L curve 0.02 away from the converged thresholds
    (Study.curve_error, without its bar: the reference text states the bars). A benchmark entry's
    curve is that of the study run on its mesh (its dW1 reproduced within the bisection bracket).
    Without the study, the FEM gold's run is the reference (both thresholds' bands excluded); without
    FEM data, the finest run of the report."""
    gold = golds.get(SPEED_SCENE)
    runs = [(s, results[s]) for s in study_specs if s in results]
    converged = load_study("fem", *SPEED_SCENE) if gold is not None else None
    if converged is not None and (converged.dW1 is None or converged.curve is None):
        converged = None
    if converged is not None:
        reference = None
        bars = float(np.max(converged.curve.error_bar))
        ref_name = (f"the FEM's converged values ({converged.describe()}): dW1/L {converged.dW1.value:.4f} +- "
                    f"{converged.dW1.error_bar:.4f}; H_mid/L curve bars up to {bars:.1e}")
    elif gold is not None:
        reference = gold
        ref_name = f"the FEM gold ({gold.summary['scene']['resolution']} elements along L; no converged study)"
    else:
        if not runs:
            return [], "none"
        plates = [(s, r) for s, r in runs if s.model == "plate"] or runs
        spec, reference = max(plates, key=lambda t: t[0].resolution)
        ref_name = f"the finest {spec.model} run (resolution {spec.resolution}; no FEM gold data for this scene)"

    def errors(run, summary: dict) -> tuple:
        if converged is None:
            return C.curve_difference_away_from_thresholds(run, reference), C.threshold_difference(run, reference)
        value = summary.get("dW1_over_L")
        return (None if run is None else converged.curve_error(run, with_bar=False),
                None if value is None else abs(value - converged.dW1.value))

    data = [_speed_row(spec.model, spec.resolution, run.summary, *errors(run, run.summary))
            for spec, run in runs if run is not reference]
    if gold is not None:  # the shell itself on its stored meshes (its study's and data/fem_fine's)
        folders = [p.parent for p in sorted((FEM_GOLD / gold_name(*SPEED_SCENE)).glob("N*/summary.json"))]
        folders += [d for d in sorted(FEM_FINE.glob("dL0.5_W0.1667_N*")) if (d / "summary.json").exists()]
        for directory in folders:
            if reference is not None and directory.resolve() == Path(reference.directory).resolve():
                continue
            fem = GoldCurve(directory)
            mesh = fem.summary.get("mesh") or {}
            label = (f"{mesh['elements_along_L']}x{mesh['elements_across_W']}" if "elements_across_W" in mesh
                     else fem.summary["scene"]["resolution"])
            data.append(_speed_row("fem", label, fem.summary, *errors(fem, fem.summary)))
    stored = read_json_object(benchmark) if converged is not None and Path(benchmark).exists() else None
    for name in (stored or {}).get("entry_order", []):
        entry = stored["entries"].get(name) or {}
        if entry.get("status") != "ok":
            continue
        study_run = ROOT / entry["study_run"] if entry.get("study_run") else None
        run = GoldCurve(study_run) if study_run is not None and (study_run / "path.csv").exists() else None
        data.append(_speed_row(f"{entry['model']} (benchmark)", entry["mesh_label"], entry, *errors(run, entry)))
    return data, ref_name


def stability_map(results, golds, table) -> list[dict]:
    """How each run ended and where it fails: Newton failure, unresolved mesh, missed pitchfork, or
    the rod's width error (its dW1 against the plate's / FEM's at the same scene)."""
    out = []
    for spec, run in sorted(results.items(), key=lambda t: (t[0].model, t[0].compression_ratio, t[0].width_ratio,
                                                            t[0].resolution or 0, t[0].poisson_ratio)):
        s = run.summary
        reached = max((float(r["dW_over_L"]) for r in run.rows if r["stage"] == "shear"), default=0.0)
        dw_max = s.get("dW_max_over_L") or float("nan")
        outcome = "ok"
        if not s.get("converged"):
            outcome = "Newton failure"
        elif s.get("dW1_over_L") is None:  # located but past the mesh's resolution, or not bracketed at all
            outcome = ("dW1 unresolved by the mesh" if (s.get("unresolved_thresholds") or {}).get("dW1_over_L")
                       else "missed pitchfork")
        resolved = s.get("resolved_up_to_dW_over_L")
        if outcome == "ok" and resolved is not None and resolved < reached - 1e-9:
            outcome = "ok (mesh unresolved near dW_max)"
        width_error = None
        if spec.model == "rod" and s.get("dW1_over_L") is not None:
            ref = golds.get((spec.compression_ratio, spec.width_ratio))
            ref_dw1 = ref.summary.get("dW1_over_L") if ref is not None else None
            if ref_dw1 is None:
                plate = next((r for r in table if r["model"] == "plate"
                              and r["compression_ratio"] == spec.compression_ratio
                              and abs(r["width_ratio"] - spec.width_ratio) < 1e-9), None)
                ref_dw1 = plate["dW1_over_L"] if plate else None
            if ref_dw1 is not None:
                width_error = s["dW1_over_L"] - ref_dw1
                if abs(width_error) > 0.03:
                    outcome = "rod width error" if outcome == "ok" else outcome + ", rod width error"
        out.append({"model": spec.model, "compression_ratio": spec.compression_ratio, "width_ratio": spec.width_ratio,
                    "resolution": spec.resolution, "poisson_ratio": spec.poisson_ratio, "outcome": outcome,
                    "reached_dW_over_L": reached, "dW_max_over_L": dw_max,
                    "reached_percent_of_dW_max": 100 * reached / dw_max if dw_max else None,
                    "resolved_up_to_dW_over_L": resolved, "rod_dW1_minus_reference": width_error,
                    "message": s.get("message", "")})
    return out


# ---------------------------------------------------------------------------- 3D snapshots
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


# ---------------------------------------------------------------------------- claims
def material_check(results, golds) -> MaterialCheck | None:
    """Is the plate/FEM gap at SPEED_SCENE the plate's material (the DEP's nu = 1/3 membrane and
    nu_b = -1/3 bending, against the shell's nu = 0)? The material's effect (the FEM shell run with
    the DEP's material, data/fem_dep, against the nu = 0 shell on the same mesh, data/fem_fine) is
    set against the gap (the plate's converged values, data/plate_gold, against the FEM gold's,
    largest difference) and the plate against the shell with its own material; with the plate's
    dW1 on each mesh of its study."""
    iso_dir = FEM_FINE / "dL0.5_W0.1667_N90"
    plate, fem = load_study("plate", *SPEED_SCENE), load_study("fem", *SPEED_SCENE)
    dep = load_dep_material()
    if dep is None or plate is None or fem is None or not (iso_dir / "summary.json").exists():
        return None
    iso = GoldCurve(iso_dir)
    dep_study = dep_material_study(fem)

    def gap(a, b, key):
        agreement = C.threshold_agreement(a, b, key) if key != "curve" else C.curve_agreement(a, b)
        return None if agreement is None else agreement.difference

    plate_dw1_study = plate.dW1.value if plate.dW1 is not None else None
    numbers = {"fem_dep_vs_nu0_dW1": C.threshold_difference(dep, iso),
               "fem_dep_vs_nu0_curve": C.curve_difference_away_from_thresholds(dep, iso),
               "plate_vs_fem_gold_dW1": gap(plate, fem, "dW1"),
               "plate_vs_fem_gold_curve": gap(plate, fem, "curve"),
               "plate_vs_fem_dep_dW1": (abs(plate_dw1_study - dep.summary["dW1_over_L"])
                                        if plate_dw1_study is not None and dep.summary.get("dW1_over_L") else None),
               "plate_vs_fem_dep_curve": gap(plate, dep_study, "curve") if dep_study is not None else None,
               "fem_dep_resolution": dep.summary["scene"]["resolution"],
               "plate_triangles": plate.finest.size}
    if any(v is None or not math.isfinite(v) for v in numbers.values()):
        return None
    points = [(m.size, m.dW1) for m in plate.meshes if m.dW1 is not None]
    trend = MeshTrend(points, fem.dW1.value) if fem.dW1 is not None and points else None
    return MaterialCheck(**numbers, mesh_trend=trend)


def benchmark_table() -> Table:
    """The benchmark (validation.benchmark): converged thresholds of the ten scenes from the stored
    FEM and plate studies, with the rod's stored study (data/benchmark/rod_thresholds.json) where
    it exists."""
    from .benchmark import CROSS_SECTION_FILE, ROD_FILE, benchmark_rows

    stored = ROOT / "data" / "benchmark"
    rows = benchmark_rows(rod_thresholds=read_json_object(stored / ROD_FILE) or None,
                          cross_section_thresholds=read_json_object(stored / CROSS_SECTION_FILE) or None)
    columns = list(rows[0].keys()) if rows else []
    shown = [c for c in columns if not c.endswith(("_basis", "_meshes"))]
    return Table("benchmark", columns, rows, csv=True, shown=shown)


#: The 1D models of the "1D models with width" section and the resolution shown for each (the
#: ribbons' default M = 101, the rod's paper M = 100); the plate at its study's finest mesh.
WIDE_MODELS = (("rod", "M100"), ("ribbon", "M101"), ("ribbon-sano-wada", "M101"), ("ribbon-trapeze", "M101"),
               ("ribbon-cross-section", "M101"), ("ribbon-wunderlich", "M101"))
#: Tolerance (units of L) of the "cheapest model within" table: the issue's 1 %.
ENOUGH_TOLERANCE = 0.01
WIDE_COLUMNS = ["compression_ratio", "width_ratio", "model", "resolution", "dW1_over_L", "dW2_over_L",
                "ref_dW1", "ref_dW2", "dW1_error", "dW2_error", "H_mid_error", "wall_time_s", "reason"]
def enough_column(tolerance: float) -> str:
    """The enough table's column of the cheapest model within `tolerance` on all three quantities."""
    return f"on_all_three_{tolerance:g}".replace(".", "_")


#: The further tolerances of the "which model is enough" table (issue 32: the map per tolerance).
ENOUGH_MORE_TOLERANCES = (0.02, 0.05)
ENOUGH_COLUMNS = ["compression_ratio", "width_ratio", "slenderness", "on_dW1", "on_dW1_bound", "on_all_three",
                  "on_all_three_bound", "wall_time_s"] + [enough_column(t) for t in ENOUGH_MORE_TOLERANCES]


def error_map_rows(path: Path | None = None) -> list[dict]:
    """The committed error map (data/error_map/error_map.csv, validation/error_map.py), [] if absent."""
    from .error_map import read_table
    from .reference import ROOT

    path = Path(path) if path is not None else ROOT / "data" / "error_map" / "error_map.csv"
    return read_table(path) if path.exists() else []


def fig9a_figure(folder: Path) -> FigureData | None:
    """Fig. 9a from its files under `folder` (the paper figures' data folder, with fig9a/ written by
    validation/paper_figures.py: write_shapes): the rows are the plate's
    deformed nodes and the centreline stations with their m2; the meshes' triangles are marks.
    None without any finished width."""
    from ddg.output.io import read_numeric_rows

    from .paper_figures import FIG9_WIDTHS, shape_files

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

    from .reference import ROOT

    folder = Path(folder) if folder is not None else ROOT / "data" / "paper_figures"
    out = []
    shapes = fig9a_figure(folder)
    if shapes is not None:
        out.append(shapes)
    fields = []
    for path in sorted((folder / "fig9").glob("W*.csv")) if (folder / "fig9").is_dir() else []:
        fields += read_numeric_rows(path)
    if fields:
        out.append(_records_figure(
            "centerline_error_field", "centerline_error_field",
            "The centreline approximation over the plate (paper Fig. 9b): delta(s, w) of Eq. (13), the distance from "
            "each deformed plate node to where the centreline and its material frame put it (Eq. 12), in % of L, "
            "on the flat strip (s, w); rows W/L, columns dW/L; plate on 2000 triangles, dL/L = 1/2 "
            "(`python -m validation.paper_figures`, data/paper_figures/fig9).", fields))
    errors = folder / "centerline_error" / "centerline_error.csv"
    if errors.exists():
        rows = [{k: r[k] for k in ("L_over_W", "W_over_L", "dW_over_L", "mean_error", "max_error", "phase")}
                for r in read_numeric_rows(errors)]
        out.append(_records_figure(
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
        out.append(_records_figure(
            "sadowsky_a11", "sadowsky_a11",
            "H_mid/L against dW/L at dL/L = 1/2 (paper Fig. A.11): the rod (M = 100), the plate (2000 triangles), "
            "the Sadowsky ribbon from the flat strip (ribbon_direct) and relaxed from each rod equilibrium "
            "(ribbon_rod, the paper's DAR-Sadowsky), one panel per W/L (data/paper_figures/a11).", a11))
    if profiles:
        out.append(_records_figure(
            "curvature_profiles", "curvature_profiles",
            "Curvature profiles along the strip (paper Figs. A.12-14): geodesic k1, normal k2 and twist tau (times "
            "L) of the rod, the Sadowsky ribbon and the plate's centreline at W/L = 1/20, dL/L = 1/2, one column per "
            "dW/L (`python -m ddg curvatures`, data/paper_figures).", profiles))
    return out


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
    from .error_map import cheapest_within, combined_error

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


def _missing(**inputs) -> str:
    """What a claim lacks: the names of the inputs that are None, joined ('' if none is)."""
    return ", ".join(f"no {name}" for name, value in inputs.items() if value is None)


def rod_study(results, profile) -> Study | None:
    """The rod's study at W/L = 1/20, dL/L = 1/2 from the profile's convergence runs."""
    resolutions = [n for n in profile.convergence.get("rod", ()) if find_run(results, "rod", 0.5, 1 / 20, n)]
    return study_from_runs("rod", [find_run(results, "rod", 0.5, 1 / 20, n) for n in resolutions], resolutions)


def dep_material_study(fem) -> Study | None:
    """The FEM shell with the plate's material (data/fem_dep, one mesh) as a study whose error bars
    (H_mid and the clamp force) are the measured errors of the nu = 0 shell on the same mesh
    (data/fem_fine against the FEM gold study's converged curves), up to where the gold study's
    curves reach; None where any is missing."""
    dep, iso_dir = load_dep_material(), FEM_FINE / "dL0.5_W0.1667_N90"
    if dep is None or fem is None or fem.curve is None or not (iso_dir / "summary.json").exists():
        return None
    zero = lambda dw: np.zeros_like(dw)  # noqa: E731
    iso = single_run_study("fem", GoldCurve(iso_dir), zero, zero)

    def error_of(dw):
        return np.abs(np.interp(dw, iso.curve.dw, iso.curve.value) - np.interp(dw, fem.curve.dw, fem.curve.value))

    def force_error_of(dw):  # the same for the clamp force, where the gold study has its force curve
        return np.abs(np.interp(dw, iso.force.dw, iso.force.value) - np.interp(dw, fem.force.dw, fem.force.value))

    study = single_run_study("fem", dep, error_of, force_error_of if fem.force is not None else None)
    # the borrowed error bars are measured only where the gold study has its curves (up to the
    # smallest dW all its meshes reached): the study ends there
    return dataclasses.replace(study, curve=study.curve.upto(fem.curve.dw[-1]),
                               force=None if study.force is None else study.force.upto(fem.force.dw[-1]))


def evaluate_claims(results, profile, golds) -> list[dict]:
    """Every claim of validation/claims.py: the single-model claims on this report's runs, the
    cross-model claims on converged values (the stored FEM and plate studies, the rod study of this
    report's convergence runs). A claim whose runs or reference data are not there does not hold
    (reason "no data: ..." naming what is missing)."""
    get = lambda m, c, w: find_run(results, m, c, w, profile.models.get(m))  # noqa: E731
    res = lambda m: "" if profile.models.get(m) is None else f", resolution {profile.models[m]}"  # noqa: E731
    out = []
    rod = find_run(results, "rod", 0.5, 1 / 20, 100)  # the claims are stated for M = 100
    rod_quarter = find_run(results, "rod", 0.25, 1 / 20, 100)
    plate6 = get("plate", 0.5, 1 / 6)
    gold6 = golds.get((0.5, 1 / 6))
    ribbon = get("ribbon", 0.5, 1 / 20)
    rods = rod_study(results, profile)
    dep6 = dep_material_study(load_study("fem", *SPEED_SCENE))
    names = {
        "rod": "rod run (M = 100, W/L = 1/20, dL/L = 1/2)",
        "rod_quarter": "rod run (M = 100, W/L = 1/20, dL/L = 1/4)",
        "plate6": f"plate run (W/L = 1/6, dL/L = 1/2{res('plate')})",
        "ribbon": f"ribbon run (W/L = 1/20, dL/L = 1/2{res('ribbon')})",
        "gold6": "FEM gold data (data/fem_gold/dL0.5_W0.1667)",
    }

    def lacking(**inputs) -> str:
        return _missing(**{names[k]: v for k, v in inputs.items()})

    out.append(C.evaluate("rod_elastica", C.elastica_error(rod) if rod else None, lacking(rod=rod)))
    out.append(C.evaluate("plate_elastica", C.elastica_error(plate6) if plate6 else None, lacking(plate6=plate6)))
    out.append(C.evaluate("ribbon_elastica", C.elastica_error(ribbon) if ribbon else None, lacking(ribbon=ribbon)))
    out.append(C.evaluate("fem_elastica", C.elastica_error(gold6) if gold6 else None, lacking(gold6=gold6)))
    out += C.cross_model_verdicts(rods, dep6)
    rods_paper = [r for r in (rod, rod_quarter) if r is not None]
    errors = [C.paper_threshold_error(r) for r in rods_paper]
    out.append(C.evaluate("rod_thresholds_paper", max(errors) if len(errors) == 2 and None not in errors else None,
                          lacking(rod=rod, rod_quarter=rod_quarter) or "a threshold the paper quotes was not located"))
    dw1_sixth = plate6.summary.get("dW1_over_L") if plate6 else None
    out.append(C.evaluate("plate_dW1_paper_sixth", abs(dw1_sixth - 0.27) if dw1_sixth is not None else None,
                          lacking(plate6=plate6) or "dW1 not located in the plate run"))
    return out


# ---------------------------------------------------------------------------- the report's data
def collect(profile: Profile, study: dict, results: dict, gold_root: Path | None = None) -> ReportData:
    """The report's data from the runs of `study` (validation.studies.specs) and the FEM gold data
    (timings.report_wall_time_s is left for build_report, which knows when it started)."""
    scenes = {(c, w) for c, w in profile.shear_curves} | {SPEED_SCENE}
    golds = load_golds(sorted(scenes), gold_root)
    all_specs = [s for group in study.values() for s in group]

    figures = [elastica_figure(results, profile, golds), *shear_curve_figures(results, profile, golds)]
    thresholds = threshold_table(results, profile, golds)
    bench = benchmark_table()
    figures.append(thresholds_figure(thresholds, [{k: finite_float(v) if k.endswith(("dW1", "dW2", "_bar", "ratio"))
                                                   else v for k, v in r.items()} for r in bench.rows]))
    force = shear_force_figure(results, profile, golds)
    if force is not None:
        figures.append(force)
    conv = convergence_data(results, study["convergence"])
    figures.append(_records_figure(
        "convergence", "convergence",
        "Convergence with resolution (paper Fig. C.16): compressed height against the exact elastica, and the "
        "H_mid(dW) curve against the finest run (away from the thresholds).", conv))
    poisson_figure, poisson = poisson_data(results, study["poisson"])
    figures.append(poisson_figure)
    speed, ref_name = speed_accuracy(results, study["speed"], golds)
    figures.append(_records_figure(
        "speed_accuracy", "speed_accuracy",
        "Speed against accuracy: each model and resolution, wall time of the full path (thresholds included) "
        f"against its error relative to {ref_name}; dashed: the Pareto front. The wall times are as the report's "
        "runs measured them: with --jobs N, N runs share the cores (README: how the committed snapshot was made). "
        "Also shown: the shell's stored meshes (fem, points; their studies' wall times, measured beside other runs) "
        "and the runs of benchmarks/speed_accuracy.py ('(benchmark)', stars: both plates and the shell on the "
        "studies' meshes, one at a time on an idle machine).",
        speed, {"reference": ref_name}))
    smap = stability_map(results, golds, thresholds)
    figures.append(_records_figure("stability_map", "stability_map",
                                   "Where each model fails and how (marker size: share of dW_max reached).", smap))
    claims = evaluate_claims(results, profile, golds)
    forces = force_table(dep_material_study(load_study("fem", *SPEED_SCENE)))
    snapshot_figure, snapshots = snapshot_data(results, profile)
    if snapshot_figure is not None:
        figures.append(snapshot_figure)

    smap_columns = list(smap[0].keys()) if smap else []
    tables = {
        "claims": Table("claims", CLAIM_COLUMNS, claims, csv=True),
        "thresholds": Table("thresholds", THRESHOLD_COLUMNS, thresholds, csv=True),
        "speed_accuracy": Table("speed_accuracy", list(speed[0].keys()) if speed else [], speed),
        "convergence": Table("convergence", list(conv[0].keys()) if conv else [], conv),
        "stability_map": Table("stability_map", smap_columns, smap, csv=True,
                               shown=[c for c in smap_columns if c != "message"]),
        "benchmark": bench,
    }
    if forces:
        tables["force"] = Table("force", FORCE_COLUMNS, forces, csv=True)
    map_rows = error_map_rows()
    if map_rows:
        wide = wide_ribbon_table(map_rows)
        tables["wide_ribbons"] = Table("wide_ribbons", WIDE_COLUMNS, wide, csv=True)
        tables["enough"] = Table("enough", ENOUGH_COLUMNS, enough_table(map_rows), csv=True)
        figures.append(wide_ribbon_figure(wide))
    figures += paper_figures()
    provenance = Provenance(profile.name, len(results), len(set(all_specs)), len(all_specs),
                            sorted(golds), sorted(scene for scene in scenes if scene not in golds))
    timings = Timings(sum(float(r.summary.get("wall_time_s") or 0.0) for r in results.values()))
    return ReportData(provenance, claims, tables, ref_name, poisson, material_check(results, golds), snapshots,
                      figures, timings)
