"""Figures of the runs themselves: convergence with resolution, speed against accuracy with its
Pareto front, and the stability map (where each model fails and how)."""
from __future__ import annotations

import numpy as np

from .style import COLORS, MARKERS, groups, legend, pyplot


def pareto(points: list[tuple[float, float]]) -> list[int]:
    """Indices of the points no other point beats in both time and error."""
    keep = []
    for i, (t, e) in enumerate(points):
        if not any((t2 <= t and e2 <= e) and (t2 < t or e2 < e) for j, (t2, e2) in enumerate(points) if j != i):
            keep.append(i)
    return keep


def convergence(rows: list[dict]):
    plt = pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.4))
    for (model,), sel in sorted(groups(rows, "model")):
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
        legend(ax, 7)
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


def speed_accuracy(rows: list[dict], reference: str):
    plt = pyplot()
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


STABILITY_CATEGORIES = ["ok", "ok (mesh unresolved near dW_max)", "missed pitchfork", "dW1 unresolved by the mesh",
                        "rod width error", "Newton failure"]


STABILITY_COLORS = ["tab:green", "yellowgreen", "tab:red", "tab:orange", "tab:purple", "black"]


def stability_map(rows: list[dict]):
    plt = pyplot()
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

