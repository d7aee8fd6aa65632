"""The scores: each submitted scene matched to a benchmark scene and its dW1/L, dW2/L and H_mid/L curve
set against the benchmark's in units of its error bars (validation/score.py's docstring: "Scores")."""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..claims import THRESHOLD_BAND
from ..estimates import Estimate, difference_away_from_thresholds
from .results import SubmittedScene
from .scenes import BENCHMARK_VERSION, THRESHOLDS, BenchmarkScene, scene_cells

#: The least pointwise error bar of H_mid/L the scores divide by (units of L). The studies' bars below it
#: are round-off, not discretisation error: past the snap (the S shape) H_mid is zero by symmetry, every
#: FEM mesh gives it to 1e-14 L and the bar is 1e-15 L there, where a code's solver tolerance rather than
#: its accuracy would decide the score; where |H_mid| > 1e-6 L the smallest bar of the studies is
#: 5.3e-7 L (dL/L = 1/3, W/L = 1/10), 5 times this floor.
H_MID_ERROR_BAR_FLOOR = 1e-7


@dataclass(frozen=True)
class Score:
    """One benchmark scene and quantity (QUANTITIES) scored (module docstring): submitted and benchmark
    values (for H_mid/L at the point of largest |difference|, at_dW_over_L, of `points` compared), the
    benchmark's error bar there, the signed difference, in_error_bars and within; None where not scored,
    `note` saying why."""
    scene: BenchmarkScene
    quantity: str
    submitted: float | None = None
    benchmark: float | None = None
    error_bar: float | None = None
    difference: float | None = None
    in_error_bars: float | None = None
    within: bool | None = None
    at_dW_over_L: float | None = None
    points: int | None = None
    line: int | None = None
    note: str = ""

    @property
    def scored(self) -> bool:
        return self.in_error_bars is not None

    def row(self) -> dict:
        """score.csv's row."""
        return {"benchmark_version": BENCHMARK_VERSION, "scene": self.scene.name, "label": self.scene.label,
                **scene_cells(self.scene), "quantity": self.quantity, "submitted": self.submitted,
                "benchmark": self.benchmark, "error_bar": self.error_bar, "difference": self.difference,
                "in_error_bars": self.in_error_bars, "within": self.within, "at_dW_over_L": self.at_dW_over_L,
                "points": self.points, "line": self.line, "note": self.note}


def threshold_score(scene: BenchmarkScene, submitted: SubmittedScene | None, key: str) -> Score:
    """dW1/L or dW2/L of a submitted scene (None: not submitted) against the benchmark's."""
    estimate: Estimate | None = scene.study.threshold(key)
    ours = None if submitted is None else submitted.threshold(key)
    line = None if submitted is None else submitted.thresholds_line
    base = Score(scene, f"{key}_over_L", ours, None if estimate is None else estimate.value,
                 None if estimate is None else estimate.error_bar, line=line)
    if estimate is None:
        return _with(base, note="no benchmark value: the FEM study has none")
    if submitted is None or submitted.thresholds_line is None:
        return _with(base, note="not submitted")
    if ours is None:
        return _with(base, note="empty: not found by the submitted code")
    difference = ours - estimate.value
    if not estimate.error_bar:
        return _with(base, difference=difference, note="the benchmark value has no error bar")
    return _with(base, difference=difference, in_error_bars=abs(difference) / estimate.error_bar,
                 within=abs(difference) <= estimate.error_bar)


def curve_score(scene: BenchmarkScene, submitted: SubmittedScene | None) -> Score:
    """The submitted H_mid/L curve against the benchmark's (module docstring)."""
    curve = scene.study.curve
    base = Score(scene, "H_mid_over_L", line=None if submitted is None or not submitted.curve
                 else submitted.curve[0][2])
    if submitted is None or not submitted.curve:
        return _with(base, note="not submitted")
    if curve is None:
        return _with(base, note="no benchmark curve: the FEM study has none")
    if len(submitted.curve) < 2:
        return _with(base, note="the submitted curve has one point; two or more are needed")
    dw, h = (np.array(v) for v in zip(*sorted((p[0], p[1]) for p in submitted.curve)))
    own = [submitted.dW1, submitted.dW2]
    keep, difference = difference_away_from_thresholds(curve, scene.study.thresholds() + own, dw, h, THRESHOLD_BAND)
    if not np.any(keep):
        return _with(base, note=f"no benchmark point inside the submitted curve's range (dW/L {dw[0]:g} to "
                                f"{dw[-1]:g}) more than {THRESHOLD_BAND:g} from the thresholds")
    bar = np.maximum(curve.error_bar[keep], H_MID_ERROR_BAR_FLOOR)
    worst = int(np.argmax(np.abs(difference)))
    note = (f"largest |difference| at dW/L = {curve.dw[keep][worst]:.4f} of {int(keep.sum())} points; "
            f"in_error_bars: the largest pointwise |difference| / error bar")
    if dw[-1] < curve.dw[-1] - 1e-9:
        note += f"; compared up to dW/L = {dw[-1]:.4f} (the benchmark goes to {curve.dw[-1]:.4f})"
    return _with(base, submitted=float(difference[worst] + curve.value[keep][worst]),
                 benchmark=float(curve.value[keep][worst]), error_bar=float(curve.error_bar[keep][worst]),
                 difference=float(difference[worst]), in_error_bars=float(np.max(np.abs(difference) / bar)),
                 within=bool(np.all(np.abs(difference) <= bar)), at_dW_over_L=float(curve.dw[keep][worst]),
                 points=int(keep.sum()), note=note)


def _with(score: Score, **changes) -> Score:
    return replace(score, **changes)


@dataclass
class Scorecard:
    """The scores of every benchmark scene (three per scene, QUANTITIES order), the submitted scene each
    matched (None: not submitted) and the submitted scenes that match none."""
    scenes: list[BenchmarkScene]
    matched: dict[str, SubmittedScene]
    unmatched: list[SubmittedScene]
    scores: list[Score]

    def of(self, scene: BenchmarkScene) -> list[Score]:
        return [s for s in self.scores if s.scene.name == scene.name]


def score_results(scenes: list[BenchmarkScene], submitted: list[SubmittedScene]) -> Scorecard:
    """Each submitted scene matched to a benchmark scene (module docstring) and scored."""
    matched, unmatched = {}, []
    for entry in submitted:
        scene = next((s for s in scenes if s.matches(entry)), None)
        if scene is None:
            unmatched.append(entry)
        else:   # two submitted scenes cannot match one: they would be within 0.2 % of each other
            matched[scene.name] = entry
    scores = []
    for scene in scenes:
        entry = matched.get(scene.name)
        scores += [threshold_score(scene, entry, key) for key in THRESHOLDS] + [curve_score(scene, entry)]
    return Scorecard(scenes, matched, unmatched, scores)
