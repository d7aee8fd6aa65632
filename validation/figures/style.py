"""The figures' shared style: each model's colour and marker, matplotlib loaded lazily, rows grouped
by columns, panel grids and legends with one entry per label."""
from __future__ import annotations

COLORS = {"rod": "tab:blue", "plate": "tab:orange", "plate-midedge": "tab:red", "ribbon": "tab:green", "fem": "black",
          "ribbon-sano-wada": "tab:olive", "ribbon-trapeze": "tab:purple", "ribbon-cross-section": "tab:pink",
          "ribbon-wunderlich": "tab:brown",
          "fem (extrapolated)": "black", "fem (converged)": "black", "plate (converged)": "tab:orange"}
MARKERS = {"rod": "o", "plate": "s", "plate-midedge": "h", "ribbon": "^", "fem": "D", "ribbon-sano-wada": "v",
           "ribbon-trapeze": "P", "ribbon-cross-section": "*", "ribbon-wunderlich": "X"}


def pyplot():
    """matplotlib.pyplot on the Agg backend (imported here, where drawing happens: the `report` and
    `plot` extras)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def groups(rows: list[dict], *keys: str) -> list[tuple[tuple, list[dict]]]:
    """Rows grouped by `keys`, groups in order of first appearance."""
    found: dict[tuple, list[dict]] = {}
    for r in rows:
        found.setdefault(tuple(r[k] for k in keys), []).append(r)
    return list(found.items())


def panel_grid(plt, count: int, cols: int, size: tuple[float, float]):
    """`count` panels in rows of `cols`, each `size` inches; the unused ones hidden."""
    nrows = -(-count // cols)
    fig, axes = plt.subplots(nrows, cols, figsize=(size[0] * cols, size[1] * nrows), squeeze=False)
    for ax in list(axes.flat)[count:]:
        ax.set_visible(False)
    return fig, list(axes.flat)[:count]


def in_panel(items: list[dict], compression: float, width: float) -> list[dict]:
    """The items of one scene (dL/L, W/L)."""
    return [r for r in items if r["compression_ratio"] == compression and r["width_ratio"] == width]


def legend_entries(axes) -> dict:
    """label -> handle over `axes`, one per label, in order of first appearance."""
    seen = {}
    for ax in axes:
        for h, label in zip(*ax.get_legend_handles_labels()):
            seen.setdefault(label, h)
    return seen


def legend(ax, size: float = 6.5, outside: bool = False, others=()) -> None:
    """One entry per label (the threshold lines repeat them; `others`: more axes whose entries it
    shows too): where it hides least, or beside the axes."""
    seen = legend_entries([*others, ax])
    if not seen:
        return
    if outside:
        ax.legend(list(seen.values()), list(seen), fontsize=size, loc="center left", bbox_to_anchor=(1.01, 0.5))
    else:
        ax.legend(list(seen.values()), list(seen), fontsize=size, framealpha=0.85, loc="best")
