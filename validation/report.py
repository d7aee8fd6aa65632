"""`python -m validation report`: run the models on the paper's scenes and write the report.

Output in DIR: index.html (self-contained: figures embedded), report.md, figures/<name>.png and
.pdf with figures/<name>.csv (every number behind each figure), tables as CSV, and summary.json
with the headline errors, the claims and the timings. Runs are cached in DIR/cache (validation/runs.py).
"""
from __future__ import annotations

import base64
import csv
import html
import io
import json
import math
import time
from pathlib import Path

import numpy as np

from ddg.analysis.analytic import clamped_elastica_midpoint_height
from ddg.geometry.strip import shear_limit
from ddg.output.io import atomic_write_text

from . import claims as C
from .reference import PAPER_DROPS_QUARTER, load_gold, paper_value
from .runs import run_all
from .studies import COMPRESSIONS, CROSS_MODEL_PLATE, PROFILES, SPEED_SCENE, specs

COLORS = {"rod": "tab:blue", "plate": "tab:orange", "ribbon": "tab:green", "fem": "black"}


def _fraction(x: float) -> str:
    for d in (2, 2.5, 3, 4, 5, 6, 8, 10, 12, 16, 20):
        if abs(x - 1 / d) < 1e-6:
            return f"1/{d:g}"
    return f"{x:.4g}"


class Figures:
    """Collects figures: PNG + PDF + CSV per figure in DIR/figures, and the PNGs for the HTML."""

    def __init__(self, out: Path):
        import matplotlib

        matplotlib.use("Agg")
        self.out = out / "figures"
        self.out.mkdir(parents=True, exist_ok=True)
        self.items: list[dict] = []

    def save(self, name: str, fig, columns: list[str], rows: list[list], caption: str) -> None:
        import matplotlib.pyplot as plt

        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=110, bbox_inches="tight")
        png = buf.getvalue()
        (self.out / f"{name}.png").write_bytes(png)
        fig.savefig(self.out / f"{name}.pdf", bbox_inches="tight")
        plt.close(fig)
        write_csv(self.out / f"{name}.csv", columns, rows)
        self.items.append({"name": name, "caption": caption, "png": png})


def write_csv(path: Path, columns: list[str], rows: list[list]) -> None:
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(columns)
    for row in rows:
        writer.writerow(["" if (isinstance(v, float) and not math.isfinite(v)) else v for v in row])
    atomic_write_text(path, buf.getvalue())


def _shear(run, key):
    return np.array([float(r[key]) for r in run.rows if r["stage"] == "shear"])


def _comp(run, key):
    return np.array([float(r[key]) for r in run.rows if r["stage"] == "compression"])


def _get(results, model, compression, width, resolution=None, poisson=0.0):
    for spec, run in results.items():
        if (spec.model == model and abs(spec.compression_ratio - compression) < 1e-9
                and abs(spec.width_ratio - width) < 1e-9 and spec.poisson_ratio == poisson
                and (resolution is None or spec.resolution == resolution)):
            return run
    return None


# ---------------------------------------------------------------------------- figures
def figure_elastica(fig_set: Figures, results, profile, golds) -> None:
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5, 3.6))
    c = np.linspace(1e-3, 0.6, 200)
    ax.plot(c, [clamped_elastica_midpoint_height(x) for x in c], "k-", lw=1, label="exact elastica")
    rows = []
    for model, width in (("rod", 1 / 20), ("plate", 1 / 6), ("plate", 1 / 20), ("ribbon", 1 / 20)):
        run = _get(results, model, 0.5, width, profile.models.get(model))
        if run is None:
            continue
        dl, h = _comp(run, "dL_over_L"), _comp(run, "H_mid_over_L")
        ax.plot(dl, h, "o", ms=3, color=COLORS[model], label=f"{model} W/L={_fraction(width)}")
        rows += [[model, width, a, b, clamped_elastica_midpoint_height(a) if a > 0 else 0.0] for a, b in zip(dl, h)]
    gold = golds.get((0.5, 1 / 6))
    if gold is not None:
        dl, h = gold.column("dL_over_L", "compression"), gold.column("H_mid_over_L", "compression")
        ax.plot(dl, h, "s", mfc="none", ms=5, color="k", label="FEM W/L=1/6")
        rows += [["fem", 1 / 6, a, b, clamped_elastica_midpoint_height(a) if a > 0 else 0.0] for a, b in zip(dl, h)]
    ax.set_xlabel("dL/L")
    ax.set_ylabel("H_mid/L")
    ax.legend(fontsize=7)
    fig_set.save("elastica", fig, ["model", "width_ratio", "dL_over_L", "H_mid_over_L", "exact_H_mid_over_L"], rows,
                 "Midpoint height under compression (paper Fig. 5b): models against the exact clamped elastica.")


def _plot_shear_column(ax, results, profile, golds, compression, width, column, thresholds=False) -> list[list]:
    """`column` against dW/L on the shear stage for every model run of the scene and the FEM gold
    (dotted dW1 and dashed dW2 lines per model if `thresholds`); the plotted numbers as CSV rows."""
    rows = []
    curves = [(model, _get(results, model, compression, width, profile.models.get(model)))
              for model in ("rod", "plate", "ribbon")] + [("fem", golds.get((compression, width)))]
    for model, run in curves:
        if run is None:
            continue
        dw, y = _shear(run, "dW_over_L"), _shear(run, column)
        if model == "fem":
            ax.plot(dw, y, "k.", ms=3, label="FEM")
        else:
            ax.plot(dw, y, "-", color=COLORS[model], label=model)
            for key, style in (("dW1_over_L", ":"), ("dW2_over_L", "--")) if thresholds else ():
                if run.summary.get(key) is not None:
                    ax.axvline(run.summary[key], color=COLORS[model], ls=style, lw=0.8)
        rows += [[model, compression, width, a, b] for a, b in zip(dw, y)]
    return rows


def figure_shear_curves(fig_set: Figures, results, profile, golds) -> None:
    import matplotlib.pyplot as plt

    for compression in COMPRESSIONS:
        scenes = [w for c, w in profile.shear_curves if c == compression]
        if not scenes:
            continue
        cols = min(3, len(scenes))
        nrows = math.ceil(len(scenes) / cols)
        fig, axes = plt.subplots(nrows, cols, figsize=(4.2 * cols, 3.3 * nrows), squeeze=False)
        rows = []
        for ax, width in zip(axes.flat, scenes):
            rows += _plot_shear_column(ax, results, profile, golds, compression, width, "H_mid_over_L", thresholds=True)
            for key, marker in (("dW1", "v"), ("dW2", "^")):
                paper = paper_value(compression, width, key)
                if paper is not None:
                    ax.plot([paper], [0.0], marker, color="crimson", ms=7, label=f"paper {key}")
            ax.set_title(f"W/L = {_fraction(width)}, dL/L = {_fraction(compression)}", fontsize=9)
            ax.set_xlabel("dW/L")
            ax.set_ylabel("H_mid/L")
            ax.legend(fontsize=6)
        for ax in list(axes.flat)[len(scenes):]:
            ax.set_visible(False)
        fig.tight_layout()
        name = f"hmid_vs_dW_dL{compression:g}"
        fig_set.save(name, fig, ["model", "compression_ratio", "width_ratio", "dW_over_L", "H_mid_over_L"], rows,
                     f"H_mid/L against dW/L at dL/L = {_fraction(compression)} (paper Figs. 6, 7); dotted: dW1, dashed: "
                     "dW2 of each model (from stability); red triangles: the paper's quoted thresholds.")


def _frame_index(frames_dir: Path) -> list[dict]:
    """The frames.pvd collection of a run: [{step, file, dW_over_L, stage}], or [] if absent."""
    import xml.etree.ElementTree as ET

    pvd = frames_dir / "frames.pvd"
    if not pvd.exists():
        return []
    return [{"step": int(d.get("timestep")), "file": frames_dir / d.get("file"), "stage": d.get("stage"),
             "dW_over_L": float(d.get("dW_over_L"))} for d in ET.parse(pvd).getroot().iter("DataSet")]


def snapshot_states(run) -> list[tuple[str, float, Path]]:
    """(phase, dW/L, frame file) of a U, a US and an S state of a plate run: the recorded shear
    state nearest to dW1/2 on U, to (dW1 + dW2)/2 on US (dW2 -> dW_end if S is never reached) and to
    (dW2 + dW_end)/2 on S."""
    frames = [f for f in _frame_index(run.directory / "frames") if f["stage"] == "shear"]
    if not frames:
        return []
    s = run.summary
    shear = [r for r in run.rows if r["stage"] == "shear"]
    dw_end = max(float(r["dW_over_L"]) for r in shear)
    dw1, dw2 = s.get("dW1_over_L"), s.get("dW2_over_L")
    targets = {"U": 0.5 * dw1 if dw1 else 0.5 * dw_end,
               "US": 0.5 * (dw1 + (dw2 or dw_end)) if dw1 else None,
               "S": 0.5 * (dw2 + dw_end) if dw2 else None}
    out = []
    for phase, target in targets.items():
        if target is None:
            continue
        rows = [r for r in shear if str(r["phase"]).rstrip("+-") == phase]
        if not rows:
            continue
        row = min(rows, key=lambda r: abs(float(r["dW_over_L"]) - target))
        frame = min(frames, key=lambda f: abs(f["dW_over_L"] - float(row["dW_over_L"])))
        if abs(frame["dW_over_L"] - float(row["dW_over_L"])) < 1e-9:
            out.append((str(row["phase"]), float(row["dW_over_L"]), frame["file"]))
    return out


def figure_snapshots(fig_set: Figures, results, profile) -> str:
    """3D shapes of U, US and S plates, narrow and wide (paper Fig. 1), from the plate runs'
    frames (matplotlib 3D; pyvista is not needed). Returns a note for the report."""
    import matplotlib.pyplot as plt

    from .studies import SNAPSHOT_SCENES

    try:
        import meshio
    except ImportError:
        return "Skipped: reading the plate frames needs meshio (Debian python3-meshio, scripts/setup.sh)."
    panels = []
    for compression, width in SNAPSHOT_SCENES:
        run = _get(results, "plate", compression, width, profile.models.get("plate"))
        if run is not None:
            panels += [(compression, width, *state) for state in snapshot_states(run)]
    if not panels:
        return "Skipped: no plate run of this profile kept its frames (the profile runs no plate on the snapshot scenes)."
    widths = sorted({p[1] for p in panels})
    cols = max(sum(1 for p in panels if p[1] == w) for w in widths)
    fig = plt.figure(figsize=(4.0 * cols, 3.0 * len(widths)))
    rows = []
    for i, width in enumerate(widths):
        for j, (compression, _, phase, dw, path) in enumerate([p for p in panels if p[1] == width]):
            mesh = meshio.read(path)
            L = float(_get(results, "plate", compression, width, profile.models.get("plate")).summary["scene"]["length"])
            xyz = mesh.points / L
            triangles = mesh.cells_dict["triangle"]
            ax = fig.add_subplot(len(widths), cols, i * cols + j + 1, projection="3d")
            ax.plot_trisurf(xyz[:, 0], xyz[:, 1], xyz[:, 2], triangles=triangles, cmap="viridis", linewidth=0.1,
                            edgecolor="0.3", antialiased=True)
            extent = np.ptp(xyz, axis=0)
            ax.set_box_aspect(np.maximum(extent, 0.05))
            ax.view_init(elev=25, azim=-60)
            ax.set_title(f"W/L = {_fraction(width)}: {phase}, dW/L = {dw:.3f}", fontsize=9)
            ax.set_xlabel("x/L", fontsize=7)
            ax.set_ylabel("y/L", fontsize=7)
            ax.set_zlabel("z/L", fontsize=7)
            ax.tick_params(labelsize=6)
            rows += [[compression, width, phase, dw, k, *map(float, p)] for k, p in enumerate(xyz)]
    fig.tight_layout()
    fig_set.save("snapshots_3d", fig, ["compression_ratio", "width_ratio", "phase", "dW_over_L", "node",
                                       "x_over_L", "y_over_L", "z_over_L"], rows,
                 "Deformed plates (paper Fig. 1): U, US and S states of a narrow and a wide strip at dL/L = 1/2, "
                 "from the plate runs' frames (U at dW1/2, US halfway between dW1 and dW2, S halfway from dW2 to "
                 "the end of the shear).")
    return (f"{len(panels)} shapes from the plate runs' frames (matplotlib 3D; the frames open in ParaView: "
            "cache/<run>/frames/frames.pvd).")


def threshold_table(results, profile, golds) -> list[dict]:
    table = []
    widths = sorted({w for _, w in profile.shear_curves} | set(profile.phase_widths))
    for compression in COMPRESSIONS:
        for width in widths:
            entries = {}
            for model in ("rod", "plate", "ribbon"):
                run = _get(results, model, compression, width, profile.models.get(model))
                if run is not None:
                    entries[model] = run.summary
            gold = golds.get((compression, width))
            if gold is not None:
                entries["fem"] = gold.summary
            for model, s in entries.items():
                row = {"model": model, "compression_ratio": compression, "width_ratio": width,
                       "dW1_over_L": s.get("dW1_over_L"), "dW2_over_L": s.get("dW2_over_L"),
                       "dW2_S_stable_over_L": s.get("dW2_S_stable_over_L"),
                       "dW_max_over_L": shear_limit(1.0, width, compression)}
                for key in ("dW1", "dW2"):
                    paper = paper_value(compression, width, key)
                    row[f"paper_{key}"] = paper
                    ours = row[f"{key}_over_L"]
                    row[f"{key}_rel_diff_vs_paper"] = None if paper is None or ours is None else ours / paper - 1
                table.append(row)
    # percent drops of dW1 against W/L = 1/20, per model and compression
    for row in table:
        base = next((r for r in table if r["model"] == row["model"] and r["compression_ratio"] == row["compression_ratio"]
                     and abs(r["width_ratio"] - 1 / 20) < 1e-9), None)
        row["dW1_drop_vs_W_1_20_percent"] = (None if base is None or base["dW1_over_L"] is None or row["dW1_over_L"] is None
                                             else 100 * (1 - row["dW1_over_L"] / base["dW1_over_L"]))
        paper_drop = PAPER_DROPS_QUARTER.get(min(PAPER_DROPS_QUARTER, key=lambda w: abs(w - row["width_ratio"])))
        close = any(abs(w - row["width_ratio"]) < 1e-9 for w in PAPER_DROPS_QUARTER)
        row["paper_drop_percent"] = paper_drop if close and row["compression_ratio"] == 0.25 else None
    return table


def figure_thresholds(fig_set: Figures, table, profile) -> None:
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(9, 3.6))
    rows = []
    for ax, compression in zip(axes, COMPRESSIONS):
        w = np.linspace(1 / 20, 1 / 2, 100)
        ax.plot(w, [shear_limit(1.0, x, compression) for x in w], "k-", lw=0.8, label="dW_max (Eq. B.1)")
        for model in ("rod", "plate", "ribbon", "fem"):
            sel = sorted((r for r in table if r["model"] == model and r["compression_ratio"] == compression),
                         key=lambda r: r["width_ratio"])
            for key, marker in (("dW1_over_L", "o-"), ("dW2_over_L", "s--")):
                pts = [(r["width_ratio"], r[key]) for r in sel if r[key] is not None]
                if pts:
                    ax.plot(*zip(*pts), marker, color=COLORS[model], ms=4, label=f"{model} {key[:3]}")
            rows += [[model, compression, r["width_ratio"], r["dW1_over_L"], r["dW2_over_L"], r["dW_max_over_L"]]
                     for r in sel]
        for width in sorted({r["width_ratio"] for r in table}):
            for key, marker in (("dW1", "v"), ("dW2", "^")):
                paper = paper_value(compression, width, key)
                if paper is not None:
                    ax.plot([width], [paper], marker, color="crimson", ms=7)
        ax.set_title(f"dL/L = {_fraction(compression)} (red: paper)", fontsize=9)
        ax.set_xlabel("W/L")
        ax.set_ylabel("threshold dW/L")
        ax.legend(fontsize=6)
    fig.tight_layout()
    fig_set.save("thresholds_vs_width", fig, ["model", "compression_ratio", "width_ratio", "dW1_over_L", "dW2_over_L",
                                              "dW_max_over_L"], rows,
                 "Thresholds dW1/L (U to US) and dW2/L (US to S) against W/L (paper Fig. 8 phase boundaries), with the "
                 "shear limit dW_max.")


def figure_shear_force(fig_set: Figures, results, profile, golds) -> None:
    import matplotlib.pyplot as plt

    scenes = [s for s in ((0.5, 1 / 20), (0.5, 1 / 6)) if s in profile.shear_curves]
    fig, axes = plt.subplots(1, len(scenes), figsize=(4.5 * len(scenes), 3.4), squeeze=False)
    rows = []
    for ax, (compression, width) in zip(axes.flat, scenes):
        rows += _plot_shear_column(ax, results, profile, golds, compression, width, "F_shear_norm", thresholds=True)
        ax.set_yscale("symlog", linthresh=1.0)
        ax.set_title(f"W/L = {_fraction(width)}, dL/L = {_fraction(compression)}", fontsize=9)
        ax.set_xlabel("dW/L")
        ax.set_ylabel("F_shear L/(E b^3)")
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig_set.save("shear_force", fig, ["model", "compression_ratio", "width_ratio", "dW_over_L", "F_shear_norm"], rows,
                 "Lateral clamp force against dW/L (paper Fig. E.18); dotted: dW1, dashed: dW2 of each model (from "
                 "stability). tests/test_shear_force.py checks the force against the derivative of the energy along "
                 "the path.")


def convergence_data(results, study_specs) -> list[dict]:
    data = []
    by_model: dict[str, list] = {}
    for spec in study_specs:
        if spec in results:
            by_model.setdefault(spec.model, []).append((spec, results[spec]))
    for model, runs in by_model.items():
        runs.sort(key=lambda t: t[0].resolution)
        finest = runs[-1][1]
        for spec, run in runs:
            data.append({
                "model": model, "resolution": spec.resolution, "width_ratio": spec.width_ratio,
                "elastica_rel_error": C.elastica_error(run),
                "curve_error_vs_finest": C.curve_difference_away_from_thresholds(run, finest) if run is not finest else None,
                "dW1_over_L": run.summary.get("dW1_over_L"), "dW2_over_L": run.summary.get("dW2_over_L"),
                "wall_time_s": run.summary.get("wall_time_s"),
            })
    return data


def figure_convergence(fig_set: Figures, data) -> None:
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(9, 3.4))
    for model in sorted({d["model"] for d in data}):
        sel = [d for d in data if d["model"] == model]
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
    fig_set.save("convergence", fig, list(data[0].keys()) if data else ["model"],
                 [list(d.values()) for d in data],
                 "Convergence with resolution (paper Fig. C.16): compressed height against the exact elastica, and the "
                 "H_mid(dW) curve against the finest run (away from the thresholds).")


def figure_poisson(fig_set: Figures, results, study_specs) -> dict:
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5, 3.6))
    rows, curves = [], {}
    for spec in study_specs:
        run = results.get(spec)
        if run is None:
            continue
        dw, h = _shear(run, "dW_over_L"), _shear(run, "H_mid_over_L")
        curves[spec.poisson_ratio] = run
        ax.plot(dw, h, "-", label=f"nu = {spec.poisson_ratio:g}")
        rows += [[spec.poisson_ratio, a, b] for a, b in zip(dw, h)]
    ax.set_xlabel("dW/L")
    ax.set_ylabel("H_mid/L")
    ax.legend(fontsize=7)
    fig_set.save("poisson", fig, ["poisson_ratio", "dW_over_L", "H_mid_over_L"], rows,
                 "Rod, W/L = 1/20, dL/L = 1/2: the Poisson ratio enters only GJ (paper Fig. G.20).")
    spread = {}
    if 0.0 in curves:
        for nu, run in curves.items():
            if nu != 0.0:
                spread[nu] = {"max_H_difference_over_L": C.curve_difference_away_from_thresholds(run, curves[0.0]),
                              "dW1_difference": C.threshold_difference(run, curves[0.0])}
    return spread


def speed_accuracy(results, study_specs, golds) -> tuple[list[dict], str]:
    gold = golds.get(SPEED_SCENE)
    runs = [(s, results[s]) for s in study_specs if s in results]
    if gold is not None:
        reference = gold
        ref_name = f"FEM gold ({gold.summary['scene']['resolution']} elements along L; FEM points: coarser shell meshes)"
    else:
        if not runs:
            return [], "none"
        plates = [(s, r) for s, r in runs if s.model == "plate"] or runs
        spec, reference = max(plates, key=lambda t: t[0].resolution)
        ref_name = f"finest {spec.model} run (resolution {spec.resolution}; no FEM gold data for this scene)"
    data = []
    for spec, run in runs:
        if run is reference:
            continue
        data.append({"model": spec.model, "resolution": spec.resolution, "wall_time_s": run.summary.get("wall_time_s"),
                     "curve_error": C.curve_difference_away_from_thresholds(run, reference),
                     "dW1_error": C.threshold_difference(run, reference),
                     "converged": run.summary.get("converged")})
    if gold is not None:  # the shell itself on coarser meshes (stored runs), against its gold mesh
        from .reference import FEM_FINE, GoldCurve

        for directory in sorted(FEM_FINE.glob("dL0.5_W0.1667_N*")):
            if not (directory / "summary.json").exists():
                continue
            fem = GoldCurve(directory)
            data.append({"model": "fem", "resolution": fem.summary["scene"]["resolution"],
                         "wall_time_s": fem.summary.get("wall_time_s"),
                         "curve_error": C.curve_difference_away_from_thresholds(fem, reference),
                         "dW1_error": C.threshold_difference(fem, reference),
                         "converged": fem.summary.get("converged")})
    return data, ref_name


def pareto(points: list[tuple[float, float]]) -> list[int]:
    """Indices of the points no other point beats in both time and error."""
    keep = []
    for i, (t, e) in enumerate(points):
        if not any((t2 <= t and e2 <= e) and (t2 < t or e2 < e) for j, (t2, e2) in enumerate(points) if j != i):
            keep.append(i)
    return keep


def figure_speed_accuracy(fig_set: Figures, data, ref_name: str) -> None:
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(9, 3.6))
    for ax, key, label in ((axes[0], "curve_error", "max |H_mid error| / L"), (axes[1], "dW1_error", "|dW1 error| / L")):
        pts = [(d["wall_time_s"], d[key], d) for d in data if d[key] and d["wall_time_s"]]
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
    fig.suptitle(f"W/L = 1/6, dL/L = 1/2; reference: {ref_name}", fontsize=8)
    fig.tight_layout()
    fig_set.save("speed_accuracy", fig, list(data[0].keys()) if data else ["model"], [list(d.values()) for d in data],
                 "Speed against accuracy: each model and resolution, wall time of the full path (thresholds included) "
                 f"against its error relative to the {ref_name}; dashed: the Pareto front.")


def stability_map(results, golds, table) -> list[dict]:
    """How each run ended and where it fails: Newton failure, unresolved mesh, missed pitchfork, or
    the rod's width error (its dW1 against the plate's / FEM's at the same scene)."""
    out = []
    for spec, run in sorted(results.items(), key=lambda t: (t[0].model, t[0].compression_ratio, t[0].width_ratio,
                                                            t[0].resolution or 0, t[0].poisson_ratio)):
        s = run.summary
        reached = max((float(r["dW_over_L"]) for r in run.rows if r["stage"] == "shear"), default=0.0)
        dw_max = s.get("dW_max_over_L") or float("nan")
        outcome = "ok"
        if not s.get("converged"):
            outcome = "Newton failure"
        elif s.get("dW1_over_L") is None:  # located but past the mesh's resolution, or not bracketed at all
            outcome = ("dW1 unresolved by the mesh" if (s.get("unresolved_thresholds") or {}).get("dW1_over_L")
                       else "missed pitchfork")
        resolved = s.get("resolved_up_to_dW_over_L")
        if outcome == "ok" and resolved is not None and resolved < reached - 1e-9:
            outcome = "ok (mesh unresolved near dW_max)"
        width_error = None
        if spec.model == "rod" and s.get("dW1_over_L") is not None:
            ref = golds.get((spec.compression_ratio, spec.width_ratio))
            ref_dw1 = ref.summary.get("dW1_over_L") if ref is not None else None
            if ref_dw1 is None:
                plate = next((r for r in table if r["model"] == "plate" and r["compression_ratio"] == spec.compression_ratio
                              and abs(r["width_ratio"] - spec.width_ratio) < 1e-9), None)
                ref_dw1 = plate["dW1_over_L"] if plate else None
            if ref_dw1 is not None:
                width_error = s["dW1_over_L"] - ref_dw1
                if abs(width_error) > 0.03:
                    outcome = "rod width error" if outcome == "ok" else outcome + ", rod width error"
        out.append({"model": spec.model, "compression_ratio": spec.compression_ratio, "width_ratio": spec.width_ratio,
                    "resolution": spec.resolution, "poisson_ratio": spec.poisson_ratio, "outcome": outcome,
                    "reached_dW_over_L": reached, "dW_max_over_L": dw_max,
                    "reached_percent_of_dW_max": 100 * reached / dw_max if dw_max else None,
                    "resolved_up_to_dW_over_L": resolved, "rod_dW1_minus_reference": width_error,
                    "message": s.get("message", "")})
    return out


def figure_stability_map(fig_set: Figures, smap) -> None:
    import matplotlib.pyplot as plt

    categories = ["ok", "ok (mesh unresolved near dW_max)", "missed pitchfork", "dW1 unresolved by the mesh",
                  "rod width error", "Newton failure"]
    colors = ["tab:green", "yellowgreen", "tab:red", "tab:orange", "tab:purple", "black"]
    fig, ax = plt.subplots(figsize=(7, 3.6))
    for entry in smap:
        cat = next((i for i, c in enumerate(categories) if entry["outcome"].startswith(c)), 0)
        if "width error" in entry["outcome"]:
            cat = categories.index("rod width error")
        y = {"rod": 0, "plate": 1, "ribbon": 2}.get(entry["model"], 3) + (0.25 if entry["compression_ratio"] == 0.25 else 0)
        ax.scatter(entry["width_ratio"], y, c=colors[cat], s=30 + 40 * (entry["reached_percent_of_dW_max"] or 0) / 100)
    for c, col in zip(categories, colors):
        ax.scatter([], [], c=col, label=c)
    ax.set_yticks([0, 1, 2])
    ax.set_yticklabels(["rod", "plate", "ribbon"])
    ax.set_xlabel("W/L (upper row of each model: dL/L = 1/4)")
    ax.legend(fontsize=6, loc="upper right")
    fig_set.save("stability_map", fig, list(smap[0].keys()) if smap else ["model"], [list(e.values()) for e in smap],
                 "Where each model fails and how (marker size: share of dW_max reached).")


# ---------------------------------------------------------------------------- claims
def load_dep_material():
    """The FEM shell run with the DDG plate's material at SPEED_SCENE (data/fem_dep), or None."""
    from .reference import FEM_DEP, GoldCurve

    directory = FEM_DEP / "dL0.5_W0.1667_N90"
    return GoldCurve(directory) if (directory / "summary.json").exists() else None


def _share_wording(effect: float, gap: float) -> tuple[str, str]:
    """How the size of the material's effect compares with the size of a gap (both largest
    absolute differences, so they do not add: the wording says "may"): (comparison, conclusion)."""
    share = effect / gap if gap > 0 else math.inf
    if share < 1 / 3:
        return "small against", "does not explain"
    if share < 2 / 3:
        return "a sizeable fraction of", "may explain part of"
    if share <= 1.5:
        return "comparable to", "may explain most of"
    return "larger than", "may explain all of"


def material_sentence(m: dict) -> str:
    """The material check in words chosen from its numbers (see material_check for the keys)."""
    parts = []
    for key, name, unit in (("dW1", "dW1/L", ""), ("curve", "H_mid", " L")):
        effect, gap = m[f"fem_dep_vs_nu0_{key}"], m[f"plate_vs_fem_gold_{key}"]
        comparison, conclusion = _share_wording(effect, gap)
        parts.append(f"in {name} the material changes the shell by {effect:.4f}{unit}, {comparison} the plate's gap of "
                     f"{gap:.4f}{unit} to the nu = 0 gold shell ({100 * effect / gap:.0f} %): the material "
                     f"{conclusion} the {name} gap" if gap > 0 else
                     f"in {name} the material changes the shell by {effect:.4f}{unit}; the plate has no gap to explain")
    own = []
    for key, name, unit in (("dW1", "dW1/L", ""), ("curve", "H_mid", " L")):
        r, g = m[f"plate_vs_fem_dep_{key}"], m[f"plate_vs_fem_gold_{key}"]
        own.append(f"{r:.4f}{unit} in {name} ({'closer than' if r < g else 'not closer than'} its {g:.4f}{unit} "
                   f"to the nu = 0 shell)")
    return (f"Material of the plate (W/L = 1/6, dL/L = 1/2): the FEM shell with the DEP's material (membrane nu = 1/3, "
            f"bending nu_b = -1/3; {m['fem_dep_resolution']} elements along L) against the nu = 0 shell on the same "
            f"mesh: " + "; ".join(parts) + f". The plate ({m['plate_triangles']} triangles) differs from the shell "
            f"with its own material by " + " and ".join(own) + ".")


def mesh_trend_sentence(points: list[tuple[int, float]], reference: float, name: str = "the FEM gold shell's") -> str:
    """The plate's dW1/L against its triangle count and whether its distance to `reference` falls
    at every refinement (points: (triangles, dW1/L), any order)."""
    points = sorted(points)
    listed = ", ".join(f"{d:.4f} ({n} triangles)" for n, d in points)
    text = f"The plate's dW1/L on this scene: {listed}, against {name} {reference:.4f}"
    if len(points) < 2:
        return text + "."
    distance = [abs(d - reference) for _, d in points]
    rises = [(points[i][0], points[i + 1][0]) for i in range(len(points) - 1) if distance[i + 1] >= distance[i]]
    if not rises:
        return text + ": its distance to it falls at every refinement."
    return (text + ": its distance to it does not fall at every refinement (it grows from "
            + ", from ".join(f"{a} to {b} triangles" for a, b in rises) + ").")


def paper_reading_sentence(table: list[dict], model: str = "fem") -> str:
    """Where the paper quotes dW1: how often its value is above `model`'s, with the differences.
    The paper reads its thresholds by eye from dynamic runs; a dynamic run leaves U late after a
    supercritical pitchfork, which would put a quoted dW1 above the onset of instability; the
    conclusion drawn is chosen from how many are above."""
    label = "FEM" if model == "fem" else model
    rows = [r for r in table if r["model"] == model and r.get("paper_dW1") is not None and r.get("dW1_over_L") is not None]
    if not rows:
        return f"No {label} dW1 to compare with the paper's quoted dW1 in this profile."
    above = [r for r in rows if r["paper_dW1"] > r["dW1_over_L"]]
    diffs = ", ".join(f"{100 * (r['paper_dW1'] / r['dW1_over_L'] - 1):+.1f} % at W/L = {_fraction(r['width_ratio'])}, "
                      f"dL/L = {_fraction(r['compression_ratio'])}" for r in rows)
    text = (f"The paper reads its thresholds by eye from dynamic runs. Where it quotes dW1 and the {label} run has one "
            f"({len(rows)} scenes), the paper's dW1 is above the {label}'s (the onset of instability) at {len(above)} "
            f"of them (paper / {label} - 1: {diffs})")
    if len(above) == len(rows):
        return text + ": as a dynamic run that leaves U late after the pitchfork would give."
    if not above:
        return text + ": a late departure from U in the paper's dynamic runs does not explain the differences."
    return text + f": a late departure from U in the paper's dynamic runs could explain at most those {len(above)}."


def claims_sentence(claims: list[dict]) -> str:
    failing = [c for c in claims if not c["holds"]]
    if not failing:
        return f"All {len(claims)} claims hold: each measured value is at or below its bound."
    return (f"**{len(failing)} of {len(claims)} claims do not hold: "
            + "; ".join(f"{c['claim']} ({c['reason']})" for c in failing) + ".**")


#: How tests/test_validation.py asserts the claims (test_claims_are_asserted_as_the_report_says checks it).
CLAIMS_TESTED_TEXT = (
    "tests/test_validation.py asserts every claim with the same function and bound on runs it makes itself at the "
    "same scenes (plate_elastica and rod_vs_plate_narrow_U on a 1000-triangle plate, the report on the profile's "
    "plate; plate_dW1_paper_sixth only with `pytest -m slow`; the FEM claims are skipped where data/fem_gold or "
    "data/fem_dep is missing). A claim that does not hold fails its test: none is marked as an expected failure. "
    "Here, a claim whose runs or reference data are not in this profile does not hold (reason 'no data').")


def material_check(results, profile, golds) -> dict | None:
    """Is the plate/FEM gap at SPEED_SCENE the plate's material (the DEP's nu = 1/3 membrane and
    nu_b = -1/3 bending, against the shell's nu = 0)? The material's effect (the FEM shell run with
    the DEP's material, data/fem_dep, against the nu = 0 shell on the same mesh, data/fem_fine) is
    set against the gap (the plate against the nu = 0 gold shell) and the plate against the shell
    with its own material; material_sentence words it from these numbers."""
    from .reference import FEM_FINE, GoldCurve

    iso_dir = FEM_FINE / "dL0.5_W0.1667_N90"
    plate = _get(results, "plate", *SPEED_SCENE, CROSS_MODEL_PLATE)
    dep = load_dep_material()
    gold = golds.get(SPEED_SCENE)
    if dep is None or gold is None or not (iso_dir / "summary.json").exists() or plate is None:
        return None
    iso = GoldCurve(iso_dir)
    out = {"fem_dep_vs_nu0_dW1": C.threshold_difference(dep, iso),
           "fem_dep_vs_nu0_curve": C.curve_difference_away_from_thresholds(dep, iso),
           "plate_vs_fem_gold_dW1": C.threshold_difference(plate, gold),
           "plate_vs_fem_gold_curve": C.curve_difference_away_from_thresholds(plate, gold),
           "plate_vs_fem_dep_dW1": C.threshold_difference(plate, dep),
           "plate_vs_fem_dep_curve": C.curve_difference_away_from_thresholds(plate, dep),
           "fem_dep_resolution": dep.summary["scene"]["resolution"],
           "plate_triangles": plate.summary["mesh"]["triangles"]}
    if any(v is None or not math.isfinite(v) for v in out.values()):
        return None
    out["statement"] = material_sentence(out)
    plates = [(run.summary["mesh"]["triangles"], run.summary["dW1_over_L"]) for spec, run in results.items()
              if spec.model == "plate" and (spec.compression_ratio, spec.width_ratio) == SPEED_SCENE
              and not spec.poisson_ratio and run.summary.get("dW1_over_L") is not None]
    if gold.summary.get("dW1_over_L") is not None and plates:
        out["plate_dW1_by_triangles"] = sorted(plates)
        out["mesh_statement"] = mesh_trend_sentence(plates, gold.summary["dW1_over_L"])
    return out


def _missing(**inputs) -> str:
    """What a claim lacks: the names of the inputs that are None, joined ('' if none is)."""
    return ", ".join(f"no {name}" for name, value in inputs.items() if value is None)


def evaluate_claims(results, profile, golds) -> list[dict]:
    """Every claim of validation/claims.py on this report's runs; a claim whose runs or reference
    data are not in this profile does not hold (reason "no data: ..." naming what is missing)."""
    get = lambda m, c, w: _get(results, m, c, w, profile.models.get(m))  # noqa: E731
    res = lambda m: "" if profile.models.get(m) is None else f", resolution {profile.models[m]}"  # noqa: E731
    out = []
    rod = _get(results, "rod", 0.5, 1 / 20, 100)  # the claims are stated for M = 100
    rod_quarter = _get(results, "rod", 0.25, 1 / 20, 100)
    plate6, plate20 = get("plate", 0.5, 1 / 6), get("plate", 0.5, 1 / 20)
    plate6_fine = _get(results, "plate", *SPEED_SCENE, CROSS_MODEL_PLATE)
    gold6 = golds.get((0.5, 1 / 6))
    dep6 = load_dep_material()
    ribbon = get("ribbon", 0.5, 1 / 20)
    names = {
        "rod": "rod run (M = 100, W/L = 1/20, dL/L = 1/2)",
        "rod_quarter": "rod run (M = 100, W/L = 1/20, dL/L = 1/4)",
        "plate6": f"plate run (W/L = 1/6, dL/L = 1/2{res('plate')})",
        "plate20": f"plate run (W/L = 1/20, dL/L = 1/2{res('plate')})",
        "plate6_fine": f"plate run (W/L = 1/6, dL/L = 1/2, resolution {CROSS_MODEL_PLATE})",
        "ribbon": f"ribbon run (W/L = 1/20, dL/L = 1/2{res('ribbon')})",
        "gold6": "FEM gold data (data/fem_gold/dL0.5_W0.1667)",
        "dep6": "FEM run with the plate's material (data/fem_dep/dL0.5_W0.1667_N90)",
    }

    def lacking(**inputs) -> str:
        return _missing(**{names[k]: v for k, v in inputs.items()})

    out.append(C.evaluate("rod_elastica", C.elastica_error(rod) if rod else None, lacking(rod=rod)))
    out.append(C.evaluate("plate_elastica", C.elastica_error(plate6) if plate6 else None, lacking(plate6=plate6)))
    out.append(C.evaluate("ribbon_elastica", C.elastica_error(ribbon) if ribbon else None, lacking(ribbon=ribbon)))
    out.append(C.evaluate("fem_elastica", C.elastica_error(gold6) if gold6 else None, lacking(gold6=gold6)))
    out.append(C.evaluate("rod_vs_plate_narrow_U", C.u_branch_difference(plate20, rod) if plate20 and rod else None,
                          lacking(plate20=plate20, rod=rod)))
    fine = lacking(plate6_fine=plate6_fine, gold6=gold6)
    out.append(C.evaluate("plate_vs_fem_curve", C.curve_difference_away_from_thresholds(plate6_fine, gold6)
                          if plate6_fine and gold6 else None, fine))
    dw1 = C.threshold_difference(plate6_fine, gold6) if plate6_fine and gold6 else None
    out.append(C.evaluate("plate_vs_fem_dW1", dw1, fine or "dW1 not located in the plate run or the FEM gold"))
    out.append(C.evaluate("plate_vs_fem_own_material_curve", C.curve_difference_away_from_thresholds(plate6_fine, dep6)
                          if plate6_fine and dep6 else None, lacking(plate6_fine=plate6_fine, dep6=dep6)))
    rods = [r for r in (rod, rod_quarter) if r is not None]
    errors = [C.paper_threshold_error(r) for r in rods]
    out.append(C.evaluate("rod_thresholds_paper", max(errors) if len(errors) == 2 and None not in errors else None,
                          lacking(rod=rod, rod_quarter=rod_quarter) or "a threshold the paper quotes was not located"))
    dw1_sixth = plate6.summary.get("dW1_over_L") if plate6 else None
    out.append(C.evaluate("plate_dW1_paper_sixth", abs(dw1_sixth - 0.27) if dw1_sixth is not None else None,
                          lacking(plate6=plate6) or "dW1 not located in the plate run"))
    return out


# ---------------------------------------------------------------------------- writing
def _md_table(rows: list[dict], columns: list[str]) -> str:
    def fmt(v):
        if v is None:
            return "-"
        if isinstance(v, float):
            return "-" if not math.isfinite(v) else f"{v:.4g}"
        return str(v).replace("|", "/")

    lines = ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    lines += ["| " + " | ".join(fmt(r.get(c)) for c in columns) + " |" for r in rows]
    return "\n".join(lines)


def _html_table(md: str) -> str:
    lines = [line for line in md.splitlines() if line.startswith("|")]
    if len(lines) < 2:
        return ""
    head = [html.escape(c.strip()) for c in lines[0].strip("|").split("|")]
    body = [[html.escape(c.strip()) for c in line.strip("|").split("|")] for line in lines[2:]]
    return ("<table><tr>" + "".join(f"<th>{h}</th>" for h in head) + "</tr>"
            + "".join("<tr>" + "".join(f"<td>{c}</td>" for c in row) + "</tr>" for row in body) + "</table>")


def build_report(profile_name: str, out: Path, jobs: int = 1, progress: bool = True, gold_root: Path | None = None) -> dict:
    t0 = time.perf_counter()
    profile = PROFILES[profile_name]()
    out = Path(out)
    study = specs(profile)
    all_specs = [s for group in study.values() for s in group]
    results = run_all(all_specs, out / "cache", jobs=jobs, progress=progress)
    scenes = {(c, w) for c, w in profile.shear_curves} | {SPEED_SCENE}
    golds = {}
    for c, w in scenes:
        gold = load_gold(c, w) if gold_root is None else load_gold(c, w, gold_root)
        if gold is not None:
            golds[(c, w)] = gold
    figs = Figures(out)
    figure_elastica(figs, results, profile, golds)
    figure_shear_curves(figs, results, profile, golds)
    table = threshold_table(results, profile, golds)
    figure_thresholds(figs, table, profile)
    figure_shear_force(figs, results, profile, golds)
    conv = convergence_data(results, study["convergence"])
    figure_convergence(figs, conv)
    poisson = figure_poisson(figs, results, study["poisson"])
    speed, ref_name = speed_accuracy(results, study["speed"], golds)
    figure_speed_accuracy(figs, speed, ref_name)
    smap = stability_map(results, golds, table)
    figure_stability_map(figs, smap)
    claims = evaluate_claims(results, profile, golds)
    snapshot_note = figure_snapshots(figs, results, profile)

    threshold_columns = ["model", "compression_ratio", "width_ratio", "dW1_over_L", "paper_dW1", "dW1_rel_diff_vs_paper",
                         "dW2_over_L", "paper_dW2", "dW2_rel_diff_vs_paper", "dW2_S_stable_over_L",
                         "dW1_drop_vs_W_1_20_percent", "paper_drop_percent", "dW_max_over_L"]
    write_csv(out / "thresholds.csv", threshold_columns, [[r.get(c) for c in threshold_columns] for r in table])
    smap_columns = list(smap[0].keys()) if smap else []
    write_csv(out / "stability_map.csv", smap_columns, [[e[c] for c in smap_columns] for e in smap])
    claim_columns = ["claim", "statement", "bound", "measured", "holds", "reason"]
    write_csv(out / "claims.csv", claim_columns, [[c[k] for k in claim_columns] for c in claims])

    missing_gold = sorted(f"dL/L={_fraction(c)} W/L={_fraction(w)}" for c, w in scenes if (c, w) not in golds)
    failing = [c for c in claims if not c["holds"]]
    sections = [
        f"# Validation report ({profile.name})", "",
        f"{len(results)} model runs ({len(set(all_specs))} requested), FEM gold scenes used: {len(golds)}"
        + (f"; no FEM gold data for {', '.join(missing_gold)} (those comparisons are left out)." if missing_gold else "."),
        "",
        "## Claims", "",
        CLAIMS_TESTED_TEXT, "",
        _md_table(claims, claim_columns), "",
        claims_sentence(claims), "",
        "## Thresholds", "",
        "dW1: lambda_min of the symmetric U branch changes sign (1e-4 L); dW2: the stable path reaches S (1e-3 L); "
        "dW2_S_stable: the S branch turns stable.", "", paper_reading_sentence(table), "",
        _md_table(table, threshold_columns), "",
        "## Where the models disagree with the paper or the reference", "",
        "Listed: dW1 or dW2 more than 10 % from the paper's quoted value; runs whose stability-map outcome is not "
        "'ok'; the plate's material and mesh against the FEM shell.", "",
    ]
    listed = len(sections)
    for r in table:
        for key in ("dW1", "dW2"):
            diff = r.get(f"{key}_rel_diff_vs_paper")
            if diff is not None and abs(diff) > 0.1:
                sections.append(f"- {r['model']} at W/L = {_fraction(r['width_ratio'])}, dL/L = "
                                f"{_fraction(r['compression_ratio'])}: {key}/L = {r[f'{key}_over_L']:.4f} against the "
                                f"paper's {r[f'paper_{key}']:.3g} ({100 * diff:+.1f} %).")
    for e in smap:
        if e["outcome"] != "ok":
            nu = f", nu = {e['poisson_ratio']:g}" if e["poisson_ratio"] else ""
            sections.append(f"- {e['model']} W/L = {_fraction(e['width_ratio'])}, dL/L = {_fraction(e['compression_ratio'])}"
                            f" (resolution {e['resolution']}{nu}): {e['outcome']}; reached {e['reached_dW_over_L']:.4f} of "
                            f"dW_max {e['dW_max_over_L']:.4f}" + (f"; rod dW1 - reference = {e['rod_dW1_minus_reference']:+.3f}"
                                                                  if e["rod_dW1_minus_reference"] is not None else ""))
    material = material_check(results, profile, golds)
    if material:
        sections.append(f"- {material['statement']}")
        if material.get("mesh_statement"):
            sections.append(f"- {material['mesh_statement']}")
    if len(sections) == listed:
        sections.append("None.")
    sections += ["", "## Speed and accuracy", "", f"Reference: {ref_name}.", "",
                 _md_table(speed, list(speed[0].keys()) if speed else []), "",
                 "## Convergence", "", _md_table(conv, list(conv[0].keys()) if conv else []), "",
                 "## Poisson ratio (rod)", ""]
    for nu, v in poisson.items():
        sections.append(f"- nu = {nu:g} vs nu = 0: max |H_mid difference| = {v['max_H_difference_over_L']:.3g} L, "
                        f"dW1 difference = {v['dW1_difference'] if v['dW1_difference'] is None else round(v['dW1_difference'], 4)}")
    sections += ["", "## Stability map", "", _md_table(smap, [c for c in smap_columns if c != "message"]), "",
                 "## 3D snapshots", "", snapshot_note, "", "## Figures", ""]
    for item in figs.items:
        sections += [f"![{item['name']}](figures/{item['name']}.png)", "", f"*{item['caption']}* "
                     f"([PDF](figures/{item['name']}.pdf), [data](figures/{item['name']}.csv))", ""]
    wall = time.perf_counter() - t0
    sections += [f"Report built in {wall:.0f} s; model run times are in the cache's summary.json files."]
    report_md = "\n".join(sections) + "\n"
    atomic_write_text(out / "report.md", report_md)

    body = []
    for block in report_md.split("\n\n"):
        if block.startswith("|"):
            body.append(_html_table(block))
        elif block.startswith("#"):
            level = len(block) - len(block.lstrip("#"))
            body.append(f"<h{level}>{html.escape(block.lstrip('#').strip())}</h{level}>")
        elif block.startswith("!["):
            name = block[2:block.index("]")]
            item = next(i for i in figs.items if i["name"] == name)
            body.append(f'<figure><img src="data:image/png;base64,{base64.b64encode(item["png"]).decode()}" '
                        f'alt="{name}"></figure>')
        else:
            body.append(f"<p>{html.escape(block)}</p>".replace("\n", "<br>"))
    page = ("<!DOCTYPE html><html><head><meta charset='utf-8'><title>ddg validation report</title><style>"
            "body{font-family:sans-serif;max-width:1100px;margin:auto}table{border-collapse:collapse;font-size:11px}"
            "td,th{border:1px solid #ccc;padding:2px 5px}img{max-width:100%}</style></head><body>"
            + "\n".join(body) + "</body></html>\n")
    atomic_write_text(out / "index.html", page)

    summary = {
        "profile": profile.name, "runs": len(results), "requested_runs": len(all_specs),
        "fem_gold_scenes": sorted(f"dL{c:g}_W{w:.4g}" for c, w in golds), "missing_fem_gold": missing_gold,
        "claims": claims, "claims_failing": [c["claim"] for c in failing],
        "thresholds": table, "speed_accuracy_reference": ref_name, "speed_accuracy": speed,
        "convergence": conv, "poisson": {str(k): v for k, v in poisson.items()},
        "stability_map": smap, "plate_material_check": material, "report_wall_time_s": wall,
        "model_wall_time_s": sum(float(r.summary.get("wall_time_s") or 0.0) for r in results.values()),
    }
    atomic_write_text(out / "summary.json", json.dumps(summary, indent=2, default=str) + "\n")
    return summary
