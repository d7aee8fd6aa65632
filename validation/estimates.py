"""Converged values with error bars: the mesh studies of the FEM shell (data/fem_gold) and of the
DDG plate (data/plate_gold), and studies of the report's own runs (the rod), read as value objects.

A study is one scene run on three or more meshes; fem_reference.convergence.estimate turns each
quantity's sequence into an extrapolated value with an error bar (Richardson with the observed
order and Roache's grid convergence index where the sequence is asymptotic, the finest value and
the spread where it is not). The claims (validation/claims.py) compare these values, never a
single chosen mesh; `Study.mesh_needed` reads from the same data which mesh of the study is
within a given accuracy of the extrapolated value.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ddg.output.io import StoredRun

from ddg.solve.thresholds import THRESHOLD_TOLERANCES

from .reference import FEM_GOLD, ROOT, gold_name

#: The DDG's threshold bisection brackets (ddg.solve.thresholds), for runs stored before their
#: summary.json recorded them: each study's error bars include them.
DDG_TOLERANCES = dict(zip(("dW1", "dW2"), THRESHOLD_TOLERANCES))

PLATE_GOLD = ROOT / "data" / "plate_gold"
MIDEDGE_GOLD = ROOT / "data" / "midedge_gold"
STUDY_ROOTS = {"fem": FEM_GOLD, "plate": PLATE_GOLD, "plate-midedge": MIDEDGE_GOLD}


@dataclass(frozen=True)
class Estimate:
    """One converged quantity: value (extrapolated, or the finest mesh's where the sequence is not
    asymptotic), error_bar (None from a single mesh), the observed order, whether the sequence was
    asymptotic, and the basis of the error bar in words."""
    value: float
    error_bar: float | None
    order: float | None = None
    asymptotic: bool = False
    basis: str = ""

    @classmethod
    def of(cls, entry: dict | None) -> Estimate | None:
        if not entry or entry.get("value") is None:
            return None
        return cls(float(entry["value"]), None if entry.get("error_bar") is None else float(entry["error_bar"]),
                   None if entry.get("order") is None else float(entry["order"]), bool(entry.get("asymptotic")),
                   str(entry.get("basis", "")))


@dataclass(frozen=True)
class Curve:
    """A quantity (H_mid/L, or the clamp force F_shear L/(E b^3)) against dW/L with a pointwise error bar
    (arrays of equal length, dW increasing), and
    each point's observed order (nan where none) and whether its sequence was asymptotic."""
    dw: np.ndarray
    value: np.ndarray
    error_bar: np.ndarray
    order: np.ndarray | None = None
    asymptotic: np.ndarray | None = None

    def at(self, dw: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(value, error bar) linearly interpolated at dw (inside the curve's range)."""
        return np.interp(dw, self.dw, self.value), np.interp(dw, self.dw, self.error_bar)

    def upto(self, last: float) -> Curve:
        """The curve's points with dW/L <= last."""
        keep = self.dw <= last + 1e-12
        return Curve(self.dw[keep], self.value[keep], self.error_bar[keep],
                     None if self.order is None else self.order[keep],
                     None if self.asymptotic is None else self.asymptotic[keep])


@dataclass(frozen=True)
class MeshResult:
    """One mesh of a study: its label (e.g. "R12", "N96x12"), size (triangles or elements along L),
    thresholds, and the folder of its run (for its H_mid curve)."""
    label: str
    size: int
    size_unit: str
    dW1: float | None
    dW2: float | None
    folder: Path | None = None


@dataclass(frozen=True)
class Study:
    """A model's mesh study of one scene (dL/L, W/L): thresholds, the H_mid/L curve and the clamp
    force's curve (`force`, F_shear L/(E b^3); None where the study has none), each converged value
    with its error bar."""
    model: str
    compression_ratio: float
    width_ratio: float
    meshes: list[MeshResult]
    dW1: Estimate | None
    dW2: Estimate | None
    curve: Curve | None
    source: str
    runs: list = field(default_factory=list, repr=False)   # in-memory runs (studies of the report's own runs)
    force: Curve | None = None

    @property
    def finest(self) -> MeshResult:
        return self.meshes[-1]

    def threshold(self, key: str) -> Estimate | None:
        return {"dW1": self.dW1, "dW2": self.dW2}[key]

    def mesh_needed(self, key: str, accuracy: float, band: float = 0.02) -> MeshResult | None:
        """The coarsest mesh of the study whose distance to the extrapolated value plus the error
        bar of that value is within `accuracy` (key "dW1", "dW2", "curve": the largest over dW
        `band` away from both thresholds, or "force": the same for the clamp force relative to its
        largest |F| there); None when no mesh of the study is."""
        for k, mesh in enumerate(self.meshes):
            error = self.mesh_error(k, key, band)
            if error is not None and error <= accuracy:
                return mesh
        return None

    def mesh_error(self, k: int, key: str, band: float = 0.02) -> float | None:
        mesh = self.meshes[k]
        if key in ("dW1", "dW2"):
            estimate, ours = self.threshold(key), getattr(mesh, key)
            if estimate is None or ours is None or estimate.error_bar is None:
                return None
            return abs(ours - estimate.value) + estimate.error_bar
        run = self.runs[k] if k < len(self.runs) else (StoredRun(mesh.folder) if mesh.folder else None)
        return self.curve_error(run, key, band) if run is not None else None

    def curve_error(self, run, key: str = "curve", band: float = 0.02, with_bar: bool = True) -> float | None:
        """The largest distance of `run`'s (any stored run's) H_mid/L curve ("curve") or clamp force
        ("force": relative to the largest |F| there) to this study's converged one, over the
        converged curve's points `band` away from both converged thresholds and within the run's
        reach, plus the converged value's error bar there (with_bar); None without a curve."""
        curve, column = (self.force, "F_shear_norm") if key == "force" else (self.curve, "H_mid_over_L")
        if curve is None:
            return None
        rows = [r for r in run.rows if r["stage"] == "shear"]
        dw, h = np.array([r["dW_over_L"] for r in rows]), np.array([r[column] for r in rows], float)
        keep = away_from(curve.dw, self.thresholds(), band) & (curve.dw <= dw.max())
        if not np.any(keep):
            return None
        order = np.argsort(dw)
        diff = np.abs(np.interp(curve.dw[keep], dw[order], h[order]) - curve.value[keep])
        scale = float(np.max(np.abs(curve.value[keep]))) if key == "force" else 1.0   # the force: relative
        worst = diff + curve.error_bar[keep] if with_bar else diff
        return float(np.max(worst)) / scale if scale > 0 else None

    def u_branch_orders(self, start: float = 0.05, band: float = 0.02) -> tuple[np.ndarray, int]:
        """Observed orders of H_mid at the asymptotic points of the U branch (start < dW/L < dW1 -
        band; H_mid barely moves below `start`, so its differences there are rounding), and how
        many points that range has."""
        if self.curve is None or self.dW1 is None or self.curve.order is None:
            return np.empty(0), 0
        inside = (self.curve.dw > start) & (self.curve.dw < self.dW1.value - band)
        return self.curve.order[inside & self.curve.asymptotic], int(inside.sum())

    def thresholds(self) -> list[float]:
        return [e.value for e in (self.dW1, self.dW2) if e is not None]

    def describe(self) -> str:
        unit = self.meshes[-1].size_unit if self.meshes else ""
        sizes = "/".join(str(m.size) for m in self.meshes)
        return f"{self.model} study ({sizes} {unit}; {self.source})"


def away_from(dw: np.ndarray, thresholds, band: float) -> np.ndarray:
    """dW values more than `band` from every threshold."""
    keep = np.ones_like(dw, dtype=bool)
    for t in thresholds:
        if t is not None and math.isfinite(t):
            keep &= np.abs(dw - t) > band
    return keep


def difference_away_from_thresholds(curve: Curve, thresholds, dw: np.ndarray, h: np.ndarray,
                                    band: float) -> tuple[np.ndarray, np.ndarray]:
    """A run's H_mid curve (dw ascending, h) against a reference curve, as the error map and the
    scorecard compare them: the reference points inside the run's dW range and more than `band` from
    every one of `thresholds` (the reference's and the run's own: near either H_mid turns or jumps,
    and a threshold's shift is scored by its own quantity), as a mask on curve.dw, and the run's H
    linearly interpolated there minus the reference (signed, on the masked points only)."""
    keep = away_from(curve.dw, thresholds, band) & (curve.dw >= dw[0]) & (curve.dw <= dw[-1])
    return keep, np.interp(curve.dw[keep], dw, h) - curve.value[keep]


def _curve(entries) -> Curve | None:
    points = [(c["dW_over_L"], c["value"], c["error_bar"], np.nan if c.get("order") is None else c["order"],
               bool(c.get("asymptotic"))) for c in entries or []
              if c.get("value") is not None and c.get("error_bar") is not None]
    if len(points) < 2:
        return None
    dw, value, bar, order, asymptotic = (np.array(v) for v in zip(*sorted(points)))
    return Curve(dw.astype(float), value.astype(float), bar.astype(float), order.astype(float), asymptotic.astype(bool))


def load_study(model: str, compression_ratio: float, width_ratio: float, root: Path | None = None,
               name: str | None = None) -> Study | None:
    """The stored study of `model` ("fem", "plate" or "plate-midedge") on a scene:
    OUT/<scene>/richardson.json of `python -m fem_reference gold` or `python -m validation plate-gold
    [--model plate-midedge]`; None without one. `name`: the scene folder when it is not the paper's
    strip (fem_reference.gold.scene_name with L/b, e.g. dL0.5_W0.05_Lb300)."""
    folder = Path(root or STUDY_ROOTS[model]) / (name or gold_name(compression_ratio, width_ratio))
    path = folder / "richardson.json"
    if not path.exists():
        return None
    data = json.loads(path.read_text())
    meshes = []
    for m in data.get("meshes", []):
        if model == "fem":
            size, unit = int(m["along"]), "elements along L"
        else:
            size, unit = int(m["triangles"]), "triangles"
        meshes.append(MeshResult(m["folder"], size, unit, m.get("dW1_over_L"), m.get("dW2_over_L"),
                                 folder / m["folder"]))
    if not meshes:
        return None
    scene = data["scene"]
    return Study(model, float(scene["compression_ratio"]), float(scene["width_ratio"]), meshes,
                 Estimate.of(data.get("dW1")), Estimate.of(data.get("dW2")), _curve(data.get("H_mid_curve")),
                 str(path.relative_to(ROOT)) if path.is_relative_to(ROOT) else str(path),
                 force=_curve(data.get("F_shear_curve")))


def study_from_runs(model: str, runs, resolutions, unit: str = "elements") -> Study | None:
    """A study of in-memory runs of one scene on increasing `resolutions` (e.g. the report's rod
    runs at M = 50/100/200), extrapolated as the stored studies are; None with fewer than 2 runs."""
    from fem_reference.convergence import study_estimates

    pairs = sorted(zip(resolutions, runs), key=lambda p: p[0])
    if len(pairs) < 2:
        return None
    resolutions, runs = [n for n, _ in pairs], [r for _, r in pairs]
    estimates = study_estimates(runs, resolutions, default_tolerances=DDG_TOLERANCES)
    scene = runs[-1].summary["scene"]
    prefix = "M" if model in ("rod", "ribbon") else "N"   # M: the rod's nodes, as its CLI names it
    meshes = [MeshResult(f"{prefix}{n}", int(n), unit, r.summary.get("dW1_over_L"), r.summary.get("dW2_over_L"))
              for n, r in zip(resolutions, runs)]
    return Study(model, float(scene["compression_ratio"]), float(scene["width_ratio"]), meshes,
                 Estimate.of(estimates.get("dW1")), Estimate.of(estimates.get("dW2")),
                 _curve(estimates.get("H_mid_curve")), "runs of this report", runs=list(runs),
                 force=_curve(estimates.get("F_shear_curve")))


def single_run_study(model: str, run, error_of, force_error_of=None) -> Study:
    """One run as a study whose curves' error bars are borrowed: `error_of(dw)` gives the pointwise
    error bar of H_mid (e.g. the same mesh's measured error for the nu = 0 shell, for the shell with
    the plate's material, data/fem_dep, which has one mesh only), `force_error_of(dw)` that of the
    clamp force (no force curve without it). Thresholds carry no error bar."""
    rows = [r for r in run.rows if r["stage"] == "shear"]
    order = np.argsort([r["dW_over_L"] for r in rows])
    dw = np.array([rows[i]["dW_over_L"] for i in order])
    value = np.array([rows[i]["H_mid_over_L"] for i in order])
    force = None
    if force_error_of is not None:
        f = np.array([rows[i]["F_shear_norm"] for i in order], float)
        force = Curve(dw, f, np.asarray(force_error_of(dw), float))
    scene = run.summary["scene"]
    resolution = int(scene.get("resolution") or 0)
    mesh = MeshResult(f"N{resolution}", resolution, "elements along L", run.summary.get("dW1_over_L"),
                      run.summary.get("dW2_over_L"))
    return Study(model, float(scene["compression_ratio"]), float(scene["width_ratio"]), [mesh],
                 None if mesh.dW1 is None else Estimate(mesh.dW1, None),
                 None if mesh.dW2 is None else Estimate(mesh.dW2, None),
                 Curve(dw, value, np.asarray(error_of(dw), float)), str(getattr(run, "directory", "run")),
                 runs=[run], force=force)
