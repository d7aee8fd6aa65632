"""Why the mid-edge plate's dW1 converges irregularly: dW1 over meshes refined across W and along L
apart, with the membrane's constant-strain share fixed, and with rows graded towards the free edges.

`python -m validation midedge-convergence [--only NAME ...] [--out data/midedge_convergence]`
runs each study run of RUNS not yet in OUT/runs.csv (resumable: the CSV is rewritten after each
run) and writes OUT/convergence.md (the tables and the observed orders). A run is the mid-edge
plate (ddg.models.midedge_plate) at dL/L = 1/2 and L/b as the benchmark (Strip.from_ratios),
compressed in 40 recorded steps, sheared to SHEAR_STOP (past dW1, before dW2) in steps of
dW_max / 120 (the default path's), dW1 located from stability (ddg.solve.thresholds, bracket
1e-4 L), no branches. Meshes: ghost_clamp_mesh with `rows` across W and `columns` along L
(default: near-equilateral triangles, ddg.geometry.plate_mesh), optionally graded across W:
y -> (W/2) [(1 - g) s + g sin(pi s / 2)], s = 2 y / W, which makes the rows at the free edges
about 1 - g times (on fine meshes; 0.65 on 8 rows at g = 0.5) and at the centre line
1 + (pi/2 - 1) g times the uniform spacing; membrane_alpha
fixes the constant-strain share of the PSRI membrane (default b^2 / h^2, which changes with h).

Three candidates were named for the irregular sequence: the clamp's ghost columns, the membrane mix
alpha = b^2 / h^2 and the 12-row S window. dW1 precedes S, so the third cannot act on it; the
studies below separate resolution across W (rows), along L (columns), the free-edge boundary
layers (grading) and alpha.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

from ddg.output.io import atomic_write_text

from .command_line import check_run_names, output_folder, resumable_runs

COMPRESSION_RATIO = 0.5
#: past dW1 (about 0.27 at W/L = 1/6, 0.16 at 1/2) and before the path leaves US
SHEAR_STOP = {1 / 6: 0.32, 1 / 2: 0.20}


@dataclass(frozen=True)
class Run:
    """One mesh of a study: W/L, rows across W, columns along L (None: near-equilateral),
    grading across W (0: uniform), the membrane's constant-strain share (None: b^2 / h^2)."""

    width_ratio: float
    rows: int
    columns: int | None = None
    grading: float = 0.0
    membrane_alpha: float | None = None

    @property
    def name(self) -> str:
        w = "W6" if math.isclose(self.width_ratio, 1 / 6) else "W2"
        parts = [w, f"R{self.rows}"]
        if self.columns is not None:
            parts.append(f"C{self.columns}")
        if self.grading:
            parts.append(f"g{self.grading:g}")
        if self.membrane_alpha is not None:
            parts.append(f"a{self.membrane_alpha:g}")
        return "_".join(parts)


#: The studies, fixed before their runs: the default meshes; across W and along L apart (the
#: columns at 12 rows doubled and tripled, the rows at 84 columns doubled, 8 rows at 168 columns);
#: rows graded (g = 0.5); alpha fixed at 0 (the node-smoothed membrane alone); at W/L = 1/2 the
#: default meshes and the columns at 16 and 24 rows doubled and tripled. Added after the first runs:
#: the clamp columns x = 0, L are regular node columns when n / 2 is even and shifted ones (half rows
#: at the free edges) when it is odd (ghost_clamp_mesh) - the default meshes of 8, 12, 18 rows have
#: regular ones, of 16, 20, 24, 28 rows shifted ones; 16 and 20 rows with 112 and 140 columns
#: (regular) against their defaults 110 and 138 separate that from the column count; at W/L = 1/2,
#: 32 rows with 76 columns (regular) against the default 74 (shifted).
RUNS = ([Run(1 / 6, r) for r in (8, 12, 16, 18, 20, 24, 28)]
        + [Run(1 / 6, 12, 168), Run(1 / 6, 12, 252), Run(1 / 6, 24, 84), Run(1 / 6, 8, 168)]
        + [Run(1 / 6, 16, 112), Run(1 / 6, 20, 140)]
        + [Run(1 / 6, r, grading=0.5) for r in (8, 12, 16, 18, 24)]
        + [Run(1 / 6, r, membrane_alpha=0.0) for r in (8, 12, 16, 24)]
        + [Run(1 / 2, r) for r in (16, 24, 32, 36, 48)]
        + [Run(1 / 2, 16, 72), Run(1 / 2, 16, 108), Run(1 / 2, 24, 112), Run(1 / 2, 32, 76)])

COLUMNS = ["name", "width_ratio", "rows", "columns", "grading", "membrane_alpha", "triangles", "free_dof",
           "status", "dW1_over_L", "newton_iterations", "wall_time_s"]


def graded(mesh, grading: float):
    """The ghost-clamp mesh with its rows graded towards the free edges (module docstring)."""
    import numpy as np

    from ddg.geometry.plate_mesh import PlateMesh

    nodes = mesh.nodes.copy()
    half = 0.5 * mesh.width
    s = nodes[:, 1] / half
    nodes[:, 1] = half * ((1.0 - grading) * s + grading * np.sin(0.5 * np.pi * s))
    return PlateMesh(nodes, mesh.triangles, mesh.length, mesh.width, 0.0, 0.0)


def run_one(run: Run) -> dict:
    """dW1 of one run (module docstring)."""
    import ddg
    from ddg.api import simulate_model
    from ddg.geometry.plate_mesh import ghost_clamp_mesh
    from ddg.models.midedge_plate import MidedgePlateModel

    strip = ddg.Strip.from_ratios(run.width_ratio, COMPRESSION_RATIO)
    mesh = ghost_clamp_mesh(strip.length, strip.width, rows=run.rows, columns=run.columns)
    if run.grading:
        mesh = graded(mesh, run.grading)
    model = MidedgePlateModel(strip, mesh=mesh, membrane_alpha=run.membrane_alpha)
    stop = SHEAR_STOP[min(SHEAR_STOP, key=lambda w: abs(w - run.width_ratio))]
    steps = int(round(120 * stop / ddg.LoadingProtocol(COMPRESSION_RATIO).resolved_shear_ratio(strip)))
    protocol = ddg.LoadingProtocol(COMPRESSION_RATIO, stop, shear_steps=steps)
    t0 = time.perf_counter()
    summary = simulate_model(model, protocol, centerline=False).summary
    return {"name": run.name, "width_ratio": run.width_ratio, "rows": run.rows, "columns": run.columns or "",
            "grading": run.grading, "membrane_alpha": model.membrane_alpha, "triangles": mesh.triangle_count,
            "free_dof": model.free.stop - model.free.start, "status": summary["status"],
            "dW1_over_L": summary["dW1_over_L"], "newton_iterations": summary["newton_iterations"],
            "wall_time_s": round(time.perf_counter() - t0, 1)}


def _value(row, key):
    v = row.get(key)
    return float(v) if v not in (None, "", "None") else None


def observed_order(h, values) -> float | None:
    """p with |v1 - v2| / |v2 - v3| = (h1^p - h2^p) / (h2^p - h3^p) for three spacings h1 > h2 > h3
    (any ratios; bisection on p in [0.05, 8]); None if the differences change sign or p is outside."""
    d1, d2 = values[0] - values[1], values[1] - values[2]
    if d1 * d2 <= 0:
        return None
    target = d1 / d2

    def ratio(p):
        return (h[0] ** p - h[1] ** p) / (h[1] ** p - h[2] ** p)

    lo, hi = 0.05, 8.0
    if not ratio(lo) <= target <= ratio(hi):
        return None
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if ratio(mid) < target else (lo, mid)
    return 0.5 * (lo + hi)


def report(rows: list[dict]) -> str:
    """convergence.md: every run, then the observed orders of the sequences in which one spacing changes."""
    by_name = {r["name"]: r for r in rows}
    lines = ["# Mid-edge plate: dW1 against the mesh, across W and along L apart",
             "",
             "Generated by `python -m validation midedge-convergence` (validation/midedge_convergence.py, whose "
             "docstring gives the runs); dL/L = 1/2, L/b as the benchmark, dW1 located to a 1e-4 L bracket.",
             "",
             "| run | W/L | rows | columns | grading | alpha | triangles | free DOF | dW1/L | Newton its | wall s |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        dw1 = _value(r, "dW1_over_L")
        lines.append(f"| {r['name']} | {float(r['width_ratio']):.4f} | {r['rows']} | {r['columns'] or 'default'} | "
                     f"{float(r['grading']):g} | {float(r['membrane_alpha']):.4f} | {r['triangles']} | "
                     f"{r['free_dof']} | {'n/a' if dw1 is None else f'{dw1:.5f}'} | {r['newton_iterations']} | "
                     f"{float(r['wall_time_s']):.1f} |")
    lines += ["", "## Observed orders", "",
              "p from three runs of a sequence in which one spacing changes (`observed_order`: any ratios); "
              "'none' where the differences change sign or p lies outside [0.05, 8].", ""]
    sequences = [("W/L = 1/6, default meshes 8/12/18", ["W6_R8", "W6_R12", "W6_R18"], "rows"),
                 ("W/L = 1/6, default meshes 12/18/28", ["W6_R12", "W6_R18", "W6_R28"], "rows"),
                 ("W/L = 1/6, default meshes 16/20/24", ["W6_R16", "W6_R20", "W6_R24"], "rows"),
                 ("W/L = 1/6, default meshes 20/24/28", ["W6_R20", "W6_R24", "W6_R28"], "rows"),
                 ("W/L = 1/6, 12 rows, columns 84/168/252", ["W6_R12", "W6_R12_C168", "W6_R12_C252"], "columns"),
                 ("W/L = 1/6, about 168 columns, rows 8/12/24", ["W6_R8_C168", "W6_R12_C168", "W6_R24"], "rows"),
                 ("W/L = 1/6, graded, rows 8/12/18", ["W6_R8_g0.5", "W6_R12_g0.5", "W6_R18_g0.5"], "rows"),
                 ("W/L = 1/6, graded, rows 12/18/24", ["W6_R12_g0.5", "W6_R18_g0.5", "W6_R24_g0.5"], "rows"),
                 ("W/L = 1/2, default meshes 16/24/36", ["W2_R16", "W2_R24", "W2_R36"], "rows"),
                 ("W/L = 1/2, default meshes 24/36/48", ["W2_R24", "W2_R36", "W2_R48"], "rows"),
                 ("W/L = 1/2, default meshes 16/32/48 (shifted clamp columns from 32)", ["W2_R16", "W2_R32", "W2_R48"],
                  "rows"),
                 ("W/L = 1/2, 16 rows, columns 36/72/108", ["W2_R16", "W2_R16_C72", "W2_R16_C108"], "columns")]
    lines += ["| sequence | dW1/L | differences | observed order |", "|---|---|---|---:|"]
    for label, names, spacing in sequences:
        if not all(n in by_name and _value(by_name[n], "dW1_over_L") is not None for n in names):
            lines.append(f"| {label} | not all run | | |")
            continue
        runs = [by_name[n] for n in names]
        values = [_value(r, "dW1_over_L") for r in runs]
        h = [1.0 / _columns(r) if spacing == "columns" else 1.0 / int(r["rows"]) for r in runs]
        p = observed_order(h, values)
        lines.append(f"| {label} | {' / '.join(f'{v:.5f}' for v in values)} | "
                     f"{values[0] - values[1]:+.5f} / {values[1] - values[2]:+.5f} | "
                     f"{'none' if p is None else f'{p:.2f}'} |")
    pairs = [("alpha fixed at 0 against b^2 / h^2, 8 rows", "W6_R8_a0", "W6_R8"),
             ("alpha fixed at 0 against b^2 / h^2, 12 rows", "W6_R12_a0", "W6_R12"),
             ("alpha fixed at 0 against b^2 / h^2, 16 rows", "W6_R16_a0", "W6_R16"),
             ("alpha fixed at 0 against b^2 / h^2, 24 rows", "W6_R24_a0", "W6_R24"),
             ("graded against uniform, 8 rows", "W6_R8_g0.5", "W6_R8"),
             ("graded against uniform, 12 rows", "W6_R12_g0.5", "W6_R12"),
             ("graded against uniform, 16 rows", "W6_R16_g0.5", "W6_R16"),
             ("graded against uniform, 18 rows", "W6_R18_g0.5", "W6_R18"),
             ("graded against uniform, 24 rows", "W6_R24_g0.5", "W6_R24"),
             ("regular clamp column (112) against shifted (110), 16 rows", "W6_R16_C112", "W6_R16"),
             ("regular clamp column (140) against shifted (138), 20 rows", "W6_R20_C140", "W6_R20"),
             ("W/L = 1/2: regular clamp column (76) against shifted (74), 32 rows", "W2_R32_C76", "W2_R32")]
    lines += ["", "## Pairs", "", "| change | dW1/L (changed) | dW1/L (default) | difference |", "|---|---:|---:|---:|"]
    for label, a, b in pairs:
        va, vb = (_value(by_name[x], "dW1_over_L") if x in by_name else None for x in (a, b))
        if va is None or vb is None:
            lines.append(f"| {label} | not all run | | |")
        else:
            lines.append(f"| {label} | {va:.6f} | {vb:.6f} | {va - vb:+.6f} |")
    return "\n".join(lines) + "\n"


def _columns(row) -> int:
    """The run's column count (the default one recomputed from its triangles: 2 n rows in [0, L] plus the ghosts)."""
    if row["columns"] not in ("", None):
        return int(row["columns"])
    return int(row["triangles"]) // (2 * int(row["rows"])) - 2


def add_arguments(parser) -> None:
    """The options of `python -m validation midedge-convergence`."""
    parser.description = __doc__.split("\n")[0]
    parser.add_argument("--only", nargs="+", default=None, help="run names (e.g. W6_R12_C168); default all")
    parser.add_argument("--out", default="data/midedge_convergence")


def run(args) -> int:
    """The runs not yet in OUT/runs.csv, one after the other, the CSV and convergence.md rewritten after each."""
    check_run_names(RUNS, args.only)
    out = output_folder(args.out)
    if out is None:
        return 2
    rows = resumable_runs(RUNS, args.only, out, COLUMNS, run_one)
    atomic_write_text(out / "convergence.md", report(rows))
    return 0


def main(argv=None) -> int:
    from .command_line import standalone

    return standalone("midedge-convergence", add_arguments, run, argv)


if __name__ == "__main__":
    raise SystemExit(main())
