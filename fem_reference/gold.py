"""Gold data: the FEM reference on the paper's scenes (section 4: dL/L in {1/2, 1/4} x W/L in
{1/20, 1/12, 1/6, 1/3, 1/2}), `python -m fem_reference gold --out data/fem_gold [--only NAME ...]`.

Each scene goes to OUT/<name>/ (path.csv, summary.json, centerline.csv; no XDMF to keep the data
folder small), name = dL<dL/L>_W<W/L> e.g. dL0.5_W0.1667. Scenes are run one at a time, in
PRIORITY order (the cross-model test needs dL0.5_W0.1667 first), an existing complete scene is
skipped (delete its folder to rerun), and OUT/index.json lists what exists with mesh, wall time
and thresholds.
"""
from __future__ import annotations

import json
import time
from pathlib import Path

from ddg.output.io import atomic_write_text

WIDTH_RATIOS = (1 / 20, 1 / 12, 1 / 6, 1 / 3, 1 / 2)
COMPRESSION_RATIOS = (1 / 2, 1 / 4)
#: Elements along L for the gold runs (across W: near-isotropic, >= 10 for W/L = 1/6).
GOLD_RESOLUTION = 60
#: Scenes run finer: W/L = 1/6 at dL/L = 1/2 is the cross-model reference. Its dW2/L on 60 / 90 / 120
#: elements: 0.4664 / 0.4336 / 0.4306 (extrapolated 0.4293), dW1/L 0.2564 / 0.2614 / 0.2640 (0.2685).
GOLD_RESOLUTIONS = {"dL0.5_W0.1667": 120}


def scene_name(compression_ratio: float, width_ratio: float) -> str:
    return f"dL{compression_ratio:.4g}_W{width_ratio:.4g}"


def scenes() -> list[tuple[str, float, float]]:
    """All ten scenes, the ones the tests need first."""
    first = [(1 / 2, 1 / 6), (1 / 2, 1 / 20), (1 / 2, 1 / 2)]
    rest = [(c, w) for c in COMPRESSION_RATIOS for w in WIDTH_RATIOS if (c, w) not in first]
    return [(scene_name(c, w), c, w) for c, w in first + rest]


def _read_summary(path: Path) -> dict | None:
    """summary.json of a scene folder, None if missing or unreadable (an unreadable one is rerun)."""
    try:
        summary = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    return summary if isinstance(summary, dict) else None


def check_gold_inputs(args) -> list[tuple[str, float, float, int]]:
    """The scenes to run as (name, dL/L, W/L, resolution), every input checked before any work:
    --only names known, --resolution within the mesh bounds and memory (mesh.checked_spec) for
    every selected scene, --out writable. One-line InputError otherwise."""
    from ddg.geometry.strip import InputError
    from ddg.output.io import check_output_directory

    from .mesh import checked_spec

    known = [name for name, _, _ in scenes()]
    only = args.only or None
    if only:
        unknown = [name for name in dict.fromkeys(only) if name not in known]
        if unknown:
            raise InputError(f"--only: unknown gold scene(s) {', '.join(map(repr, unknown))}; "
                             f"choose from {', '.join(known)}")
    selected = []
    for name, dL, W in scenes():
        if only and name not in only:
            continue
        resolution = GOLD_RESOLUTIONS.get(name, GOLD_RESOLUTION) if args.resolution is None else args.resolution
        checked_spec(resolution, W, None, "--resolution")
        selected.append((name, dL, W, int(resolution)))
    check_output_directory(args.out, "--out")
    return selected


def run_gold(args) -> int:
    from ddg.geometry.strip import LoadingProtocol, Strip

    from .api import simulate

    selected = check_gold_inputs(args)
    out = Path(args.out)
    status = 0
    try:
        for name, dL, W, resolution in selected:
            target = out / name
            old = _read_summary(target / "summary.json")
            if old and old.get("converged") and (old.get("scene") or {}).get("resolution") == resolution:
                continue
            strip = Strip.from_ratios(W, dL)
            protocol = LoadingProtocol(dL)
            t0 = time.perf_counter()
            result = simulate(strip, protocol, resolution, out=target, fields=False, progress=not args.quiet)
            if not args.quiet:
                print(f"{name}: converged {result.converged}, {time.perf_counter() - t0:.0f} s, "
                      f"dW1/L {result.summary['dW1_over_L']}, dW2/L {result.summary['dW2_over_L']}", flush=True)
            status = status or (0 if result.converged else 3)
            write_index(out)
    finally:  # also after Ctrl-C: the index lists the interrupted scene as not complete
        from ddg.output.interrupts import deferred_signals

        with deferred_signals():
            write_index(out)
    return status


def write_index(out: Path) -> None:
    """OUT/index.json: every scene folder with a summary, its mesh, wall time and thresholds."""
    index = {}
    for name, dL, W in scenes():
        s = _read_summary(out / name / "summary.json")
        if s is None:
            continue
        scene, mesh = s.get("scene") or {}, s.get("mesh") or {}
        index[name] = {"compression_ratio": dL, "width_ratio": W, "converged": bool(s.get("converged")),
                       "status": s.get("status"), "message": s.get("message", ""),
                       "resolution": scene.get("resolution"), "triangles": mesh.get("triangles"),
                       "n_dof": s.get("n_dof"), "wall_time_s": s.get("wall_time_s"),
                       "H_mid_over_L_compressed": s.get("H_mid_over_L_compressed"),
                       "dW1_over_L": s.get("dW1_over_L"), "dW2_over_L": s.get("dW2_over_L"),
                       "dW_max_over_L": s.get("dW_max_over_L"),
                       "resolved_up_to_dW_over_L": s.get("resolved_up_to_dW_over_L")}
    out.mkdir(parents=True, exist_ok=True)
    atomic_write_text(out / "index.json", json.dumps(index, indent=2) + "\n")
    write_readme(out, index)


README_HEAD = """# FEM gold data (fem_reference, nonlinear Naghdi shell)

Regenerate all scenes (one at a time, complete ones are skipped; about 1-2 hours on 2 cores):

    .venv/bin/python -m fem_reference gold --out data/fem_gold

One scene: `--only dL0.5_W0.1667` (names dL<dL/L>_W<W/L>: dL0.5_W0.05, dL0.5_W0.08333,
dL0.5_W0.1667, dL0.5_W0.3333, dL0.5_W0.5, dL0.25_W0.05, ...). Default mesh: 60 elements along L
(120 for dL0.5_W0.1667, the cross-model reference, about 22 min), across W near-isotropic and at
least 60 W/L. Each folder holds path.csv, summary.json and centerline.csv (the DDG output
contract); `index.json` lists what exists.

Mesh convergence of the W/L = 1/6, dL/L = 1/2 scene, whole paths on 60/90/120 elements along L
(`python -m fem_reference convergence-table --runs ../fem_fine/dL0.5_W0.1667_N60
../fem_fine/dL0.5_W0.1667_N90 dL0.5_W0.1667 --out ../fem_convergence/dL0.5_W0.1667_full`):
../fem_convergence/dL0.5_W0.1667_full/convergence.md. Estimated errors of the 120-element gold run
against the Richardson extrapolation: dW1/L 0.0046 (extrapolated 0.2685), dW2/L 0.0014 (0.4293),
H_mid/L up to 0.0036 L on the path (one point, dW/L = 0.358 on US, where the observed order is
unreliable: 0.009 L). The other gold scenes are on 60 elements, where the same scene is off by
0.012 in dW1/L, 0.037 in dW2/L and up to 0.024 L in H_mid/L: read them as such.

## What exists (written by the gold command)

| scene | elements along L | triangles | unknowns | H_mid/L compressed | dW1/L | dW2/L | complete | wall time s |
|---|---:|---:|---:|---:|---:|---:|---|---:|
"""


def write_readme(out: Path, index: dict) -> None:
    """OUT/README.md: how to regenerate, and the table of the scenes that exist."""
    missing = [name for name, _, _ in scenes() if name not in index]

    def fmt(v, spec="{:.4f}"):
        return "-" if not isinstance(v, (int, float)) or isinstance(v, bool) else spec.format(v)

    def complete(e):
        if e["converged"]:
            return "yes"
        return f"no ({e['status']}): {e['message']}" if e.get("status") else f"no: {e['message']}"

    rows = [f"| {name} | {fmt(e['resolution'], '{}')} | {fmt(e['triangles'], '{}')} | {fmt(e['n_dof'], '{}')} "
            f"| {fmt(e['H_mid_over_L_compressed'], '{:.6f}')} | {fmt(e['dW1_over_L'])} | {fmt(e['dW2_over_L'])} "
            f"| {complete(e)} | {fmt(e['wall_time_s'], '{:.0f}')} |" for name, e in index.items()]
    text = README_HEAD + "\n".join(rows) + "\n"
    if missing:
        text += f"\nNot yet run (one command away, see above): {', '.join(missing)}.\n"
    atomic_write_text(out / "README.md", text)
