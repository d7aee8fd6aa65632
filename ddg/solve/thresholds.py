"""The shear thresholds dW1 (U to US, a supercritical pitchfork) and dW2 (US to S), located from
the stability of the discrete equilibria instead of by eye.

- dW1: on the symmetric U branch, followed without branch switching, lambda_min (the lowest
  eigenvalue of the free-DOF Hessian) changes sign; regula falsi (Illinois) on dW until the
  bracket is below the tolerance (1e-4 L by default).
- dW2, the paper's: the smallest dW at which the stable path (branch switching on) is in the
  point-symmetric S state. Where US ends in a fold (a limit point in dW, where the strip snaps),
  that is the fold itself: pseudo-arclength from the last US state goes round it, the fold's dW
  is the vertex of the parabola through the three states about the turn (refined until they lie
  within the tolerance), and the recorded path's landing in S after the fold (or, without it, an
  energy descent just past the fold) confirms that the strip snaps to S (locate_fold_snap).
  Otherwise, or if that check fails, bisection on the phase label of the state reached from the
  last US state (to 1e-3 L by default); where the pseudo-arclength pass reached S without a turn,
  on stable states only, the bisection starts from the bracket of its last two states.
- dW2_S_stable: where the S branch itself becomes stable, lambda_min of S (followed backwards
  without switching) changing sign; it differs from dW2 when US ends in a fold and snaps to S.

Each refinement starts from a recorded equilibrium (its DOFs and the rod's reference frames) and
uses its own PathFollower, so the recorded path is not disturbed.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from .arclength import ArclengthOptions, ArclengthTracer
from .continuation import ContinuationFailure, PathFollower
from .newton import newton
from .stability import lowest_modes
from .state import Snapshot, State, phase_of


#: Smallest substep of a refinement's follower: a trial load it cannot reach in 1/64 of the way
#: sits on the critical point itself (Newton converges only linearly there), and the next trial,
#: between it and either end, is cheaper than more halvings (the rod at M = 400 spent about 400
#: iterations on each of two such trials with the path's 1/4096)
TRIAL_MIN_SUBSTEP = 1.0 / 64


def _follower(model, options, switching: bool) -> PathFollower:
    """A path follower for the refinements: near the thresholds Newton converges only linearly, so
    without the load steps' fail-fast on contraction (NewtonOptions.contraction_limit), which there
    costs more iterations than it saves (docs/findings/measured.md)."""
    newton_options = replace(options.newton, contraction_limit=None)
    return PathFollower(model, replace(options, newton=newton_options, branch_switching=switching,
                                       min_substep=max(options.min_substep, TRIAL_MIN_SUBSTEP)))


def _advance(model, options, snapshot: Snapshot, shear: float, switching: bool,
             spent: list | None = None) -> State | None:
    model.restore_frames(snapshot.frames)
    follower = _follower(model, options, switching)
    follower.remember(snapshot.state, restart=True)
    try:
        return follower.advance(snapshot.state, snapshot.state.compression, shear)
    except ContinuationFailure:
        return None
    finally:
        if spent is not None:
            spent[0] += follower.newton_iterations


def _lambda_min(model, state: State) -> float:
    return float(lowest_modes(model, state.evaluation.hessian, 1)[0])


def locate_sign_change(model, options, start: Snapshot, other: float, tolerance: float,
                       spent: list | None = None) -> float | None:
    """dW where lambda_min changes sign on the branch through `start`, between start.state.shear
    and `other` (either side), following the branch without switching. None if the branch
    cannot be followed to `other` or lambda_min has the same sign at both ends."""
    a, lam_a = start.state.shear, _lambda_min(model, start.state)
    end = _advance(model, options, start, other, switching=False, spent=spent)
    if end is None:
        return None
    b, lam_b = other, _lambda_min(model, end)
    if lam_a * lam_b > 0:
        return None
    side = 0
    samples = [(a, lam_a), (b, lam_b)]  # true values (Illinois halves the stale end's copy below)
    while abs(b - a) > tolerance:
        guess = (a * lam_b - b * lam_a) / (lam_b - lam_a)
        guess = min(max(guess, min(a, b) + 0.01 * abs(b - a)), max(a, b) - 0.01 * abs(b - a))
        settled = _interpolated_root(samples, a, b, tolerance)
        if settled is not None:
            return settled
        # Where lambda_min is nearly linear the secant lands on the critical point itself, where the
        # Hessian is singular and Newton converges slowly or not at all: the first trial goes halfway
        # from the guess to the `a` end, a third sample that settles the interpolation; then the
        # guess, then points between it and the `b` end.
        for trial in (0.5 * (guess + a), guess, 0.5 * (guess + b), 0.75 * a + 0.25 * b, 0.25 * a + 0.75 * b):
            state = _advance(model, options, start, trial, switching=False, spent=spent)
            if state is not None:
                guess = trial
                break
        else:
            return None
        lam = _lambda_min(model, state)
        samples.append((guess, lam))
        if lam * lam_a > 0:
            a, lam_a = guess, lam
            if side == -1:
                lam_b *= 0.5  # Illinois: keep the stale end from stalling the secant
            side = -1
        else:
            b, lam_b = guess, lam
            if side == 1:
                lam_a *= 0.5
            side = 1
    return (a * lam_b - b * lam_a) / (lam_b - lam_a) if lam_b != lam_a else 0.5 * (a + b)


def _interpolated_root(samples: list, a: float, b: float, tolerance: float) -> float | None:
    """The root of lambda_min(dW) in the bracket [a, b] when interpolation has settled it: the
    quadratic through the three samples nearest the bracket and the secant through the two nearest
    its root agree within tolerance / 2 (lambda_min is smooth in dW along the branch). Spares the
    solves at the critical point itself, where the Hessian is singular and Newton converges slowly
    (docs/findings/measured.md)."""
    if len(samples) < 3:
        return None
    low, high = min(a, b), max(a, b)
    centre = 0.5 * (low + high)
    near = sorted(samples, key=lambda p: abs(p[0] - centre))[:3]
    x = np.array([p[0] for p in near]) - centre
    y = np.array([p[1] for p in near])
    if len(set(x)) < 3:
        return None
    coefficients = np.polyfit(x / (high - low), y, 2)
    roots = [r.real * (high - low) + centre for r in np.roots(coefficients)
             if abs(r.imag) < 1e-12 and low <= r.real * (high - low) + centre <= high]
    if len(roots) != 1:
        return None
    two = sorted(near, key=lambda p: abs(p[0] - roots[0]))[:2]
    if two[0][1] == two[1][1]:
        return None
    secant = two[0][0] - two[0][1] * (two[1][0] - two[0][0]) / (two[1][1] - two[0][1])
    return roots[0] if abs(secant - roots[0]) < 0.5 * tolerance else None


def locate_phase_change(model, options, start: Snapshot, first_after: float, is_after, tolerance: float,
                        spent: list | None = None) -> float | None:
    """Smallest dW in (start.state.shear, first_after] whose stable state (branch switching on,
    continued from `start`) satisfies is_after(state); bisection, None if a step fails."""
    lo, hi = start, first_after
    while hi - lo.state.shear > tolerance:
        mid = 0.5 * (lo.state.shear + hi)
        state = _advance(model, options, lo, mid, switching=True, spent=spent)
        if state is None:
            return None
        if is_after(state):
            hi = mid
        else:
            lo = Snapshot.take(model, state)
    return hi


#: The arclength tracer's default largest step, which the fold's first pass may reach
ARCLENGTH_MAX_STEP = ArclengthOptions().max_step
ARCLENGTH_MIN_STEP = ArclengthOptions().min_step
#: Refinements of the arclength step (each a quarter of the last) before the fold is given up
FOLD_REFINEMENTS = 6
#: Arclength states per pass towards the fold before it is given up (the first pass starts with a
#: step of a quarter of the bracket and grows it: 5-8 states reach the fold on the rod at M = 100
#: and on both plates at ~2000 triangles, measured; at M = 200 and 400 the tracer stalls near
#: dW/L = 0.52 and the bisection takes over, so a cap bounds what the attempt costs there)
FOLD_POINTS = 20


def _arclengths(states, tracer) -> list[float]:
    """Arclength coordinates of consecutive states in the tracer's metric (the first at 0)."""
    free = tracer.model.free
    s = [0.0]
    for a, b in zip(states[:-1], states[1:]):
        dq = b.q[free] - a.q[free]
        s.append(s[-1] + float(np.sqrt(tracer.inner(dq, b.shear - a.shear, dq, b.shear - a.shear))))
    return s


def _vertex(states, tracer, direction: float) -> float:
    """dW at the vertex of the parabola dW(s) through three consecutive arclength states about a
    turn (s their arclength distances in the tracer's metric; the turn a maximum of dW for
    direction +1, a minimum for -1)."""
    s = _arclengths(states, tracer)
    w = [direction * st.shear for st in states]
    a2, a1, a0 = np.polyfit(np.array(s) - s[1], w, 2)
    if a2 >= 0.0:
        return direction * max(w)  # not a maximum: the turn is sharper than a parabola
    peak = -a1 / (2.0 * a2)
    inside = s[0] - s[1] <= peak <= s[2] - s[1]
    return direction * (float(np.polyval([a2, a1, a0], peak)) if inside else max(w))


def locate_fold_snap(model, options, start: Snapshot, first_after: float, is_after, tolerance: float,
                     spent: list | None = None, landed: State | None = None,
                     narrowed: list | None = None) -> float | None:
    """dW of the fold where the branch through `start` (stable up to there) ends, if it lies in
    (start.state.shear, first_after] and the strip snaps from it to a state with is_after(state);
    None otherwise (no fold in the bracket, an instability before it, or another snap).

    Pseudo-arclength goes from `start` towards first_after until dW turns back; the three states
    about the turn bracket the fold, refined (from the last state before them, with a quarter of
    the step) until their dW lie within `tolerance`. Then the snap must land on a stable state
    that is_after accepts. `landed` is the state the recorded path reached at first_after, one
    recorded load step after `start`: where is_after accepts it, the path's own snap (it failed
    into this fold, the only end of the stable branch inside the bracket, and descended) is that
    landing. Otherwise Newton's energy descent from the state nearest the fold, with the clamp
    moved to the fold's dW plus `tolerance`, must reach one: the state the path follower would
    reach there, without its failed solves.

    narrowed (a list, filled in place): where the branch reaches is_after without a turn, stable
    throughout, [the Snapshot of its last state before, the first is_after state's dW]: the phase
    change of the stable path lies between them (bisection may start there)."""
    L = model.strip.length
    direction = 1.0 if first_after >= start.state.shear else -1.0
    step = abs(first_after - start.state.shear) / L / 4.0
    origin, frames = start.state, start.frames
    used = [0]
    try:
        for _ in range(FOLD_REFINEMENTS):
            model.restore_frames(frames)
            steps = ArclengthOptions(initial_step=step, max_step=max(16.0 * step, ARCLENGTH_MAX_STEP),
                                     min_step=min(step / 64, ARCLENGTH_MIN_STEP), max_points=FOLD_POINTS)
            tracer = ArclengthTracer(model, options.newton, steps)
            seen = [origin.shear * direction]

            def stop(state, seen=seen):
                beyond = state.shear * direction
                turned = beyond < seen[-1]
                seen.append(beyond)
                return turned or beyond > first_after * direction or is_after(state)

            points, why = tracer.trace(origin, direction, stop=stop, keep_hessians=False)
            used[0] += tracer.newton_iterations
            if why != "stop condition" or len(points) < 1 or not (points[-1].shear * direction < seen[-2]):
                if narrowed is not None and why == "stop condition" and is_after(points[-1]) \
                        and all(p.stable for p in [origin] + points):
                    # S reached without a fold, along a stable branch: the stable path itself
                    last = points[-2] if len(points) >= 2 else origin
                    model.restore_frames(last.frames if last is not origin else frames)
                    narrowed[:] = [Snapshot(replace(last, evaluation=model.evaluate(last.q)), model.save_frames()),
                                   points[-1].shear]
                return None  # no turn within the bracket (or S reached without a fold)
            chain = [origin] + points
            before, peak, after = chain[-3:] if len(chain) >= 3 else (None, None, None)
            if before is None or not all(p.stable for p in chain[:-2]):
                return None  # the branch loses stability before the fold: not a fold snap
            if max(abs(peak.shear - before.shear), abs(peak.shear - after.shear)) <= tolerance:
                fold = _vertex([before, peak, after], tracer, direction)
                break
            step = _arclengths([before, peak], tracer)[1] / 4.0
            frames = before.frames
            model.restore_frames(frames)
            origin = replace(before, evaluation=model.evaluate(before.q))  # its Hessian was not kept
        else:
            return None
        if landed is not None and landed.stable and is_after(landed):
            return fold
        # the snap: energy descent from the stable state nearest the fold, just past it
        model.restore_frames(peak.frames if peak.stable else before.frames)
        seed = peak if peak.stable else before
        q = model.apply_clamps(seed.q, seed.compression, fold + direction * tolerance)
        model.commit(q)
        result = newton(model, q, options.newton, minimize=True)
        used[0] += result.iterations
        if not (result.converged and result.positive_definite):
            return None
        reached = State(result.q, result.evaluation, seed.compression, fold + direction * tolerance, True)
        return fold if is_after(reached) else None
    finally:
        if spent is not None:
            spent[0] += used[0]


#: Bisection brackets (units of L) of dW1 and dW2 (dW2_S_stable uses dW2's); summary.json records
#: them as threshold_tolerances_over_L, and the mesh studies add them to the error bars.
THRESHOLD_TOLERANCES = (1e-4, 1e-3)


def shear_thresholds(model, options, last_u: Snapshot | None, first_us: float | None,
                     last_us: Snapshot | None, first_s: Snapshot | None,
                     tolerances: tuple[float, float] = THRESHOLD_TOLERANCES, near_fold: Snapshot | None = None) -> dict:
    """dW1, dW2 and dW2_S_stable (in metres; None where not bracketed by the recorded path),
    "dW2_method" ("fold": the vertex of the fold US ends in, located by pseudo-arclength;
    "bisection": on the phase reached; None) and "newton_iterations": those spent locating them.
    near_fold: the path's last US state before its snap into S (State.snapped_from), between last_us
    and first_s: the fold's location starts there, a hard substep from the fold, instead of a
    recorded load step."""

    L = model.strip.length
    saved = model.save_frames()
    out = {"dW1": None, "dW2": None, "dW2_S_stable": None, "dW2_method": None}
    spent = [0]
    try:
        if last_u is not None and first_us is not None:
            out["dW1"] = locate_sign_change(model, options, last_u, first_us, tolerances[0] * L, spent)
        if last_us is not None and first_s is not None:
            def in_s(state):
                return phase_of(model, state).startswith("S")

            narrowed = []
            out["dW2"] = locate_fold_snap(model, options, near_fold or last_us, first_s.state.shear, in_s,
                                           tolerances[1] * L, spent, landed=first_s.state, narrowed=narrowed)
            if out["dW2"] is None and near_fold is not None:
                # the state before the snap need not sit below a fold of its own branch (a substep
                # that failed short of a snap elsewhere): from the recorded US state, as without it
                narrowed = []
                out["dW2"] = locate_fold_snap(model, options, last_us, first_s.state.shear, in_s, tolerances[1] * L,
                                               spent, landed=first_s.state, narrowed=narrowed)
            out["dW2_method"] = "fold"
            if out["dW2"] is None:
                start, first_after = narrowed or (last_us, first_s.state.shear)
                out["dW2"] = locate_phase_change(model, options, start, first_after, in_s, tolerances[1] * L, spent)
                out["dW2_method"] = "bisection" if out["dW2"] is not None else None
            out["dW2_S_stable"] = locate_sign_change(model, options, first_s, last_us.state.shear, tolerances[1] * L,
                                                     spent)
    finally:
        model.restore_frames(saved)
        out["newton_iterations"] = spent[0]
    return out
