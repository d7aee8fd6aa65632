"""Quasi-static continuation of the clamp displacement with adaptive load steps.

The load is the clamp translation (dL, dW). Between recorded equilibria the solver takes
substeps: a tangent predictor (the linear response of the free DOFs to the clamp motion,
H_ff dq_f = -H_fc dq_c) followed by Newton; a failed substep is undone and halved, an easy
one (few Newton iterations) lets the next grow. Compression starts from an inextensible
first-mode guess, so the solver lands on the buckled branch, and every converged state is
checked by a Cholesky factorisation of the free-DOF Hessian: where it fails during
compression the solver descends along the negative eigenvector (branch selection), and past
a pitchfork during shear it switches to the stable branch the same way (if enabled).
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ..limits import InputError
from .arclength import ArclengthOptions, ArclengthTracer
from .extrapolation import LOAD_PREDICTOR_POINTS, extrapolate
from .probe import SILENT, Probe
from .newton import NewtonOptions, check_option, newton, settled
from .stability import lowest_modes
from .state import Snapshot, State, asymmetry, crosses, phase_of


#: The largest push off an unstable state (relative to L) tried before giving up on it.
MAX_KICK = 0.05

#: Where a path's Newton iterations go (PathFollower.iterations_by_phase, summary.json
#: "newton_iterations_by_phase"): solves of load steps that converged and that failed (the step
#: was then halved), leaving unstable states (branch switching at pitchforks), the compression's
#: first buckled state, and snaps past folds (pseudo-arclength and energy descent).
PHASES = ("accepted steps", "rejected steps", "branch switching", "compression start", "fold snaps")


class ContinuationFailure(RuntimeError):
    """The path could not be continued; the message says where."""


@dataclass
class ContinuationOptions:
    newton: NewtonOptions = field(default_factory=NewtonOptions)
    min_substep: float = 1.0 / 4096   # smallest substep, as a fraction of a recorded interval
    easy_iterations: int = 4           # substeps converging this fast let the next one double
    branch_switching: bool = True      # leave unstable equilibria along the negative eigenvector
    eigenvalues: bool = True           # compute lambda_min at every recorded equilibrium
    kick: float = 1e-3                 # size of the push off an unstable state, relative to L
    jump_substep: float = 1.0 / 16     # below this substep a failing branch is left by energy descent
    predictor: str = "secant"          # "secant" (extrapolate the branch), "tangent", or "both" (secant, then tangent)
    grow_after: int = 2                # easy substeps in a row before the substep doubles
    branch_sign: int = 1               # +1: leave a pitchfork onto the '+' branch (US+), -1: onto US-

    PREDICTORS = ("secant", "tangent", "both")

    def __post_init__(self) -> None:
        if not isinstance(self.newton, NewtonOptions):
            raise InputError(f"ContinuationOptions(newton={self.newton!r}): must be a ddg.NewtonOptions")
        self.newton = replace(self.newton)  # validated again: options objects can be changed after creation

        def c(name, *args, **kw):
            setattr(self, name, check_option("ContinuationOptions", name, getattr(self, name), *args, **kw))

        # below 2^-30 of a recorded interval the substeps are lost in round-off of the load
        c("min_substep", "float", 2.0**-30, 1.0)
        c("easy_iterations", "int", 0, 1000)
        c("branch_switching", "bool")
        c("eigenvalues", "bool")
        c("kick", "float", 0.0, MAX_KICK, low_open=True)
        c("jump_substep", "float", 0.0, 1.0, low_open=True)
        c("grow_after", "int", 1, 1000)
        if self.predictor not in self.PREDICTORS:
            raise InputError(f"ContinuationOptions(predictor={self.predictor!r}): "
                             f"choose one of {list(self.PREDICTORS)}")
        if isinstance(self.branch_sign, bool) or self.branch_sign not in (1, -1):
            raise InputError(f"ContinuationOptions(branch_sign={self.branch_sign!r}): must be +1 (US+, S+) or -1 (US-, "
                             f"S-)")


#: Solved points of the constrained branch (amplitude along the mode held) through which the
#: slide off a saddle extrapolates its next point (_slide_along_mode): a quadratic, as the branch
#: bends with the square of the amplitude past a pitchfork.
SLIDE_PREDICTOR_POINTS = 3

#: Largest number of states traced along the unstable part of a folded branch (_snap_past_fold).
#: The paper's plate at L/b = 4000, W/L = 1/20 (2100 triangles) goes from the fold of US at dW/L =
#: 0.3848 back to a second fold at 0.3586 and on, stable again, to 0.3848 in about 100 (measured).
SNAP_POINTS = 160


class PathFollower:
    def __init__(self, model, options: ContinuationOptions | None = None, probe: Probe | None = None):
        self.model = model
        self.options = options or ContinuationOptions()
        self.probe = probe or SILENT  # told of every Newton solve (ddg.solve.probe)
        self.substep = 1.0
        self.newton_iterations = 0
        self._easy_streak = 0
        self._history: list[tuple[np.ndarray, np.ndarray]] = []  # (load, q) of the last equilibria on this branch
        self._fold_tried_at = None
        #: the last state from which a snap's energy descent did not converge (_jump): not tried again
        #: from it at shorter substeps, where the descent starts from the same shape
        self._descent_failed_from = None
        self.folds: list[float] = []  # dW (m) of the limit points met (pseudo-arclength turned back there)
        #: Newton iterations per phase of the path (PHASES), the public record of where they go
        self.iterations_by_phase: dict[str, int] = dict.fromkeys(PHASES, 0)
        self.line_search_trials = 0  # shortened Newton steps tried in load steps (evaluations, not iterations)
        #: the load steps use Newton's fail-fast on contraction (if the options ask) until a path
        #: would stop with it; then it is off for the rest of this follower
        self._fail_fast = self.options.newton.contraction_limit is not None

    def iteration_breakdown(self) -> dict[str, int]:
        """Newton iterations per phase and the line search's shortened steps (summary.json's
        newton_iterations_by_phase)."""
        return {**self.iterations_by_phase, "line search trials": self.line_search_trials}

    def _spent(self, iterations: int, phase: str, converged: bool = True) -> None:
        self.newton_iterations += iterations
        self.iterations_by_phase[phase] += iterations
        self.probe.solve(phase, iterations, converged)

    # ------------------------------------------------------------------ predictors
    def remember(self, state: State, restart: bool = False) -> None:
        if restart:
            self._history = []
        self._history = (self._history + [(np.array([state.compression, state.shear]), state.q.copy())])[
            -LOAD_PREDICTOR_POINTS:]

    def _extrapolate(self, compression: float, shear: float) -> np.ndarray | None:
        """Polynomial extrapolation (secant, up to a cubic through LOAD_PREDICTOR_POINTS points) of
        the last equilibria on the current branch to the new load, if they lie on the same load line.

        On a curved branch it captures the second-order (membrane) part of the motion that the
        tangent predictor misses, which for thin plates decides whether Newton converges."""
        if len(self._history) < 2:
            return None
        target = np.array([compression, shear])
        last = self._history[-1][0]
        direction = target - last
        norm2 = float(direction @ direction)
        if norm2 == 0.0:
            return None
        params, qs = [], []
        for load, q in self._history:
            offset = load - last
            if abs(offset[0] * direction[1] - offset[1] * direction[0]) > 1e-9 * norm2 + 1e-300:
                params, qs = [], []  # an earlier point off the line: keep only the later ones
                continue
            params.append(float(offset @ direction) / norm2)
            qs.append(q)
        if len(params) < 2 or len(set(params)) < len(params):
            return None
        # the polynomial at t = 1 (the target); the last point sits at t = 0
        return extrapolate(params, qs, 1.0)

    # ------------------------------------------------------------------ pieces
    def rest(self) -> State:
        q = self.model.reset()
        ev = self.model.evaluate(q)
        stable = self.model.free_matrix(ev.hessian).cholesky()
        state = State(q, ev, 0.0, 0.0, stable)
        self.remember(state, restart=True)
        return state

    def start_compression(self, compression: float, direction: int = 1) -> State:
        """First buckled equilibrium at a small compression, from an inextensible guess."""
        model = self.model
        first = compression
        for attempt in range(12):
            model.reset()
            q = model.apply_clamps(model.buckled_guess(compression, direction), compression, 0.0)
            model.commit(q)
            result = newton(model, q, self.options.newton, minimize=True)
            self._spent(result.iterations, "compression start", result.converged)
            if result.converged:
                state = State(result.q, result.evaluation, compression, 0.0, bool(result.positive_definite),
                              result.iterations)
                state = self._ensure_stable(state, direction)
                if state is not None:
                    self.remember(state, restart=True)
                return state
            compression *= 0.5
        raise ContinuationFailure(
            f"Newton failed to find the buckled state at the start of compression (tried dL/L from "
            f"{first / self._length:.4g} down to {compression / self._length:.4g}); only the flat state at dL/L = 0 "
            f"converged"
        )

    def advance(self, state: State, compression: float, shear: float) -> State:
        """Continue from `state` to the clamp displacement (compression, shear)."""
        start = np.array([state.compression, state.shear])
        target = np.array([compression, shear])
        t = 0.0
        iterations = 0
        switched = False
        snapped_from = None
        while t < 1.0:
            t_next = min(1.0, t + self.substep)
            load = start + t_next * (target - start)
            # near singular points (thresholds) Newton converges only linearly: allow it more iterations
            hard = self.substep <= self.options.jump_substep
            new = self._step(state, *load, patient=hard)
            before = Snapshot.take(self.model, state) if new is None and hard else None
            folds = len(self.folds)
            if new is None and hard and self.options.branch_switching and self._descent_failed_from is not state:
                # the branch has ended (a fold): let the strip snap to the nearest stable state
                new = self._jump(state, *load)
                if new is not None:
                    self.folds.append(state.shear)  # the branch ended within this substep
            if new is None and hard and load[0] == state.compression and self._fold_tried_at is not state:
                self._fold_tried_at = state  # once per state: a second failure is not a fold
                # Newton stalls near a limit point of dW (or energy descent slid too slowly to
                # converge): pseudo-arclength goes round the fold and, with switching, follows the
                # unstable part to the branch the strip snaps to; or past a hard spot to the target
                new = self._across_fold(state, *load)
            if new is not None and len(self.folds) > folds:
                snapped_from = before
            if new is None:
                self._easy_streak = 0
                self.substep *= 0.5
                if self.substep < self.options.min_substep and self._fail_fast:
                    # the load steps' fail-fast (NewtonOptions.contraction_limit) gives up solves
                    # that might converge slowly: before the path is given up, it is switched off
                    # for the rest of this follower and the rest of the interval retried from the
                    # last equilibrium
                    self._fail_fast = False
                    self.substep = 1.0
                    continue
                if self.substep < self.options.min_substep:
                    strip = self.model.strip
                    limit = strip.shear_limit(state.compression) if state.compression > 0 else float("nan")
                    reach = (f"; that is {100 * abs(state.shear) / limit:.2f} % of dW_max/L = "
                             f"{limit / self._length:.4g} "
                             "(Eq. B.1)") if state.shear != 0.0 and limit > 0 else ""
                    fold = ""
                    if self.folds and abs(self.folds[-1] - state.shear) < abs(target[1] - start[1]) + 1e-12:
                        fold = (f"; the branch folds at dW/L = {self.folds[-1] / self._length:.6g} (a limit point: "
                                "beyond it the branch turns back unstable; see branches.csv)")
                    raise ContinuationFailure(
                        f"Newton failed to converge beyond dL/L = {state.compression / self._length:.6g}, "
                        f"dW/L = {state.shear / self._length:.6g}{reach} (substep below {self.options.min_substep:g} "
                        f"of a recorded interval){fold}"
                    )
                continue
            iterations += new.iterations
            switched = switched or new.branch_switched
            self.remember(new, restart=new.branch_switched)
            if new.iterations <= self.options.easy_iterations:
                self._easy_streak += 1
                if self._easy_streak >= self.options.grow_after:
                    self.substep = min(1.0, 2.0 * self.substep)
            else:
                self._easy_streak = 0
            state, t = new, t_next
        state.iterations = iterations
        state.branch_switched = switched
        if snapped_from is not None:
            state.snapped_from = snapped_from
        return state

    @property
    def _length(self) -> float:
        return self.model.strip.length

    def _step(self, state: State, compression: float, shear: float, patient: bool = False) -> State | None:
        """One substep: predictor (extrapolated from the branch, else the tangent), Newton; on an
        unstable result, branch switching. None if it does not converge."""
        model = self.model
        saved = model.save_frames()
        new_clamps = model.clamp_values(compression, shear)
        opts = self.options.newton if self._fail_fast else replace(self.options.newton, contraction_limit=None)
        if patient:
            # near thresholds Newton converges only linearly: more iterations, a milder give-up test
            give_up = 2 * opts.give_up_after if opts.give_up_after else None
            opts = replace(opts, max_iterations=min(2 * opts.max_iterations, 1000), give_up_after=give_up,
                           give_up_ratio=0.5, contraction_limit=None)
        result = None
        extrapolated = None
        if self.options.predictor != "tangent" and self._history and np.array_equal(state.q, self._history[-1][1]):
            extrapolated = self._extrapolate(compression, shear)
        if extrapolated is not None:
            q = extrapolated
            q[model.constrained] = new_clamps
            result = newton(model, q, opts)
            self._spent(result.iterations, "accepted steps" if result.converged else "rejected steps", result.converged)
            self.line_search_trials += result.line_search_trials
            if not result.converged:
                model.restore_frames(saved)
                result = None
        if result is None and (extrapolated is None or self.options.predictor != "secant"):
            dq_c = new_clamps - state.q[model.constrained]
            K = model.free_matrix(state.evaluation.hessian)
            q = state.q.copy()
            q[model.constrained] = new_clamps
            q[model.free] -= K.solve(model.coupling(state.evaluation.hessian, dq_c))
            result = newton(model, q, opts)
            self._spent(result.iterations, "accepted steps" if result.converged else "rejected steps", result.converged)
            self.line_search_trials += result.line_search_trials
        if result is None or not result.converged:
            model.restore_frames(saved)
            return None
        new = State(result.q, result.evaluation, compression, shear, bool(result.positive_definite), result.iterations)
        if not new.stable and self.options.branch_switching:
            new = self._ensure_stable(new, 0)
            if new is None:
                model.restore_frames(saved)
        return new

    def _across_fold(self, state: State, compression: float, shear: float) -> State | None:
        """Pseudo-arclength continuation from `state` towards dW = shear. If the branch gets
        there, the equilibrium at `shear` (Newton from the interpolated arclength states); if it
        turns back first (a fold), None, with the fold's dW appended to self.folds."""
        model = self.model
        saved = model.save_frames()
        direction = 1.0 if shear >= state.shear else -1.0
        span = abs(shear - state.shear) / self._length
        tracer = ArclengthTracer(model, self.options.newton,
                                 ArclengthOptions(initial_step=span / 4, max_step=max(span, 1e-4), max_points=40))

        def past_either_end(s):
            return (s.shear - shear) * direction >= 0 or (s.shear - state.shear) * direction < 0

        points, _ = tracer.trace(state, direction, stop=past_either_end, keep_hessians=False)
        self._spent(tracer.newton_iterations, "fold snaps")
        shears = np.array([state.shear] + [p.shear for p in points])
        if points and (points[-1].shear - shear) * direction >= 0:
            before, after = ([state] + points)[-2:]
            weight = (shear - before.shear) / (after.shear - before.shear)
            model.restore_frames(before.frames if before.frames is not None else saved)
            q = (1 - weight) * before.q + weight * after.q
            q[model.constrained] = model.clamp_values(compression, shear)
            result = newton(model, q, self.options.newton)
            self._spent(result.iterations, "fold snaps", result.converged)
            if result.converged:
                new = State(result.q, result.evaluation, compression, shear, bool(result.positive_definite),
                            result.iterations + tracer.newton_iterations)
                if new.stable or not self.options.branch_switching:
                    return new
                new = self._ensure_stable(new, 0)
                if new is not None:
                    return new
        elif points:
            self.folds.append(float(shears[np.argmax(shears * direction)]))
            if self.options.branch_switching:
                snapped = self._snap_past_fold(points[-1], compression, shear)
                if snapped is not None:
                    return snapped
        model.restore_frames(saved)
        return None

    def _snap_past_fold(self, turned: State, compression: float, shear: float) -> State | None:
        """Where an asymmetric (US) branch folds, follow its unstable part on to the symmetric
        branch it meets (U or S, a pitchfork of that branch), then that branch to dW = shear:
        the state the strip snaps to if it is stable there (None otherwise). Energy descent
        (_jump) reaches the same state, but on a plate it slides slowly along the soft valley."""
        model = self.model
        if not phase_of(model, turned).startswith("US"):
            return None
        model.restore_frames(turned.frames)
        tracer = ArclengthTracer(model, self.options.newton)
        direction = -1.0 if shear >= turned.shear else 1.0
        stop_s = crosses(lambda s: model.midpoint(s.q)[2], turned, "S", model)
        stop_u = crosses(lambda s: asymmetry(model, s), turned, "U", model)

        def beyond(s):
            # the unstable part turned at a second fold into a stable branch that reaches dW = shear
            return s.stable and (s.shear - shear) * direction <= 0

        def stop(s):
            a, b = stop_s(s), stop_u(s)
            return True if (a is True or b is True or beyond(s)) else ("drop" if (a or b) else False)

        points, why = tracer.trace(turned, direction, stop=stop, max_points=SNAP_POINTS, keep_hessians=False)
        self._spent(tracer.newton_iterations, "fold snaps")
        if why != "stop condition" or not points:
            return None
        if beyond(points[-1]):
            return self._land_on_turned_branch([turned] + points, compression, shear)
        junction = points[-1]
        if phase_of(model, junction).startswith("US"):
            # the tracer stepped through the junction onto the mirror branch: the symmetric state
            # lies between (the two sides are mirror images, so interpolating where the measure
            # vanishes is within O(step^2) of it); converge it at its dW on the symmetric branch
            after = tracer.dropped
            if after is None:
                return None
            measure = (lambda s: model.midpoint(s.q)[2]) if stop_s(after) == "drop" else (lambda s: asymmetry(model, s))
            ma, mb = measure(junction), measure(after)
            weight = ma / (ma - mb)
            q = (1 - weight) * junction.q + weight * after.q
            between = junction.shear + weight * (after.shear - junction.shear)
            model.restore_frames(junction.frames)
            q[model.constrained] = model.clamp_values(compression, between)
            result = newton(model, q, self.options.newton)
            self._spent(result.iterations, "fold snaps", result.converged)
            if not result.converged or phase_of(model, State(result.q, None, compression, between,
                                                             False)).startswith("US"):
                return None
            model.commit(result.q, result.evaluation)
            junction = State(result.q, result.evaluation, compression, between, bool(result.positive_definite))
        follower = PathFollower(model, replace(self.options, branch_switching=False))
        follower.remember(junction, restart=True)
        try:
            new = follower.advance(junction, compression, shear)
        except ContinuationFailure:
            return None
        finally:
            self._spent(follower.newton_iterations, "fold snaps")
        if not new.stable:
            return None
        new.branch_switched = True
        return new

    def _land_on_turned_branch(self, chain: list[State], compression: float, shear: float) -> State | None:
        """The stable state at dW = shear on the branch the traced chain reached after its second
        fold: Newton from the interpolation of the chain's last two states. A snap releases energy,
        so the state must lie below the chain's first (the fold's) energy; None otherwise."""
        model = self.model
        before, after = chain[-2:]
        weight = (shear - before.shear) / (after.shear - before.shear)
        model.restore_frames(before.frames if before.frames is not None else after.frames)
        q = (1 - weight) * before.q + weight * after.q
        q[model.constrained] = model.clamp_values(compression, shear)
        result = newton(model, q, self.options.newton)
        self._spent(result.iterations, "fold snaps", result.converged)
        if not (result.converged and result.positive_definite) or \
                result.evaluation.energy >= chain[0].evaluation.energy:
            return None
        return State(result.q, result.evaluation, compression, shear, True, result.iterations, branch_switched=True)

    def _jump(self, state: State, compression: float, shear: float) -> State | None:
        """Quasi-static snap: descend in energy from the predicted state at the new load."""
        model = self.model
        saved = model.save_frames()
        q = model.apply_clamps(state.q, compression, shear)
        model.commit(q)
        result = newton(model, q, self.options.newton, minimize=True)
        self._spent(result.iterations, "fold snaps", result.converged)
        if result.converged and result.positive_definite:
            return State(result.q, result.evaluation, compression, shear, True, result.iterations, branch_switched=True)
        if not result.converged:
            self._descent_failed_from = state
        model.restore_frames(saved)
        return None

    def _ensure_stable(self, state: State, direction: int) -> State | None:
        """Leave an unstable equilibrium along its lowest mode and descend to a stable one.

        direction = +1: choose the sign that raises the midpoint (compression, the U branch);
        direction = 0: the sign that raises the first half of the strip against the second
        (the '+' branch of a pitchfork during shear).
        """
        if state.stable:
            return state
        model = self.model
        _, modes = lowest_modes(model, state.evaluation.hessian, 1, vectors=True)
        mode = np.zeros(model.n_dof)
        mode[model.free] = modes[:, 0]
        mode /= np.max(np.abs(mode[model.node_dofs]))
        sign = 1.0 if model.mode_sign(mode, direction) >= 0 else -1.0
        if direction == 0:
            sign *= self.options.branch_sign
        slid = self._slide_along_mode(state, sign * mode)
        if slid is not None:
            return slid
        # fallback: close to a pitchfork lambda_min is small, and a push of 1e-5 L may leave a
        # residual below Newton's tolerance at the saddle itself: grow the push until the descent
        # gets away
        k = self.options.kick
        pushes = [k] + [k * 10**j for j in range(1, 4) if k * 10**j <= MAX_KICK] + [0.1 * k]
        for kick in pushes:
            saved = model.save_frames()
            q = state.q + sign * kick * self._length * mode
            model.commit(q)
            result = newton(model, q, self.options.newton, minimize=True)
            self._spent(result.iterations, "branch switching", result.converged)
            if result.converged and result.positive_definite:
                return State(result.q, result.evaluation, state.compression, state.shear, True,
                             state.iterations + result.iterations, branch_switched=True)
            model.restore_frames(saved)
        return None

    def _constrained_equilibrium(self, q: np.ndarray, origin: np.ndarray, direction: np.ndarray, amplitude: float):
        """Equilibrium with the amplitude along `direction` (free DOFs) held: grad_f E + mu w = 0,
        w . (q_f - origin_f) / (w . w) = amplitude. Bordered Newton (two solves with one
        factorisation per iteration); returns (q, evaluation, mu) or None. The rod's frames are
        committed at every iterate, as in newton()."""
        model = self.model
        free = model.free
        w = direction[free]
        ww = float(w @ w)
        rscale = model.residual_scale()[free]
        lscale = model.length_scale()[free]
        q = q.copy()
        mu, first, correction = 0.0, None, np.inf
        ev = model.evaluate(q)
        for iteration in range(self.options.newton.max_iterations + 1):
            r = ev.gradient[free] + mu * w
            c = float(w @ (q[free] - origin[free])) / ww - amplitude
            res = float(np.max(np.abs(r / rscale)))
            if not np.isfinite(res):
                return None
            if settled(model, self.options.newton, res, correction) and abs(c) < 1e-12 * self._length:
                return q, ev, mu
            first = res if first is None else first
            if iteration == self.options.newton.max_iterations or res > 1e3 * first:
                return None
            K = model.free_matrix(ev.hessian)
            x1, x2 = K.solve(np.column_stack([-r, w])).T
            dmu = (float(w @ x1) + c * ww) / float(w @ x2)
            dq = x1 - dmu * x2
            correction = float(np.max(np.abs(dq / lscale)))
            q[free] += dq
            mu += dmu
            ev = model.evaluate(q)
            self._spent(1, "branch switching")
            model.commit(q, ev)
        return None

    def _slide_along_mode(self, unstable: State, mode: np.ndarray) -> State | None:
        """From an unstable equilibrium to the stable one its lowest mode leads to (the US branch
        past a pitchfork, the buckled branch from the flat state), without energy descent.

        The amplitude a along the mode is held (_constrained_equilibrium) and doubled from the
        kick while the energy keeps falling with it (the multiplier mu has the sign of -dE/da),
        then the root of mu(a) is bracketed and found by the secant method; plain Newton from there
        lands on the equilibrium, accepted if stable. A fixed push followed by modified Newton
        slides slowly along the soft, curved valley instead (docs/findings/measured.md)."""
        model = self.model
        L = self._length
        saved = model.save_frames()
        origin = unstable.q
        points = []  # (a, q, mu * direction, frames)

        def solve(q, a):
            out = self._constrained_equilibrium(q, origin, mode, a * L)
            if out is None:
                return None
            points.append((a, out[0], out[2], model.save_frames(), out[1]))
            return points[-1]

        a = self.options.kick
        model.commit(origin + a * L * mode)
        if solve(origin + a * L * mode, a) is None or points[-1][2] <= 0.0:
            model.restore_frames(saved)
            return None  # the energy does not fall along the mode: not a saddle we can leave this way
        growth = 2.0
        while points[-1][2] > 0.0:  # energy still falling: double the amplitude
            a0, q0, _, frames0, _ = points[-1]
            a = growth * a0
            if a > 0.5:
                model.restore_frames(saved)
                return None
            if len(points) >= 2:  # polynomial extrapolation in a of the constrained branch
                near = points[-SLIDE_PREDICTOR_POINTS:]
                predicted = extrapolate([p[0] for p in near], [p[1] for p in near], a)
            else:
                predicted = q0 + (a - a0) * L * mode
            model.restore_frames(frames0)
            if solve(predicted, a) is None:
                model.restore_frames(frames0)
                growth = 1.0 + 0.5 * (growth - 1.0)  # a shorter step along the constrained branch
                if growth < 1.1:
                    model.restore_frames(saved)
                    return None
        # the root of mu(a) lies between the last two amplitudes: secant steps on the constrained
        # branch, each predicted by the quadratic through the three solved points nearest to it (a
        # chord between the bracket's ends, or a line through two points below, is too far off the
        # curved branch for the constrained Newton); Newton from a point whose multiplier is small
        # lands on the equilibrium
        lo, hi = points[-2], points[-1]
        below = points[-3] if len(points) >= 3 else None
        side = 0
        for _ in range(12):
            if abs(lo[2]) <= 0.05 * abs(hi[2]) or abs(hi[2]) <= 0.05 * abs(lo[2]):
                nearest = lo if abs(lo[2]) <= abs(hi[2]) else hi
                model.restore_frames(nearest[3])
                result = newton(model, nearest[1], self.options.newton, evaluation=nearest[4])
                self._spent(result.iterations, "branch switching", result.converged)
                if result.converged and result.positive_definite:
                    return State(result.q, result.evaluation, unstable.compression, unstable.shear, True,
                                 unstable.iterations + result.iterations, branch_switched=True)
            a = lo[0] + lo[2] / (lo[2] - hi[2]) * (hi[0] - lo[0])
            if below is not None:  # the quadratic through the solved points nearest to a
                near = sorted({p[0]: p for p in points}.values(), key=lambda p: abs(p[0] - a))
                near = near[:SLIDE_PREDICTOR_POINTS]
                predicted = extrapolate([p[0] for p in near], [p[1] for p in near], a)
            else:
                predicted = lo[1] + (a - lo[0]) * L * mode
            model.restore_frames(lo[3])
            point = solve(predicted, a)
            if point is None:
                break
            if point[2] > 0.0:
                if side == 1:  # Illinois: the stale end's multiplier halved, so the secant keeps closing in
                    hi = hi[:2] + (0.5 * hi[2],) + hi[3:]
                below, lo, side = lo, point, 1
            else:
                if side == -1:
                    lo = lo[:2] + (0.5 * lo[2],) + lo[3:]
                hi, side = point, -1
        model.restore_frames(saved)
        return None


def relax_from(model, source_model, source_state: State, options: ContinuationOptions) -> State:
    """Energy descent under `model` from a converged state of `source_model` (same DOF layout),
    with the source's reference frames; a stable equilibrium of `model` or ContinuationFailure."""
    model.restore_frames(source_model.save_frames())
    result = newton(model, source_state.q, options.newton, minimize=True)
    if not result.converged:
        L = model.strip.length
        raise ContinuationFailure(f"the ribbon did not relax from the rod state at dL/L = "
                                  f"{source_state.compression / L:.6g}, "
                                  f"dW/L = {source_state.shear / L:.6g} "
                                  f"({result.message or 'Newton did not converge'})")
    model.commit(result.q, result.evaluation)
    return State(result.q, result.evaluation, source_state.compression, source_state.shear,
                 bool(result.positive_definite), result.iterations)
