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

from ddg.io import atomic_write_text

WIDTH_RATIOS = (1 / 20, 1 / 12, 1 / 6, 1 / 3, 1 / 2)
COMPRESSION_RATIOS = (1 / 2, 1 / 4)
#: Elements along L for the gold runs (across W: near-isotropic, >= 10 for W/L = 1/6).
GOLD_RESOLUTION = 60


def scene_name(compression_ratio: float, width_ratio: float) -> str:
    return f"dL{compression_ratio:.4g}_W{width_ratio:.4g}"


def scenes() -> list[tuple[str, float, float]]:
    """All ten scenes, the ones the tests need first."""
    first = [(1 / 2, 1 / 6), (1 / 2, 1 / 20), (1 / 2, 1 / 2)]
    rest = [(c, w) for c in COMPRESSION_RATIOS for w in WIDTH_RATIOS if (c, w) not in first]
    return [(scene_name(c, w), c, w) for c, w in first + rest]


def run_gold(args) -> int:
    from ddg.geometry.strip import InputError, LoadingProtocol, Strip

    from .api import simulate

    out = Path(args.out)
    known = {name for name, _, _ in scenes()}
    only = args.only or None
    if only:
        unknown = sorted(set(only) - known)
        if unknown:
            raise InputError(f"unknown gold scene(s) {unknown}; choose from {sorted(known)}")
    resolution = args.resolution or GOLD_RESOLUTION
    status = 0
    for name, dL, W in scenes():
        if only and name not in only:
            continue
        target = out / name
        summary_path = target / "summary.json"
        if summary_path.exists():
            old = json.loads(summary_path.read_text())
            if old.get("converged") and old["scene"].get("resolution") == resolution:
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
    write_index(out)
    return status


def write_index(out: Path) -> None:
    """OUT/index.json: every scene folder with a summary, its mesh, wall time and thresholds."""
    index = {}
    for name, dL, W in scenes():
        path = out / name / "summary.json"
        if not path.exists():
            continue
        s = json.loads(path.read_text())
        index[name] = {"compression_ratio": dL, "width_ratio": W, "converged": s["converged"],
                       "message": s["message"], "resolution": s["scene"]["resolution"],
                       "triangles": s["mesh"]["triangles"], "n_dof": s["n_dof"],
                       "wall_time_s": s["wall_time_s"], "H_mid_over_L_compressed": s["H_mid_over_L_compressed"],
                       "dW1_over_L": s["dW1_over_L"], "dW2_over_L": s["dW2_over_L"],
                       "dW_max_over_L": s["dW_max_over_L"],
                       "resolved_up_to_dW_over_L": s["resolved_up_to_dW_over_L"]}
    out.mkdir(parents=True, exist_ok=True)
    atomic_write_text(out / "index.json", json.dumps(index, indent=2) + "\n")
