"""dW1 of the DDG plate over every structured mesh in a range of sizes: the mesh trend against
the jitter of the mesh's aspect rounding.

`python -m validation plate-mesh-scan [--width-ratio 0.5] [--triangles 1200 3400] [--equilateral]
[--out data/plate_modes]` (old spelling `python -m validation.plate_mesh_scan`) runs the plate (dL/L
= 1/2, 20 compression steps, shear to 0.22 L in steps of 0.01 L: past dW1 at W/L = 1/2, thresholds
on, no branches) on each distinct structured mesh (n columns, n_y rows) whose target size lies in
the range, and writes OUT/mesh_scan_W<W/L>.csv and .md with the triangles, h_y/W, the column spacing
over that of equilateral triangles (the aspect) and dW1/L. With --equilateral the meshes are the
exactly equilateral ones of the same n_y (ddg.geometry.plate_mesh.equilateral_columns; aspect 1,
files ..._equilateral). Resumable: finished meshes are read back from the CSV.
"""
from __future__ import annotations

import csv
import math
import time
from pathlib import Path

from ddg.output.io import atomic_write_text, write_table_csv

from .command_line import output_folder, standalone

COMPRESSION_RATIO = 0.5
SHEAR_RATIO = 0.22


def meshes(width_ratio: float, low: int, high: int, step: int = 25,
           equilateral: bool = False) -> list[tuple[int, int, int, float]]:
    """(target triangles, n, n_y, aspect) of each distinct structured mesh with target in [low, high]."""
    from ddg.geometry.plate_mesh import structured_size
    from ddg.geometry.strip import Strip

    strip = Strip.from_ratios(width_ratio, COMPRESSION_RATIO)
    seen = {}
    for target in range(low, high + 1, step):
        n, n_y = structured_size(strip.length, strip.width, target)
        aspect = (strip.length / n) / (0.5 * math.sqrt(3.0) * strip.width / n_y)
        if equilateral:
            from ddg.geometry.plate_mesh import equilateral_columns

            n, aspect = len(equilateral_columns(strip.length, strip.width, n_y)) - 2, 1.0
        if (n, n_y) not in seen:
            seen[(n, n_y)] = (target, n, n_y, aspect)
    return sorted(seen.values())


def run_mesh(width_ratio: float, target: int, equilateral: bool = False) -> dict:
    import ddg
    from ddg.geometry.plate_mesh import structured_mesh

    strip = ddg.Strip.from_ratios(width_ratio, COMPRESSION_RATIO)
    mesh = structured_mesh(strip.length, strip.width, target, equilateral=True) if equilateral else None
    protocol = ddg.LoadingProtocol(COMPRESSION_RATIO, shear_ratio=SHEAR_RATIO, compression_steps=20,
                                   shear_steps=int(round(SHEAR_RATIO * 100)))
    t0 = time.perf_counter()
    result = ddg.simulate(strip, protocol, model="plate", resolution=None if equilateral else target, mesh=mesh,
                          branches=False)
    return {"triangles": result.summary["mesh"]["triangles"], "dW1_over_L": result.summary["dW1_over_L"],
            "wall_time_s": time.perf_counter() - t0}


def add_arguments(parser) -> None:
    """The options of `python -m validation plate-mesh-scan`."""
    parser.description = __doc__.split("\n")[0]
    parser.add_argument("--width-ratio", type=float, default=0.5)
    parser.add_argument("--triangles", type=int, nargs=2, default=[1200, 3400])
    parser.add_argument("--equilateral", action="store_true", help="exactly equilateral meshes of the same n_y")
    parser.add_argument("--out", default="data/plate_modes")


def run(args) -> int:
    """Each mesh of the range not yet in OUT's CSV run, the CSV and the table rewritten after each."""
    out = output_folder(args.out)   # a file or an unwritable folder: one line, exit 2
    if out is None:
        return 2
    name = f"mesh_scan_W{args.width_ratio:.4g}" + ("_equilateral" if args.equilateral else "")
    done = {}
    if (out / f"{name}.csv").exists():
        with open(out / f"{name}.csv", newline="") as fh:
            done = {(int(r["n"]), int(r["n_y"])): r for r in csv.DictReader(fh)}
    rows = []
    for target, n, n_y, aspect in meshes(args.width_ratio, *args.triangles, equilateral=args.equilateral):
        if (n, n_y) in done:
            rows.append(done[(n, n_y)])
            continue
        measured = run_mesh(args.width_ratio, target, args.equilateral)
        rows.append({"target": target, "n": n, "n_y": n_y, "h_y_over_W": 1.0 / n_y, "aspect": aspect, **measured})
        print(f"{target} -> {measured['triangles']} triangles, aspect {aspect:.4f}: dW1/L {measured['dW1_over_L']}",
              flush=True)
        _write(out, name, rows, args.width_ratio)
    _write(out, name, rows, args.width_ratio)
    return 0


def main(argv=None) -> int:
    """`python -m validation.plate_mesh_scan [options]`: the same as `python -m validation plate-mesh-scan
    [options]`."""
    return standalone("plate-mesh-scan", add_arguments, run, argv)


def _write(out: Path, name: str, rows: list[dict], width_ratio: float) -> None:
    write_table_csv(out / f"{name}.csv", rows)
    lines = [f"# Plate dW1/L over structured meshes, W/L = {width_ratio:.4g}, dL/L = {COMPRESSION_RATIO} "
             "(validation/plate_mesh_scan.py)", "",
             "aspect: column spacing over that of equilateral triangles (the rounding of n odd and n_y even).", "",
             "| triangles | n | n_y | h_y/W | aspect | dW1/L | wall s |", "|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        lines.append(f"| {r['triangles']} | {r['n']} | {r['n_y']} | {float(r['h_y_over_W']):.4f} | "
                     f"{float(r['aspect']):.4f} | {float(r['dW1_over_L']):.5f} | {float(r['wall_time_s']):.0f} |")
    atomic_write_text(out / f"{name}.md", "\n".join(lines) + "\n")


if __name__ == "__main__":
    raise SystemExit(main())
