"""Which side is unconverged at W/L = 1/2: the mid-edge plate's U branch against the shell's
(where they disagree, which side is wrong).

`python -m validation wide-check --out data/midedge_wide [--rows 16 24 36 54] [--membranes psri full]
[--no-anisotropic] [--table-only]` (old spelling `python -m validation.wide_check`)

At dL/L = 1/4, W/L = 1/2 (L/b = 1181) the mid-edge plate's dW1/L (0.0858/0.0874/0.0872 on 16/24/36
rows) stays about 0.002 L above the FEM's converged 0.0853 +- 0.0002. This study follows the
mid-edge plate with both membranes (ddg.models.midedge_plate.MEMBRANES) on ghost-clamp meshes of
ROWS rows, and with the PSRI membrane on the ANISOTROPIC meshes (rows x element columns along L:
is it the resolution along L or across W that the plate lacks?), to dW/L = SHEAR_RATIO (past
dW1, at the default's recorded-step density: 48 steps), dW1 located. It tabulates, beside the FEM
gold study's meshes (data/fem_gold/dL0.25_W0.5, read, not run), the U branch's clamp shear force
F L/(E b^3) and H_mid/L at dW/L = AT (linear interpolation between recorded steps), the compressed
H_mid/L against the exact elastica, and dW1/L.

Each run is a folder OUT/<membrane>_R<rows>/ or OUT/psri_R<rows>_C<columns>/ (path.csv,
summary.json); a finished run is kept (resumable run by run; Ctrl-C keeps what finished).
OUT/summary.json and OUT/wide_check.md hold the table.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

from ddg.output.io import StoredRun, atomic_write_text, finished_run_summary

from .command_line import standalone

WIDTH_RATIO, COMPRESSION_RATIO = 1 / 2, 1 / 4
ROWS = (16, 24, 36, 54)
#: (rows across W, element columns along L) of the anisotropic meshes; the default ghost-clamp mesh
#: has 36, 54, 84 and 124 columns on 16, 24, 36 and 54 rows (h_x nearest sqrt(3)/2 h_y)
ANISOTROPIC = ((12, 72), (16, 72), (24, 108))
MEMBRANES = ("psri", "full")
SHEAR_RATIO = 0.2
SHEAR_STEPS = 48
AT = (0.02, 0.04, 0.06)
FEM_SCENE = "dL0.25_W0.5"
#: data/fem_gold (validation.reference.FEM_GOLD)
ROOT_FEM = Path(__file__).resolve().parents[1] / "data" / "fem_gold"


def run_plate(rows: int, membrane: str, target: Path, columns: int | None = None) -> dict:
    """One mid-edge plate run into `target` (kept if finished); `columns` element columns along L,
    or the default ghost-clamp mesh's."""
    import ddg
    from ddg.geometry.plate_mesh import ghost_clamp_mesh

    summary = finished_run_summary(target)
    if summary is not None:
        return summary
    strip = ddg.Strip.from_ratios(WIDTH_RATIO, COMPRESSION_RATIO)
    protocol = ddg.LoadingProtocol(COMPRESSION_RATIO, SHEAR_RATIO, compression_steps=40, shear_steps=SHEAR_STEPS)
    return ddg.simulate(strip, protocol, model="plate-midedge", mesh=ghost_clamp_mesh(strip.length, strip.width,
                                                                                      rows=rows, columns=columns),
                        membrane=membrane, out=target, branches=False, centerline=False).summary


def interpolate(run, column: str, dw: float) -> float | None:
    """`column` of the shear stage of a StoredRun at dW/L = dw (linear between recorded rows; None
    outside them)."""
    rows = [r for r in run.rows if r["stage"] == "shear"]
    x = np.array([r["dW_over_L"] for r in rows])
    if not len(x) or not x.min() <= dw <= x.max():
        return None
    order = np.argsort(x)
    return float(np.interp(dw, x[order], np.array([r[column] for r in rows], float)[order]))


def row_of(label: str, folder: Path) -> dict:
    run = StoredRun(folder)
    summary = run.summary
    mesh = summary.get("mesh") or {}
    return {"run": label, "triangles": mesh.get("triangles"), "dW1_over_L": summary.get("dW1_over_L"),
            "H_mid_over_L_compressed": summary.get("H_mid_over_L_compressed"),
            **{f"F_shear_norm_at_{dw:g}": interpolate(run, "F_shear_norm", dw) for dw in AT},
            **{f"H_mid_over_L_at_{dw:g}": interpolate(run, "H_mid_over_L", dw) for dw in AT}}


def write_tables(out: Path, fem_root: Path) -> dict:
    from ddg.analysis.analytic import clamped_elastica_midpoint_height

    rows = []
    for folder in sorted((fem_root / FEM_SCENE).glob("N*/summary.json")):
        rows.append(row_of(f"fem {folder.parent.name}", folder.parent))
    rows.sort(key=lambda r: (r["triangles"] or 0))
    def size(name: str) -> tuple[int, int]:   # psri_R16 -> (16, 0), psri_R16_C72 -> (16, 72)
        parts = name.split("_")[1:]
        return int(parts[0][1:]), int(parts[1][1:]) if len(parts) > 1 else 0

    for membrane in MEMBRANES:
        for folder in sorted(out.glob(f"{membrane}_R*/summary.json"), key=lambda p: size(p.parent.name)):
            if finished_run_summary(folder.parent) is not None:
                n_rows, columns = size(folder.parent.name)
                label = f"{n_rows} rows" + (f" x {columns} columns" if columns else "")
                rows.append(row_of(f"plate-midedge {membrane} {label}", folder.parent))
    exact = clamped_elastica_midpoint_height(COMPRESSION_RATIO)
    summary = {"scene": {"width_ratio": WIDTH_RATIO, "compression_ratio": COMPRESSION_RATIO},
               "shear_ratio": SHEAR_RATIO, "shear_steps": SHEAR_STEPS, "at_dW_over_L": list(AT),
               "elastica_H_mid_over_L_compressed": exact, "rows": rows}
    header = (["run", "triangles", "dW1/L", "H_mid/L compressed - elastica"]
              + [f"F L/(E b^3) at dW/L {dw:g}" for dw in AT] + [f"H_mid/L at dW/L {dw:g}" for dw in AT])

    def f(x, spec):
        return "-" if x is None else format(x, spec)

    lines = ["# W/L = 1/2, dL/L = 1/4: the U branch of the mid-edge plate and of the shell", "",
             "Written by `python -m validation.wide_check` (its docstring gives the method). FEM rows: the gold "
             f"study's meshes (data/fem_gold/{FEM_SCENE}, full path); plate rows: this study's runs (to dW/L = "
             f"{SHEAR_RATIO:g}). Exact elastica compressed H_mid/L: {exact:.6f}.", "",
             "| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for r in rows:
        cells = [r["run"], str(r["triangles"]), f(r["dW1_over_L"], ".4f"),
                 f(None if r["H_mid_over_L_compressed"] is None else r["H_mid_over_L_compressed"] - exact, "+.1e")]
        cells += [f(r[f"F_shear_norm_at_{dw:g}"], ".4f") for dw in AT]
        cells += [f(r[f"H_mid_over_L_at_{dw:g}"], ".6f") for dw in AT]
        lines.append("| " + " | ".join(cells) + " |")
    atomic_write_text(out / "summary.json", json.dumps(summary, indent=1) + "\n")
    atomic_write_text(out / "wide_check.md", "\n".join(lines) + "\n")
    return summary


def add_arguments(parser) -> None:
    """The options of `python -m validation wide-check`."""
    parser.description = __doc__.split("\n\n")[0]
    parser.add_argument("--out", default="data/midedge_wide")
    parser.add_argument("--rows", type=int, nargs="+", default=list(ROWS))
    parser.add_argument("--membranes", nargs="+", default=list(MEMBRANES))
    parser.add_argument("--no-anisotropic", action="store_true", help="without the ANISOTROPIC meshes")
    parser.add_argument("--table-only", action="store_true", help="no run: rewrite the table")


def run(args) -> int:
    """Every option checked before any folder is made, then the runs (finished ones kept) and the
    table rewritten after each; Ctrl-C: the table of what finished, exit 130."""
    from ddg.geometry.strip import InputError
    from ddg.output.io import check_output_directory

    try:
        bad = [m for m in args.membranes if m not in MEMBRANES]
        if bad:
            raise InputError(f"--membranes {bad[0]!r}: choose from {list(MEMBRANES)}")
        odd = [r for r in args.rows if r < 2 or r % 2 or r > 200]
        if odd:
            raise InputError(f"--rows {odd[0]}: an even number of rows in [2, 200]")
        out = check_output_directory(args.out, "--out")
    except InputError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    out.mkdir(parents=True, exist_ok=True)
    try:
        if not args.table_only:
            for rows, columns in ([] if args.no_anisotropic else ANISOTROPIC):
                summary = run_plate(rows, "psri", out / f"psri_R{rows}_C{columns}", columns)
                print(f"psri {rows} rows x {columns} columns: dW1/L {summary.get('dW1_over_L')}", flush=True)
                write_tables(out, ROOT_FEM)
            for membrane in args.membranes:
                for rows in args.rows:
                    summary = run_plate(rows, membrane, out / f"{membrane}_R{rows}")
                    print(f"{membrane} {rows} rows: dW1/L {summary.get('dW1_over_L')}", flush=True)
                    write_tables(out, ROOT_FEM)
    except KeyboardInterrupt:
        write_tables(out, ROOT_FEM)
        return 130
    write_tables(out, ROOT_FEM)
    return 0


def main(argv=None) -> int:
    """`python -m validation.wide_check [options]`: the same as `python -m validation wide-check [options]`."""
    return standalone("wide-check", add_arguments, run, argv)


if __name__ == "__main__":
    sys.exit(main())
