"""The sweep's phase diagram in the manner of the paper's Fig. 8: dW1/L and dW2/L against W/L, one
panel per dL/L, one curve per model (and L/b, resolution), with the FEM shell's gold thresholds:
per scene the converged value of its mesh study and its error bar (data/fem_gold/index.json,
written by `python -m fem_reference gold`; read as a file, so ddg imports nothing of fem_reference).

matplotlib is optional (the 'plot' extra); `write_phase_diagram` raises ImportError without it.
"""
from __future__ import annotations

import math
import textwrap
from pathlib import Path

from ..geometry.strip import shear_limit
from ..output.io import finite_float, read_json_object, save_figure

#: The repository's data folder (the FEM gold index and its studies); absent in an installed wheel.
DATA = Path(__file__).resolve().parents[2] / "data"

PHASE_COLOURS = {"U": "#dbe9f6", "US": "#fde6cf", "S": "#dff2de"}


def gold_thresholds(data: Path = DATA) -> list[dict]:
    """The FEM gold thresholds of the paper's strip (L/b = 1181) per scene of
    DATA/fem_gold/index.json: dL/L, W/L, dW1/L, dW2/L and their error bars dW1_error, dW2_error.

    A scene with a mesh study (its entry's "study": "dW1" and "dW2", each {"value", "error_bar"},
    fem_reference.convergence.estimate: Richardson extrapolation or the finest mesh, with its error
    bar) gives the study's converged values and error bars, `meshes` its meshes and `basis`
    "study"; a scene without one, the finished finest run's thresholds with no error bar (None)
    and `basis` "single run". Scenes of another strip (the error map's, "slenderness" set) are
    left out. [] without the index."""
    index = read_json_object(Path(data) / "fem_gold" / "index.json")
    out = []
    for scene, entry in sorted((index or {}).items()):
        if not isinstance(entry, dict) or entry.get("slenderness") is not None:
            continue  # a strip other than the paper's (the error map's scenes)
        study = entry.get("study") if isinstance(entry.get("study"), dict) else {}
        point = {"scene": scene, "dL_over_L": entry.get("compression_ratio"), "W_over_L": entry.get("width_ratio"),
                 "meshes": study.get("meshes")}
        for key in ("dW1", "dW2"):
            estimate = study.get(key) if isinstance(study.get(key), dict) else {}
            value = finite_float(estimate.get("value"))
            point[f"{key}_over_L"] = value
            point[f"{key}_error"] = finite_float(estimate.get("error_bar")) if value is not None else None
        point["basis"] = "study"
        if point["dW1_over_L"] is None and point["dW2_over_L"] is None:
            if not entry.get("converged"):
                continue  # no study and no finished run
            point.update(dW1_over_L=finite_float(entry.get("dW1_over_L")),
                         dW2_over_L=finite_float(entry.get("dW2_over_L")),
                         dW1_error=None, dW2_error=None, basis="single run", meshes=None)
        if finite_float(point["dL_over_L"]) is None or finite_float(point["W_over_L"]) is None:
            continue
        if point["dW1_over_L"] is not None or point["dW2_over_L"] is not None:
            out.append(point)
    return out


def write_phase_diagram(out, rows: list[dict], data: Path = DATA) -> tuple[list[Path], str]:
    """DIR/phase_diagram.png and .pdf from the table rows, with the FEM gold thresholds of
    `data` (gold_thresholds); returns the paths and the caption (also printed under the figure)."""
    fig, caption = phase_diagram_figure(rows, gold_thresholds(data))
    out = Path(out)
    written = [save_figure(fig, out / f"phase_diagram.{suffix}", dpi=150) for suffix in ("png", "pdf")]
    return written, caption


def phase_diagram_figure(rows: list[dict], gold: list[dict]):
    """The phase diagram (a matplotlib Figure, no pyplot state) of the table rows and the gold
    thresholds (gold_thresholds), and its caption."""
    import importlib

    importlib.import_module("matplotlib")  # ImportError without the 'plot' extra, before any work
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    usable = [r for r in rows if r.get("dW1_over_L") is not None or r.get("dW2_over_L") is not None]
    panels = sorted({r["dL_over_L"] for r in rows}, reverse=True) or [0.5]
    caption = _caption(rows, usable, gold, panels)
    fig = Figure(figsize=(5.2 * len(panels), 4.6))
    FigureCanvasAgg(fig)
    axes = fig.subplots(1, len(panels), squeeze=False)[0]
    widths = sorted({r["W_over_L"] for r in rows} | {g["W_over_L"] for g in gold if _near(g["dL_over_L"], panels)})
    for ax, compression in zip(axes, panels):
        mine = [r for r in usable if r["dL_over_L"] == compression]
        lo, hi = (min(widths), max(widths)) if widths else (0.05, 0.5)
        logx = hi / lo > 3.0
        xs = _span(lo, hi, logx)
        limit = [shear_limit(1.0, w, compression) for w in xs]
        ax.plot(xs, limit, color="0.55", lw=1.0, label=r"$\Delta W_{max}/L$ (Eq. B.1)")
        series = _series(mine)
        if series:
            first = series[0][1]
            _shade(ax, first, compression)
        for number, (name, points) in enumerate(series):
            colour = f"C{number % 10}"
            w1 = [(p["W_over_L"], p["dW1_over_L"]) for p in points if p["dW1_over_L"] is not None]
            w2 = [(p["W_over_L"], p["dW2_over_L"]) for p in points if p["dW2_over_L"] is not None]
            if w1:
                ax.plot(*zip(*w1), "o-", color=colour, ms=4, lw=1.4, label=f"{name}: $\\Delta W_1/L$")
            if w2:
                ax.plot(*zip(*w2), "s--", color=colour, ms=4, lw=1.4, mfc="white", label=f"{name}: $\\Delta W_2/L$")
        for key, marker, label in (("dW1", "^", r"FEM shell (gold): $\Delta W_1/L$"),
                                   ("dW2", "v", r"FEM shell (gold): $\Delta W_2/L$")):
            pts = [g for g in gold if abs(g["dL_over_L"] - compression) < 1e-9 and g[f"{key}_over_L"] is not None]
            if not pts:
                continue
            x = [g["W_over_L"] for g in pts]
            y = [g[f"{key}_over_L"] for g in pts]
            err = [g[f"{key}_error"] or 0.0 for g in pts]
            ax.errorbar(x, y, yerr=err if any(err) else None, fmt=marker, color="black", ms=5, capsize=3,
                        elinewidth=1.0, label=label, zorder=5)
        if logx:
            ax.set_xscale("log")
            ax.minorticks_off()
        ticks = _spread(sorted({r["W_over_L"] for r in rows}) or widths, lo, hi, logx)
        ax.set_xticks(ticks)
        ax.set_xticklabels([f"{w:.3g}" for w in ticks], fontsize=8)
        ax.set_xlabel("W / L")
        ax.set_ylabel(r"$\Delta W / L$")
        ax.set_ylim(0.0, max(limit) * 1.02)
        ax.set_title(f"$\\Delta L/L$ = {compression:g}", fontsize=10)
        ax.legend(fontsize=6.5, loc="upper right")
    wrapped = "\n".join(textwrap.wrap(caption, width=int(92 * len(panels))))
    lines = wrapped.count("\n") + 1
    fig.text(0.01, 0.01, wrapped, fontsize=7, va="bottom", ha="left")
    fig.tight_layout(rect=(0, (lines * 7 * 1.25 + 8) / (4.6 * 72), 1, 1))
    return fig, caption


def _series(rows: list[dict]) -> list[tuple[str, list[dict]]]:
    """Rows grouped by (model, L/b, resolution), each sorted by W/L; the name says what differs."""
    groups: dict = {}
    for r in rows:
        groups.setdefault((r["model"], round(r["L_over_b"], 6), r["resolution"]), []).append(r)
    slender = len({k[1] for k in groups}) > 1
    resolutions = len({(k[0], k[2]) for k in groups}) > len({k[0] for k in groups})
    out = []
    for (model, lb, resolution), points in sorted(groups.items()):
        name = model + (f" L/b={lb:.4g}" if slender else "") + (f" N={resolution}" if resolutions else "")
        out.append((name, sorted(points, key=lambda p: p["W_over_L"])))
    return out


def _shade(ax, points: list[dict], compression: float) -> None:
    """Phases U (below dW1), US (dW1 to dW2) and S (dW2 to dW_max) of one series, as in Fig. 8."""
    pts = [p for p in points if p["dW1_over_L"] is not None and p["dW2_over_L"] is not None]
    if len(pts) < 2:
        return
    x = [p["W_over_L"] for p in pts]
    w1 = [p["dW1_over_L"] for p in pts]
    w2 = [p["dW2_over_L"] for p in pts]
    top = [shear_limit(1.0, w, compression) for w in x]
    ax.fill_between(x, 0.0, w1, color=PHASE_COLOURS["U"], lw=0)
    ax.fill_between(x, w1, w2, color=PHASE_COLOURS["US"], lw=0)
    ax.fill_between(x, w2, top, color=PHASE_COLOURS["S"], lw=0)
    i = len(x) // 2
    for text, y in (("U", 0.5 * w1[i]), ("US", 0.5 * (w1[i] + w2[i])), ("S", 0.5 * (w2[i] + top[i]))):
        ax.text(x[i], y, text, ha="center", va="center", fontsize=11, color="0.35")


def _caption(rows, usable, gold, panels) -> str:
    runs = len(rows)
    missing = runs - len(usable)
    text = (f"Thresholds of {runs} run{'s' * (runs != 1)} (sweep.csv): dW1/L (filled, solid) where the U branch "
            "loses stability, dW2/L (open, dashed) where the stable path reaches S; grey: dW_max/L (Eq. B.1); "
            "shading: the phases of the first curve.")
    if missing:
        text += (f" {missing} run{'s' * (missing != 1)} located neither threshold and "
                 f"{'are' if missing != 1 else 'is'} not drawn.")
    shown = [g for g in gold if _near(g["dL_over_L"], panels)]
    if not shown:
        return text + " No FEM gold data for these dL/L (data/fem_gold): no reference points, no error bars."
    with_bars = [g for g in shown if g["basis"] == "study"]
    text += (f" Black: the FEM shell's gold thresholds (data/fem_gold, {len(shown)} scene{'s' * (len(shown) != 1)} "
             "at the paper's thickness b = 0.127 mm)")
    if with_bars:
        def largest(key):
            errors = [g[f"{key}_error"] for g in with_bars if g[f"{key}_error"] is not None]
            return _fmt(max(errors)) if errors else "none"

        every = "every scene" if len(with_bars) == len(shown) else f"{len(with_bars)} of them"
        text += (f": for {every} the converged value of its mesh study with its error bar (Richardson extrapolation "
                 "or the finest mesh, fem_reference.convergence; largest dW1 +/-" + largest("dW1")
                 + ", dW2 +/-" + largest("dW2") + ")")
    rest = len(shown) - len(with_bars)
    if rest:
        text += (f"; {'the other ' if with_bars else ''}{rest} scene{'s' * (rest != 1)} "
                 f"{'have' if rest != 1 else 'has'} a single run, no mesh study and no error bar")
    return text + "."


def _spread(values: list[float], lo: float, hi: float, logx: bool) -> list[float]:
    """The values to label on the W/L axis, at least 0.08 of the axis length apart (the first kept)."""
    scale = (lambda v: math.log(v)) if logx else (lambda v: v)
    gap = 0.08 * (scale(hi) - scale(lo)) if hi > lo else 0.0
    kept: list[float] = []
    for v in values:
        if not kept or scale(v) - scale(kept[-1]) >= gap:
            kept.append(v)
    return kept


def _near(value, panels) -> bool:
    return any(abs(value - p) < 1e-9 for p in panels)


def _span(lo: float, hi: float, logx: bool, n: int = 60) -> list[float]:
    if hi <= lo:
        return [lo, hi]
    if logx:
        return [lo * (hi / lo) ** (i / (n - 1)) for i in range(n)]
    return [lo + (hi - lo) * i / (n - 1) for i in range(n)]


def _fmt(value) -> str:
    return "?" if value is None else f"{value:.2g}"


