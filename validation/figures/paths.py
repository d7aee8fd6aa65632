"""Figures of the path: H_mid and the clamp force against dW/L, the compressed elastica, the
thresholds against W/L with the phases shaded, the ribbons with width, the Poisson ratio's effect
(paper Figs. 5b, 6-8, A.11, E.18, G.20)."""
from __future__ import annotations

import numpy as np

from ..table import fraction
from .style import COLORS, MARKERS, groups, in_panel, legend, legend_entries, panel_grid, pyplot


def elastica(rows: list[dict], exact: list[tuple[float, float]]):
    """Fig. 5b: H_mid/L against dL/L per model (its own marker) on the exact elastica, and below
    the residual H_mid - H_elastica (errors ~1e-4 L are invisible on the curve)."""
    plt = pyplot()
    fig, (ax, res) = plt.subplots(2, 1, figsize=(5.2, 5.2), sharex=True, gridspec_kw={"height_ratios": [2, 1.3]})
    ex = np.array(sorted(exact))
    ax.plot(ex[:, 0], ex[:, 1], "k-", lw=1, label="exact elastica")
    for (model, width), sel in groups(rows, "model", "width_ratio"):
        dl = np.array([r["dL_over_L"] for r in sel])
        h = np.array([r["H_mid_over_L"] for r in sel])
        color = COLORS.get(model, "gray")
        marker = MARKERS.get(model, "o")
        label = f"{'FEM' if model == 'fem' else model} W/L={fraction(width)}"
        ax.plot(dl, h, marker, mfc="none", ms=4, color=color, label=label)
        keep = dl > 0
        res.plot(dl[keep], h[keep] - np.interp(dl[keep], ex[:, 0], ex[:, 1]), marker + "-", mfc="none", ms=3, lw=0.6,
                 color=color, label=label)
    res.axhline(0.0, color="k", lw=0.6)
    res.set_yscale("symlog", linthresh=1e-5)
    ax.set_ylabel("H_mid/L")
    res.set_xlabel("dL/L")
    res.set_ylabel("H_mid - H_elastica (/L)\n(symlog, linear |.| < 1e-5)", fontsize=7)
    ax.legend(fontsize=7)
    fig.tight_layout()
    return fig


def _shear_panel(ax, rows: list[dict], column: str, thresholds: list[dict]) -> None:
    """`column` against dW/L per model (FEM as points), each model's dW1 (dotted) and dW2 (dashed)."""
    for (model,), sel in groups(rows, "model"):
        dw, y = [r["dW_over_L"] for r in sel], [r[column] for r in sel]
        mine = [t for t in thresholds if t["model"] == model]
        resolved = next((t.get("resolved_up_to_dW_over_L") for t in mine if t.get("resolved_up_to_dW_over_L")), None)
        if model == "fem":
            ax.plot(dw, y, "k.", ms=3, label="FEM")
        elif resolved is None or resolved >= max(dw) - 1e-12:
            ax.plot(dw, y, "-", color=COLORS.get(model, "gray"), label=model)
        else:   # past the last state the mesh resolves: thin and faint, with its own legend entry
            dw, y = np.asarray(dw), np.asarray(y)
            inside = dw <= resolved + 1e-12
            ax.plot(dw[inside], y[inside], "-", color=COLORS.get(model, "gray"), label=model)
            ax.plot(dw[~inside], y[~inside], "-", lw=0.7, alpha=0.45, color=COLORS.get(model, "gray"),
                    label=f"{model} past its mesh's resolution")
        for t in mine:
            for key, style in (("dW1_over_L", ":"), ("dW2_over_L", "--")):
                if t[key] is not None:
                    ax.axvline(t[key], color=COLORS.get(model, "gray"), ls=style, lw=0.8)


def shear_curves(rows: list[dict], panels: list[tuple[float, float]], thresholds: list[dict], paper: list[dict]):
    plt = pyplot()
    fig, axes = panel_grid(plt, len(panels), min(3, len(panels)), (4.2, 3.3))
    for ax, (compression, width) in zip(axes, panels):
        _shear_panel(ax, in_panel(rows, compression, width), "H_mid_over_L", in_panel(thresholds, compression, width))
        for p in (p for p in paper if p["width_ratio"] == width):
            ax.plot([p["value"]], [0.0], "v" if p["key"] == "dW1" else "^", color="crimson", ms=7,
                    label=f"paper {p['key']}")
        ax.set_title(f"W/L = {fraction(width)}, dL/L = {fraction(compression)}", fontsize=9)
        ax.set_xlabel("dW/L (dotted: dW1, dashed: dW2 of the model in its colour)", fontsize=7)
        ax.set_ylabel("H_mid/L")
        legend(ax)
    fig.tight_layout()
    return fig


#: Shading of the mesh studies' converged curves
BAND_COLORS = {"fem (converged)": "0.35", "plate (converged)": "tab:orange"}


def shear_force(rows: list[dict], panels: list[tuple[float, float]], thresholds: list[dict]):
    """Runs' forces as curves; the rows of a mesh study's converged force (model "... (converged)",
    with error_bar) as a band of +- the error bar."""
    plt = pyplot()
    fig, axes = panel_grid(plt, len(panels), min(2, len(panels)), (4.8, 3.4))
    studies = [r for r in rows if str(r["model"]).endswith("(converged)")]
    runs = [r for r in rows if not str(r["model"]).endswith("(converged)")]
    for ax, (compression, width) in zip(axes, panels):
        for (model,), sel in groups(in_panel(studies, compression, width), "model"):
            dw = np.array([b["dW_over_L"] for b in sel])
            v, e = np.array([b["F_shear_norm"] for b in sel]), np.array([b["error_bar"] for b in sel])
            ax.fill_between(dw, v - e, v + e, color=BAND_COLORS.get(model, "gray"), alpha=0.3, lw=0,
                            label=f"{model} +- error bar")
        mine = in_panel(runs, compression, width)
        _shear_panel(ax, mine, "F_shear_norm", in_panel(thresholds, compression, width))
        ax.set_yscale("symlog", linthresh=1.0)
        # the bands (and a non-asymptotic extrapolation) may dip far below zero where an error bar
        # exceeds the force (near dW_max): the axis stops a little below the runs' lowest force
        lowest = min([0.0] + [float(r["F_shear_norm"]) for r in mine])
        ax.set_ylim(bottom=lowest - 0.2)
        ax.set_title(f"W/L = {fraction(width)}, dL/L = {fraction(compression)}", fontsize=9)
        ax.set_xlabel("dW/L")
        ax.set_ylabel("F_shear L/(E b^3)\n(symlog: linear for |F| < 1, log beyond)", fontsize=8)
    seen = legend_entries(axes)   # one legend for all panels, beside them
    fig.tight_layout(rect=(0, 0, 0.8, 1))
    fig.legend(list(seen.values()), list(seen), fontsize=7, loc="center left", bbox_to_anchor=(0.8, 0.5))
    return fig


def thresholds(rows: list[dict], compressions: list[float], dW_max: dict, paper: list[dict]):
    plt = pyplot()
    fig, axes = plt.subplots(1, len(compressions), figsize=(4.5 * len(compressions), 3.6), squeeze=False)
    for ax, compression in zip(axes.flat, compressions):
        ax.plot(*zip(*dW_max[compression]), "k-", lw=0.8, label="dW_max (Eq. B.1)")
        for (model,), sel in groups([r for r in rows if r["compression_ratio"] == compression], "model"):
            converged = model.endswith("(converged)")
            for key, marker in (("dW1_over_L", "o-"), ("dW2_over_L", "s--")):
                pts = [(r["width_ratio"], r[key], r.get(f"{key[:3]}_error_bar")) for r in sel if r[key] is not None]
                if not pts:
                    continue
                if converged:   # the benchmark's converged values: open markers with their error bars
                    ax.errorbar([p[0] for p in pts], [p[1] for p in pts], yerr=[p[2] or 0.0 for p in pts],
                                fmt=marker[0], mfc="none", ms=6, capsize=2.5, lw=0.9, color=COLORS.get(model, "gray"),
                                label=f"{model} {key[:3]}")
                else:
                    ax.plot(*zip(*[p[:2] for p in pts]), marker, color=COLORS.get(model, "gray"), ms=4,
                            label=f"{model} {key[:3]}")
        _shade_phases(ax, [r for r in rows if r["compression_ratio"] == compression], dW_max[compression])
        for k, p in enumerate(p for p in paper if p["compression_ratio"] == compression):
            ax.plot([p["width_ratio"]], [p["value"]], "v" if p["key"] == "dW1" else "^", color="crimson", ms=7,
                    label=f"paper {p['key']} (Fig. 8)")
        ax.set_title(f"dL/L = {fraction(compression)}", fontsize=9)
        ax.set_xlabel("W/L")
        ax.set_ylabel("threshold dW/L")
    legend(list(axes.flat)[-1], 6.5, outside=True, others=list(axes.flat)[:-1])
    fig.tight_layout()
    return fig


PHASE_SHADES = (("U", "#e8f0ff"), ("US", "#fff3d6"), ("S", "#e6f6e6"))


def _shade_phases(ax, rows: list[dict], dw_max: list[tuple[float, float]]) -> None:
    """U below dW1, US between dW1 and dW2, S between dW2 and dW_max, from the reference's
    thresholds (the FEM's where the rows have it, else the plate's), shaded and labelled."""
    for model in ("fem (converged)", "fem", "fem (extrapolated)", "plate"):
        sel = sorted((r for r in rows if r["model"] == model and r["dW1_over_L"] is not None),
                     key=lambda r: r["width_ratio"])
        if len(sel) >= 2:
            break
    else:
        return
    w = np.array([r["width_ratio"] for r in sel])
    d1 = np.array([r["dW1_over_L"] for r in sel])
    top = np.interp(w, *map(np.array, zip(*sorted(dw_max))))
    d2 = np.array([r["dW2_over_L"] if r["dW2_over_L"] is not None else t for r, t in zip(sel, top)])
    for (name, colour), (lo, hi) in zip(PHASE_SHADES, ((np.zeros_like(d1), d1), (d1, d2), (d2, top))):
        label = f"{name} ({'FEM' if model.startswith('fem') else model})"
        ax.fill_between(w, lo, hi, color=colour, zorder=0, label=label)


def wide_ribbons(rows: list[dict], compressions: list[float]):
    """dW1/L (circles) and dW2/L (squares) against W/L per model, one panel per compression."""
    plt = pyplot()
    fig, axes = plt.subplots(1, len(compressions), figsize=(4.8 * len(compressions), 3.8), squeeze=False)
    for ax, compression in zip(axes.flat, compressions):
        for (model,), sel in groups([r for r in rows if r["compression_ratio"] == compression], "model"):
            sel = sorted(sel, key=lambda r: r["width_ratio"])
            style = "-" if model.startswith("fem") else ":"
            for key, marker in (("dW1_over_L", "o"), ("dW2_over_L", "s")):
                pts = [(r["width_ratio"], r[key]) for r in sel if r[key] is not None]
                if pts:
                    ax.plot(*zip(*pts), marker + style, color=COLORS.get(model, "gray"), ms=4, lw=1,
                            label=f"{model} {key[:3]}")
        ax.set_xscale("log")
        ax.set_title(f"dL/L = {fraction(compression)}", fontsize=9)
        ax.set_xlabel("W/L (log scale)")
        ax.set_ylabel("threshold dW/L")
        ax.legend(fontsize=5.5, ncol=2)
    fig.tight_layout()
    return fig


def poisson(rows: list[dict]):
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(5, 3.6))
    for (nu,), sel in groups(rows, "poisson_ratio"):
        ax.plot([r["dW_over_L"] for r in sel], [r["H_mid_over_L"] for r in sel], "-", label=f"nu = {nu:g}")
    ax.set_xlabel("dW/L")
    ax.set_ylabel("H_mid/L")
    ax.legend(fontsize=7)
    return fig


A11_STYLES = {"rod": ("tab:blue", "-"), "plate": ("tab:orange", "-"), "ribbon_direct": ("tab:green", "--"),
              "ribbon_rod": ("tab:red", ":")}


def sadowsky_a11(rows: list[dict]):
    """Fig. A.11: H_mid/L against dW/L per model, one panel per W/L."""
    plt = pyplot()
    widths = sorted({r["width_ratio"] for r in rows})
    fig, axes = panel_grid(plt, len(widths), len(widths), (4.4, 3.4))
    for ax, width in zip(axes, widths):
        for (model,), sel in groups([r for r in rows if r["width_ratio"] == width], "model"):
            colour, style = A11_STYLES.get(model, ("gray", "-"))
            sel = sorted(sel, key=lambda r: r["dW_over_L"])
            ax.plot([r["dW_over_L"] for r in sel], [r["H_mid_over_L"] for r in sel], style, color=colour, lw=1.3,
                    label=model.replace("_", " "))
        ax.set_title(f"W/L = {fraction(width)}, dL/L = 1/2", fontsize=9)
        ax.set_xlabel("dW/L")
        ax.set_ylabel("H_mid/L")
        legend(ax, 7)
    fig.tight_layout()
    return fig

