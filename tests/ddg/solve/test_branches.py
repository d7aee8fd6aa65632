"""The bifurcation diagram of the shear stage (ddg.solve.branches): every branch, stable and not,
traced by pseudo-arclength continuation in dW (ddg.solve.arclength)."""
import numpy as np
import pytest
from scipy.interpolate import CubicSpline, PchipInterpolator

import ddg


def run(model, resolution, shear_ratio, shear_steps):
    strip = ddg.Strip.from_ratios(0.05, 0.5)
    protocol = ddg.LoadingProtocol(0.5, shear_ratio=shear_ratio, compression_steps=20, shear_steps=shear_steps)
    result = ddg.simulate(strip, protocol, model=model, resolution=resolution, branches=True)
    assert result.converged, result.summary["message"]
    return result


def branch(result, name, key=None):
    rows = [r for r in result.branch_rows if r["branch"] == name]
    return rows if key is None else np.array([r[key] for r in rows])


@pytest.fixture(scope="module")
def rod():
    """W/L = 1/20, dL/L = 1/2, M = 100, sheared to dW/L = 0.6 (past dW2 = 0.524)."""
    return run("rod", 100, 0.6, 60)


@pytest.fixture(scope="module")
def narrow_plate():
    """The same scene as a plate of 600 triangles: its US branch ends in a fold (about 35 s)."""
    return run("plate", 600, 0.47, 47)


def test_the_diagram_has_U_both_US_branches_and_S(rod):
    assert [b for b in rod.summary["branches"]] == ["U", "US+", "US-", "S+"]
    assert {r["phase"] for r in branch(rod, "U")} == {"U"}
    assert {r["phase"] for r in branch(rod, "US+")} == {"US+"}
    assert {r["phase"] for r in branch(rod, "US-")} == {"US-"}
    assert {r["phase"] for r in branch(rod, "S+")} == {"S+"}


@pytest.mark.parametrize("which", ["rod", "narrow_plate"])
def test_states_reported_stable_on_any_branch_have_positive_lambda_min(which, request):
    """stable (a Cholesky factorisation succeeded) and lambda_min > 0 say the same thing, on the
    recorded path and on every traced branch, unstable parts included."""
    result = request.getfixturevalue(which)
    for rows in (result.rows, result.branch_rows):
        stable = np.array([bool(r["stable"]) for r in rows])
        lam = np.array([r["lambda_min"] for r in rows])
        assert np.all(lam[stable] > 0)
        assert np.all(lam[~stable] < 0)
    assert any(not r["stable"] for r in result.branch_rows)  # the unstable parts are there


@pytest.mark.parametrize("which", ["rod", "narrow_plate"])
def test_the_number_of_unstable_directions_is_the_inertia_of_the_hessian(which, request):
    """negative_eigenvalues (the negative pivots of the LDL^T, Sylvester's law) is 0 exactly on the
    stable states; past a pitchfork of U or before S becomes stable it is 1: one critical mode."""
    result = request.getfixturevalue(which)
    for rows in (result.rows, result.branch_rows):
        for r in rows:
            assert (r["negative_eigenvalues"] == 0) == bool(r["stable"]), r
    unstable_u = [r["negative_eigenvalues"] for r in branch(result, "U") if not r["stable"]]
    assert unstable_u and set(unstable_u) <= {1, 2}
    assert unstable_u[0] == 1  # the first unstable U states: the pitchfork's one mode


def test_U_branch_turns_unstable_at_dW1_and_matches_natural_continuation(rod):
    """The arclength trace of U changes stability where the thresholds module puts dW1, and it
    lies on the same equilibria as the recorded path (which follows U up to dW1)."""
    dw, lam = branch(rod, "U", "dW_over_L"), branch(rod, "U", "lambda_min")
    dw1 = rod.summary["dW1_over_L"]
    k = int(np.nonzero(lam <= 0)[0][0])
    assert dw[k - 1] < dw1 <= dw[k]
    h_branch = CubicSpline(dw, branch(rod, "U", "H_mid_over_L"))  # interpolation error ~1e-7 L
    path_dw = rod.column("dW_over_L", "shear")
    on_u = path_dw < dw1
    assert np.max(np.abs(h_branch(path_dw[on_u]) - rod.column("H_mid_over_L", "shear")[on_u])) < 1e-6


def test_US_branches_run_from_the_pitchfork_to_the_S_branch(rod):
    """US+ starts at U (dW1, the shape symmetric to 1e-4 L) and ends on S where S turns stable."""
    s = rod.summary
    for name in ("US+", "US-"):
        dw, h = branch(rod, name, "dW_over_L"), branch(rod, name, "H_mid_over_L")
        assert dw[0] == pytest.approx(s["dW1_over_L"], abs=1e-3)
        assert dw[-1] == pytest.approx(s["dW2_S_stable_over_L"], abs=1e-3)
        assert abs(h[-1]) < 5e-3
        assert s["branches"][name]["end"] == "stop condition"
    # the rod maps a state onto its half turn: US- is US+ turned, every image checked
    assert [s["branches"][name]["source"] for name in ("US+", "US-")] == ["pseudo-arclength", "half turn of US+"]


def test_US_plus_and_US_minus_are_mirror_images(rod):
    """Mirror images under the half turn about the vertical axis through the clamps' midpoint:
    clamp force and energy equal along the branch; H_mid too, compared away from the two
    junctions where H_mid(dW) has square-root ends. The two branches are sampled at different
    arclength points, so this is interpolation-limited (measured up to 1.5e-5 L where the samples
    are 0.02 apart); at equal dW the recorded paths of US+ and US- agree to 1e-7 L
    (tests/ddg/solve/test_thresholds.py)."""
    s = rod.summary
    plus, minus = branch(rod, "US+", "dW_over_L"), branch(rod, "US-", "dW_over_L")
    inner = minus[(minus > s["dW1_over_L"] + 0.01) & (minus < s["dW2_S_stable_over_L"] - 0.01)]
    assert inner.size > 10
    for key, tolerance in (("H_mid_over_L", 5e-5), ("F_shear_norm", 1e-4), ("energy", 1e-5)):
        a = PchipInterpolator(plus, branch(rod, "US+", key))(inner)
        b = PchipInterpolator(minus, branch(rod, "US-", key))(inner)
        scale = np.max(np.abs(branch(rod, "US+", key)))
        assert np.max(np.abs(a - b)) < tolerance * max(scale, 1.0), key


def test_S_branch_is_unstable_before_and_stable_after_dW2_S_stable(rod):
    dw, lam = branch(rod, "S+", "dW_over_L"), branch(rod, "S+", "lambda_min")
    order = np.argsort(dw)
    dw, lam = dw[order], lam[order]
    threshold = rod.summary["dW2_S_stable_over_L"]
    assert np.all(lam[dw < threshold - 1e-3] < 0) and np.all(lam[(dw > threshold + 1e-3) & (dw < 0.6)] > 0)
    assert np.all(np.abs(branch(rod, "S+", "H_mid_over_L")) < 1e-8)


def test_narrow_plate_US_branch_folds_and_the_path_snaps_to_S(narrow_plate):
    """The plate's US branch ends in a fold (a limit point in dW), not at the S pitchfork: past it
    the branch turns back unstable and meets S at a smaller dW. The recorded path goes round the
    fold and snaps to S there; dW2 (the stable path reaches S, to 1e-3 L) is the
    fold, and S turns stable just before it (measured 0.4517, 0.4519, 0.4511 at 600 triangles).
    (A second, tiny fold pair at dW/L = 0.3745-0.3747 is a short unstable stretch inside US.)"""
    s = narrow_plate.summary
    # met by the recorded path: the small fold inside US (0.3745) and the end of US
    assert len(s["folds_dW_over_L"]) == 2 and s["folds_dW_over_L"][0] == pytest.approx(0.3745, abs=1e-3)
    fold = s["folds_dW_over_L"][-1]
    assert fold == pytest.approx(s["dW2_over_L"], abs=1e-3)
    assert s["dW2_S_stable_over_L"] < fold
    dw, lam = branch(narrow_plate, "US+", "dW_over_L"), branch(narrow_plate, "US+", "lambda_min")
    top = int(np.argmax(dw))
    # the path's record of the fold is the last state before its snap where the snap is an energy
    # descent (ddg.solve.continuation.PathFollower.folds), the fold itself where pseudo-arclength went
    # round it: within a hard substep (jump_substep of a recorded interval) below the branch's fold.
    # Restated when the descent began to land here (issue 49): the path's fold 0.45125, the branch's
    # 0.45157, the substep 6e-4 L; it was 2e-4 while the descent failed and the arclength pass found it
    interval = 0.47 / 47
    assert 0.0 <= dw[top] - fold <= ddg.ContinuationOptions().jump_substep * interval + 1e-9
    beyond = slice(top + 1, None)
    bottom = top + 1 + int(np.argmin(dw[beyond]))
    assert bottom - top >= 3 and np.all(np.diff(dw[top:bottom + 1]) < 0)  # going back in dW ...
    assert np.all(lam[top + 1:bottom] < 0)                                # ... unstable ...
    # ... to S, which it meets where S turns stable. Near that junction the picture is a
    # supercritical pitchfork of S (stable US for dW just below it), so the branch folds once
    # more, 3e-5 L before S (measured 0.45104 vs 0.45107), and is stable from there to S.
    assert dw[-1] == pytest.approx(s["dW2_S_stable_over_L"], abs=2e-4)
    assert s["dW2_S_stable_over_L"] - dw[bottom] < 2e-4
    assert abs(branch(narrow_plate, "US+", "H_mid_over_L")[-1]) < 0.03
    phases = narrow_plate.column("phase", "shear")
    assert phases[-1] == "S+" and "US+" in phases


def test_past_the_pitchfork_the_path_slides_onto_us_along_the_critical_mode():
    """Leaving the unstable U past dW1 holds the amplitude along the critical mode and doubles it
    while the energy falls (bordered Newton), then finds the multiplier's root: a stable,
    asymmetric equilibrium (US+) in tens of iterations, where a fixed push followed by modified
    Newton slid for 225 (rod, M = 100) to 345 (M = 40). The state is an equilibrium of the free problem."""
    import ddg
    from ddg.api import make_model
    from ddg.solve.state import phase_label
    from ddg.solve.continuation import ContinuationOptions, PathFollower
    from ddg.solve.newton import ROUNDOFF_STALL_FACTOR, NewtonOptions, scaled_residual

    strip = ddg.Strip.from_ratios(0.05, 0.5)
    L = strip.length
    model = make_model("rod", strip, 40)
    from rod_states import compressed_state

    follower = PathFollower(model, ContinuationOptions(branch_switching=False))
    state = compressed_state(follower)
    state = follower.advance(state, 0.5 * L, 0.37 * L)  # past dW1 = 0.35 L on U, unstable
    assert not state.stable and phase_label(model, state.q, state.compression, state.shear) == "U"
    before = follower.iterations_by_phase["branch switching"]
    follower.options = ContinuationOptions()
    slid = follower._ensure_stable(state, 0)
    spent = follower.iterations_by_phase["branch switching"] - before
    assert slid is not None and slid.stable and slid.branch_switched
    assert phase_label(model, slid.q, slid.compression, slid.shear) == "US+"
    # converged as Newton judges it: the residual below tolerance or in the round-off band above the
    # model's floor estimate (ddg.solve.newton.settled)
    assert scaled_residual(model, slid.evaluation.gradient) <= max(NewtonOptions().residual_tol,
                                                                   ROUNDOFF_STALL_FACTOR * model.residual_floor())
    # measured 80 here (M = 40, dW/L = 0.37); the energy descent it replaces took 345
    assert spent < 160, f"{spent} Newton iterations to leave the saddle"


def test_a_trace_without_hessians_keeps_only_the_last_one():
    """The fold snaps trace with keep_hessians=False: every state but the last drops its Hessian (a
    band of the whole model, 90 MB on a 15000-triangle plate: a 200-point snap held 17 GB and the
    W/L = 1/20, L/b = 4000 study's 18-row run was killed for it), keeping q, energy, gradient and
    frames; the states themselves are those of a trace that keeps every Hessian."""
    from ddg.solve.arclength import ArclengthOptions, ArclengthTracer
    from ddg.solve.newton import NewtonOptions

    strip = ddg.Strip.from_ratios(1 / 20, 0.5)
    run = ddg.simulate(strip, ddg.LoadingProtocol(0.5, shear_ratio=0.05), model="rod", resolution=30,
                       branches=False, centerline=False)
    model, state = run.model, run.final_state
    frames = model.save_frames()
    runs = {}
    for keep in (True, False):
        model.restore_frames(frames)
        tracer = ArclengthTracer(model, NewtonOptions(), ArclengthOptions(max_points=6))
        runs[keep] = tracer.trace(state, 1.0, keep_hessians=keep)[0]
    kept, light = runs[True], runs[False]
    assert len(kept) == len(light) == 6
    assert all(s.evaluation.hessian is not None for s in kept)
    assert all(s.evaluation.hessian is None for s in light[:-1]) and light[-1].evaluation.hessian is not None
    for a, b in zip(kept, light):
        assert np.array_equal(a.q, b.q) and a.shear == b.shear and a.evaluation.energy == b.evaluation.energy


def test_a_fine_rod_traces_every_branch_to_its_end():
    """At M = 400 the stretching makes Newton's residual stall at 3-4 times the model's round-off
    floor estimate. The corrector accepts that as converged, as Newton does (a correction below
    step_tol, the residual within ROUNDOFF_STALL_FACTOR of the floor); before, every corrector there
    failed and U ended at dW/L = 0.092 after 15 states, S after one. Measured now: U 55 states to
    the end of the shear, US+ and US- 37 each to S, S+ 68; dW2 is then found at the fold, 2.3e-6 from
    where S turns stable (bound 1e-5, about four times that)."""
    result = run("rod", 400, None, 120)
    branches = result.summary["branches"]
    assert list(branches) == ["U", "US+", "US-", "S+"]
    assert branches["U"]["end"] == branches["S+"]["end"] == "left the shear range"
    assert branches["US+"]["end"] == branches["US-"]["end"] == "stop condition"
    assert min(b["points"] for b in branches.values()) >= 20
    assert result.summary["dW2_located_by"] == "fold"
    assert result.summary["dW2_over_L"] == pytest.approx(result.summary["dW2_S_stable_over_L"], abs=1e-5)
