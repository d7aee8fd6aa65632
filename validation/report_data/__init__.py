"""The validation report's data: one ReportData object computed from the runs, no rendering.

Every number the report states comes from here: the tables (claims, thresholds, speed-accuracy,
convergence, stability map, benchmark, and from the error map the ribbons with width and the
cheapest model within a tolerance) as rows (validation.table.Table), each figure as the rows of
its CSV with the few marks it draws besides (validation.table.FigureData; validation/figures draws
a figure from these alone), the claims as rows (validation/claims.py), the verdicts of the report's
sentences (validation/verdicts.py), the timings and the provenance. validation/report.py renders it
(templates, CSV, summary.json).

One module per part: the data object (data), the runs read back (runs), the path's figures
(curves), the thresholds and the stability map (thresholds), speed against accuracy (speed), the
3D snapshots (snapshots), the claims and the material check (claim_checks), the error map's
tables (map_tables), the paper's figures from their committed data (paper); `collect` gathers
them.
"""
from __future__ import annotations

from pathlib import Path

from ddg.output.io import finite_float

from ..estimates import load_study
from ..studies import SPEED_SCENE, Profile
from ..table import FigureData, Table, fraction, records_figure
from .claim_checks import (CLAIM_COLUMNS, FORCE_COLUMNS, dep_material_study, evaluate_claims, force_table,
                           material_check, rod_study)
from .curves import (FORCE_SCENES, convergence_data, elastica_figure, poisson_data, shear_column, shear_curve_figures,
                     shear_force_figure)
from .data import BENCHMARK_SUMMARY, SUMMARY_FIGURE, Provenance, ReportData, Snapshots, Timings, benchmark_summary
from .map_tables import (ENOUGH_COLUMNS, ENOUGH_MORE_TOLERANCES, ENOUGH_TOLERANCE, WIDE_COLUMNS, WIDE_MODELS,
                         enough_column, enough_table, error_map_rows, wide_ribbon_figure, wide_ribbon_table)
from .paper import fig9a_figure, paper_figures
from .runs import MODELS, compression_values, find_run, load_golds, shear_values
from .snapshots import snapshot_data, snapshot_states
from .speed import SPEED_BENCHMARK, speed_accuracy
from .thresholds import THRESHOLD_COLUMNS, benchmark_table, stability_map, threshold_table, thresholds_figure

__all__ = ["BENCHMARK_SUMMARY", "CLAIM_COLUMNS", "ENOUGH_COLUMNS", "ENOUGH_MORE_TOLERANCES", "ENOUGH_TOLERANCE",
           "FORCE_COLUMNS", "FORCE_SCENES", "FigureData", "MODELS", "Provenance", "ReportData", "SPEED_BENCHMARK",
           "SUMMARY_FIGURE", "Snapshots", "THRESHOLD_COLUMNS", "Table", "Timings", "WIDE_COLUMNS", "WIDE_MODELS",
           "benchmark_summary", "benchmark_table", "collect", "compression_values", "convergence_data",
           "dep_material_study", "elastica_figure", "enough_column", "enough_table", "error_map_rows",
           "evaluate_claims", "fig9a_figure", "find_run", "force_table", "fraction", "load_golds", "material_check",
           "paper_figures", "poisson_data", "records_figure", "rod_study", "shear_column", "shear_curve_figures",
           "shear_force_figure", "shear_values", "snapshot_data", "snapshot_states", "speed_accuracy",
           "stability_map", "threshold_table", "thresholds_figure", "wide_ribbon_figure", "wide_ribbon_table"]


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
    figures.append(records_figure(
        "convergence", "convergence",
        "Convergence with resolution (paper Fig. C.16): compressed height against the exact elastica, and the "
        "H_mid(dW) curve against the finest run (away from the thresholds).", conv))
    poisson_figure, poisson = poisson_data(results, study["poisson"])
    figures.append(poisson_figure)
    speed, ref_name = speed_accuracy(results, study["speed"], golds)
    figures.append(records_figure(
        "speed_accuracy", "speed_accuracy",
        "Speed against accuracy: each model and resolution, wall time of the full path (thresholds included) "
        f"against its error relative to {ref_name}; dashed: the Pareto front. The wall times are as the report's "
        "runs measured them: with --jobs N, N runs share the cores (README: how the committed snapshot was made). "
        "Also shown: the shell's stored meshes (fem, points; their studies' wall times, measured beside other runs) "
        "and the runs of benchmarks/speed_accuracy.py ('(benchmark)', stars: both plates and the shell on the "
        "studies' meshes, one at a time on an idle machine).",
        speed, {"reference": ref_name}))
    smap = stability_map(results, golds, thresholds)
    figures.append(records_figure("stability_map", "stability_map",
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

