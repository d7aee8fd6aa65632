"""Data of the report's Fig. 9 (the deformed plates and the centreline approximation's error over
the plate, Eq. 13): `python -m validation paper-figures --out data/paper_figures` (old spelling
`python -m validation.paper_figures`).

For W/L in FIG9_WIDTHS at dL/L = 1/2, the plate on FIG9_TRIANGLES triangles is followed along its
stable path to each dW/L of FIG9_SHEARS (ddg.studies.curvature_studies.states_at_shears), and at every
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

import io
import sys
from pathlib import Path

FIG9_WIDTHS = (1 / 20, 1 / 12, 1 / 6, 1 / 3)
FIG9_SHEARS = (0.3, 0.5)
FIG9_TRIANGLES = 2000
COLUMNS = ("W_over_L", "dW_over_L", "s_over_L", "w_over_L", "delta_percent")


def field_file(out: Path, width: float) -> Path:
    return Path(out) / "fig9" / f"W{width:.4g}.csv"


def shape_files(out: Path, width: float) -> dict[str, Path]:
    folder = Path(out) / "fig9a"
    return {kind: folder / f"W{width:.4g}_{kind}.csv" for kind in ("triangles", "nodes", "centerline")}


def write_figure9(out: Path, widths=FIG9_WIDTHS, shears=FIG9_SHEARS, triangles: int = FIG9_TRIANGLES,
                  quiet: bool = False, parts=("fields", "shapes")) -> list[Path]:
    """Each width's Fig. 9b field file and Fig. 9a shape files (module docstring), from one plate
    path per width: a width whose files of `parts` all exist is skipped, and a width missing only
    one part writes only that. Returns the files written now (a width's field file, its
    centreline file)."""
    import ddg
    from ddg.analysis.centerline_approx import centerline_error_field, centerline_frame
    from ddg.studies.curvature_studies import states_at_shears
    from ddg.output.io import atomic_write_text

    written = []
    for width in widths:
        field_path, shapes = field_file(out, width), shape_files(out, width)
        fields = "fields" in parts and not field_path.exists()
        shaped = "shapes" in parts and not shapes["centerline"].exists()
        if not (fields or shaped):
            continue
        strip = ddg.Strip.from_ratios(width, 0.5)
        L = strip.length
        deltas, nodes, line = io.StringIO(), io.StringIO(), io.StringIO()
        deltas.write(",".join(COLUMNS) + "\n")
        nodes.write("dW_over_L,node,x_over_L,y_over_L,z_over_L\n")
        line.write("dW_over_L,s_over_L,x_over_L,y_over_L,z_over_L,m2_x,m2_y,m2_z\n")
        mesh = None
        for model, state in states_at_shears("plate", strip, 0.5, list(shears), triangles):
            mesh, shear = model.mesh, state.shear / L
            if fields:
                field = centerline_error_field(model, state.q)
                for s, w, d in zip(field["s_over_L"], field["w_over_L"], field["delta"]):
                    deltas.write(f"{width:.6g},{shear:.6g},{s:.5g},{w:.5g},{100 * d:.4g}\n")
                if not quiet:
                    print(f"W/L = {width:.4g}, dW/L = {shear:.3g}: mean delta {100 * field['mean']:.3g} %, max "
                          f"{100 * field['max']:.3g} %", file=sys.stderr, flush=True)
            if shaped:
                for k, x in enumerate(model.positions(state.q) / L):
                    nodes.write(f"{shear:.6g},{k},{x[0]:.6g},{x[1]:.6g},{x[2]:.6g}\n")
                frame = centerline_frame(model, state.q)
                for s, x, m2 in zip(frame["s"] / L, frame["x"] / L, frame["m2_node"]):
                    line.write(f"{shear:.6g},{s:.6g},{x[0]:.6g},{x[1]:.6g},{x[2]:.6g},"
                               f"{m2[0]:.6g},{m2[1]:.6g},{m2[2]:.6g}\n")
        if fields:
            atomic_write_text(field_path, deltas.getvalue())
            written.append(field_path)
        if shaped:
            atomic_write_text(shapes["triangles"], "i,j,k\n" + "".join(f"{a},{b},{c}\n" for a, b, c in mesh.triangles))
            atomic_write_text(shapes["nodes"], nodes.getvalue())
            atomic_write_text(shapes["centerline"], line.getvalue())   # last: it marks the width finished
            written.append(shapes["centerline"])
    return written


def write_fields(out: Path, **kw) -> list[Path]:
    """Fig. 9b's files alone (write_figure9)."""
    return write_figure9(out, parts=("fields",), **kw)


def write_shapes(out: Path, **kw) -> list[Path]:
    """Fig. 9a's files alone (write_figure9)."""
    return write_figure9(out, parts=("shapes",), **kw)


def add_arguments(parser) -> None:
    """The options of `python -m validation paper-figures`."""
    parser.description = __doc__.splitlines()[0]
    parser.add_argument("--out", default="data/paper_figures")
    parser.add_argument("--quiet", action="store_true")


def run(args) -> int:
    """Fig. 9's and Fig. 9a's files (write_figure9) after --out is checked."""
    from ddg.geometry.strip import InputError
    from ddg.output.io import check_output_directory

    try:
        check_output_directory(args.out, "--out")
    except InputError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    write_figure9(Path(args.out), quiet=args.quiet)
    return 0


def main(argv=None) -> int:
    """`python -m validation.paper_figures [options]`: the same as `python -m validation paper-figures [options]`."""
    from .command_line import standalone

    return standalone("paper-figures", add_arguments, run, argv)


if __name__ == "__main__":
    raise SystemExit(main())
