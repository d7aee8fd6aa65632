"""Figures of the deformed strip: 3D snapshots of U, US and S plates, the plate's mesh beside its
centreline rendering (Eq. 12), the centreline approximation's error (Eq. 13) over the plate and
against L/W, and the curvature profiles along the strip (paper Figs. 1, 9a, 9b, 10, A.12-14)."""
from __future__ import annotations

import numpy as np

from ..table import fraction
from .style import COLORS, MARKERS, groups, legend, pyplot


def snapshots(rows: list[dict], panels: list[dict]):
    """3D shapes, one row of panels per width: rendered with pyvista (lit surfaces, one camera and
    one colour scale for all panels, clamps drawn; ddg.output.render) when the render extra is
    installed, else matplotlib 3D surfaces from the rows. The frames also open in ParaView."""
    plt = pyplot()
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
    pyplot()
    from ddg.cli import centerline_error_figure

    return centerline_error_figure(rows, sorted({r["dW_over_L"] for r in rows}))


def curvature_profiles(rows: list[dict]):
    """Figs. A.12-14: k1 L, k2 L, tau L against s/L, a row per curvature, a column per dW/L, a
    line per model."""
    plt = pyplot()
    shears = sorted({round(float(r["dW_over_L"]), 6) for r in rows})
    names = (("k1_L", "k1 L (geodesic)"), ("k2_L", "k2 L (normal)"), ("tau_L", "tau L (twist)"))
    fig, axes = plt.subplots(3, len(shears), figsize=(3.6 * len(shears), 6.6), squeeze=False, sharex=True)
    for j, shear in enumerate(shears):
        for (model,), sel in groups([r for r in rows if abs(float(r["dW_over_L"]) - shear) < 1e-9], "model"):
            sel = sorted(sel, key=lambda r: r["s_over_L"])
            for i, (key, _) in enumerate(names):
                axes[i][j].plot([r["s_over_L"] for r in sel], [r[key] for r in sel], MARKERS.get(model, "o") + "-",
                                ms=2, lw=0.8, color=COLORS.get(model, "gray"), label=model)
        axes[0][j].set_title(f"dW/L = {shear:g}", fontsize=9)
        axes[-1][j].set_xlabel("s/L")
    for i, (_, label) in enumerate(names):
        axes[i][0].set_ylabel(label, fontsize=8)
    legend(axes[0][0], 6.5)
    fig.tight_layout()
    return fig


def centerline_error_field(rows: list[dict]):
    """Fig. 9b: delta(s, w) in % of L on the flat strip, a row of panels per W/L, a column per
    dW/L, one colour scale (log) for all."""
    import matplotlib.colors as mcolors
    import matplotlib.tri as mtri

    plt = pyplot()
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

    plt = pyplot()
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

