"""Steps after the recorded path: the thresholds dW1, dW2 (ddg.solve.thresholds) and every
branch of the shear stage (ddg.solve.branches), started from recorded states.

`Brackets` listens to the recorded shear rows and keeps the states that bracket the phase
changes U -> US and US -> S; `ThresholdStep` and `BranchStep` are the driver's AfterSteps.
"""
from __future__ import annotations

import time

from ..analysis.observables import observe, unresolved_reason
from ..solve.branches import trace_branches
from ..solve.state import Snapshot, phase_of
from ..solve.thresholds import shear_thresholds

THRESHOLD_KEYS = ("dW1_over_L", "dW2_over_L", "dW2_S_stable_over_L")


class Brackets:
    """The recorded states that bracket the phase changes U -> US and US -> S (a driver
    listener on the shear rows of `model`; phase from the row, or from phase_of(state))."""

    def __init__(self, model, phase_of_row=lambda row: row["phase"]):
        self.model = model
        self.phase_of_row = phase_of_row
        self.last_u: Snapshot | None = None
        self.first_us: float | None = None
        self.last_us: Snapshot | None = None
        self.first_s: Snapshot | None = None
        #: the last US state before the snap into S, where the path snapped past a fold: within a
        #: hard substep of the fold, where the fold's location starts (ddg.solve.thresholds)
        self.near_fold: Snapshot | None = None

    def __call__(self, stage: str, state, row: dict) -> None:
        if stage == "shear":
            self.track(state, self.phase_of_row(row))

    def track(self, state, phase: str) -> None:
        model = self.model
        if phase == "U" and self.first_us is None:
            self.last_u = Snapshot.take(model, state)
        elif phase.startswith("US"):
            if self.first_us is None and self.last_u is not None:
                self.first_us = state.shear
            if self.first_s is None:
                self.last_us = Snapshot.take(model, state)
        elif phase.startswith("S") and self.first_s is None and self.last_us is not None:
            self.first_s = Snapshot.take(model, state)
            before = getattr(state, "snapped_from", None)
            if before is not None and phase_of(model, before.state).startswith("US") and \
                    _between(before.state.shear, self.last_us.state.shear, state.shear):
                self.near_fold = before


def _between(x: float, a: float, b: float) -> bool:
    return min(a, b) < x < max(a, b)


def locate_thresholds(summary: dict, model, options, brackets: Brackets) -> None:
    """dW1, dW2 and dW2_S_stable from stability, refined from the bracketing recorded states;
    summary keys THRESHOLD_KEYS, dW2_located_by ("fold", "bisection" or None: ddg.solve.thresholds),
    threshold_wall_time_s, threshold_newton_iterations."""
    t0 = time.perf_counter()
    found = shear_thresholds(model, options, brackets.last_u, brackets.first_us, brackets.last_us, brackets.first_s,
                             near_fold=brackets.near_fold)
    L = model.strip.length
    for key, name in zip(("dW1", "dW2", "dW2_S_stable"), THRESHOLD_KEYS):
        summary[name] = None if found[key] is None else abs(found[key]) / L
    summary["dW2_located_by"] = found["dW2_method"]
    summary["threshold_wall_time_s"] = time.perf_counter() - t0
    summary["threshold_newton_iterations"] = found["newton_iterations"]


def check_thresholds_resolved(summary: dict, rows: list[dict]) -> None:
    """Null every threshold located from states the discretisation does not resolve
    (ddg.analysis.observables.unresolved_reason); its value and the reason go to
    `unresolved_thresholds`, a line to `warnings`. No threshold is printed from such a state."""
    for key in THRESHOLD_KEYS:
        value = summary.get(key)
        if value is None:
            continue
        reason = unresolved_reason(rows, value)
        if reason is not None:
            summary[key] = None
            summary["unresolved_thresholds"][key] = {"value": value, "reason": reason}
            summary["warnings"].append(f"{key} = {value:.4g} not reported (unresolved): {reason}")


class ThresholdStep:
    """AfterStep: the thresholds of `model` into `summary`. prefix "rod_" reports a driving
    rod's thresholds under rod_* keys (the rod-driven ribbon), its warnings marked "rod: "."""

    stage = "threshold location"
    checkpoint = "running: path done, locating thresholds"

    def __init__(self, summary: dict, model, options, brackets: Brackets, rows: list[dict] | None = None,
                 prefix: str = ""):
        self.summary, self.model, self.options, self.brackets = summary, model, options, brackets
        self.rows, self.prefix = rows, prefix

    def run(self, outcome) -> None:
        rows = outcome.rows if self.rows is None else self.rows
        if not self.prefix:
            locate_thresholds(self.summary, self.model, self.options, self.brackets)
            check_thresholds_resolved(self.summary, rows)
            return
        found = {"warnings": [], "unresolved_thresholds": {}}
        locate_thresholds(found, self.model, self.options, self.brackets)
        check_thresholds_resolved(found, rows)
        for key in THRESHOLD_KEYS:
            self.summary[f"{self.prefix}{key}"] = found[key]
        self.summary["threshold_wall_time_s"] = found["threshold_wall_time_s"]
        self.summary["threshold_newton_iterations"] = found["threshold_newton_iterations"]
        self.summary["warnings"].extend(f"rod: {w}" for w in found["warnings"])


class BranchStep:
    """AfterStep: every branch of the shear stage by pseudo-arclength (ddg.solve.branches) from
    the compressed state; their rows (branches.csv) into `rows`, a per-branch summary under the
    summary key `branches`."""

    stage = "branch tracing"
    checkpoint = "running: thresholds located, tracing branches"

    def __init__(self, summary: dict, model, options, shear_max: float, brackets: Brackets):
        self.summary, self.model, self.options = summary, model, options
        self.shear_max, self.brackets = shear_max, brackets
        self.compressed: Snapshot | None = None
        self.rows: list[dict] = []

    def remember_compressed(self, outcome) -> None:
        """Driver on_compressed hook: the recorded state at the end of compression."""
        self.compressed = Snapshot.take(self.model, outcome.compressed)

    def run(self, outcome) -> None:
        if self.compressed is None:
            return
        model = self.model
        t0 = time.perf_counter()
        saved = model.save_frames()
        try:
            diagram = trace_branches(model, self.options, self.compressed, self.shear_max, self.brackets.first_s)
        finally:
            model.restore_frames(saved)
        self.summary["branches"] = diagram.summary(model.strip.length)
        self.summary["branches_newton_iterations"] = diagram.newton_iterations
        self.summary["branches_wall_time_s"] = time.perf_counter() - t0
        self.rows = [{"branch": b.name, **observe(model, s, "shear", True)} for b in diagram.branches for s in b.states]
