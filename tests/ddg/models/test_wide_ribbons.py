"""The 1D ribbon models with width (issue 17, items 1-2): ribbon-sano-wada, ribbon-trapeze,
ribbon-wunderlich (ddg.models.wide_ribbons) against exact solutions, the rod and their own limits.

Their assembled derivatives are checked with the other rod-family models in
tests/ddg/models/test_model_derivatives.py; here the physics: each is the rod (and the exact elastica) under
compression, where the twist vanishes; each tends to the rod as the strip narrows at fixed
thickness; the trapeze term adds T W^2 / 12 to the twist stiffness under a tension T; the
Wunderlich ruling factor and its pole; the Sano-Wada regularisation length.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import ddg
from ddg.analysis.analytic import clamped_elastica_midpoint_height
from ddg.energies.rod_curvature import material_curvatures
from ddg.energies.rod_twist import discrete_twist
from ddg.energies.wunderlich import SERIES_BELOW, ruling_factor
from ddg.models.rod import RodModel
from ddg.models.wide_ribbons import (CrossSectionRibbon, SanoWadaRibbon, TrapezeRibbon, WunderlichRibbon,
                                     sano_wada_zeta)

WIDE_RIBBONS = ("ribbon-sano-wada", "ribbon-trapeze", "ribbon-cross-section", "ribbon-wunderlich")
NODES = 101  # the ribbons' default; the rod is compared at the same M


def run(model: str, width_ratio: float, compression_ratio: float = 0.5, shear_ratio=None, nodes: int = NODES,
        **kwargs):
    strip = ddg.Strip.from_ratios(width_ratio, compression_ratio)
    protocol = ddg.LoadingProtocol(compression_ratio, shear_ratio=shear_ratio, **kwargs)
    return ddg.simulate(strip, protocol, model=model, resolution=nodes, branches=False)


# --------------------------------------------------------------------------- compression: tau = 0, the elastica
@pytest.mark.parametrize("model", WIDE_RIBBONS)
def test_compressed_ribbon_is_the_rod_and_the_elastica(model):
    """Under compression alone the strip stays untwisted (tau = 0), where every ribbon energy and
    its first derivatives reduce to the rod's: H_mid is the rod's to round-off and the exact
    clamped elastica's to the discretisation error (the rod's own, 9.6e-5 L at M = 101)."""
    ribbon = run(model, 1 / 6, shear_ratio=0.0, compression_steps=20)
    rod = run("rod", 1 / 6, shear_ratio=0.0, compression_steps=20)
    assert ribbon.converged, ribbon.summary["message"]
    h_ribbon, h_rod = ribbon.summary["H_mid_over_L_compressed"], rod.summary["H_mid_over_L_compressed"]
    exact = clamped_elastica_midpoint_height(0.5)
    # measured: |ribbon - rod| 0 to 6e-17 L; |rod - exact| 9.6e-5 L (bound ~3x)
    assert abs(h_ribbon - h_rod) < 1e-10
    assert abs(h_ribbon - exact) < 3e-4
    state, instance = ribbon.final_state, ribbon.model
    _, _, _, _, m_ref = instance.frames(state.q)
    tau = discrete_twist(state.q[instance.theta_dofs], m_ref)
    assert np.max(np.abs(tau)) * ribbon.model.strip.length < 1e-9


# --------------------------------------------------------------------------- the narrow limit
#: W/L at L/b = 1181 (the paper's): W^2 / (b L) = 0.74, 0.18, 0.046.
NARROW_WIDTHS = (1 / 40, 1 / 80, 1 / 160)


@pytest.fixture(scope="module")
def narrow_runs():
    return {(model, w): run(model, w).summary for model in ("rod",) + WIDE_RIBBONS for w in NARROW_WIDTHS}


@pytest.mark.parametrize("model", WIDE_RIBBONS)
def test_ribbons_tend_to_the_rod_as_the_strip_narrows(model, narrow_runs):
    """At fixed thickness, W -> 0 takes W^2 / (b L) -> 0 and every ribbon to the rod: the gap of dW1
    falls at each halving of W, below 2e-3 at W^2 / (b L) = 0.18 and 2e-4 at 0.046, and so does
    the gap of dW2 between the two narrowest widths, below the same 2e-4 at 0.046. Measured gaps of
    dW1 at 0.74 / 0.18 / 0.046: sano-wada 8.9e-3 / 7.6e-4 / 6.5e-5, trapeze 1.2e-3 / 4.5e-4 /
    4.4e-5, wunderlich 9.1e-3 / 7.6e-4 / 6.5e-5 (bounds ~2.5-3x the values at the two narrow
    widths). dW2 gaps at 0.18 / 0.046: sano-wada and wunderlich 1.28e-3 / 7.2e-5, trapeze 1.49e-3 /
    9.7e-5 (falling ~16x per halving of W, as (W^2 / (b L))^2). Until dW2 was located at the fold
    (issue 31) it came from a bisection biased up to its 1e-3 bracket, and this test bounded the dW2
    gap by 1e-3 at both widths (measured <= 7e-4 then); the bound was changed after the precise
    values were seen. The cross-section ribbon tends to the rod with W/L (its clamp layer), see
    below."""
    gaps = []
    for w in NARROW_WIDTHS:
        rod, ribbon = narrow_runs[("rod", w)], narrow_runs[(model, w)]
        # the cross-section ribbon at W/L = 1/40 folds at dW/L = 0.8254, 98.1 % of dW_max, after
        # both thresholds (measured); any other stop fails here
        folded_near_max = (ribbon["status"] == "stopped" and "folds" in ribbon["message"]
                           and ribbon["resolved_up_to_dW_over_L"] > 0.95 * rod["dW_max_over_L"])
        assert ribbon["converged"] or folded_near_max, ribbon["message"]
        gaps.append(abs(ribbon["dW1_over_L"] - rod["dW1_over_L"]))
    if model == "ribbon-cross-section":
        # its torsion-warping (Eq. V) holds the twist over a clamp layer 0.20 W long, an O(W/L)
        # effect that the shell has too: the gap closes with W/L, not with W^2/(b L). Bound at the
        # narrowest width: that layer's length over L, 0.2 W/L = 1.25e-3 (measured gaps 1.6e-3,
        # 2.5e-3, 7.5e-4: unresolved by M = 101 at the two narrow widths, so not monotone).
        assert gaps[2] < gaps[0] and gaps[2] < 0.2 * NARROW_WIDTHS[2], gaps
        return
    assert gaps[0] > gaps[1] > gaps[2], gaps
    assert gaps[1] < 2e-3 and gaps[2] < 2e-4, gaps
    dw2_gaps = [abs(narrow_runs[(model, w)]["dW2_over_L"] - narrow_runs[("rod", w)]["dW2_over_L"])
                for w in NARROW_WIDTHS[1:]]
    assert dw2_gaps[1] < dw2_gaps[0] and dw2_gaps[1] < 2e-4, dw2_gaps


# --------------------------------------------------------------------------- trapeze: the tension's twist stiffness
def test_trapeze_tension_adds_t_w2_over_12_to_the_twist_stiffness():
    """A straight strip stretched by eps and twisted uniformly by tau: the trapeze term's coupling
    E b W^3 eps tau^2 / 24 makes the twist stiffness GJ + T W^2 / 12 with T = E b W eps (Green's
    trapeze effect). Measured from the model's energy at small tau against the rod's: to 1e-9."""
    strip = ddg.Strip(length=0.1, width=0.01, thickness=1e-4, young_modulus=1e9)
    eps = 1e-3
    stiffness = {}
    for cls in (RodModel, TrapezeRibbon):
        model = cls(strip, 41)
        q = model.rest_state()
        q[model.node_dofs] *= 1.0 + eps  # uniform stretch about x = 0
        free_length = model.voronoi_lengths.sum()
        twist = 1e-3 / strip.length  # per unit length, quartic term negligible (W^2 tau / b = 1e-2)
        energies = []
        for tau in (-twist, 0.0, twist):
            qt = q.copy()
            qt[model.theta_dofs] = tau * model.centerline.edge_arclength
            energies.append(model.evaluate(qt, gradient=False, hessian=False).energy)
        stiffness[cls.name] = (energies[0] - 2 * energies[1] + energies[2]) / twist**2 / free_length
    tension = strip.young_modulus * strip.width * strip.thickness * eps
    added = stiffness["ribbon-trapeze"] - stiffness["rod"]
    assert added == pytest.approx(tension * strip.width**2 / 12.0, rel=1e-6)
    assert stiffness["rod"] == pytest.approx(strip.twisting_stiffness, rel=1e-6)


# --------------------------------------------------------------------------- Wunderlich: the ruling factor
def test_ruling_factor_series_and_closed_form_agree_and_have_the_pole_at_two():
    """g(v) = 2 artanh(v/2) / v: series below SERIES_BELOW and closed form above meet to round-off;
    g' and g'' match central differences; g = 1 + v^2 / 12 near 0; g -> inf at |v| = 2."""
    v = np.array([SERIES_BELOW * (1 - 1e-12), SERIES_BELOW * (1 + 1e-12)])
    g, g1, g2 = ruling_factor(v)
    assert abs(g[0] - g[1]) < 1e-14 and abs(g1[0] - g1[1]) < 1e-12 and abs(g2[0] - g2[1]) < 1e-11
    for point in (0.03, 0.5, 1.5, -1.2):
        value, first, second = (a[0] for a in ruling_factor(np.array([point])))
        # steps: truncation h^2 g'''/6 and h^2 g''''/12 (up to ~10 h^2 near v = 1.5) against
        # round-off 1e-16 / h and 1e-16 / h^2
        for h, order, rel in ((1e-6, 1, 1e-8), (1e-4, 2, 1e-5)):
            gp, gm = ruling_factor(np.array([point + h]))[0][0], ruling_factor(np.array([point - h]))[0][0]
            if order == 1:
                assert first == pytest.approx((gp - gm) / (2 * h), rel=rel, abs=1e-9)
            else:
                assert second == pytest.approx((gp - 2 * value + gm) / h**2, rel=rel, abs=1e-7)
    assert ruling_factor(np.array([1e-3]))[0][0] == pytest.approx(1 + 1e-6 / 12, rel=1e-15)
    assert np.isinf(ruling_factor(np.array([2.0, -2.5]))[0]).all()
    assert ruling_factor(np.array([1.999]))[0][0] > 3.0


def test_wunderlich_energy_is_infinite_past_the_pole():
    """A state whose ruling slope changes by more than 2 / W between neighbouring nodes has no
    developable strip of width W: the energy is +inf (Newton's line search rejects such a step)."""
    strip = ddg.Strip(length=0.1, width=0.02, thickness=1e-4, young_modulus=1e9)
    model = WunderlichRibbon(strip, 15, zeta=10.0)
    q = model.buckled_guess(0.02)
    model.commit(q)
    q[model.theta_dofs[7]] += 0.5  # a twist kink where the strip is curved
    ev = model.evaluate(q)
    assert model.resolution_indicators(q)["max_ruling_rate"] > 2.0
    assert math.isinf(ev.energy) and not np.all(np.isfinite(ev.gradient))
    ev = model.evaluate_piecewise(q)   # the piecewise composition says the same
    assert math.isinf(ev.energy) and not np.all(np.isfinite(ev.gradient))
    q[model.theta_dofs[7]] -= 0.49
    assert math.isfinite(model.evaluate(q).energy) and model.resolution_indicators(q)["max_ruling_rate"] < 2.0


def test_sano_wada_zeta_is_their_width_regularisation():
    """zeta^2 = (1 - nu) W^4 / (60 b^2) (Eq. A.5), the Sano-Wada ribbon's and the Wunderlich
    ribbon's default; an explicit zeta replaces it."""
    strip = ddg.Strip(length=0.1, width=0.01, thickness=1e-4, young_modulus=1e9, poisson_ratio=0.3)
    zeta = math.sqrt(0.7 * strip.width**4 / (60 * strip.thickness**2))
    assert sano_wada_zeta(strip) == pytest.approx(zeta, rel=1e-14)
    assert SanoWadaRibbon(strip, 21).zeta == pytest.approx(zeta, rel=1e-14)
    assert WunderlichRibbon(strip, 21).zeta == pytest.approx(zeta, rel=1e-14)
    assert WunderlichRibbon(strip, 21, zeta=0.01).zeta == 0.01


def test_zeta_is_refused_where_it_does_not_apply():
    """zeta is an option of the ribbon and the Wunderlich ribbon only: one-line InputError."""
    strip = ddg.Strip.from_ratios(0.05, 0.5)
    protocol = ddg.LoadingProtocol(0.5)
    for model in ("rod", "ribbon-trapeze", "ribbon-sano-wada"):
        with pytest.raises(ddg.InputError, match="zeta applies"):
            ddg.simulate(strip, protocol, model=model, zeta=0.1)


@pytest.mark.parametrize("length", [-0.1, float("nan"), float("inf"), 11.0, "0.2", True])
def test_a_curvature_gradient_outside_its_range_is_refused_in_one_line(length):
    """CrossSectionRibbon's curvature_gradient (in widths) is a number in [0, 10]: anything else is an
    InputError naming the value and the range, before the model is built."""
    with pytest.raises(ddg.InputError, match=r"curvature_gradient=.*") as refused:
        CrossSectionRibbon(ddg.Strip.from_ratios(0.05, 0.5), 11, curvature_gradient=length)
    assert "\n" not in str(refused.value)


def test_wunderlich_strains_are_consistent_with_the_model():
    """The pair terms read the same strains as the stencil terms (a smoke check of the wiring):
    a bent, twisted state's Wunderlich part equals the pair sum recomputed from its strains."""
    strip = ddg.Strip(length=0.1, width=0.005, thickness=1e-4, young_modulus=1e9)
    model = WunderlichRibbon(strip, 21, zeta=0.05)
    q = model.buckled_guess(0.02)
    model.commit(q)
    q[model.theta_dofs] += 0.02 * np.sin(np.linspace(0, 3, len(model.theta_dofs)))
    parts = model.evaluate(q, gradient=False, hessian=False).parts
    x = q[model.node_dofs]
    _, _, m1, m2, m_ref = model.frames(q)
    kappa_n, _ = material_curvatures(x, m1, m2)
    tau = discrete_twist(q[model.theta_dofs], m_ref)
    assert parts["wunderlich"] == pytest.approx(model.pair_terms(kappa_n, tau)[0].sum(), rel=1e-14)
    assert parts["wunderlich"] > 0.0


# --------------------------------------------------------------------------- the coupled terms' own derivatives
def coupled_part_errors(model, base, q, scale, step=1e-6):
    """Relative errors (scaled DOFs) of the gradient and Hessian of E_model - E_base, the terms
    the model adds to its base (same frames, same committed state), against central differences
    of that difference: the Wunderlich pairs or the trapeze term alone, however small a share of
    the whole energy they hold."""
    def parts(qq, hessian=True):
        a, b = model.evaluate(qq, hessian=hessian), base.evaluate(qq, hessian=hessian)
        return a.energy - b.energy, a.gradient - b.gradient, \
            (a.hessian.to_dense() - b.hessian.to_dense()) if hessian else None

    energy, gradient, hessian = parts(q)
    n = q.size
    fd_gradient, jacobian = np.zeros(n), np.zeros((n, n))
    for i in range(n):
        dq = np.zeros(n)
        dq[i] = step * scale[i]
        plus, minus = parts(q + dq, hessian=False), parts(q - dq, hessian=False)
        fd_gradient[i] = (plus[0] - minus[0]) / (2 * step)
        jacobian[:, i] = (plus[1] - minus[1]) * scale / (2 * step)
    scaled = hessian * np.outer(scale, scale)
    return (np.linalg.norm(fd_gradient - gradient * scale) / np.linalg.norm(gradient * scale),
            np.linalg.norm(0.5 * (jacobian + jacobian.T) - scaled) / np.linalg.norm(scaled))


@pytest.mark.parametrize("seed", (0, 1, 2))
@pytest.mark.parametrize("kind", ("ribbon-trapeze", "ribbon-wunderlich"))
def test_coupled_terms_alone_match_finite_differences(kind, seed):
    """The trapeze term (against the rod) and the Wunderlich pair terms (against the Sadowsky
    ribbon with the same zeta) on their own: gradient and Hessian against central differences at
    committed twisted states, W/L = 1/10 and 1/20, 14 nodes. Measured: trapeze gradient errors
    5.5e-10 .. 8.9e-10, Hessian 2.5e-10 .. 2.9e-10; Wunderlich (|W eta'| 0.66 .. 1.08, the pairs
    holding 0.1-1 % of the energy, so the differences carry the whole energy's round-off)
    gradient 2.6e-9 .. 4.6e-8, Hessian 3.9e-10 .. 7.6e-9. Bound 2e-7, 4x the largest."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).parents[2]))
    from rod_states import rod_dof_scale, twisted_rod_state

    from ddg.models.ribbon import RibbonModel

    strip = ddg.Strip(length=0.1, width=0.005 if kind == "ribbon-wunderlich" else 0.01, thickness=0.001,
                      young_modulus=1e9, poisson_ratio=0.3)
    # (the cross-section ribbon has DOFs the rod lacks: its terms are checked alone in
    # tests/ddg/energies/test_cross_section.py and with the whole model in tests/ddg/models/test_model_derivatives.py)
    if kind == "ribbon-trapeze":
        model, base = TrapezeRibbon(strip, 14), RodModel(strip, 14)
    else:
        model, base = WunderlichRibbon(strip, 14, zeta=0.02), RibbonModel(strip, 14, zeta=0.02)
    q = twisted_rod_state(model, seed)
    twisted_rod_state(base, seed)  # the same committed frames
    model.evaluate(q)
    assert getattr(model, "largest_ruling_rate", 0.0) < 1.9
    gradient_error, hessian_error = coupled_part_errors(model, base, q, rod_dof_scale(model))
    assert gradient_error < 2e-7 and hessian_error < 2e-7, (gradient_error, hessian_error)


def test_a_wunderlich_state_near_the_pole_says_so():
    """stop_note names the barrier when |W eta'| is within 10 % of the pole, and is silent on a
    state well inside it (the driver adds the note to a stopped run's message and warnings)."""
    strip = ddg.Strip(length=0.1, width=0.02, thickness=1e-4, young_modulus=1e9)
    model = WunderlichRibbon(strip, 15, zeta=10.0)
    q = model.buckled_guess(0.02)
    model.commit(q)
    assert model.stop_note(q) is None
    base = q[model.theta_dofs[7]]
    for kink in np.linspace(0.0, 0.5, 201):
        q[model.theta_dofs[7]] = base + kink
        rate = model.resolution_indicators(q)["max_ruling_rate"]
        if 1.85 < rate < 2.0:
            break
    assert 1.85 < rate < 2.0, rate
    note = model.stop_note(q)
    assert note is not None and "pole of Wunderlich's ruling factor" in note and f"{rate:.3f}" in note


@pytest.mark.slow
def test_a_wunderlich_path_stopped_at_the_barrier_is_reported_so():
    """W/L = 1/20, dL/L = 1/2, zeta = 4 zeta_SW: the path stops at dW/L 0.7255 with |W eta'| =
    1.95 (measured); the message and the warnings say the fold may be the log barrier."""
    strip = ddg.Strip.from_ratios(1 / 20, 0.5)
    result = ddg.simulate(strip, ddg.LoadingProtocol(0.5), model="ribbon-wunderlich", resolution=NODES,
                          branches=False, zeta=4 * sano_wada_zeta(strip))
    assert result.summary["status"] == "stopped"
    assert "log barrier" in result.summary["message"]
    assert any("pole of Wunderlich's ruling factor" in w for w in result.summary["warnings"])


def test_cross_section_curvature_change_per_width_of_a_sinusoid():
    """curvature_change_per_width = W max |kappa_n'| / max |kappa_n|: on a planar centreline bent as
    kappa_n(s) = K sin(2 pi s / lambda) it is 2 pi W / lambda (to the discretisation's O(h^2)), and
    the stop note quotes it only above LONG_WAVELENGTH_LIMIT."""
    from ddg.models.wide_ribbons import CrossSectionRibbon

    strip = ddg.Strip.from_ratios(1 / 12, 0.5)
    nodes = 401
    model = CrossSectionRibbon(strip, nodes)
    length = strip.length
    for wavelength, expect_note in ((length, False), (length / 8, True)):
        s = np.linspace(0.0, length, nodes)
        curvature = 5.0 / length   # kappa_n = K sin(2 pi s / lambda): the tangent's angle is its integral
        angle = -curvature * wavelength / (2 * np.pi) * np.cos(2 * np.pi * s / wavelength)
        h = s[1] - s[0]
        edge_angle = 0.5 * (angle[1:] + angle[:-1])
        x = np.zeros((nodes, 3))
        x[1:, 0] = np.cumsum(h * np.cos(edge_angle))
        x[1:, 2] = np.cumsum(h * np.sin(edge_angle))
        q = np.zeros(model.n_dof)
        q[model.node_dofs] = x
        model.commit(q, model.evaluate(q))
        indicators = model.resolution_indicators(q)
        expected = 2 * np.pi * strip.width / wavelength
        # measured 0.26 % (lambda = L) and 0.32 % (L / 8) below: the difference quotient and the
        # sampled maximum are O((2 pi h / lambda)^2); the bound is three times the larger
        assert indicators["curvature_change_per_width"] == pytest.approx(expected, rel=0.01)
        note = model.stop_note(q)
        assert (note is not None) == expect_note
        if expect_note:
            assert f"{indicators['curvature_change_per_width']:.2g} times" in note
