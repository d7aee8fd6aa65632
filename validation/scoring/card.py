"""The scorecard written: a line per scored scene, score.csv, score.md (the table and its legend) and
score.png (the thresholds against W/L, the benchmark with its error bars and the submitted values)."""
from __future__ import annotations

import sys
from pathlib import Path

from ddg.output.io import atomic_write_text, save_figure, write_table_csv

from ..claims import THRESHOLD_BAND
from ..table import fraction_label
from .scenes import BENCHMARK_VERSION, THRESHOLDS, BenchmarkScene
from .scores import H_MID_ERROR_BAR_FLOOR, Score, Scorecard

SCORE_COLUMNS = ("benchmark_version", "scene", "label", "compression_ratio", "width_ratio", "slenderness",
                 "poisson_ratio", "quantity", "submitted", "benchmark", "error_bar", "difference", "in_error_bars",
                 "within", "at_dW_over_L", "points", "line", "note")
MISSING = "\u2013"   # en dash, as validation.benchmark


def _verdict(score: Score) -> str:
    return "within" if score.within else "outside"


def summary_line(scene: BenchmarkScene, scores: list[Score]) -> str:
    """One line per scored scene, e.g. "dL1/2 W1/20 Lb1181: dW1 0.3412 vs 0.3393 +- 0.0019 (1.0 bars)
    within; dW2 ...; H_mid ..."."""
    parts = []
    for s in scores:
        name = s.quantity.replace("_over_L", "")
        if s.quantity == "H_mid_over_L":
            if s.scored:
                parts.append(f"H_mid max |diff| {abs(s.difference):.3g} at dW/L {s.at_dW_over_L:.3f} (+- "
                             f"{s.error_bar:.2g} there; {s.in_error_bars:.1f} bars) {_verdict(s)}")
            else:
                parts.append(f"H_mid {s.note}")
        elif s.scored:
            parts.append(f"dW{name[-1]} {s.submitted:.4f} vs {s.benchmark:.4f} +- {s.error_bar:.4f} "
                         f"({s.in_error_bars:.1f} bars) {_verdict(s)}")
        else:
            parts.append(f"{name} {s.note}" if s.submitted is None else f"{name} {s.submitted:.4f} ({s.note})")
    return f"{scene.label}: " + "; ".join(parts)


def _cell(value, spec: str = "{:.4f}") -> str:
    if value is None:
        return MISSING
    if isinstance(value, bool):
        return "yes" if value else "no"
    return spec.format(value)


def markdown(card: Scorecard, source: str) -> str:
    """score.md: the counts, the table (one line per scene and quantity) and its legend."""
    scored = [s for s in card.scores if s.scored]
    lines = [f"# Scorecard against the thin-strip shear benchmark {BENCHMARK_VERSION} (validation/score.py)", "",
             f"Results: {source}. Scenes submitted: {len(card.matched)} of {len(card.scenes)}; quantities scored: "
             f"{len(scored)}, within the benchmark's error bar: {sum(bool(s.within) for s in scored)}.", ""]
    if card.unmatched:
        lines += [f"No benchmark scene at: {'; '.join(f'{u.describe()} (line {u.line})' for u in card.unmatched)}.",
                  ""]
    lines += ["| scene | quantity | submitted | benchmark \u00b1 error bar | difference | in error bars | within | "
              "note |", "|---|---|---:|---:|---:|---:|---|---|"]
    for s in card.scores:
        spec, bar_spec = ("{:.4g}", "{:.2g}") if s.quantity == "H_mid_over_L" else ("{:.4f}", "{:.4f}")
        bench = MISSING if s.benchmark is None else (
            spec.format(s.benchmark) + ("" if s.error_bar is None else " \u00b1 " + bar_spec.format(s.error_bar)))
        note = "" if s.scored and s.quantity != "H_mid_over_L" else s.note
        lines.append(f"| {s.scene.label} | {s.quantity.replace('_over_L', '/L')} | {_cell(s.submitted, spec)} | "
                     f"{bench} | {_cell(s.difference, '{:+.3g}')} | {_cell(s.in_error_bars, '{:.1f}')} | "
                     f"{_cell(s.within)} | {note} |")
    legend = (f"dW1/L (U -> US) and dW2/L (US -> S) in units of L; the benchmark is the FEM shell's converged value "
              f"with its error bar (data/fem_gold, the rule of its README.md). difference = submitted - benchmark; "
              f"in error bars = |difference| / error bar; within: |difference| <= error bar. H_mid/L: over the "
              f"benchmark curve's points inside the submitted curve's range and more than {THRESHOLD_BAND:g} from "
              f"the benchmark's and the submitted thresholds, the largest |difference| (the submitted, benchmark "
              f"and error bar columns at that point) and the largest |difference| / pointwise error bar (the bar "
              f"counted as at least {H_MID_ERROR_BAR_FLOOR:g} L); within: every point within its bar. "
              f"{MISSING}: none. The benchmark's files: `python -m validation score --benchmark DIR`.")
    return "\n".join(lines) + "\n\n" + legend + "\n"


def figure(card: Scorecard, path: Path) -> Path | None:
    """score.png: dW1/L and dW2/L against W/L, one colour per dL/L and L/b, the benchmark with its error
    bars (open circles) and the submitted values (crosses); None with one line naming the extra if
    matplotlib is missing."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("figure skipped: matplotlib is missing (pip install 'ddg-strips[plot]')", file=sys.stderr)
        return None
    series = sorted({(s.compression_ratio, round(s.slenderness)) for s in card.scenes}, key=lambda k: (-k[0], k[1]))
    colours = {k: f"C{i % 10}" for i, k in enumerate(series)}
    fig, axes = plt.subplots(1, 2, figsize=(9.5, 4.0))
    for ax, key, title in zip(axes, THRESHOLDS, ("dW1/L (U -> US)", "dW2/L (US -> S)")):
        for group in series:
            members = sorted((s for s in card.scenes if (s.compression_ratio, round(s.slenderness)) == group),
                             key=lambda s: s.width_ratio)
            bench = [(s.width_ratio, s.study.threshold(key)) for s in members if s.study.threshold(key) is not None]
            if bench:
                ax.errorbar([w for w, _ in bench], [e.value for _, e in bench],
                            yerr=[e.error_bar or 0.0 for _, e in bench], color=colours[group], marker="o",
                            mfc="none", ms=5, lw=0.8, capsize=2.5,
                            label=f"dL/L = {fraction_label(group[0])}, L/b = {group[1]}")
            ours = [(s.width_ratio, card.matched[s.name].threshold(key)) for s in members
                    if s.name in card.matched and card.matched[s.name].threshold(key) is not None]
            if ours:
                ax.plot([w for w, _ in ours], [v for _, v in ours], ls="", marker="x", ms=7, color=colours[group])
        ax.set_xscale("log")
        widths = sorted({s.width_ratio for s in card.scenes})
        ax.set_xticks(widths, [fraction_label(w) for w in widths], fontsize=7)
        ax.minorticks_off()
        ax.set_xlabel("W/L")
        ax.set_title(title, fontsize=9)
        ax.tick_params(labelsize=7)
    axes[0].legend(fontsize=6, frameon=False)
    fig.text(0.01, 0.01, f"benchmark {BENCHMARK_VERSION}: FEM converged value \u00b1 error bar (open circles); "
             "submitted: crosses", fontsize=7)
    fig.tight_layout(rect=(0, 0.04, 1, 1))
    save_figure(fig, path, dpi=100)
    plt.close(fig)
    return path


def write_scorecard(card: Scorecard, out: Path, source: str) -> list[Path]:
    """OUT/score.csv, OUT/score.md and OUT/score.png (when matplotlib is installed)."""
    out = Path(out)
    write_table_csv(out / "score.csv", [s.row() for s in card.scores], list(SCORE_COLUMNS))
    atomic_write_text(out / "score.md", markdown(card, source))
    png = figure(card, out / "score.png")
    return [out / "score.csv", out / "score.md"] + ([png] if png is not None else [])
