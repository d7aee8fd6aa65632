"""The published benchmark: the thresholds dW1/L and dW2/L of the paper's ten scenes with error
bars, FEM shell against DDG plate, beside the paper's quoted values and the rod:
`python -m validation benchmark [--out data/benchmark] [--no-rod]` (old spelling
`python -m validation.benchmark`).

The ten scenes are dL/L in {1/2, 1/4} x W/L in {1/20, 1/12, 1/6, 1/3, 1/2}, at the paper's strip
(L = 0.15 m for dL/L = 1/2 and 0.10 m for 1/4, b = 0.127 mm: L/b = 1181 and 787;
validation.studies.COMPRESSIONS x WIDTHS_GOLD). For each one the FEM and plate values are the
converged values of their stored mesh studies (data/fem_gold and data/plate_gold, read by
validation.estimates.load_study; fem_reference.convergence.estimate: Richardson with the observed
order and Roache's grid convergence index where the sequence is asymptotic, else the finest value
with the spread); the plate-FEM comparison is validation.claims.threshold_agreement (the
difference in units of the combined error bar, the sum of the two). The rod's values come from its
own study on M = 50/100/200 elements (three runs of ddg.simulate per scene, a few seconds), stored in
OUT/rod_thresholds.json after each scene and not rerun when present there (resumable; --no-rod
computes none and uses the stored ones where the file exists); likewise the 1D model with its
cross-section (ribbon-cross-section) on M = 51/101/201 nodes, in
OUT/cross_section_thresholds.json. Writes OUT/benchmark.csv (every
column, with the meshes of each study) and OUT/benchmark.md (the table and its legend), and prints
the table. Regenerate after a new mesh study: `.venv/bin/python -m validation benchmark --out
data/benchmark`.
"""
from __future__ import annotations

import json
import sys
import time
from pathlib import Path

from ddg.output.io import atomic_write_text, read_json_object, write_table_csv

from .claims import threshold_agreement
from .command_line import standalone
from .estimates import Estimate, Study, load_study, study_from_runs
from .reference import gold_name, paper_value
from .studies import COMPRESSIONS, WIDTHS_GOLD
from .table import fraction_label

#: Elements along L of the rod's study on each scene.
ROD_RESOLUTIONS = (50, 100, 200)
THRESHOLDS = ("dW1", "dW2")
ROD_FILE = "rod_thresholds.json"
CROSS_SECTION_FILE = "cross_section_thresholds.json"
#: The 1D models with a study per scene: their file in OUT and their resolutions.
ONE_D_STUDIES = {"rod": (ROD_FILE, ROD_RESOLUTIONS), "ribbon-cross-section": (CROSS_SECTION_FILE, (51, 101, 201))}
MISSING = "\u2013"   # en dash: no data

LEGEND = (
    "dW1/L and dW2/L are the clamp shears at the pitchfork (U -> US) and at the snap (US -> S) in units of "
    "L; W\u00b2/(bL) is the width squared over thickness times length (L/b = 1181.1). Each FEM (data/fem_gold), "
    "plate (the paper's, data/plate_gold) and mid-edge plate (data/midedge_gold) value is the converged "
    "value of that model's mesh study of the scene, "
    "\u00b1 its error bar: fem_reference.convergence.estimate, i.e. the Richardson extrapolation with the "
    "observed order and Roache's grid convergence index as error bar where the finest three meshes are in "
    "the asymptotic range (safety factor 1.25 at an observed order of 1.5 or more, 3 below), else the finest "
    "mesh's value with three times the largest difference of the finest three meshes as error bar (the rule "
    "of data/fem_gold/README.md), plus the bisection tolerance of the threshold. |diff|/combined is "
    "|plate - FEM| (or |mid-edge - FEM|) divided by the "
    "combined error bar, the sum of the two error bars (validation.claims.threshold_agreement). Paper: the "
    "values quoted in the text of Huang, Wang, Li, Jawed (at dL/L = 1/4 and W/L > 1/20, 0.23 times the "
    "quoted percent drop). Rod: the converged value of the rod's study on M = 50/100/200 elements, the "
    "same estimate; cross-section: that of the 1D model with its cross-section (ribbon-cross-section) on "
    "M = 51/101/201 nodes. \u2013: no data (no study, or no value or error bar in it). The meshes each value rests "
    "on, the signed differences and the basis of every error bar are listed per row in benchmark.csv."
)


def benchmark_scenes() -> list[tuple[float, float]]:
    """The ten benchmark scenes (dL/L, W/L): dL/L = 1/2 first, then 1/4; W/L increasing."""
    return [(c, w) for c in COMPRESSIONS for w in sorted(WIDTHS_GOLD)]


def estimate_basis(estimate: Estimate | None) -> str | None:
    """The basis of an error bar in words: "Richardson, order 1.84" where the study is asymptotic,
    else the estimate's own basis; None without an estimate."""
    if estimate is None:
        return None
    if estimate.asymptotic and estimate.order is not None:
        return f"Richardson, order {estimate.order:.2f}"
    return estimate.basis or None


def _study_columns(prefix: str, study: Study | None, key: str) -> dict:
    estimate = study.threshold(key) if study is not None else None
    return {f"{prefix}_{key}": None if estimate is None else estimate.value,
            f"{prefix}_{key}_error_bar": None if estimate is None else estimate.error_bar,
            f"{prefix}_{key}_basis": estimate_basis(estimate),
            f"{prefix}_{key}_meshes": None if estimate is None else "/".join(basis_meshes(study, key))}


def basis_meshes(study: Study, key: str) -> list[str]:
    """The labels of the meshes a threshold's estimate rests on: the finest three of the study's
    meshes that have it (fem_reference.convergence.estimate)."""
    return [m.label for m in study.meshes if getattr(m, key) is not None][-3:]


def _safe_load(load, model: str, compression_ratio: float, width_ratio: float) -> Study | None:
    try:
        return load(model, compression_ratio, width_ratio)
    except (OSError, ValueError, KeyError, TypeError):   # an unreadable study is no study
        return None


def benchmark_rows(rod_thresholds: dict | None = None, load=None, cross_section_thresholds: dict | None = None
                   ) -> list[dict]:
    """One row per scene (benchmark_scenes() order) of the benchmark: W^2/(bL), then for dW1 and dW2 the FEM
    and plate converged values with error bar, basis and meshes, the signed difference plate - FEM,
    |difference| / combined error bar, the paper's value and the rod's value with error bar.
    `rod_thresholds`, `cross_section_thresholds`: the output of rod_thresholds() for "rod" and
    "ribbon-cross-section" ({scene name: {...}}), or None; `load(model,
    dL/L, W/L)` gives a Study or None (default validation.estimates.load_study). Missing data is None."""
    import ddg

    load = load or load_study
    rows = []
    for compression, width in benchmark_scenes():
        strip = ddg.Strip.from_ratios(width, compression)
        fem = _safe_load(load, "fem", compression, width)
        plate = _safe_load(load, "plate", compression, width)
        midedge = _safe_load(load, "plate-midedge", compression, width)
        rod = (rod_thresholds or {}).get(gold_name(compression, width)) or {}
        cross = (cross_section_thresholds or {}).get(gold_name(compression, width)) or {}
        row = {"compression_ratio": compression, "width_ratio": width,
               "width_squared_over_thickness_length": width**2 * strip.slenderness}
        for key in THRESHOLDS:
            row.update(_study_columns("fem", fem, key))
            row.update(_study_columns("plate", plate, key))
            fem_value, plate_value = row[f"fem_{key}"], row[f"plate_{key}"]
            row[f"{key}_difference"] = (None if fem_value is None or plate_value is None
                                        else plate_value - fem_value)
            agreement = None if fem is None or plate is None else threshold_agreement(plate, fem, key)
            row[f"{key}_in_error_bars"] = None if agreement is None else agreement.in_error_bars
            row.update(_study_columns("midedge", midedge, key))
            midedge_value = row[f"midedge_{key}"]
            row[f"midedge_{key}_difference"] = (None if fem_value is None or midedge_value is None
                                                else midedge_value - fem_value)
            agreement = None if fem is None or midedge is None else threshold_agreement(midedge, fem, key)
            row[f"midedge_{key}_in_error_bars"] = None if agreement is None else agreement.in_error_bars
            row[f"paper_{key}"] = paper_value(compression, width, key)
            row[f"rod_{key}"] = rod.get(key)
            row[f"rod_{key}_error_bar"] = rod.get(f"{key}_error_bar")
            row[f"cross_section_{key}"] = cross.get(key)
            row[f"cross_section_{key}_error_bar"] = cross.get(f"{key}_error_bar")
        rows.append(row)
    return rows


def rod_study(compression_ratio: float, width_ratio: float, resolutions=ROD_RESOLUTIONS,
              model: str = "rod") -> Study | None:
    """A 1D model's study of one scene (the rod by default): ddg.simulate at each resolution (no
    branch tracing), the runs read as a study by validation.estimates.study_from_runs."""
    import ddg

    strip = ddg.Strip.from_ratios(width_ratio, compression_ratio)
    runs = [ddg.simulate(strip, ddg.LoadingProtocol(compression_ratio), model=model, resolution=m, branches=False)
            for m in resolutions]
    return study_from_runs(model, runs, list(resolutions))


def rod_thresholds(out: Path, scenes=None, quiet: bool = True, model: str = "rod") -> dict:
    """A 1D model's converged thresholds per scene (the rod by default; ONE_D_STUDIES), {scene name:
    {"dW1", "dW1_error_bar", "dW2", "dW2_error_bar", "wall_time_s", "resolutions", "converged"}}
    (values None where the study has none), for `scenes` ((dL/L, W/L) pairs, default all ten).
    Stored in OUT/<its file> (atomically) after each scene; a scene already in the file is not rerun."""
    out = Path(out)
    filename, resolutions = ONE_D_STUDIES[model]
    path = out / filename
    stored = read_json_object(path) or {}
    for compression, width in scenes if scenes is not None else benchmark_scenes():
        name = gold_name(compression, width)
        if name in stored:
            continue
        t0 = time.perf_counter()
        study = rod_study(compression, width, resolutions, model)
        entry = {}
        for key in THRESHOLDS:
            estimate = study.threshold(key) if study is not None else None
            entry[key] = None if estimate is None else estimate.value
            entry[f"{key}_error_bar"] = None if estimate is None else estimate.error_bar
        entry["wall_time_s"] = time.perf_counter() - t0
        entry["resolutions"] = list(resolutions)
        entry["converged"] = bool(study is not None and all(r.summary.get("converged") for r in study.runs))
        stored[name] = entry
        out.mkdir(parents=True, exist_ok=True)
        atomic_write_text(path, json.dumps(stored, indent=2) + "\n")
        if not quiet:
            print(f"{model} {name}: dW1/L {entry['dW1']}, dW2/L {entry['dW2']}, {entry['wall_time_s']:.0f} s",
                  file=sys.stderr, flush=True)
    return stored


def _number(value, spec: str = "{:.4f}") -> str:
    return MISSING if value is None else spec.format(value)


def with_bar(value, error_bar) -> str:
    """A converged value with its error bar, "0.3511 \u00b1 0.0012" (the value alone without a bar,
    MISSING without a value): the benchmark's cells here and in the validation report's summary."""
    if value is None:
        return MISSING
    return _number(value) if error_bar is None else f"{value:.4f} \u00b1 {error_bar:.4f}"


def markdown_table(rows: list[dict]) -> str:
    """The benchmark as a markdown table (no legend), one line per row of benchmark_rows()."""
    lines = ["| dL/L | W/L | W\u00b2/(bL) | FEM dW1/L | plate dW1/L | \\|diff\\|/combined | mid-edge dW1/L | "
             "\\|diff\\|/combined | FEM dW2/L | plate dW2/L | \\|diff\\|/combined | mid-edge dW2/L | "
             "\\|diff\\|/combined | paper dW1/L | paper dW2/L | rod dW1/L | rod dW2/L | cross-section dW1/L | "
             "cross-section dW2/L |",
             "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        cells = [fraction_label(r["compression_ratio"]), fraction_label(r["width_ratio"]),
                 _number(r["width_squared_over_thickness_length"], "{:.1f}")]
        for key in THRESHOLDS:
            cells += [with_bar(r[f"fem_{key}"], r[f"fem_{key}_error_bar"]),
                      with_bar(r[f"plate_{key}"], r[f"plate_{key}_error_bar"]),
                      _number(r[f"{key}_in_error_bars"], "{:.1f}"),
                      with_bar(r[f"midedge_{key}"], r[f"midedge_{key}_error_bar"]),
                      _number(r[f"midedge_{key}_in_error_bars"], "{:.1f}")]
        cells += [_number(r["paper_dW1"]), _number(r["paper_dW2"]),
                  with_bar(r["rod_dW1"], r["rod_dW1_error_bar"]), with_bar(r["rod_dW2"], r["rod_dW2_error_bar"]),
                  with_bar(r["cross_section_dW1"], r["cross_section_dW1_error_bar"]),
                  with_bar(r["cross_section_dW2"], r["cross_section_dW2_error_bar"])]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def basis_counts(rows: list[dict], prefix: str = "fem") -> dict:
    """How the `prefix` model's entries (dW1 and dW2 of every row with a value) rest: entries, on
    three or more meshes, asymptotic (Richardson)."""
    bases = [(r[f"{prefix}_{key}_meshes"], r[f"{prefix}_{key}_basis"]) for r in rows for key in THRESHOLDS
             if r[f"{prefix}_{key}"] is not None]
    return {"entries": len(bases), "three_meshes": sum(1 for m, _ in bases if m and len(m.split("/")) >= 3),
            "asymptotic": sum(1 for _, b in bases if b and b.startswith("Richardson"))}


def basis_sentence(rows: list[dict]) -> str:
    """One sentence counting the bases of the FEM and plate entries (benchmark.md, the README)."""
    parts = []
    for prefix, name in (("fem", "FEM"), ("plate", "plate"), ("midedge", "mid-edge plate")):
        c = basis_counts(rows, prefix)
        parts.append(f"{c['three_meshes']} of the {c['entries']} {name} entries rest on three meshes, "
                     f"{c['asymptotic']} of them asymptotic")
    return "; ".join(parts) + "."


def write_benchmark(out: Path, rows: list[dict]) -> None:
    """OUT/benchmark.csv (every column of benchmark_rows(); empty cells where missing) and
    OUT/benchmark.md (the markdown table and its legend), written atomically."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    write_table_csv(out / "benchmark.csv", rows)
    text = ("# Thresholds of the ten benchmark scenes: FEM shell, DDG plate, paper, rod, cross-section "
            "(validation/benchmark.py)\n\n"
            + markdown_table(rows) + "\n" + basis_sentence(rows) + "\n\n" + LEGEND + "\n")
    atomic_write_text(out / "benchmark.md", text)


def add_arguments(parser) -> None:
    """The options of `python -m validation benchmark`."""
    parser.description = __doc__.split("\n")[0]
    parser.add_argument("--out", default="data/benchmark", help="output directory (default data/benchmark)")
    parser.add_argument("--no-rod", action="store_true",
                        help="run no 1D model (rod, ribbon-cross-section); use their stored files in OUT where "
                             "they exist")


def run(args) -> int:
    """The command: rod thresholds (unless --no-rod), then the benchmark files and table."""
    from ddg.geometry.strip import InputError
    from ddg.output.io import check_output_directory

    try:
        out = check_output_directory(args.out, "--out")
    except InputError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    if args.no_rod:
        rods, crosses = read_json_object(out / ROD_FILE), read_json_object(out / CROSS_SECTION_FILE)
    else:
        rods = rod_thresholds(out, quiet=False)
        crosses = rod_thresholds(out, quiet=False, model="ribbon-cross-section")
    rows = benchmark_rows(rods, cross_section_thresholds=crosses or None)
    write_benchmark(out, rows)
    print(markdown_table(rows), end="")
    return 0


def main(argv=None) -> int:
    """`python -m validation.benchmark [options]`: the same as `python -m validation benchmark [options]`."""
    return standalone("benchmark", add_arguments, run, argv)


if __name__ == "__main__":
    raise SystemExit(main())
