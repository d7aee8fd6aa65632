"""The report's data object: ReportData (everything the report states; the templates only lay it
out) with its provenance, timings and 3D snapshots, and the benchmark in brief for its summary."""
from __future__ import annotations

from dataclasses import dataclass

from ddg.output.io import finite_float

from ..table import FigureData, Table, fraction
from ..verdicts import (PAPER_DISAGREEMENT, ClaimsVerdict, MaterialCheck, PaperReading, paper_disagreements,
                        unusual_outcomes)


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
    from ..benchmark import with_bar

    rows = [{"dL/L": fraction(r["compression_ratio"]), "W/L": fraction(r["width_ratio"])}
            | {heading: with_bar(finite_float(r.get(key)), finite_float(r.get(f"{key}_error_bar")))
               for heading, key in BENCHMARK_SUMMARY} for r in table.rows]
    return Table("benchmark_summary", ["dL/L", "W/L"] + [heading for heading, _ in BENCHMARK_SUMMARY], rows)

