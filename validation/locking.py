"""Membrane locking of the mid-edge plate, measured.

`python -m validation locking --out data/midedge_locking [--fem]` (old spelling `python -m validation.locking`)

A plate discretisation that locks stores spurious membrane energy when it bends: the thinner the
plate, the more it stiffens, so its pitchfork U -> US comes late on coarse meshes. The study runs
the scene W/L = 1/6, dL/L = 1/2 at three slendernesses L/b = 300, 1181 (the paper's strip) and
4000, on 8, 12 and 18 rows of the ghost-clamp mesh, with the two membranes of the mid-edge plate
(ddg.models.midedge_plate.MEMBRANES: "full", the constant-strain triangles alone, and "psri",
alpha = b^2/h^2 of them and the rest node-smoothed), along the path to dW/L = SHEAR_RATIO (past
dW1 but at the locked 8-row plate at L/b = 4000), and records dW1/L, the Newton iterations and the stretching share of
the energy (path.csv `stretching_share`) along the U branch. With --fem it adds the shell
reference (fem_reference, P2 + bubble with its own PSRI) on 64 x 8 elements at the same three
slendernesses: the membrane share of its energy along the default path (to dW_max, without
threshold location: the U branch is what is compared).

Each run is a folder OUT/Lb<L/b>/<membrane>_R<rows>/ (or fem_N64x8/) with path.csv and
summary.json; a finished run is kept (resumable run by run, Ctrl-C keeps what finished).
OUT/summary.json and OUT/locking.md tabulate them, with any other shell run stored as
OUT/Lb<L/b>/fem_N<along>x<across>/: the 96 x 12 check of the shell's membrane share at L/b = 1181
was run to dW/L = 0.26 (`python -m fem_reference simulate --width-ratio 0.16666666666666666
--compression-ratio 0.5 --shear-ratio 0.26 --shear-steps 44 --resolution 96 --across 12 --no-fields
--no-centerline --no-thresholds --no-branch-switching --out OUT/Lb1181.1/fem_N96x12`).
"""
from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

from ddg.output.io import atomic_write_text, finished_run_summary

from .command_line import output_folder, standalone

WIDTH_RATIO, COMPRESSION_RATIO = 1 / 6, 0.5
SLENDERNESSES = (300.0, 1181.1, 4000.0)
ROWS = (8, 12, 18)
MEMBRANES = ("full", "psri")
#: The path is followed to this dW/L (dW1/L is 0.2654 +- 0.0031 at L/b = 1181, FEM gold; the
#: locked 8-row plate's 0.3056), with the default's recorded-step density (120 steps to dW_max).
SHEAR_RATIO = 0.36
#: dW/L at which the stretching share of the U branch is tabulated.
SHARE_AT = (0.1, 0.2, 0.25)
FEM_MESH = (64, 8)


def _steps(strip) -> int:
    from ddg.geometry.strip import LoadingProtocol

    dw_max = LoadingProtocol(COMPRESSION_RATIO).resolved_shear_ratio(strip)
    return max(10, int(round(120 * SHEAR_RATIO / dw_max)))


def run_plate(slenderness: float, rows: int, membrane: str, target: Path) -> dict:
    """One mid-edge plate run into `target` (kept if finished)."""
    import ddg
    from ddg.geometry.plate_mesh import ghost_clamp_mesh

    summary = finished_run_summary(target)
    if summary is not None:
        return summary
    strip = ddg.Strip.from_ratios(WIDTH_RATIO, COMPRESSION_RATIO, slenderness)
    protocol = ddg.LoadingProtocol(COMPRESSION_RATIO, shear_ratio=SHEAR_RATIO, shear_steps=_steps(strip))
    mesh = ghost_clamp_mesh(strip.length, strip.width, rows=rows)
    return ddg.simulate(strip, protocol, model="plate-midedge", mesh=mesh, membrane=membrane, out=target,
                        branches=False, centerline=False).summary


def run_fem(slenderness: float, target: Path) -> dict | None:
    """The shell on FEM_MESH into `target` (a child process: dolfinx stays out of this one)."""
    summary = finished_run_summary(target)
    if summary is not None:
        return summary
    command = [sys.executable, "-m", "fem_reference", "simulate", "--width-ratio", repr(WIDTH_RATIO),
               "--compression-ratio", repr(COMPRESSION_RATIO), "--slenderness", repr(slenderness),
               "--resolution", str(FEM_MESH[0]), "--across", str(FEM_MESH[1]), "--no-fields", "--no-centerline",
               "--no-thresholds", "--quiet", "--out", str(target)]
    subprocess.run(command, check=False)
    return finished_run_summary(target)


def _share_at(rows: list[dict], dw: float) -> float | None:
    """Stretching share of the U state recorded nearest dW/L = dw (None past the U branch)."""
    shear = [r for r in rows if r["stage"] == "shear" and r["phase"] == "U"]
    if not shear or max(r["dW_over_L"] for r in shear) < dw - 0.01:
        return None
    return min(shear, key=lambda r: abs(r["dW_over_L"] - dw)).get("stretching_share")


def tabulate_run(folder: Path) -> dict:
    """{dW/L as text: stretching share of U there} of one stored run (SHARE_AT)."""
    from ddg.output.io import StoredRun

    rows = StoredRun(str(folder)).rows
    return {f"{dw:g}": _share_at(rows, dw) for dw in SHARE_AT}


def tabulate(out: Path) -> dict:
    from ddg.output.io import StoredRun

    entries = []
    for slenderness in SLENDERNESSES:
        folder = out / f"Lb{slenderness:g}"
        fem = sorted((p.name for p in folder.glob("fem_N*")), key=lambda n: int(n[5:].split("x")[0]))
        names = [(m, r, f"{m}_R{r}") for m in MEMBRANES for r in ROWS] + [("fem", n[5:], n) for n in fem]
        for membrane, rows, name in names:
            if finished_run_summary(folder / name) is None:
                continue
            run = StoredRun(str(folder / name))
            s = run.summary
            entries.append({"slenderness": slenderness, "model": "fem" if membrane == "fem" else "plate-midedge",
                            "dW_last_over_L": run.rows[-1]["dW_over_L"] if run.rows else None,
                            "membrane": membrane, "rows": rows, "folder": f"{folder.name}/{name}",
                            "triangles": (s.get("mesh") or {}).get("triangles"), "status": s["status"],
                            "dW1_over_L": s.get("dW1_over_L"), "newton_iterations": s.get("newton_iterations"),
                            "wall_time_s": s.get("wall_time_s"), "folds": len(s.get("folds_dW_over_L") or []),
                            "alpha": (s.get("membrane") or {}).get("alpha"),
                            "stretching_share": tabulate_run(folder / name)})
    summary = {"scene": {"width_ratio": WIDTH_RATIO, "compression_ratio": COMPRESSION_RATIO,
                         "shear_ratio": SHEAR_RATIO}, "runs": entries}
    atomic_write_text(out / "summary.json", json.dumps(summary, indent=2) + "\n")
    lines = ["# Membrane locking of the mid-edge plate (validation/locking.py)", "",
             f"W/L = 1/6, dL/L = 1/2, path to dW/L = {SHEAR_RATIO}. Regenerate: `.venv/bin/python -m "
             f"validation.locking --out {out} --fem`. stretching share: stretching energy over the whole on the U "
             "branch at dW/L = " + ", ".join(f"{dw:g}" for dw in SHARE_AT) + ".", "",
             "| L/b | model | membrane | rows | alpha | dW1/L | reached dW/L | share "
             + " | share ".join(f"{dw:g}" for dw in SHARE_AT)
             + " | folds | Newton its | wall s | status |",
             "|---:|---|---|---:|---:|---:|---:|" + "---:|" * len(SHARE_AT) + "---:|---:|---:|---|"]
    for e in entries:
        shares = " | ".join(_fmt(v, "{:.4f}") for v in e["stretching_share"].values())
        lines.append(f"| {e['slenderness']:g} | {e['model']} | {e['membrane']} | {e['rows']} | "
                     f"{_fmt(e['alpha'], '{:.2g}')} | {_fmt(e['dW1_over_L'])} | {_fmt(e['dW_last_over_L'])} | "
                     f"{shares} | {e['folds']} | "
                     f"{e['newton_iterations']} | {_fmt(e['wall_time_s'], '{:.0f}')} | {e['status']} |")
    lines += ["", "rows: rows of triangles across W (plate); elements along x across (shell)."]
    lines += ["", "rows: rows of triangles across W (plate), elements along x across (shell)."]
    atomic_write_text(out / "locking.md", "\n".join(lines) + "\n")
    return summary


def _fmt(value, spec="{:.4f}"):
    return "-" if not isinstance(value, (int, float)) or isinstance(value, bool) else spec.format(value)


def add_arguments(parser) -> None:
    """The options of `python -m validation locking`."""
    parser.description = __doc__.split("\n")[0]
    parser.add_argument("--out", default="data/midedge_locking")
    parser.add_argument("--fem", action="store_true", help="also the shell on 64 x 8 at each slenderness")
    parser.add_argument("--table-only", action="store_true", help="no run: rewrite the tables")


def run(args) -> int:
    """The study's runs (finished ones kept), then the tables; Ctrl-C or SIGTERM: the tables of what
    is finished, exit 130."""
    from ddg.output.interrupts import terminate_as_interrupt

    terminate_as_interrupt()  # SIGTERM too: the run in progress is written "interrupted", the table rewritten
    out = output_folder(args.out)   # a file or an unwritable folder: one line, exit 2
    if out is None:
        return 2
    try:
        if not args.table_only:
            for slenderness in SLENDERNESSES:
                for rows in ROWS:
                    for membrane in MEMBRANES:
                        t0 = time.perf_counter()
                        s = run_plate(slenderness, rows, membrane, out / f"Lb{slenderness:g}" / f"{membrane}_R{rows}")
                        print(f"L/b {slenderness:g} {membrane} R{rows}: dW1/L {s.get('dW1_over_L')} "
                              f"({time.perf_counter() - t0:.0f} s)", flush=True)
                        tabulate(out)
                if args.fem:
                    run_fem(slenderness, out / f"Lb{slenderness:g}" / ("fem_N%dx%d" % FEM_MESH))
                    tabulate(out)
    except KeyboardInterrupt:
        tabulate(out)
        return 130
    tabulate(out)
    return 0


def main(argv=None) -> int:
    """`python -m validation.locking [options]`: the same as `python -m validation locking [options]`."""
    return standalone("locking", add_arguments, run, argv)


if __name__ == "__main__":
    sys.exit(main())
