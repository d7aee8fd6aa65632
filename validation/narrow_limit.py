"""The narrow strip against the rod: is the narrow plate's and shell's dW2 below
the rod's physics or discretisation?

At W/L = 1/20, dL/L = 1/2 and the paper's L/b = 1181, W^2/(b L) = 2.95: a strip that wide relative
to sqrt(b L) is not a rod, since its cross-section bends (anticlastic and membrane effects grow with
W^2/(b L)). A rod's normalised thresholds depend on L/b only through W/b (its in-plane bending
stiffness); a plate's and a shell's should approach the rod's as W^2/(b L) -> 0 at fixed W/L, if
the gap is physics.

`python -m validation narrow-limit [--out data/narrow_limit] [--slenderness 1181.10236 300 100]`
(old spelling `python -m validation.narrow_limit`) runs, at each L/b, the FEM shell (fem_reference
simulate, 64 x 8 and 96 x 12 elements), the DDG plate (exactly equilateral meshes of 8 and 12 rows),
the rod (M = 100, 200; it depends on L/b through its in-plane bending stiffness only, (W/b)^2 times
its out-of-plane one) and the 1D model with its cross-section (ribbon-cross-section, M = 101, 201)
through the default path (docs/guide/run_a_scene.rst: 40 compression and 120 shear steps to dW_max,
no branch tracing) into OUT/Lb<L/b>/<model>_<mesh>/ (path.csv, summary.json; at the paper's L/b the
FEM and plate runs are those of data/fem_gold and data/plate_gold), then writes
OUT/narrow_limit.json and OUT/narrow_limit.md: dW1/L and dW2/L per model and mesh, with W^2/(b L).
Resumable run by run (a finished run is kept); the FEM runs in a subprocess, so dolfinx stays inside
fem_reference.
"""
from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

from ddg.output.io import atomic_write_text, finished_run_summary

from .command_line import output_folder, refuse, standalone

WIDTH_RATIO = 1 / 20
COMPRESSION_RATIO = 1 / 2
PAPER_SLENDERNESS = 1181.1023622047244
FEM_MESHES = ((64, 8), (96, 12))
PLATE_ROWS = (8, 12)
ROD_RESOLUTIONS = (100, 200)
CROSS_SECTION_RESOLUTIONS = (101, 201)


def run_fem(folder: Path, slenderness: float, along: int, across: int) -> dict | None:
    """One FEM shell run (subprocess: python -m fem_reference simulate), or its stored summary."""
    if (done := finished_run_summary(folder)) is not None:
        return done
    command = [sys.executable, "-m", "fem_reference", "simulate", "--width-ratio", repr(WIDTH_RATIO),
               "--compression-ratio", repr(COMPRESSION_RATIO), "--slenderness", repr(slenderness),
               "--resolution", str(along), "--across", str(across), "--no-fields", "--no-centerline", "--quiet",
               "--out", str(folder)]
    subprocess.run(command, check=False)
    return finished_run_summary(folder)


def run_ddg(folder: Path, model: str, slenderness: float, resolution: int) -> dict | None:
    """One DDG run (plate: an equilateral mesh of `resolution` rows; the 1D models: M = resolution)."""
    if (done := finished_run_summary(folder)) is not None:
        return done
    import ddg
    from ddg.geometry.plate_mesh import equilateral_mesh

    strip = ddg.Strip.from_ratios(WIDTH_RATIO, COMPRESSION_RATIO, slenderness)
    protocol = ddg.LoadingProtocol(COMPRESSION_RATIO)
    if model == "plate":
        mesh = equilateral_mesh(strip.length, strip.width, resolution)
        ddg.simulate(strip, protocol, model="plate", mesh=mesh, out=folder, branches=False, progress=False,
                     centerline=False)
    else:
        ddg.simulate(strip, protocol, model=model, resolution=resolution, out=folder, branches=False, progress=False,
                     centerline=False)
    return finished_run_summary(folder)


def runs(slenderness: float) -> list[tuple[str, str, int, int | None]]:
    """(model, folder name, resolution, across) of the runs at one L/b."""
    out = [("fem", f"fem_N{a}x{c}", a, c) for a, c in FEM_MESHES]
    out += [("plate", f"plate_R{r}", r, None) for r in PLATE_ROWS]
    out += [("rod", f"rod_M{m}", m, None) for m in ROD_RESOLUTIONS]
    out += [("ribbon-cross-section", f"ribbon-cross-section_M{m}", m, None) for m in CROSS_SECTION_RESOLUTIONS]
    return out


def slenderness_name(slenderness: float) -> str:
    return f"Lb{slenderness:.0f}"


def run_folder(out: Path, slenderness: float, model: str, name: str) -> Path:
    """Where a run is: at the paper's L/b the FEM and plate runs are those of the mesh studies
    (data/fem_gold, data/plate_gold: the same meshes and path), elsewhere OUT/Lb<L/b>/<name>."""
    if abs(slenderness - PAPER_SLENDERNESS) < 1e-6 and model in ("fem", "plate"):
        from .estimates import STUDY_ROOTS
        from .reference import gold_name

        mesh = name.split("_", 1)[1]
        return STUDY_ROOTS[model] / gold_name(COMPRESSION_RATIO, WIDTH_RATIO) / mesh
    return out / slenderness_name(slenderness) / name


def table(out: Path, slendernesses) -> list[dict]:
    """One row per finished run: L/b, W^2/(b L), model, mesh, dW1/L, dW2/L, status, wall time."""
    rows = []
    for s in slendernesses:
        for model, name, resolution, across in runs(s):
            summary = finished_run_summary(run_folder(out, s, model, name))
            if summary is None:
                continue
            rows.append({"slenderness": s, "width_squared_over_thickness_length": WIDTH_RATIO**2 * s,
                         "model": model, "mesh": name.split("_", 1)[1], "dW1_over_L": summary.get("dW1_over_L"),
                         "dW2_over_L": summary.get("dW2_over_L"), "status": summary.get("status"),
                         "wall_time_s": summary.get("wall_time_s"),
                         **{f"{k}_unresolved": ((summary.get("unresolved_thresholds") or {}).get(k) or {}).get("value")
                            for k in ("dW1_over_L", "dW2_over_L")}})
    return rows


def write_table(out: Path, rows: list[dict]) -> None:
    atomic_write_text(out / "narrow_limit.json", json.dumps(rows, indent=2) + "\n")

    def f(v, unresolved=None):
        if v is None:
            return "–" if unresolved is None else f"({unresolved:.4f})"
        return f"{v:.4f}"

    lines = [f"# Narrow strip against the rod: W/L = {WIDTH_RATIO:g}, dL/L = {COMPRESSION_RATIO:g}", "",
             "| L/b | W^2/(b L) | model | mesh | dW1/L | dW2/L | status | wall s |",
             "|---:|---:|---|---|---:|---:|---|---:|"]
    for r in rows:
        lines.append(f"| {r['slenderness']:.0f} | {r['width_squared_over_thickness_length']:.3f} | {r['model']} | "
                     f"{r['mesh']} | {f(r['dW1_over_L'], r.get('dW1_over_L_unresolved'))} | "
                     f"{f(r['dW2_over_L'], r.get('dW2_over_L_unresolved'))} | {r['status']} | "
                     f"{(r['wall_time_s'] or 0):.0f} |")
    lines += ["", "In parentheses: a threshold the run located but did not report, because the run left its "
              "model's resolved range before it (summary.json warnings: e.g. a strain above 2 %).", "",
              "The rod depends on L/b only through its in-plane bending stiffness E b W^3 / 12, (W/b)^2 times "
              "its out-of-plane one: W/b = W/L * L/b."]
    atomic_write_text(out / "narrow_limit.md", "\n".join(lines) + "\n")


def add_arguments(parser) -> None:
    """The options of `python -m validation narrow-limit`."""
    parser.description = __doc__.split("\n\n")[0]
    parser.add_argument("--out", default="data/narrow_limit")
    parser.add_argument("--slenderness", type=float, nargs="+", default=[PAPER_SLENDERNESS, 300.0, 100.0])


def run(args) -> int:
    """Every run at each L/b (finished ones kept), the table rewritten after each; an L/b outside
    [20, 1e5] is refused as a parse error (one line, SystemExit(2)) before any folder is made."""
    bad = [s for s in args.slenderness if not 20.0 <= s <= 1e5]
    if bad:
        refuse(f"--slenderness {bad[0]:g} is outside [20, 1e5]")
    out = output_folder(args.out)   # a file or an unwritable folder: one line, exit 2
    if out is None:
        return 2
    for s in args.slenderness:
        for model, name, resolution, across in runs(s):
            folder = run_folder(out, s, model, name)
            t0 = time.perf_counter()
            summary = (run_fem(folder, s, resolution, across) if model == "fem"
                       else run_ddg(folder, model, s, resolution))
            print(f"L/b {s:.0f} {name}: {None if summary is None else summary.get('status')}, "
                  f"{time.perf_counter() - t0:.0f} s, dW1/L {(summary or {}).get('dW1_over_L')}, "
                  f"dW2/L {(summary or {}).get('dW2_over_L')}", flush=True)
            write_table(out, table(out, args.slenderness))
    return 0


def main(argv=None) -> int:
    """`python -m validation.narrow_limit [options]`: the same as `python -m validation narrow-limit [options]`."""
    return standalone("narrow-limit", add_arguments, run, argv)


if __name__ == "__main__":
    raise SystemExit(main())
