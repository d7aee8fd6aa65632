"""The thresholds' tables and figure: dW1/L, dW2/L per model and scene against the paper's values and
drops, the thresholds against W/L (paper Fig. 8) with the benchmark's converged values, how each run
ended (the stability map) and the benchmark table itself."""
from __future__ import annotations

import numpy as np

from ddg.geometry.strip import shear_limit
from ddg.output.io import read_json_object

from ..reference import PAPER_DROPS_QUARTER, ROOT, paper_value
from ..studies import COMPRESSIONS
from ..table import FigureData, Table
from .runs import MODELS, find_run


THRESHOLD_COLUMNS = ["model", "compression_ratio", "width_ratio", "dW1_over_L", "paper_dW1", "dW1_rel_diff_vs_paper",
                     "dW2_over_L", "paper_dW2", "dW2_rel_diff_vs_paper", "dW2_S_stable_over_L",
                     "dW1_drop_vs_W_1_20_percent", "paper_drop_percent", "dW_max_over_L", "resolved_up_to_dW_over_L"]


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


def benchmark_table() -> Table:
    """The benchmark (validation.benchmark): converged thresholds of the ten scenes from the stored
    FEM and plate studies, with the rod's stored study (data/benchmark/rod_thresholds.json) where
    it exists."""
    from ..benchmark import CROSS_SECTION_FILE, ROD_FILE, benchmark_rows

    stored = ROOT / "data" / "benchmark"
    rows = benchmark_rows(rod_thresholds=read_json_object(stored / ROD_FILE) or None,
                          cross_section_thresholds=read_json_object(stored / CROSS_SECTION_FILE) or None)
    columns = list(rows[0].keys()) if rows else []
    shown = [c for c in columns if not c.endswith(("_basis", "_meshes"))]
    return Table("benchmark", columns, rows, csv=True, shown=shown)

