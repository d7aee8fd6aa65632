"""Data of the report's Fig. 9 (the deformed plates and the centreline approximation's error over
the plate, Eq. 13): `python -m validation.paper_figures --out data/paper_figures`.

For W/L in FIG9_WIDTHS at dL/L = 1/2, the plate on FIG9_TRIANGLES triangles is followed along its
stable path to each dW/L of FIG9_SHEARS (ddg.analysis.curvatures.states_at_shears), and at every
node the distance delta(s, w) / L from the plate's deformed node to the position the centreline
and its material frame give it (Eq. 12; ddg.analysis.centerline_approx.centerline_error_field) is
written to OUT/fig9/W<W/L>.csv (columns W_over_L, dW_over_L, s_over_L, w_over_L,
delta_percent). One file per width, written atomically: a finished width is skipped on a rerun,
and an interrupted run loses only the width in progress.

Fig. 9a, the deformed plates beside their centreline rendering, comes from the same states:
OUT/fig9a/W<W/L>_triangles.csv (the mesh, node indices i, j, k), W<W/L>_nodes.csv (dW_over_L,
node, x_over_L, y_over_L, z_over_L: the plate's deformed nodes) and W<W/L>_centerline.csv
(dW_over_L, s_over_L, the centreline x_over_L, y_over_L, z_over_L and its second director m2_x,
m2_y, m2_z at each station: Eq. (12) puts the point at w across the width at x + w m2), the
centreline file written last, so that it marks the width finished.

The other paper figures' data come from the ddg command line (data/paper_figures/generate.sh).
"""
from __future__ import annotations

import argparse
import io
import sys
from pathlib import Path

FIG9_WIDTHS = (1 / 20, 1 / 12, 1 / 6, 1 / 3)
FIG9_SHEARS = (0.3, 0.5)
FIG9_TRIANGLES = 2000
COLUMNS = ("W_over_L", "dW_over_L", "s_over_L", "w_over_L", "delta_percent")


def field_file(out: Path, width: float) -> Path:
    return Path(out) / "fig9" / f"W{width:.4g}.csv"


def write_fields(out: Path, widths=FIG9_WIDTHS, shears=FIG9_SHEARS, triangles: int = FIG9_TRIANGLES,
                 quiet: bool = False) -> list[Path]:
    """Each width's delta field into its file (module docstring); returns the files written now."""
    import ddg
    from ddg.analysis.centerline_approx import centerline_error_field
    from ddg.analysis.curvatures import states_at_shears
    from ddg.output.io import atomic_write_text

    written = []
    for width in widths:
        path = field_file(out, width)
        if path.exists():
            continue
        strip = ddg.Strip.from_ratios(width, 0.5)
        buf = io.StringIO()
        buf.write(",".join(COLUMNS) + "\n")
        for model, state in states_at_shears("plate", strip, 0.5, list(shears), triangles):
            field = centerline_error_field(model, state.q)
            shear = state.shear / strip.length
            for s, w, d in zip(field["s_over_L"], field["w_over_L"], field["delta"]):
                buf.write(f"{width:.6g},{shear:.6g},{s:.5g},{w:.5g},{100 * d:.4g}\n")
            if not quiet:
                print(f"W/L = {width:.4g}, dW/L = {shear:.3g}: mean delta {100 * field['mean']:.3g} %, max "
                      f"{100 * field['max']:.3g} %", file=sys.stderr, flush=True)
        atomic_write_text(path, buf.getvalue())
        written.append(path)
    return written


def shape_files(out: Path, width: float) -> dict[str, Path]:
    folder = Path(out) / "fig9a"
    return {kind: folder / f"W{width:.4g}_{kind}.csv" for kind in ("triangles", "nodes", "centerline")}


def write_shapes(out: Path, widths=FIG9_WIDTHS, shears=FIG9_SHEARS, triangles: int = FIG9_TRIANGLES,
                 quiet: bool = False) -> list[Path]:
    """Each width's deformed plates and centreline frames (Fig. 9a; module docstring); returns the
    centreline files written now (a width whose centreline file exists is skipped)."""
    import ddg
    from ddg.analysis.centerline_approx import centerline_frame
    from ddg.analysis.curvatures import states_at_shears
    from ddg.output.io import atomic_write_text

    written = []
    for width in widths:
        files = shape_files(out, width)
        if files["centerline"].exists():
            continue
        strip = ddg.Strip.from_ratios(width, 0.5)
        L = strip.length
        nodes, line = io.StringIO(), io.StringIO()
        nodes.write("dW_over_L,node,x_over_L,y_over_L,z_over_L\n")
        line.write("dW_over_L,s_over_L,x_over_L,y_over_L,z_over_L,m2_x,m2_y,m2_z\n")
        mesh = None
        for model, state in states_at_shears("plate", strip, 0.5, list(shears), triangles):
            mesh = model.mesh
            shear = state.shear / L
            for k, x in enumerate(model.positions(state.q) / L):
                nodes.write(f"{shear:.6g},{k},{x[0]:.6g},{x[1]:.6g},{x[2]:.6g}\n")
            frame = centerline_frame(model, state.q)
            for s, x, m2 in zip(frame["s"] / L, frame["x"] / L, frame["m2_node"]):
                line.write(f"{shear:.6g},{s:.6g},{x[0]:.6g},{x[1]:.6g},{x[2]:.6g},{m2[0]:.6g},{m2[1]:.6g},{m2[2]:.6g}\n")
            if not quiet:
                print(f"Fig. 9a: W/L = {width:.4g}, dW/L = {shear:.3g}", file=sys.stderr, flush=True)
        atomic_write_text(files["triangles"], "i,j,k\n" + "".join(f"{a},{b},{c}\n" for a, b, c in mesh.triangles))
        atomic_write_text(files["nodes"], nodes.getvalue())
        atomic_write_text(files["centerline"], line.getvalue())
        written.append(files["centerline"])
    return written


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m validation.paper_figures", description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="data/paper_figures")
    parser.add_argument("--quiet", action="store_true")
    args = parser.parse_args(argv)
    from ddg.geometry.strip import InputError
    from ddg.output.io import check_output_directory

    try:
        check_output_directory(args.out, "--out")
    except InputError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    write_fields(Path(args.out), quiet=args.quiet)
    write_shapes(Path(args.out), quiet=args.quiet)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
