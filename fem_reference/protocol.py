"""The Naghdi strip as a stepper of ddg.protocol's compress-then-shear loop, and its thresholds.

ShellStepper is what ddg.protocol.driver.follow needs of a solver (rest, advance, failure,
summarise) on top of continuation.Stepper's adaptive load stepping, loads in units of L:

* compression: the first recorded step starts from the inextensible guess (at most
  continuation.GUESS_COMPRESSION_LIMIT), the rest continue from the last state;
* shear: at the first recorded U state with a negative eigenvalue the path switches to US+
  along the critical mode (continuation.switch_branch) inside that step, so the recorded row is
  the switched state (paper App. E); the stepper keeps the brackets of the thresholds as
  restartable points (load, state, secant history): the last stable U and the first unstable
  U state (dW1), the last US and the first S state after the switch (dW2);
* every recorded state is an continuation.Observation (its row of path.csv, eigenvalues from
  one factorisation).

threshold_steps() gives dW1 (inertia bisection on U, continuation.locate_dw1) and dW2
(bisection from US, continuation.locate_dw2) as ddg.protocol after-steps: they run once the
path has ended, from the brackets, so the path itself is never disturbed by them.
"""
from __future__ import annotations

import time

import numpy as np

from ddg.protocol.after import ThresholdStep
from ddg.protocol.driver import AfterStep

from . import continuation
from .continuation import GUESS_COMPRESSION_LIMIT, Branch, ContinuationFailure, Observation

#: summary.json's message while the thresholds are located: the DDG models' threshold step's
LOCATING = ThresholdStep.checkpoint


class ShellStepper:
    """ddg.protocol.driver.Stepper for the shell (see the module docstring); loads in units of L."""

    failure = ContinuationFailure

    def __init__(self, stepper: continuation.Stepper, observer: continuation.Observer,
                 options: continuation.ContinuationOptions, shear_ratio: float):
        self.stepper, self.observer, self.options = stepper, observer, options
        self.model, self.solver = stepper.model, stepper.solver
        self.shear_ratio = shear_ratio
        self.switched = False
        self.branch_switch: dict | None = None  # summary.json's branch_switch
        self.last_stable_u: tuple | None = None  # (point, lambda_min)
        self.first_unstable_u: tuple | None = None  # (shear, lambda_min) of the first unstable U state
        self.last_us: tuple | None = None  # point
        self.first_s: float | None = None  # shear of the first S state after a US one
        self.step_times: list[float] = []

    def point(self) -> tuple:
        """(load, state, secant history): where continuation.Stepper.restore restarts from."""
        s = self.stepper
        return (s.load, self.model.get_state(), Branch(list(s.branch.loads), list(s.branch.states)))

    def _observe(self, stage: str, iterations: int, t0: float, switched: bool = False) -> Observation:
        return self.observer.observe(stage, iterations, switched, time.perf_counter() - t0)

    def rest(self) -> Observation:
        t0 = time.perf_counter()
        self.model.set_clamp(0.0, 0.0)
        return self._observe("compression", 0, t0)

    def advance(self, state, compression: float, shear: float, stage: str, index: int) -> Observation:
        t0 = time.perf_counter()
        if stage == "compression" and index == 0:
            iterations = self._start_compression(compression)
        else:
            if stage == "shear" and index == 0:
                self.stepper.branch.reset(self.stepper.load, self.model.get_state())
            iterations = 0
        iterations += self.stepper.advance((compression, shear)).newton_iterations
        observed = self._observe(stage, iterations, t0)
        if stage == "shear":
            observed = self._after_shear_step(observed, iterations, t0)
        self.step_times.append(time.perf_counter() - t0)
        return observed

    def _start_compression(self, target: float) -> int:
        guess_at = min(target, GUESS_COMPRESSION_LIMIT)
        self.model.set_clamp(guess_at, 0.0)
        self.model.inextensible_guess(guess_at)
        try:
            with self.solver.counting("compression start"):
                iterations = self.solver.newton()
        except Exception as exc:  # noqa: BLE001  (NewtonFailure or a PETSc error: the path cannot start)
            raise ContinuationFailure(f"Newton from the inextensible guess at dL/L = {guess_at:g}: {exc}") from exc
        self.stepper.branch.reset(self.stepper.load, self.model.get_state())
        return iterations

    def _after_shear_step(self, observed: Observation, iterations: int, t0: float) -> Observation:
        """Brackets of the thresholds, and the branch switch at the first unstable U state."""
        row = observed.row
        if not self.switched and row["phase"] == "U":
            if observed.negative == 0:
                self.last_stable_u = (self.point(), row["lambda_min"])
            elif self.first_unstable_u is None and self.last_stable_u is not None:
                self.first_unstable_u = (row["dW_over_L"], row["lambda_min"])
            if observed.negative > 0 and self.options.branch_switching:
                observed = self._switch(observed, iterations, t0)
                row = observed.row
        if self.switched and self.first_s is None:
            if row["phase"].startswith("US"):
                self.last_us = self.point()
            elif row["phase"].startswith("S") and self.last_us is not None:
                self.first_s = row["dW_over_L"]
        return observed

    def _switch(self, unstable: Observation, iterations: int, t0: float) -> Observation:
        t_switch = time.perf_counter()
        with self.solver.clock.section("branch switching"):
            if unstable.mode is not None:  # the critical mode of this state, observed above
                value, mode = unstable.row["lambda_min"], unstable.mode
            else:
                values, vectors = self.solver.lowest_modes(1)
                value, mode = values[0], vectors[0]
            try:
                switch_iterations, amplitude = continuation.switch_branch(self.stepper, mode,
                                                                          self.options.perturbation)
            except ContinuationFailure as exc:
                exc.reached = unstable  # the unstable U state is recorded, then the path stops
                raise
        self.switched = True
        self.branch_switch = {"dW_over_L": float(unstable.row["dW_over_L"]), "mode_eigenvalue": float(value),
                              "start_amplitude_over_L": self.options.perturbation,
                              "amplitude_over_L": float(amplitude), "unstable_U_lambda_min": float(value),
                              "wall_time_s": time.perf_counter() - t_switch}
        return self._observe("shear", iterations + switch_iterations, t0, switched=True)

    def failure_message(self, exc: BaseException) -> str:
        load = self.stepper.load
        share = 100.0 * abs(load[1]) / self.shear_ratio if self.shear_ratio > 0 else 0.0
        return (f"stopped converging at dL/L = {load[0]:.6f}, dW/L = {load[1]:.6f} "
                f"({share:.1f} % of dW_max): {exc}")

    def summarise(self, summary: dict) -> None:
        """Newton iterations (total and by phase), the branch switch, and the solver clock's
        split of the driver's wall_time_s (path_wall_time_s: all but the build, thresholds
        included; wall_time_by_phase_s: fem_reference.solver.TIME_PHASES plus the build, summing
        to wall_time_s)."""
        summary["newton_iterations"] = self.solver.total_iterations
        breakdown = self.stepper.iteration_breakdown()
        summary["newton_iterations_by_phase"] = breakdown
        if self.options.thresholds:
            summary["threshold_newton_iterations"] = breakdown["threshold dW1"] + breakdown["threshold dW2"]
        summary["branch_switch"] = self.branch_switch
        summary["fold_traces"] = list(self.stepper.fold_traces)  # continuation.trace_across_fold
        summary["threshold_tolerances_over_L"] = {"dW1": self.options.dw1_tolerance, "dW2": self.options.dw2_tolerance}
        summary["wall_time_per_step_s"] = float(np.mean(self.step_times)) if self.step_times else None
        clock = self.solver.clock
        path_wall = summary["wall_time_s"] - summary["build_wall_time_s"]  # the driver's wall time, build excluded
        summary["path_wall_time_s"] = path_wall
        summary["wall_time_by_phase_s"] = clock.breakdown(path_wall, {"build": summary["build_wall_time_s"]})
        summary["wall_time_within_phases_s"] = {k: dict(v) for k, v in clock.within.items()}


def threshold_steps(shell: ShellStepper, summary: dict) -> list[AfterStep]:
    """dW1 and dW2 from the brackets the path left (none without options.thresholds): each
    restarts the shell from its bracket's lower point; summary gets dW1_over_L, dW2_over_L
    (|dW| / L) and threshold_wall_time_s (their sum)."""
    if not shell.options.thresholds:
        return []
    summary["threshold_wall_time_s"] = 0.0

    def timed(locate):
        def run(outcome) -> None:
            t0 = time.perf_counter()
            with shell.solver.clock.section("threshold location"):
                locate()
            summary["threshold_wall_time_s"] += time.perf_counter() - t0
        return run

    def dw1() -> None:
        if shell.first_unstable_u is None or shell.last_stable_u is None:
            return
        (low, low_lambda), (high_shear, high_lambda) = shell.last_stable_u, shell.first_unstable_u
        try:
            found, _ = continuation.locate_dw1(shell.stepper, low, high_shear, shell.options.dw1_tolerance,
                                               lambdas=(low_lambda, high_lambda))
        except ContinuationFailure as exc:  # the path stands; dW1 stays null, with the reason
            summary.setdefault("warnings", []).append(f"dW1 not located (bisection on U): {exc}")
            return
        summary["dW1_over_L"] = abs(found)

    def dw2() -> None:
        if shell.first_s is None or shell.last_us is None:
            return
        found, _ = continuation.locate_dw2(shell.stepper, shell.last_us, shell.first_s, shell.options.dw2_tolerance)
        summary["dW2_over_L"] = abs(found)

    return [AfterStep(ThresholdStep.stage, timed(dw1), f"{LOCATING} (dW1, bisection on U)"),
            AfterStep(ThresholdStep.stage, timed(dw2), f"{LOCATING} (dW2, bisection from US)")]
