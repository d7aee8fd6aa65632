"""The public timing/callback interface of a run: what benchmarks and progress displays watch.

Pass a Probe (or a subclass overriding what it needs) as `ddg.simulate(..., probe=...)`:

- solve(phase, iterations, converged): every Newton solve the path follower makes, with its
  phase (ddg.solve.continuation.PHASES: accepted steps, rejected steps, branch switching,
  compression start, fold snaps);
- step(stage, row, wall_s): every recorded step (the row of path.csv) and the wall time spent
  reaching it since the previous one.

Solves inside threshold location and branch tracing are counted in summary.json
(threshold_newton_iterations, branches_newton_iterations), not reported here. A probe costs a
method call per Newton solve and per step; the default one does nothing.
"""
from __future__ import annotations


class Probe:
    """Receives a run's events; override solve and/or step."""

    def solve(self, phase: str, iterations: int, converged: bool) -> None:
        """One Newton solve of the path follower."""

    def step(self, stage: str, row: dict, wall_s: float) -> None:
        """One recorded step (stage "compression" or "shear") and its wall time (s)."""


#: The probe used when none is given.
SILENT = Probe()
