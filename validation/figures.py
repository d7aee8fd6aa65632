"""The report's figures, each drawn from its data alone: draw(FigureData) -> matplotlib figure.

A drawing function takes the figure's rows (the rows of its CSV, as dicts) and its marks
(validation/report_data.py FigureData), never a run; so every number a figure shows is in its
data, and a figure can be drawn from hand-made rows. matplotlib is imported lazily (the `report`
extra).
"""
from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from .report_data import FigureData, fraction

COLORS = {"rod": "tab:blue", "plate": "tab:orange", "ribbon": "tab:green", "fem": "black",
          "ribbon-sano-wada": "tab:olive", "ribbon-trapeze": "tab:purple", "ribbon-wunderlich": "tab:brown",
          "fem (extrapolated)": "black"}
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
def elastica(rows: list[dict], exact: list[tuple[float, float]]):
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(5, 3.6))
    ax.plot(*zip(*exact), "k-", lw=1, label="exact elastica")
    for (model, width), sel in _groups(rows, "model", "width_ratio"):
        dl, h = [r["dL_over_L"] for r in sel], [r["H_mid_over_L"] for r in sel]
        if model == "fem":
            ax.plot(dl, h, "s", mfc="none", ms=5, color="k", label=f"FEM W/L={fraction(width)}")
        else:
            ax.plot(dl, h, "o", ms=3, color=COLORS[model], label=f"{model} W/L={fraction(width)}")
    ax.set_xlabel("dL/L")
    ax.set_ylabel("H_mid/L")
    ax.legend(fontsize=7)
    return fig


def _shear_panel(ax, rows: list[dict], column: str, thresholds: list[dict]) -> None:
    """`column` against dW/L per model (FEM as points), each model's dW1 (dotted) and dW2 (dashed)."""
    for (model,), sel in _groups(rows, "model"):
        dw, y = [r["dW_over_L"] for r in sel], [r[column] for r in sel]
        if model == "fem":
            ax.plot(dw, y, "k.", ms=3, label="FEM")
            continue
        ax.plot(dw, y, "-", color=COLORS[model], label=model)
        for t in (t for t in thresholds if t["model"] == model):
            for key, style in (("dW1_over_L", ":"), ("dW2_over_L", "--")):
                if t[key] is not None:
                    ax.axvline(t[key], color=COLORS[model], ls=style, lw=0.8)


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
        ax.set_xlabel("dW/L")
        ax.set_ylabel("H_mid/L")
        ax.legend(fontsize=6)
    fig.tight_layout()
    return fig


def shear_force(rows: list[dict], panels: list[tuple[float, float]], thresholds: list[dict]):
    plt = _pyplot()
    fig, axes = _panel_grid(plt, len(panels), len(panels), (4.5, 3.4))
    for ax, (compression, width) in zip(axes, panels):
        _shear_panel(ax, _in_panel(rows, compression, width), "F_shear_norm", _in_panel(thresholds, compression, width))
        ax.set_yscale("symlog", linthresh=1.0)
        ax.set_title(f"W/L = {fraction(width)}, dL/L = {fraction(compression)}", fontsize=9)
        ax.set_xlabel("dW/L")
        ax.set_ylabel("F_shear L/(E b^3)")
        ax.legend(fontsize=7)
    fig.tight_layout()
    return fig


def thresholds(rows: list[dict], compressions: list[float], dW_max: dict, paper: list[dict]):
    plt = _pyplot()
    fig, axes = plt.subplots(1, len(compressions), figsize=(4.5 * len(compressions), 3.6), squeeze=False)
    for ax, compression in zip(axes.flat, compressions):
        ax.plot(*zip(*dW_max[compression]), "k-", lw=0.8, label="dW_max (Eq. B.1)")
        for (model,), sel in _groups([r for r in rows if r["compression_ratio"] == compression], "model"):
            for key, marker in (("dW1_over_L", "o-"), ("dW2_over_L", "s--")):
                pts = [(r["width_ratio"], r[key]) for r in sel if r[key] is not None]
                if pts:
                    ax.plot(*zip(*pts), marker, color=COLORS[model], ms=4, label=f"{model} {key[:3]}")
        for p in (p for p in paper if p["compression_ratio"] == compression):
            ax.plot([p["width_ratio"]], [p["value"]], "v" if p["key"] == "dW1" else "^", color="crimson", ms=7)
        ax.set_title(f"dL/L = {fraction(compression)} (red: paper)", fontsize=9)
        ax.set_xlabel("W/L")
        ax.set_ylabel("threshold dW/L")
        ax.legend(fontsize=6)
    fig.tight_layout()
    return fig


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
    axes[0].set_ylabel("|H_mid / H_elastica - 1| after compression")
    axes[1].set_xlabel("resolution")
    axes[1].set_ylabel("max |H_mid(dW) - finest| / L")
    for ax in axes:
        ax.legend(fontsize=7)
    fig.tight_layout()
    return fig


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
            sel = sorted((p for p in pts if p[2]["model"] == model), key=lambda p: p[2]["resolution"])
            ax.loglog([p[0] for p in sel], [p[1] for p in sel], "o-", color=COLORS[model], label=model)
            for p in sel:
                ax.annotate(str(p[2]["resolution"]), (p[0], p[1]), fontsize=6)
        front = pareto([(p[0], p[1]) for p in pts])
        if front:
            fp = sorted((pts[i][0], pts[i][1]) for i in front)
            ax.plot(*zip(*fp), "k--", lw=0.8, label="Pareto front")
        ax.set_xlabel("wall time of the full path (s)")
        ax.set_ylabel(label)
        ax.legend(fontsize=7)
    fig.suptitle(f"W/L = 1/6, dL/L = 1/2; reference: {reference}", fontsize=8)
    fig.tight_layout()
    return fig


def stability_map(rows: list[dict]):
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7, 3.6))
    for entry in rows:
        cat = next((i for i, c in enumerate(STABILITY_CATEGORIES) if entry["outcome"].startswith(c)), 0)
        if "width error" in entry["outcome"]:
            cat = STABILITY_CATEGORIES.index("rod width error")
        row = {"rod": 0, "plate": 1, "ribbon": 2}.get(entry["model"], 3)
        y = row + (0.25 if entry["compression_ratio"] == 0.25 else 0)
        ax.scatter(entry["width_ratio"], y, c=STABILITY_COLORS[cat],
                   s=30 + 40 * (entry["reached_percent_of_dW_max"] or 0) / 100)
    for c, col in zip(STABILITY_CATEGORIES, STABILITY_COLORS):
        ax.scatter([], [], c=col, label=c)
    ax.set_yticks([0, 1, 2])
    ax.set_yticklabels(["rod", "plate", "ribbon"])
    ax.set_xlabel("W/L (upper row of each model: dL/L = 1/4)")
    ax.legend(fontsize=6, loc="upper right")
    return fig


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


DRAW = {"elastica": elastica, "shear_curves": shear_curves, "shear_force": shear_force, "thresholds": thresholds,
        "convergence": convergence, "poisson": poisson, "speed_accuracy": speed_accuracy,
        "stability_map": stability_map, "snapshots": snapshots, "wide_ribbons": wide_ribbons}


def draw(data: FigureData):
    """The matplotlib figure of `data`, from its rows and marks only."""
    return DRAW[data.kind](data.records(), **data.marks)


def save(fig, directory: Path, name: str) -> bytes:
    """DIR/<name>.png (110 dpi) and .pdf; the figure is closed; returns the PNG bytes."""
    plt = _pyplot()
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110, bbox_inches="tight")
    png = buf.getvalue()
    (directory / f"{name}.png").write_bytes(png)
    fig.savefig(directory / f"{name}.pdf", bbox_inches="tight")
    plt.close(fig)
    return png
