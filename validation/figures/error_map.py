"""The error map's figures: each model's wall time against its combined error per width, and per
dL/L and tolerance the cheapest model measured within the tolerance at each scene (W/L, L/b)."""
from __future__ import annotations

from ..table import fraction_label
from .style import pyplot

#: The error map's markers by model family (the ribbons: squares).
FAMILY_MARKERS = {"rod": "o", "plate": "^", "plate-midedge": "v", "fem": "D"}


def family_marker(model: str) -> str:
    return FAMILY_MARKERS.get(model, "s")


def map_speed_accuracy(rows: list[dict], widths: list[float], models: list[str], tolerance: float):
    """A panel per W/L in `widths`: each row's wall time against its combined error (1, faint,
    where a quantity is missing), filled at dL/L = 1/2, open at smaller dL/L; `tolerance` dashed;
    the colours in `models` order."""
    plt = pyplot()
    colours = {m: f"C{k}" for k, m in enumerate(models)}
    fig, axes = plt.subplots(1, len(widths), figsize=(3.0 * len(widths), 3.2), sharey=True, squeeze=False)
    for ax, w in zip(axes[0], widths):
        for r in rows:
            if abs(r["width_ratio"] - w) > 1e-6:
                continue
            e = r["combined_error"]
            filled = r["compression_ratio"] > 0.4
            ax.scatter(r["wall_time_s"], e if e is not None else 1.0, marker=family_marker(r["model"]), s=18,
                       facecolors=colours[r["model"]] if filled else "none", edgecolors=colours[r["model"]],
                       alpha=0.85 if e is not None else 0.3)
        ax.axhline(tolerance, color="0.5", lw=0.6, ls="--")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_title(f"W/L = {fraction_label(w)}", fontsize=9)
        ax.set_xlabel("wall time (s)", fontsize=8)
        ax.tick_params(labelsize=7)
    axes[0, 0].set_ylabel("max over dW1, dW2, H_mid of\nerror + reference error bar (/L)", fontsize=8)
    handles = [plt.Line2D([], [], ls="", marker=family_marker(m), color=colours[m], label=m) for m in models]
    fig.legend(handles=handles, loc="upper center", ncol=len(models), fontsize=7, frameon=False)
    fig.text(0.01, 0.01, "the paper's L/b only; filled: dL/L = 1/2, open: smaller; faint at 1: a quantity missing; "
             f"dashed: {tolerance:g}", fontsize=6)
    fig.tight_layout(rect=(0, 0.03, 1, 0.9))
    return fig


def enough_map(rows: list[dict], compressions: list[float], tolerances: list[float], models: list[str]):
    """A panel per dL/L (rows) and tolerance (columns): at each scene (W/L, L/b) the cheapest model
    within the tolerance, named with its resolution ("none" and a cross where none is), open where
    the scene is held out; the colours in `models` order."""
    plt = pyplot()
    colours = {m: f"C{k}" for k, m in enumerate(models)}
    fig, axes = plt.subplots(len(compressions), len(tolerances), figsize=(4.2 * len(tolerances),
                                                                          3.2 * len(compressions)), squeeze=False)
    for i, c in enumerate(compressions):
        for j, tol in enumerate(tolerances):
            ax = axes[i, j]
            for r in rows:
                if r["compression_ratio"] != c or r["tolerance"] != tol:
                    continue
                x, y, model = r["width_ratio"], r["slenderness"], r["model"]
                label = "none" if model is None else f"{model}\n{r['resolution_label']}"
                colour = "0.6" if model is None else colours[model]
                marker = "x" if model is None else family_marker(model)
                ax.scatter(x, y, marker=marker, color=colour, s=40,
                           facecolors="none" if r["role"] == "held-out" else colour)
                ax.annotate(label, (x, y), textcoords="offset points", xytext=(4, 4), fontsize=6)
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_xlabel("W/L", fontsize=8)
            ax.set_ylabel("L/b", fontsize=8)
            ax.set_title(f"dL/L = {fraction_label(c)}: cheapest DDG model (else FEM mesh)\nwithin {tol:g} on dW1, "
                         "dW2 and H_mid (measured there)", fontsize=7)
            ax.tick_params(labelsize=7)
    fig.tight_layout()
    return fig
