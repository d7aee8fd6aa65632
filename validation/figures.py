"""The report's figures, each drawn from its data alone: draw(FigureData) -> matplotlib figure.

A drawing function takes the figure's rows (the rows of its CSV, as dicts) and its marks
(validation/report_data.py FigureData), never a run; so every number a figure shows is in its
data, and a figure can be drawn from hand-made rows. matplotlib is imported lazily (the `report`
extra).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .report_data import FigureData, fraction

COLORS = {"rod": "tab:blue", "plate": "tab:orange", "plate-midedge": "tab:red", "ribbon": "tab:green", "fem": "black",
          "ribbon-sano-wada": "tab:olive", "ribbon-trapeze": "tab:purple", "ribbon-cross-section": "tab:pink",
          "ribbon-wunderlich": "tab:brown",
          "fem (extrapolated)": "black", "fem (converged)": "black", "plate (converged)": "tab:orange"}
STABILITY_CATEGORIES = ["ok", "ok (mesh unresolved near dW_max)", "missed pitchfork", "dW1 unresolved by the mesh",
                        "rod width error", "Newton failure"]
STABILITY_COLORS = ["tab:green", "yellowgreen", "tab:red", "tab:orange", "tab:purple", "black"]


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _groups(rows: list[dict], *keys: str) -> list[tuple[tuple, list[dict]]]:
    """Rows grouped by `keys`, groups in order of first appearance."""
    groups: dict[tuple, list[dict]] = {}
    for r in rows:
        groups.setdefault(tuple(r[k] for k in keys), []).append(r)
    return list(groups.items())


def pareto(points: list[tuple[float, float]]) -> list[int]:
    """Indices of the points no other point beats in both time and error."""
    keep = []
    for i, (t, e) in enumerate(points):
        if not any((t2 <= t and e2 <= e) and (t2 < t or e2 < e) for j, (t2, e2) in enumerate(points) if j != i):
            keep.append(i)
    return keep


# ---------------------------------------------------------------------------- one function per kind
MARKERS = {"rod": "o", "plate": "s", "plate-midedge": "h", "ribbon": "^", "fem": "D", "ribbon-sano-wada": "v",
           "ribbon-trapeze": "P", "ribbon-cross-section": "*", "ribbon-wunderlich": "X"}


def elastica(rows: list[dict], exact: list[tuple[float, float]]):
    """Fig. 5b: H_mid/L against dL/L per model (its own marker) on the exact elastica, and below
    the residual H_mid - H_elastica (errors ~1e-4 L are invisible on the curve)."""
    plt = _pyplot()
    fig, (ax, res) = plt.subplots(2, 1, figsize=(5.2, 5.2), sharex=True, gridspec_kw={"height_ratios": [2, 1.3]})
    ex = np.array(sorted(exact))
    ax.plot(ex[:, 0], ex[:, 1], "k-", lw=1, label="exact elastica")
    for (model, width), sel in _groups(rows, "model", "width_ratio"):
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
    for (model,), sel in _groups(rows, "model"):
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


def _panel_grid(plt, count: int, cols: int, size: tuple[float, float]):
    nrows = -(-count // cols)
    fig, axes = plt.subplots(nrows, cols, figsize=(size[0] * cols, size[1] * nrows), squeeze=False)
    for ax in list(axes.flat)[count:]:
        ax.set_visible(False)
    return fig, list(axes.flat)[:count]


def _in_panel(items: list[dict], compression: float, width: float) -> list[dict]:
    return [r for r in items if r["compression_ratio"] == compression and r["width_ratio"] == width]


def shear_curves(rows: list[dict], panels: list[tuple[float, float]], thresholds: list[dict], paper: list[dict]):
    plt = _pyplot()
    fig, axes = _panel_grid(plt, len(panels), min(3, len(panels)), (4.2, 3.3))
    for ax, (compression, width) in zip(axes, panels):
        _shear_panel(ax, _in_panel(rows, compression, width), "H_mid_over_L", _in_panel(thresholds, compression, width))
        for p in (p for p in paper if p["width_ratio"] == width):
            ax.plot([p["value"]], [0.0], "v" if p["key"] == "dW1" else "^", color="crimson", ms=7,
                    label=f"paper {p['key']}")
        ax.set_title(f"W/L = {fraction(width)}, dL/L = {fraction(compression)}", fontsize=9)
        ax.set_xlabel("dW/L (dotted: dW1, dashed: dW2 of the model in its colour)", fontsize=7)
        ax.set_ylabel("H_mid/L")
        _legend(ax)
    fig.tight_layout()
    return fig


def _legend_entries(axes) -> dict:
    """label -> handle over `axes`, one per label, in order of first appearance."""
    seen = {}
    for ax in axes:
        for h, label in zip(*ax.get_legend_handles_labels()):
            seen.setdefault(label, h)
    return seen


def _legend(ax, size: float = 6.5, outside: bool = False, others=()) -> None:
    """One entry per label (the threshold lines repeat them; `others`: more axes whose entries it
    shows too): where it hides least, or beside the axes."""
    seen = _legend_entries([*others, ax])
    if not seen:
        return
    if outside:
        ax.legend(list(seen.values()), list(seen), fontsize=size, loc="center left", bbox_to_anchor=(1.01, 0.5))
    else:
        ax.legend(list(seen.values()), list(seen), fontsize=size, framealpha=0.85, loc="best")


#: Shading of the mesh studies' converged curves
BAND_COLORS = {"fem (converged)": "0.35", "plate (converged)": "tab:orange"}


def shear_force(rows: list[dict], panels: list[tuple[float, float]], thresholds: list[dict]):
    """Runs' forces as curves; the rows of a mesh study's converged force (model "... (converged)",
    with error_bar) as a band of +- the error bar."""
    plt = _pyplot()
    fig, axes = _panel_grid(plt, len(panels), min(2, len(panels)), (4.8, 3.4))
    studies = [r for r in rows if str(r["model"]).endswith("(converged)")]
    runs = [r for r in rows if not str(r["model"]).endswith("(converged)")]
    for ax, (compression, width) in zip(axes, panels):
        for (model,), sel in _groups(_in_panel(studies, compression, width), "model"):
            dw = np.array([b["dW_over_L"] for b in sel])
            v, e = np.array([b["F_shear_norm"] for b in sel]), np.array([b["error_bar"] for b in sel])
            ax.fill_between(dw, v - e, v + e, color=BAND_COLORS.get(model, "gray"), alpha=0.3, lw=0,
                            label=f"{model} +- error bar")
        mine = _in_panel(runs, compression, width)
        _shear_panel(ax, mine, "F_shear_norm", _in_panel(thresholds, compression, width))
        ax.set_yscale("symlog", linthresh=1.0)
        # the bands (and a non-asymptotic extrapolation) may dip far below zero where an error bar
        # exceeds the force (near dW_max): the axis stops a little below the runs' lowest force
        lowest = min([0.0] + [float(r["F_shear_norm"]) for r in mine])
        ax.set_ylim(bottom=lowest - 0.2)
        ax.set_title(f"W/L = {fraction(width)}, dL/L = {fraction(compression)}", fontsize=9)
        ax.set_xlabel("dW/L")
        ax.set_ylabel("F_shear L/(E b^3)\n(symlog: linear for |F| < 1, log beyond)", fontsize=8)
    seen = _legend_entries(axes)   # one legend for all panels, beside them
    fig.tight_layout(rect=(0, 0, 0.8, 1))
    fig.legend(list(seen.values()), list(seen), fontsize=7, loc="center left", bbox_to_anchor=(0.8, 0.5))
    return fig


def thresholds(rows: list[dict], compressions: list[float], dW_max: dict, paper: list[dict]):
    plt = _pyplot()
    fig, axes = plt.subplots(1, len(compressions), figsize=(4.5 * len(compressions), 3.6), squeeze=False)
    for ax, compression in zip(axes.flat, compressions):
        ax.plot(*zip(*dW_max[compression]), "k-", lw=0.8, label="dW_max (Eq. B.1)")
        for (model,), sel in _groups([r for r in rows if r["compression_ratio"] == compression], "model"):
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
    _legend(list(axes.flat)[-1], 6.5, outside=True, others=list(axes.flat)[:-1])
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
    plt = _pyplot()
    fig, axes = plt.subplots(1, len(compressions), figsize=(4.8 * len(compressions), 3.8), squeeze=False)
    for ax, compression in zip(axes.flat, compressions):
        for (model,), sel in _groups([r for r in rows if r["compression_ratio"] == compression], "model"):
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


def convergence(rows: list[dict]):
    plt = _pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.4))
    for (model,), sel in sorted(_groups(rows, "model")):
        n = [d["resolution"] for d in sel]
        axes[0].loglog(n, [abs(d["elastica_rel_error"]) for d in sel], "o-", color=COLORS[model], label=model)
        pts = [(d["resolution"], d["curve_error_vs_finest"]) for d in sel if d["curve_error_vs_finest"]]
        if pts:
            axes[1].loglog(*zip(*pts), "o-", color=COLORS[model], label=model)
    axes[0].set_xlabel("resolution (rod nodes M / plate triangles)")
    axes[0].set_ylabel("|H_mid / H_elastica - 1|\nafter compression", fontsize=8)
    axes[1].set_xlabel("resolution (rod nodes M / plate triangles)")
    axes[1].set_ylabel("max |H_mid(dW) - finest| / L", fontsize=8)
    for ax in axes:
        _slope_guides(ax)
        _legend(ax, 7)
    fig.tight_layout()
    return fig


def _slope_guides(ax) -> None:
    """Dashed lines of slope -1 and -2 (error ~ N^-1, N^-2) through the upper right of the data."""
    lines = [line for line in ax.get_lines() if len(line.get_xdata())]
    if not lines:
        return
    x = np.concatenate([np.asarray(line.get_xdata(), float) for line in lines])
    y = np.concatenate([np.asarray(line.get_ydata(), float) for line in lines])
    ok = (x > 0) & (y > 0)
    if ok.sum() < 2:
        return
    x0, x1 = np.min(x[ok]), np.max(x[ok])
    y0 = np.max(y[ok])
    for order, style in ((1, (0, (4, 3))), (2, (0, (1, 2)))):
        xs = np.array([x0, x1])
        ax.plot(xs, y0 * (xs / x0) ** (-order), color="0.5", ls=style, lw=0.8, label=f"slope -{order}")


def poisson(rows: list[dict]):
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(5, 3.6))
    for (nu,), sel in _groups(rows, "poisson_ratio"):
        ax.plot([r["dW_over_L"] for r in sel], [r["H_mid_over_L"] for r in sel], "-", label=f"nu = {nu:g}")
    ax.set_xlabel("dW/L")
    ax.set_ylabel("H_mid/L")
    ax.legend(fontsize=7)
    return fig


def speed_accuracy(rows: list[dict], reference: str):
    plt = _pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.6))
    for ax, key, label in ((axes[0], "curve_error", "max |H_mid error| / L"),
                           (axes[1], "dW1_error", "|dW1 error| / L")):
        pts = [(d["wall_time_s"], d[key], d) for d in rows if d[key] and d["wall_time_s"]]
        for model in sorted({p[2]["model"] for p in pts}):
            # by wall time: a mesh sequence's order (resolutions may be labels such as "96x12")
            sel = sorted((p for p in pts if p[2]["model"] == model), key=lambda p: p[0])
            base = model.removesuffix(" (benchmark)")   # the benchmark's entries: the model's colour, stars
            marker = "*" if base != model else MARKERS.get(model, "o")
            color = COLORS.get(base, "gray")
            # one line through a mesh sequence; the shell's stored meshes (several series, labels such
            # as "96x12", their studies' wall times) as points
            joined = base != model or all(isinstance(p[2]["resolution"], (int, float)) for p in sel)
            ax.loglog([p[0] for p in sel], [p[1] for p in sel], marker + ("-" if joined else ""), color=color,
                      label=model)
            for k, p in enumerate(sel):   # alternate above / below the point so neighbours do not overlap
                ax.annotate(str(p[2]["resolution"]), (p[0], p[1]), xytext=(4, 5 if k % 2 == 0 else -9),
                            textcoords="offset points", fontsize=6, color=color)
        front = pareto([(p[0], p[1]) for p in pts])
        if front:
            fp = sorted((pts[i][0], pts[i][1]) for i in front)
            ax.plot(*zip(*fp), "k--", lw=0.8, label="Pareto front")
        ax.set_xlabel("wall time of the full path (s)")
        ax.set_ylabel(label)
        ax.legend(fontsize=7)
    fig.suptitle(f"W/L = 1/6, dL/L = 1/2; reference: {reference}\nwall times as each run measured them ("
                 "'(benchmark)': benchmarks/speed_accuracy.py, idle machine; labels: resolution or rows)", fontsize=7)
    fig.tight_layout()
    return fig


def stability_map(rows: list[dict]):
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7, 3.6))
    placed: dict[tuple, int] = {}
    for entry in rows:
        cat = stability_category(entry["outcome"])
        row = {"rod": 0, "plate": 1, "ribbon": 2}.get(entry["model"], 3)
        y = row + (0.25 if entry["compression_ratio"] == 0.25 else 0)
        key = (round(float(entry["width_ratio"]), 6), y)
        shift = placed.get(key, 0)     # several runs of one scene (resolutions): side by side
        placed[key] = shift + 1
        x = float(entry["width_ratio"]) * (1.0 + 0.06 * shift)
        ax.scatter(x, y + 0.07 * shift, c=STABILITY_COLORS[cat], edgecolors="k", linewidths=0.4, alpha=0.85,
                   s=25 + 35 * (entry["reached_percent_of_dW_max"] or 0) / 100, zorder=3)
    for c, col in zip(STABILITY_CATEGORIES, STABILITY_COLORS):
        ax.scatter([], [], c=col, label=c)
    ax.set_yticks([0, 1, 2, 3])
    ax.set_yticklabels(["rod", "plate", "ribbon", "ribbons with width"])
    ax.set_xlabel("W/L (upper row of each model: dL/L = 1/4)")
    ax.legend(fontsize=6, loc="upper right")
    return fig


def stability_category(outcome: str) -> int:
    """Index in STABILITY_CATEGORIES of an outcome: the longest category it starts with ("ok (mesh
    unresolved near dW_max)" is not plain "ok"); an outcome naming the rod's width error is that."""
    if "width error" in outcome:
        return STABILITY_CATEGORIES.index("rod width error")
    matches = [i for i, c in enumerate(STABILITY_CATEGORIES) if outcome.startswith(c)]
    return max(matches, key=lambda i: len(STABILITY_CATEGORIES[i]), default=0)


def snapshots(rows: list[dict], panels: list[dict]):
    """3D shapes, one row of panels per width: rendered with pyvista (lit surfaces, one camera and
    one colour scale for all panels, clamps drawn; ddg.output.render) when the render extra is
    installed, else matplotlib 3D surfaces from the rows. The frames also open in ParaView."""
    plt = _pyplot()
    widths = sorted({p["width_ratio"] for p in panels})
    cols = max(sum(1 for p in panels if p["width_ratio"] == w) for w in widths)
    rendered = _rendered_snapshots(panels, widths, cols)
    if rendered is not None:
        fig = plt.figure(figsize=(rendered.shape[1] / 110, rendered.shape[0] / 110))
        ax = fig.add_axes([0, 0, 1, 1])
        ax.imshow(rendered)
        ax.set_axis_off()
        return fig
    fig = plt.figure(figsize=(4.0 * cols, 3.0 * len(widths)))
    for i, width in enumerate(widths):
        for j, panel in enumerate([p for p in panels if p["width_ratio"] == width]):
            keys = ("compression_ratio", "width_ratio", "phase", "dW_over_L")
            xyz = np.array([[r["x_over_L"], r["y_over_L"], r["z_over_L"]] for r in rows
                            if all(r[k] == panel[k] for k in keys)])
            ax = fig.add_subplot(len(widths), cols, i * cols + j + 1, projection="3d")
            ax.plot_trisurf(xyz[:, 0], xyz[:, 1], xyz[:, 2], triangles=panel["triangles"], cmap="viridis",
                            linewidth=0.1, edgecolor="0.3", antialiased=True)
            ax.set_box_aspect(np.maximum(np.ptp(xyz, axis=0), 0.05))
            ax.view_init(elev=25, azim=-60)
            ax.set_title(f"W/L = {fraction(width)}: {panel['phase']}, dW/L = {panel['dW_over_L']:.3f}", fontsize=9)
            ax.set_xlabel("x/L", fontsize=7)
            ax.set_ylabel("y/L", fontsize=7)
            ax.set_zlabel("z/L", fontsize=7)
            ax.tick_params(labelsize=6)
    fig.tight_layout()
    return fig


def _rendered_snapshots(panels: list[dict], widths: list[float], cols: int):
    """The panels drawn by pyvista as one RGB image, or None without the render extra."""
    from ddg.geometry.strip import InputError

    if any("frame" not in p for p in panels):
        return None
    try:
        from ddg.output.render import render_grid

        grid = []
        for width in widths:
            row = [(p["frame"], f"W/L = {fraction(width)}: {p['phase']}, dW/L = {p['dW_over_L']:.3f}")
                   for p in panels if p["width_ratio"] == width]
            grid += row + [None] * (cols - len(row))
        return render_grid(grid, None, columns=cols)
    except InputError:  # the render extra (pyvista) is not installed
        return None


def centerline_error(rows: list[dict]):
    """Fig. 10: drawn as `ddg centerline-error` draws it (ddg.cli.centerline_error_figure: mean and
    largest delta of Eq. 13 in % of L against L/W on log axes, one colour per dW/L)."""
    _pyplot()
    from ddg.cli import centerline_error_figure

    return centerline_error_figure(rows, sorted({r["dW_over_L"] for r in rows}))


def curvature_profiles(rows: list[dict]):
    """Figs. A.12-14: k1 L, k2 L, tau L against s/L, a row per curvature, a column per dW/L, a
    line per model."""
    plt = _pyplot()
    shears = sorted({round(float(r["dW_over_L"]), 6) for r in rows})
    names = (("k1_L", "k1 L (geodesic)"), ("k2_L", "k2 L (normal)"), ("tau_L", "tau L (twist)"))
    fig, axes = plt.subplots(3, len(shears), figsize=(3.6 * len(shears), 6.6), squeeze=False, sharex=True)
    for j, shear in enumerate(shears):
        for (model,), sel in _groups([r for r in rows if abs(float(r["dW_over_L"]) - shear) < 1e-9], "model"):
            sel = sorted(sel, key=lambda r: r["s_over_L"])
            for i, (key, _) in enumerate(names):
                axes[i][j].plot([r["s_over_L"] for r in sel], [r[key] for r in sel], MARKERS.get(model, "o") + "-",
                                ms=2, lw=0.8, color=COLORS.get(model, "gray"), label=model)
        axes[0][j].set_title(f"dW/L = {shear:g}", fontsize=9)
        axes[-1][j].set_xlabel("s/L")
    for i, (_, label) in enumerate(names):
        axes[i][0].set_ylabel(label, fontsize=8)
    _legend(axes[0][0], 6.5)
    fig.tight_layout()
    return fig


def centerline_error_field(rows: list[dict]):
    """Fig. 9b: delta(s, w) in % of L on the flat strip, a row of panels per W/L, a column per
    dW/L, one colour scale (log) for all."""
    import matplotlib.colors as mcolors
    import matplotlib.tri as mtri

    plt = _pyplot()
    widths = sorted({r["W_over_L"] for r in rows})
    shears = sorted({r["dW_over_L"] for r in rows})
    values = np.array([r["delta_percent"] for r in rows], dtype=float)
    positive = values[values > 0]
    norm = mcolors.LogNorm(vmin=max(positive.min(), positive.max() * 1e-4), vmax=positive.max())
    fig, axes = plt.subplots(len(widths), len(shears), figsize=(4.6 * len(shears), 1.0 + 1.6 * len(widths)),
                             squeeze=False)
    fig.subplots_adjust(hspace=0.75, wspace=0.25, right=0.82)
    image = None
    for i, width in enumerate(widths):
        for j, shear in enumerate(shears):
            sel = [r for r in rows if r["W_over_L"] == width and r["dW_over_L"] == shear]
            ax = axes[i][j]
            if not sel:
                ax.set_visible(False)
                continue
            s = np.array([r["s_over_L"] for r in sel])
            w = np.array([r["w_over_L"] for r in sel])
            raw = np.array([r["delta_percent"] for r in sel], dtype=float)
            image = ax.tripcolor(mtri.Triangulation(s, w), np.maximum(raw, norm.vmin), shading="gouraud", norm=norm,
                                 cmap="viridis")
            ax.set_title(f"W/L = {fraction(width)}, dW/L = {shear:g}: mean {np.mean(raw):.2g} %, max "
                         f"{np.max(raw):.2g} %", fontsize=8)
            ax.set_xlim(0, 1)
            ax.set_ylabel("w/L", fontsize=7)
            ax.tick_params(labelsize=6)
        axes[i][0].set_ylabel("w/L", fontsize=7)
    for ax in axes[-1]:
        ax.set_xlabel("s/L", fontsize=8)
    if image is not None:
        fig.colorbar(image, cax=fig.add_axes([0.85, 0.15, 0.02, 0.7]), label="delta (% of L), log scale")
    return fig


def deformed_plates(rows: list[dict], triangles: dict, stations_drawn: int = 12):
    """Fig. 9a: the plate's deformed mesh (blue) and its centreline rendering (red: the centreline,
    and at `stations_drawn` stations the line x + w m2, -W/2 <= w <= W/2, that Eq. (12) puts
    across the width), a row of panels per W/L, a column per dW/L; equal axes."""
    from mpl_toolkits.mplot3d.art3d import Line3DCollection

    plt = _pyplot()
    widths = sorted({r["W_over_L"] for r in rows})
    shears = sorted({r["dW_over_L"] for r in rows})
    fig = plt.figure(figsize=(4.6 * len(shears), 2.7 * len(widths)))
    for i, width in enumerate(widths):
        tri = np.asarray(triangles[width], dtype=int)
        edges = np.unique(np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1), axis=0)
        for j, shear in enumerate(shears):
            sel = [r for r in rows if r["W_over_L"] == width and r["dW_over_L"] == shear]
            nodes = sorted((r for r in sel if r["kind"] == "plate node"), key=lambda r: r["index"])
            line = sorted((r for r in sel if r["kind"] == "centreline"), key=lambda r: r["index"])
            if not nodes or not line:
                continue
            xyz = np.array([[r["x_over_L"], r["y_over_L"], r["z_over_L"]] for r in nodes])
            c = np.array([[r["x_over_L"], r["y_over_L"], r["z_over_L"]] for r in line])
            m2 = np.array([[r["m2_x"], r["m2_y"], r["m2_z"]] for r in line])
            ax = fig.add_subplot(len(widths), len(shears), i * len(shears) + j + 1, projection="3d")
            ax.add_collection3d(Line3DCollection(xyz[edges], colors="tab:blue", linewidths=0.25, alpha=0.7,
                                                 label="plate (DEP mesh)"))
            ax.plot(c[:, 0], c[:, 1], c[:, 2], "-", color="crimson", lw=1.4, label="centreline")
            pick = np.unique(np.linspace(0, len(c) - 1, stations_drawn).round().astype(int))
            across = np.stack([c[pick] - 0.5 * width * m2[pick], c[pick] + 0.5 * width * m2[pick]], axis=1)
            ax.add_collection3d(Line3DCollection(across, colors="crimson", linewidths=1.0,
                                                 label="x + w m2 (Eq. 12)"))
            lo, hi = xyz.min(axis=0), xyz.max(axis=0)
            for setter, a, b in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), lo, hi):
                setter(a, b)
            ax.set_box_aspect(np.maximum(hi - lo, 0.02))
            ax.view_init(elev=28, azim=-62)
            ax.set_title(f"W/L = {fraction(width)}, dW/L = {shear:g}", fontsize=9)
            ax.tick_params(labelsize=5, pad=0)
            ax.set_xlabel("x/L", fontsize=6, labelpad=-8)
            ax.set_ylabel("y/L", fontsize=6, labelpad=-8)
            ax.set_zlabel("z/L", fontsize=6, labelpad=-8)
            if i == 0 and j == 0:
                ax.legend(fontsize=6, loc="upper left")
    fig.tight_layout()
    return fig


A11_STYLES = {"rod": ("tab:blue", "-"), "plate": ("tab:orange", "-"), "ribbon_direct": ("tab:green", "--"),
              "ribbon_rod": ("tab:red", ":")}


def sadowsky_a11(rows: list[dict]):
    """Fig. A.11: H_mid/L against dW/L per model, one panel per W/L."""
    plt = _pyplot()
    widths = sorted({r["width_ratio"] for r in rows})
    fig, axes = _panel_grid(plt, len(widths), len(widths), (4.4, 3.4))
    for ax, width in zip(axes, widths):
        for (model,), sel in _groups([r for r in rows if r["width_ratio"] == width], "model"):
            colour, style = A11_STYLES.get(model, ("gray", "-"))
            sel = sorted(sel, key=lambda r: r["dW_over_L"])
            ax.plot([r["dW_over_L"] for r in sel], [r["H_mid_over_L"] for r in sel], style, color=colour, lw=1.3,
                    label=model.replace("_", " "))
        ax.set_title(f"W/L = {fraction(width)}, dL/L = 1/2", fontsize=9)
        ax.set_xlabel("dW/L")
        ax.set_ylabel("H_mid/L")
        _legend(ax, 7)
    fig.tight_layout()
    return fig


DRAW = {"elastica": elastica, "centerline_error": centerline_error, "curvature_profiles": curvature_profiles,
        "sadowsky_a11": sadowsky_a11, "centerline_error_field": centerline_error_field,
        "deformed_plates": deformed_plates, "shear_curves": shear_curves, "shear_force": shear_force,
        "thresholds": thresholds,
        "convergence": convergence, "poisson": poisson, "speed_accuracy": speed_accuracy,
        "stability_map": stability_map, "snapshots": snapshots, "wide_ribbons": wide_ribbons}


def draw(data: FigureData):
    """The matplotlib figure of `data`, from its rows and marks only."""
    return DRAW[data.kind](data.records(), **data.marks)


def save(fig, directory: Path, name: str) -> bytes:
    """DIR/<name>.png (110 dpi) and .pdf, byte-stable (ddg.output.io.save_figure); the figure is
    closed; returns the PNG bytes."""
    from ddg.output.io import save_figure

    plt = _pyplot()
    directory = Path(directory)
    png = save_figure(fig, directory / f"{name}.png", dpi=110, bbox_inches="tight").read_bytes()
    save_figure(fig, directory / f"{name}.pdf", bbox_inches="tight")
    plt.close(fig)
    return png
