"""The benchmark's scenes: every scene with a finished FEM gold study on two meshes or more, its
converged values with error bars, the benchmark's release and the digest of the studies it was
made from (validation/score.py's docstring: "The benchmark")."""
from __future__ import annotations

import hashlib
from dataclasses import dataclass
from pathlib import Path

from ..benchmark import basis_meshes, estimate_basis
from ..estimates import Study, load_study
from ..reference import FEM_GOLD, ROOT
from ..table import fraction_label

#: Every release of the benchmark and the digest of the studies it was made from (benchmark_digest):
#: a new or extended mesh study in data/fem_gold, or a new error-bar rule, is a new release.
#: tests/validation/test_score.py checks that the committed studies are BENCHMARK_VERSION's, so changed data cannot
#: keep an old version. What each release changed: docs/reference/benchmark.rst, "Releases".
BENCHMARK_RELEASES = {
    "2026.11-1": "e7a809c515e9c367",   # 28 scenes
    "2026.11-2": "b42ced51e49a96e2",   # dL/L = 1/3, W/L = 1/6 on a fourth mesh (216 x 28)
    "2026.11-3": "473e7825cf89c444",   # dL/L = 1/3, W/L = 1/3 on a fourth mesh (216 x 54)
}
#: The benchmark's release: the newest of BENCHMARK_RELEASES.
BENCHMARK_VERSION = list(BENCHMARK_RELEASES)[-1]
#: The gold runs' Poisson ratio (summary.json scene.poisson_ratio; ddg.Strip's default).
BENCHMARK_POISSON_RATIO = 0.0
#: Relative tolerance on dL/L, W/L and L/b for a submitted row to be a benchmark scene (0.1 %).
MATCH_TOLERANCE = 1e-3
THRESHOLDS = ("dW1", "dW2")
QUANTITIES = ("dW1_over_L", "dW2_over_L", "H_mid_over_L")
SCENE_COLUMNS = ("compression_ratio", "width_ratio", "slenderness", "poisson_ratio")


@dataclass(frozen=True)
class BenchmarkScene:
    """One scene of the benchmark: its data/fem_gold folder, dL/L, W/L, L/b and the FEM study."""
    name: str
    compression_ratio: float
    width_ratio: float
    slenderness: float
    study: Study

    @property
    def label(self) -> str:
        """e.g. "dL1/2 W1/20 Lb1181"."""
        return (f"dL{fraction_label(self.compression_ratio)} W{fraction_label(self.width_ratio)} "
                f"Lb{self.slenderness:.0f}")

    def matches(self, submitted) -> bool:
        """A submitted scene (validation.scoring.results.SubmittedScene) is this one: nu = 0, and dL/L,
        W/L and L/b within MATCH_TOLERANCE relative."""
        return submitted.poisson_ratio == BENCHMARK_POISSON_RATIO and close(
            (submitted.compression_ratio, submitted.width_ratio, submitted.slenderness),
            (self.compression_ratio, self.width_ratio, self.slenderness))


def close(values, references) -> bool:
    """Each value within MATCH_TOLERANCE of its reference, relative."""
    return all(abs(v - r) <= MATCH_TOLERANCE * abs(r) for v, r in zip(values, references))


def load_benchmark(root: Path = FEM_GOLD) -> list[BenchmarkScene]:
    """The benchmark's scenes (module docstring), in fem_reference.gold.all_scenes() order: those whose
    folder in `root` has a study (richardson.json) on at least two meshes."""
    import ddg
    from fem_reference.gold import all_scenes

    scenes = []
    for name, compression, width, slenderness in all_scenes():
        study = load_study("fem", compression, width, root=root, name=name)
        if study is None or len(study.meshes) < 2:
            continue
        if slenderness is None:
            slenderness = ddg.Strip.from_ratios(width, compression).slenderness
        scenes.append(BenchmarkScene(name, compression, width, float(slenderness), study))
    return scenes


def benchmark_digest(scenes: list[BenchmarkScene]) -> str:
    """A digest of the studies (richardson.json) the benchmark is read from: 16 hex digits."""
    digest = hashlib.sha256()
    for scene in scenes:
        source = Path(scene.study.source)   # relative to the checkout where it is inside it (load_study)
        digest.update(scene.name.encode())
        digest.update((source if source.is_absolute() else ROOT / source).read_bytes())
    return digest.hexdigest()[:16]


def scene_cells(scene: BenchmarkScene) -> dict:
    """A scene's dL/L, W/L, L/b and nu as the cells of a row."""
    return {"compression_ratio": scene.compression_ratio, "width_ratio": scene.width_ratio,
            "slenderness": scene.slenderness, "poisson_ratio": BENCHMARK_POISSON_RATIO}


def benchmark_rows(scenes: list[BenchmarkScene]) -> list[dict]:
    """benchmark.csv's rows (module docstring); None where a value is missing."""
    rows = []
    for scene in scenes:
        row = {"version": BENCHMARK_VERSION, "scene": scene.name, **scene_cells(scene)}
        for key in THRESHOLDS:
            estimate = scene.study.threshold(key)
            row[f"{key}_over_L"] = None if estimate is None else estimate.value
            row[f"{key}_error_bar"] = None if estimate is None else estimate.error_bar
            row[f"{key}_basis"] = estimate_basis(estimate)
            row[f"{key}_meshes"] = None if estimate is None else "/".join(basis_meshes(scene.study, key))
        row["H_mid_points"] = 0 if scene.study.curve is None else len(scene.study.curve.dw)
        row["source"] = scene.study.source
        rows.append(row)
    return rows


def curve_rows(scenes: list[BenchmarkScene]) -> list[dict]:
    """benchmark_H_mid.csv's rows: every point of every scene's H_mid/L curve."""
    rows = []
    for scene in scenes:
        curve = scene.study.curve
        if curve is None:
            continue
        for dw, h, bar in zip(curve.dw, curve.value, curve.error_bar):
            rows.append({"version": BENCHMARK_VERSION, "scene": scene.name, **scene_cells(scene),
                         "dW_over_L": float(dw), "H_mid_over_L": float(h), "error_bar": float(bar)})
    return rows
