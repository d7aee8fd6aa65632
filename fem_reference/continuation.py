"""The loading protocol on the Naghdi strip: adaptive load stepping, stability, thresholds and
branch switching (paper section 4, App. B, E).

* Compression: from an inextensible guess (shell.NaghdiStrip.inextensible_guess) at the first
  load step (at most dL/L = 0.2: the cosine mode cannot span more inextensibly), then the clamp
  at x = L moves by -dL in `compression_steps` recorded steps.
* Shear: the same clamp moves by dW along y in `shear_steps` recorded steps up to dW_max
  (Eq. B.1) or the requested shear ratio.
* Each recorded step is reached by adaptive substeps: Newton (solver.Solver) from the last
  converged state with the clamp increment lifted into the first correction (a tangent
  predictor; ContinuationOptions.predictor = "secant" extrapolates the last two converged states
  first and retries without on failure); a failed substep is halved; a substep that converged
  in <= 6 iterations doubles the next one.
  A substep that still fails below 1e-4 L is past a fold: the state snaps to the next stable
  equilibrium by Levenberg-Marquardt energy descent (solver.Solver.descend).
* Stability after every recorded step: inertia of the constrained tangent (MUMPS L D L^T) and
  its lowest eigenvalue in the metric of shell.EIGEN_NORMALISATION (SLEPc shift-invert on the
  same factorisation, solver.Solver.stability).
* dW1: the symmetric mesh keeps the U branch exactly symmetric, so the path stays on U past the
  pitchfork; at the first recorded step with a negative eigenvalue the bracket is bisected on
  the U branch (solving from the last stable U state, the inertia deciding) until it is
  narrower than 1e-4 L, the first two points straddling the secant root of the recorded
  lambda_min (locate_dw1).
* Branch switch: at that step, the critical mode phi (displacement part normalised to max 1 in
  units of L, sign chosen so the highest point moves into the first half: US+) is added with
  the amplitude that minimises the energy along phi, searched from `perturbation` upward
  (or downward) by factors of 2, then Newton. The switch counts only if the result is US
  (no half-turn symmetry to 1e-4 L) and has no negative eigenvalue.
* dW2: once on US, the first recorded step labelled S is bracketed and bisected (solving from
  the last US state) to 1e-3 L: dW2 is the smallest dW found in S (a failed advance past the
  fold of US narrows the bracket to the substep that failed, locate_dw2).

Counters: every Newton solve counts its iterations in one phase of solver.ITERATION_PHASES
(Stepper.advance: "accepted steps" / "rejected steps" / "fold snaps", or the threshold phase the
stepper is in, Stepper.phase; switch_branch: "branch switching"); Stepper.step_halvings and
Stepper.snaps count the substeps halved and the snaps made; Stepper.iteration_breakdown() is
summary.json's newton_iterations_by_phase.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from ddg.solve.state import SYMMETRY_TOLERANCE, phase_from_measures

from petsc4py import PETSc

from .shell import NaghdiStrip
from .solver import ITERATION_PHASES, NewtonFailure, Solver  # noqa: F401  (ITERATION_PHASES re-exported)

DW1_TOLERANCE = 1e-4
DW2_TOLERANCE = 1e-3
#: The inextensible cosine guess is used at most at this compression (units of L).
GUESS_COMPRESSION_LIMIT = 0.2


class ContinuationFailure(RuntimeError):
    pass


@dataclass
class StepStats:
    newton_iterations: int = 0
    substeps: int = 0
    rejected: int = 0
    snaps: int = 0


@dataclass
class ContinuationOptions:
    min_substep: float = 1e-7  # units of L
    max_substep: float = 0.05  # units of L
    snap_substep: float = 1e-4  # below this failing substep, snap by energy descent (a fold)
    easy_iterations: int = 6  # Newton's last, correction-size check adds one to the ~4 quadratic steps
    max_growth: float = 2.0
    perturbation: float = 1e-3  # starting amplitude of the branch-switch perturbation, units of L
    branch_switching: bool = True
    thresholds: bool = True
    eigenvalues: bool = True
    #: "tangent": Newton from the last converged state, the clamp increment lifted into its first
    #: correction; "secant": from the extrapolation of the last two converged states on the
    #: branch, retried as "tangent" on failure. Measured at 60 x 10 elements, W/L = 1/6, dL/L = 1/2
    #: (whole path, thresholds included): 1213 Newton iterations with "tangent", 1510 with
    #: "secant" (the secant's error is twice the tangent's for equal steps; on the US branch
    #: Newton from it needs 8-16 iterations per step against 7-12), the same states to 1e-8 L.
    predictor: str = "tangent"
    #: where a substep of the path (not of a threshold's bisection) fails below snap_substep and the
    #: descent fails too, trace the branch by pseudo-arclength through its fold, down its unstable
    #: part and on to the first stable state beyond the target (trace_across_fold), once per
    #: converged state
    fold_tracing: bool = True
    #: width of the final bracket of dW1 (the midpoint is reported: within half of it) and of dW2
    #: (its upper end, the first S state found, is reported: within it), units of L; the gold
    #: runs' mesh studies use 1e-4 for both (fem_reference.gold.GOLD_TOLERANCES)
    dw1_tolerance: float = DW1_TOLERANCE
    dw2_tolerance: float = DW2_TOLERANCE

    def __post_init__(self):
        if self.predictor not in ("tangent", "secant"):
            raise ValueError(f"predictor = {self.predictor!r}: 'tangent' or 'secant'")
        for name in ("dw1_tolerance", "dw2_tolerance"):
            value = getattr(self, name)
            if not (isinstance(value, float) and 1e-7 <= value <= 1e-2):
                raise ValueError(f"{name} = {value!r}: a float in [1e-7, 1e-2] (units of L)")


@dataclass
class Branch:
    """Last converged states on the current branch (for the secant predictor)."""

    loads: list = field(default_factory=list)
    states: list = field(default_factory=list)

    def push(self, load, state):
        self.loads = (self.loads + [np.asarray(load, float)])[-2:]
        self.states = (self.states + [state])[-2:]

    def reset(self, load, state):
        self.loads, self.states = [np.asarray(load, float)], [state]


class Stepper:
    """Adaptive load stepping of one NaghdiStrip; loads are (compression, shear) in units of L."""

    def __init__(self, model: NaghdiStrip, solver: Solver, options: ContinuationOptions):
        self.model, self.solver, self.options = model, solver, options
        self.branch = Branch()
        self.substep = math.inf
        #: the phase (solver.ITERATION_PHASES) every solve of advance() counts in, converged or
        #: not; None: the path's own load steps ("accepted steps", "rejected steps", "fold snaps")
        self.phase: str | None = None
        self.step_halvings = 0  # substeps halved after failing (all phases)
        #: load of the last substep that failed below min_substep (set when advance raises
        #: ContinuationFailure; the model is then at the last converged state, self.load)
        self.failed_load: np.ndarray | None = None
        self.snaps = 0  # substeps that converged by energy descent past a fold (all phases)
        self._fold_traced_from: tuple | None = None  # load of the last state a fold trace started from
        self._fold_trace_failed_at: float | None = None  # dW of the last fold trace that found no snap
        #: the fold traces made: their start and landing dW/L, states traced and outcome
        self.fold_traces: list[dict] = []

    def iteration_breakdown(self) -> dict:
        """summary.json's newton_iterations_by_phase: the solver's Newton iterations per phase
        (ITERATION_PHASES; they sum to solver.total_iterations), then counts (not iterations):
        "failed solves" (Newton solves that raised NewtonFailure, every phase), "step halvings"
        and "snaps" (Stepper.advance, every phase), "chord steps" (iterations that reused the
        last factorisation, NewtonOptions.chord_below; already counted in the phases), "round-off
        convergences" (solves accepted with the residual stalled within the round-off floor,
        solver.ROUNDOFF_STALL_ITERATIONS)."""
        return {**self.solver.iterations_by_phase, "failed solves": self.solver.failed_solves,
                "step halvings": self.step_halvings, "snaps": self.snaps, "chord steps": self.solver.chord_steps,
                "round-off convergences": self.solver.roundoff_convergences}

    def may_trace_fold(self, current) -> bool:
        """A fold trace starts once per converged state, and not within FOLD_TRACE_RETRY of the dW
        where one found no snap: each tiny substep that still converges there would start another
        (the shell on 96 x 12 at L/b = 4000 made 8 traces of up to 200 states within 1e-4 L)."""
        if self._fold_traced_from == tuple(current):
            return False
        failed = self._fold_trace_failed_at
        return failed is None or abs(float(current[1]) - failed) > FOLD_TRACE_RETRY

    @property
    def load(self) -> np.ndarray:
        return np.array(self.model.clamp)

    def _predict(self, target: np.ndarray) -> np.ndarray | None:
        b = self.branch
        if self.options.predictor != "secant" or len(b.states) < 2:
            return None
        d_old = b.loads[1] - b.loads[0]
        d_new = target - b.loads[1]
        n_old, n_new = np.linalg.norm(d_old), np.linalg.norm(d_new)
        if n_old == 0.0 or n_new == 0.0 or np.dot(d_old, d_new) < 0.999 * n_old * n_new:
            return None
        return b.states[1] + (b.states[1] - b.states[0]) * (n_new / n_old)

    def solve_at(self, target, state0: np.ndarray, use_predictor: bool = True) -> int:
        """Newton at load `target` from state0 (or the secant prediction); raises NewtonFailure."""
        target = np.asarray(target, float)
        guess = self._predict(target) if use_predictor else None
        self.model.set_state(state0 if guess is None else guess)
        self.model.set_clamp(*target)
        return self.solver.newton()

    def advance(self, target) -> StepStats:
        """From the current converged state to the load `target` by adaptive substeps."""
        target = np.asarray(target, float)
        stats = StepStats()
        start_state = self.model.get_state()
        current = self.load
        if len(self.branch.states) == 0:
            self.branch.reset(current, start_state)
        if self.phase is None:
            accepted, rejected, snap = "accepted steps", "rejected steps", "fold snaps"
        else:
            accepted = rejected = snap = self.phase
        while np.linalg.norm(target - current) > 1e-14:
            remaining = np.linalg.norm(target - current)
            size = min(self.substep, remaining, self.options.max_substep)
            trial = target if size >= remaining * (1 - 1e-12) else current + (target - current) * (size / remaining)
            state0 = self.branch.states[-1]
            ok = False
            for use_predictor in (True, False):
                try:
                    with self.solver.counting(accepted, rejected):
                        its = self.solve_at(trial, state0, use_predictor)
                    ok = True
                    break
                except NewtonFailure:
                    stats.rejected += 1
                    if self._predict(trial) is None:
                        break
            if not ok and size <= self.options.snap_substep:
                self.model.set_state(state0)
                self.model.set_clamp(*trial)
                try:
                    with self.solver.counting(snap):
                        its = self.solver.descend()
                    ok = True
                    stats.snaps += 1
                    self.snaps += 1
                except NewtonFailure:
                    stats.rejected += 1
            landed = False
            if (not ok and size <= self.options.snap_substep and self.options.fold_tracing and self.phase is None
                    and trial[0] == current[0] and self.may_trace_fold(current)):
                self._fold_traced_from = tuple(current)
                self.model.set_state(state0)
                self.model.set_clamp(*current)
                with self.solver.counting(snap):
                    its = trace_across_fold(self, trial)
                ok = landed = its is not None
                if not ok:
                    self._fold_trace_failed_at = float(current[1])
                if ok:
                    stats.snaps += 1
                    self.snaps += 1
            if not ok:
                self.model.set_state(state0)
                self.model.set_clamp(*current)
                self.substep = size / 2.0
                self.step_halvings += 1
                if self.substep < self.options.min_substep:
                    self.failed_load = np.array(trial)
                    raise ContinuationFailure(
                        f"load step below {self.options.min_substep:g} L without convergence from "
                        f"dL/L = {current[0]:.6f}, dW/L = {current[1]:.6f}")
                continue
            stats.newton_iterations += its
            stats.substeps += 1
            current = trial
            if landed:  # another branch: the secant history starts again
                self.branch.reset(current, self.model.get_state())
            else:
                self.branch.push(current, self.model.get_state())
            if its <= self.options.easy_iterations:
                self.substep = size * self.options.max_growth
            else:
                self.substep = size
        return stats

    def restore(self, load, state, history: Branch | None = None) -> None:
        self.substep = math.inf
        self.model.set_state(state)
        self.model.set_clamp(*load)
        if history is not None:
            self.branch = Branch(list(history.loads), list(history.states))
        else:
            self.branch.reset(load, state)


# --- across a fold -----------------------------------------------------------------------------
#: Pseudo-arclength across a fold (trace_across_fold): first and largest step (the norm of
#: Solver.arclength_correct, units of L), the step below which the trace is given up, and the most
#: states it traces. The paper's plate at L/b = 4000, W/L = 1/20 needed 136 states from the fold
#: of US round a second fold to the stable branch beyond (ddg.solve.continuation.SNAP_POINTS).
FOLD_TRACE_STEP = (1e-3, 0.02)
FOLD_TRACE_MIN_STEP = 1e-6
FOLD_TRACE_POINTS = 200
#: No new trace within this dW (units of L) of one that found no snap: the dW2 bisection bracket.
FOLD_TRACE_RETRY = DW2_TOLERANCE


def trace_across_fold(stepper: Stepper, target) -> int | None:
    """From the converged state at stepper.load, follow the branch by pseudo-arclength in the
    shear towards target[1]: through its fold (where natural continuation and the descent fail),
    down the unstable part and, after a second fold, along the stable branch it turns into, to
    the first stable state (inertia) past target[1] after an unstable one. Newton at `target` from
    the interpolation of the last two states gives the state the strip snaps to, kept if stable
    and lower in energy than the fold's state (a snap releases energy). Where the unstable part
    meets S instead (a pitchfork of S), Newton at `target` from that junction, kept if in S,
    stable and lower. Returns the iterations
    spent (arclength corrections and the closing Newton's), or None with the model back at the
    start (recorded in stepper.fold_traces either way)."""
    model, solver = stepper.model, stepper.solver
    compression, shear = (float(v) for v in stepper.load)
    goal = float(target[1])
    direction = 1.0 if goal >= shear else -1.0
    start_state, start_shear, start_energy = model.get_state(), shear, model.energy()
    weight = 1.0 / start_state.size
    record = {"from_dW_over_L": shear, "to_dW_over_L": goal, "states": 0, "outcome": ""}
    stepper.fold_traces.append(record)
    spent = 0

    def give_up(why: str) -> None:
        record["outcome"] = why
        model.set_state(start_state)
        model.set_clamp(compression, start_shear)

    try:
        t_q, t_w = solver.shear_tangent(compression, shear, weight)
        t_q, t_w = direction * t_q, direction * t_w
        ds = FOLD_TRACE_STEP[0]
        previous = (start_state, shear)
        seen_unstable = False
        while record["states"] < FOLD_TRACE_POINTS:
            anchor, anchor_shear = model.get_state(), shear
            model.set_state(anchor + ds * t_q)
            try:
                its, new_shear = solver.arclength_correct(compression, anchor_shear + ds * t_w, anchor, anchor_shear,
                                                          (t_q, t_w), ds, weight)
            except NewtonFailure:
                spent += solver.last_iterations
                model.set_state(anchor)
                model.set_clamp(compression, anchor_shear)
                ds *= 0.5
                if ds < FOLD_TRACE_MIN_STEP:
                    give_up(f"pseudo-arclength step below {FOLD_TRACE_MIN_STEP:g} at dW/L = {anchor_shear:.6f}")
                    return None
                continue
            spent += its
            record["states"] += 1
            shear = new_shear
            stable = solver.negative_eigenvalues() == 0
            seen_unstable = seen_unstable or not stable
            if seen_unstable and phase_of(model, model.positions())[0].startswith("S"):
                # the unstable part of US met S (a pitchfork of S, as the rod's does): Newton at the
                # target from that junction, on S
                model.set_clamp(compression, goal)
                spent += solver.newton()
                if (solver.negative_eigenvalues() != 0 or model.energy() >= start_energy
                        or not phase_of(model, model.positions())[0].startswith("S")):
                    give_up(f"S met at dW/L = {shear:.6f}, but not stable and lower at dW/L = {goal:.6f}")
                    return None
                record["outcome"] = f"landed on S at dW/L = {goal:.6f} (met at {shear:.6f})"
                return spent
            if seen_unstable and stable and (shear - goal) * direction >= 0:
                before, before_shear = previous
                w = (goal - before_shear) / (shear - before_shear)
                model.set_state((1.0 - w) * before + w * model.get_state())
                model.set_clamp(compression, goal)
                spent += solver.newton()
                if solver.negative_eigenvalues() != 0 or model.energy() >= start_energy:
                    give_up(f"the state at dW/L = {goal:.6f} past the second fold is not a stable snap")
                    return None
                record["outcome"] = f"landed at dW/L = {goal:.6f}"
                return spent
            if abs(shear) > 1.0:
                give_up(f"left the shear range at dW/L = {shear:.6f}")
                return None
            previous = (model.get_state(), shear)
            new_q, new_w = solver.shear_tangent(compression, shear, weight)
            sign = 1.0 if weight * float(np.dot(new_q, t_q)) + new_w * t_w >= 0.0 else -1.0
            t_q, t_w = sign * new_q, sign * new_w
            if its <= 4:
                ds = min(FOLD_TRACE_STEP[1], 1.5 * ds)
        give_up(f"{FOLD_TRACE_POINTS} states traced without a stable state past dW/L = {goal:.6f}")
        return None
    except (NewtonFailure, PETSc.Error) as exc:
        give_up(f"failed: {exc}")
        return None


# --- observation ------------------------------------------------------------------------------
def phase_of(model: NaghdiStrip, positions: np.ndarray) -> tuple[str, float, float]:
    """(phase, half-turn defect, point-reflection defect): the DDG models' rule
    (ddg.solve.state.phase_from_measures, SYMMETRY_TOLERANCE L) on the shell's measures: the
    defects from the symmetric mesh (NaghdiStrip.symmetry_defects), the rise from the centerline
    nodes (highest point of the material line y = 0 in x < L/2 minus that in x > L/2)."""
    mirror, point = model.symmetry_defects(positions)
    compression, _ = model.clamp
    flat = compression == 0.0 and abs(positions[model.centre_node, 2]) < SYMMETRY_TOLERANCE

    def rise() -> float:
        z = positions[model.centerline_nodes, 2]
        xs = model.nodes_ref[model.centerline_nodes, 0]
        return float(np.max(z[xs < 0.5 - 1e-12]) - np.max(z[xs > 0.5 + 1e-12]))

    return phase_from_measures(mirror, point, rise, flat), mirror, point


@dataclass
class Observation:
    row: dict
    state: np.ndarray
    negative: int
    mode: np.ndarray | None = None


class Observer:
    """Rows of path.csv from the current state of the model."""

    def __init__(self, model: NaghdiStrip, solver: Solver, energy_unit: float, eigenvalues: bool = True):
        self.model, self.solver = model, solver
        self.energy_unit = energy_unit
        self.eigenvalues = eigenvalues

    def observe(self, stage: str, iterations: int, switched: bool = False, wall: float = float("nan"),
                want_mode: bool = False) -> Observation:
        m = self.model
        pos = m.positions()
        phase, mirror, point = phase_of(m, pos)
        force = m.clamp_reaction() / 12.0  # units of E b^3 / L (D = 1, see shell docstring)
        # inertia and lambda_min from one assembly and one factorisation of the tangent
        negative, values, vectors = self.solver.stability(1 if self.eigenvalues or want_mode else 0)
        lam, mode = float("nan"), None
        if len(values):
            lam, mode = float(values[0]), vectors[0]
        compression, shear = m.clamp
        energy = m.energy()
        row = {
            "stage": stage,
            "dL_over_L": compression,
            "dW_over_L": shear,
            "H_mid_over_L": float(pos[m.centre_node, 2]),
            "F_shear_norm": float(force[1]),
            "energy": energy * self.energy_unit,
            "lambda_min": lam,
            "phase": phase,
            "F_axial_norm": -float(force[0]),
            "stable": negative == 0,
            "newton_iterations": int(iterations),
            "branch_switched": bool(switched),
            **m.resolution_indicators(),
            "negative_eigenvalues": int(negative),
            "stretching_share": m.membrane_energy() / energy if energy > 0.0 else 0.0,
            "half_turn_defect_over_L": mirror,
            "point_reflection_defect_over_L": point,
            "wall_time_s": wall,
        }
        return Observation(row, m.get_state(), negative, mode)

    def centerline(self, stations: int = 101) -> np.ndarray:
        """(stations, 3) deformed material line y = 0, units of L, uniform in x."""
        m = self.model
        pos = m.positions()[m.centerline_nodes]
        s = np.linspace(0.0, 1.0, stations)
        xs = m.nodes_ref[m.centerline_nodes, 0]
        return np.column_stack([np.interp(s, xs, pos[:, k]) for k in range(3)])


# --- thresholds and branch switching -------------------------------------------------------------
def locate_dw1(stepper: Stepper, low: tuple, high_shear: float, tol: float = DW1_TOLERANCE, lambdas=None):
    """Bisect on the U branch for the first negative eigenvalue of the tangent (its inertia).

    low = (load, state, history) of the last stable U state; high_shear the first unstable dW.
    Returns (dW1, newton_iterations) with dW1 the midpoint of the final bracket (< tol wide).

    lambdas = (lambda_min at low, lambda_min at high_shear), the recorded observations: the first
    two trial points are then the secant root of lambda_min(dW) minus and plus 0.45 tol. On U
    lambda_min crosses zero transversally at the pitchfork and is close to linear over one
    recorded step, so the inertia there usually closes the bracket (0.9 tol wide) after two
    solves instead of log2(step/tol) bisections (6 at 60 elements); where it does not, the
    bisection goes on from the narrowed bracket. The result is the same bracket midpoint,
    within tol of the plain bisection's."""
    load_a, state_a, history_a = low
    a, b = float(load_a[1]), float(high_shear)
    iterations = 0
    trials = []
    if lambdas is not None and np.all(np.isfinite(lambdas)) and lambdas[0] > 0.0 > lambdas[1]:
        root = a + (b - a) * lambdas[0] / (lambdas[0] - lambdas[1])
        trials = [root - 0.45 * tol, root + 0.45 * tol]
    saved_phase, stepper.phase = stepper.phase, "threshold dW1"
    try:
        while b - a > tol:
            mid = 0.5 * (a + b)
            while trials:
                trial = trials.pop(0)
                if a < trial < b:
                    mid = trial
                    break
            stepper.restore(load_a, state_a, history_a)
            try:
                stats = stepper.advance((load_a[0], mid))
            except ContinuationFailure:
                # next to the pitchfork U's tangent is nearly singular and Newton may fail there
                # (the thin shell at L/b = 4000, 0.9e-4 L from it, before the solver accepted a
                # residual stalled at round-off): a secant trial gives way to the plain bisection,
                # whose points lie farther from the pitchfork
                if not trials and mid == 0.5 * (a + b):
                    raise
                trials = []
                continue
            iterations += stats.newton_iterations
            if stepper.solver.negative_eigenvalues() == 0:
                a = mid
                load_a, state_a = np.array(stepper.load), stepper.model.get_state()
                history_a = Branch(list(stepper.branch.loads), list(stepper.branch.states))
            else:
                b = mid
    finally:
        stepper.phase = saved_phase
    return 0.5 * (a + b), iterations


def switch_branch(stepper: Stepper, mode: np.ndarray, perturbation: float, growth: float = 2.0,
                  max_amplitude: float = 0.5, max_increment: float = 0.01):
    """Leave the unstable U state (current) for US+ along the critical mode phi.

    The state is held at RMS amplitude A (units of L) along phi by a force mu M phi (bordered
    Newton, solver.newton_bordered), A growing from `perturbation` in increments that double
    (up to max_increment, halved on failure, secant predictor) until the holding force changes
    sign (A passed the US amplitude); Newton without the constraint from
    the interpolated state then lands on US+ (a pure perturbation of the U state followed by
    Newton falls back to U: the linear mode stretches the mid-surface at finite amplitude).
    Returns (iterations, amplitude) or raises ContinuationFailure unless the result is US with
    no negative eigenvalue. Its Newton iterations count as "branch switching"."""
    with stepper.solver.counting("branch switching"):
        return _switch_branch(stepper, mode, perturbation, growth, max_amplitude, max_increment)


def _switch_branch(stepper, mode, perturbation, growth, max_amplitude, max_increment):
    m, solver = stepper.model, stepper.solver
    base = m.get_state()
    load = stepper.load
    c = solver.M.createVecLeft()
    phi_vec = c.duplicate()
    phi_vec.setArray(mode)
    solver.M.mult(phi_vec, c)
    area = m.params.width
    phi = mode * math.sqrt(area / phi_vec.dot(c))  # RMS displacement of phi = 1 (units of L)
    m.set_state(phi)
    phi_u = m.displacement_nodes()
    xs = m.nodes_ref[m.centerline_nodes, 0]
    z = phi_u[m.centerline_nodes, 2]
    if np.max(z[xs < 0.5]) - np.max(z[xs > 0.5]) < 0.0:
        phi = -phi
    phi_vec.setArray(phi / area)  # c . (q - q_U) = RMS amplitude along phi
    solver.M.mult(phi_vec, c)
    iterations = 0
    history = [(0.0, 0.0, base)]  # (amplitude, holding force mu, state)
    da = perturbation
    while True:
        a_last, mu_last, s_last = history[-1]
        a = a_last + da
        if a > max_amplitude:
            m.set_state(base)
            raise ContinuationFailure(f"branch switch at dW/L = {load[1]:.5f}: the force holding the mode "
                                      f"amplitude kept its sign up to {max_amplitude} L")
        if len(history) >= 2:  # secant predictor in the amplitude
            a_prev, _, s_prev = history[-2]
            guess = s_last + (s_last - s_prev) * (da / (a_last - a_prev))
        else:
            guess = base + a * phi
        m.set_state(guess)
        m.set_clamp(*load)
        try:
            its, mu = solver.newton_bordered(c, base, a, mu_last)
        except NewtonFailure:
            da /= 2.0
            if da < 1e-3 * perturbation:
                m.set_state(base)
                raise ContinuationFailure(f"branch switch at dW/L = {load[1]:.5f}: amplitude continuation "
                                          f"stalled at {a_last:.3g} L") from None
            continue
        iterations += its
        history.append((a, mu, m.get_state()))
        if mu <= 0.0:
            break
        if its <= 6:
            da = min(growth * da, max_increment)
    (a0, mu0, s0), (a1, mu1, s1) = history[-2], history[-1]
    w = mu0 / (mu0 - mu1)
    m.set_state(s0 + w * (s1 - s0))
    m.set_clamp(*load)
    try:
        iterations += solver.newton()
    except NewtonFailure as exc:
        m.set_state(base)
        raise ContinuationFailure(f"branch switch at dW/L = {load[1]:.5f}: {exc}") from None
    phase, _, _ = phase_of(m, m.positions())
    if not (phase.startswith("US") and solver.negative_eigenvalues() == 0):
        m.set_state(base)
        raise ContinuationFailure(f"branch switch at dW/L = {load[1]:.5f} reached {phase or 'flat'}, not a stable US")
    stepper.branch.reset(load, m.get_state())
    stepper.substep = math.inf
    c.destroy()
    phi_vec.destroy()
    return iterations, a0 + w * (a1 - a0)


def locate_dw2(stepper: Stepper, low: tuple, high_shear: float, tol: float = DW2_TOLERANCE):
    """Smallest dW (to tol) at which the stable path, followed from the last US state `low`,
    is point-symmetric (phase S). Returns (dW2, newton_iterations).

    The US branch either reaches S continuously (the phase at the bisection point decides) or
    ends in a fold, past which Newton from the US side cannot converge: the stable path snaps to
    S there, so a failed step also counts as past dW2. No energy descent during the bisection
    (on the shell it takes hundreds of Levenberg-Marquardt steps per snap).

    A failed advance still tells where US ends: it converged on US up to the load it stopped at
    and failed on the substep after it, narrower than 2 min_substep, so that substep is the new
    bracket (min_substep = tol/8 here: the bracket closes without further bisection). Newton
    gives up once its residual has stalled for 6 iterations (NewtonOptions.stall_window) instead
    of running to max_iterations: past the fold it oscillates between two residual levels."""
    load_a, state_a, history_a = low
    a, b = float(load_a[1]), float(high_shear)
    solver = stepper.solver
    before = solver.iterations_by_phase["threshold dW2"]
    saved, saved_newton = stepper.options, solver.options
    stepper.options = replace(saved, snap_substep=0.0, min_substep=max(saved.min_substep, tol / 8.0))
    solver.options = replace(saved_newton, stall_window=6)
    saved_phase, stepper.phase = stepper.phase, "threshold dW2"
    try:
        while b - a > tol:
            mid = 0.5 * (a + b)
            stepper.restore(load_a, state_a, history_a)
            try:
                stepper.advance((load_a[0], mid))
            except ContinuationFailure:
                b = min(mid, float(stepper.failed_load[1]))  # beyond the fold of US
                reached = float(stepper.load[1])  # the model is at the last converged substep
                if reached > a and phase_of(stepper.model, stepper.model.positions())[0].startswith("US"):
                    a = reached
                    load_a, state_a = np.array(stepper.load), stepper.model.get_state()
                    history_a = Branch(list(stepper.branch.loads), list(stepper.branch.states))
                continue
            phase, _, _ = phase_of(stepper.model, stepper.model.positions())
            if phase.startswith("S"):
                b = mid
            else:
                a = mid
                load_a, state_a = np.array(stepper.load), stepper.model.get_state()
                history_a = Branch(list(stepper.branch.loads), list(stepper.branch.states))
    finally:
        stepper.options, solver.options = saved, saved_newton
        stepper.phase = saved_phase
    return b, solver.iterations_by_phase["threshold dW2"] - before
