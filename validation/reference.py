"""What the models are compared with: the paper's quoted values, the exact elastica, the FEM gold
data, and the comparison metrics.

Paper values (Huang, Wang, Li, Jawed, section 4; read by eye from dynamic runs and experiments):
dL/L = 1/2: W/L = 1/20: dW1/L ~ 0.36, dW2/L ~ 0.52; W/L = 1/6: dW1/L ~ 0.27; W/L = 1/2: ~ 0.17.
dL/L = 1/4: W/L = 1/20: 0.23 and 0.37; dW1 drops by 15.8, 29.1 and 65.6 % at W/L = 1/12, 1/6, 1/2.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ddg.output.io import StoredRun

ROOT = Path(__file__).resolve().parent.parent
FEM_GOLD = ROOT / "data" / "fem_gold"
FEM_FINE = ROOT / "data" / "fem_fine"   # FEM runs kept for comparison (other meshes)
FEM_DEP = ROOT / "data" / "fem_dep"     # FEM shell with the DDG plate's material (--material dep)

#: (dL/L, W/L) -> {"dW1": value, "dW2": value} as quoted in the text of the paper.
PAPER_THRESHOLDS = {
    (0.5, 0.05): {"dW1": 0.36, "dW2": 0.52},
    (0.5, 1 / 6): {"dW1": 0.27},
    (0.5, 0.5): {"dW1": 0.17},
    (0.25, 0.05): {"dW1": 0.23, "dW2": 0.37},
    (0.25, 1 / 12): {"dW1": 0.23 * (1 - 0.158)},
    (0.25, 1 / 6): {"dW1": 0.23 * (1 - 0.291)},
    (0.25, 0.5): {"dW1": 0.23 * (1 - 0.656)},
}
#: Percent drops of dW1 against W/L = 1/20 quoted at dL/L = 1/4 (W/L = 1/12, 1/6, 1/2).
PAPER_DROPS_QUARTER = {1 / 12: 15.8, 1 / 6: 29.1, 0.5: 65.6}


def paper_value(compression_ratio: float, width_ratio: float, key: str):
    for (c, w), values in PAPER_THRESHOLDS.items():
        if abs(c - compression_ratio) < 1e-9 and abs(w - width_ratio) < 1e-6:
            return values.get(key)
    return None


def gold_name(compression_ratio: float, width_ratio: float) -> str:
    """The gold scene folder, as fem_reference.gold.scene_name writes it."""
    return f"dL{compression_ratio:.4g}_W{width_ratio:.4g}"


#: A FEM reference run read from data/fem_gold/<scene>/ (or any output folder of the contract).
GoldCurve = StoredRun


def load_gold(compression_ratio: float, width_ratio: float, root: Path = FEM_GOLD) -> GoldCurve | None:
    """The scene's FEM reference run: the finest mesh of its study (fem_reference.gold.finest_run),
    or None."""
    from fem_reference.gold import finest_run

    directory = finest_run(Path(root) / gold_name(compression_ratio, width_ratio))
    if directory is None or not (directory / "path.csv").exists():
        return None
    return GoldCurve(directory)


def load_dep_material(root: Path = FEM_DEP) -> GoldCurve | None:
    """The FEM shell run with the DDG plate's material at W/L = 1/6, dL/L = 1/2 (data/fem_dep), or None."""
    directory = Path(root) / "dL0.5_W0.1667_N90"
    return GoldCurve(directory) if (directory / "summary.json").exists() else None


def curve_error(dw: np.ndarray, h: np.ndarray, dw_ref: np.ndarray, h_ref: np.ndarray,
                exclude: list[float] = (), band: float = 0.02) -> float:
    """Largest |H(dW) - H_ref(dW)| (in units of L) over the common dW range, away from the given
    thresholds (|dW - t| > band: there a small shift of the threshold is a large error in H).
    H_mid is the same on the mirror branches (US+/US-), so the branch sign does not matter."""
    dw, h, dw_ref, h_ref = map(np.asarray, (dw, h, dw_ref, h_ref))
    order = np.argsort(dw_ref)
    dw_ref, h_ref = dw_ref[order], h_ref[order]
    keep = (dw >= dw_ref[0]) & (dw <= dw_ref[-1])
    for t in exclude:
        if t is not None and np.isfinite(t):
            keep &= np.abs(dw - t) > band
    if not np.any(keep):
        return float("nan")
    return float(np.max(np.abs(h[keep] - np.interp(dw[keep], dw_ref, h_ref))))
