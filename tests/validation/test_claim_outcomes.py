"""How a claim's outcome follows from its numbers (validation/claims.py): a single-model claim holds
at or below its bound and not without data; a cross-model claim holds, fails or is undecided by its
difference and combined error bar, at its worst point, and fails where the reference stops short or
data is missing; the clamp force is compared relative to the reference's force, per range
(validation.report_data.force_table)."""
import pytest

from validation import claims as C


def test_a_claim_without_data_does_not_hold():
    bound = C.CLAIMS["rod_elastica"].bound
    assert C.evaluate("rod_elastica", 0.5 * bound)["holds"] is True
    above = C.evaluate("rod_elastica", -2 * bound)  # the sign of an error does not matter
    assert above["holds"] is False and above["reason"] == f"measured {2 * bound:.4g} > bound {bound:g}"
    missing = C.evaluate("rod_elastica", None, "no rod run")
    assert missing["holds"] is False and missing["measured"] is None and missing["reason"] == "no data: no rod run"
    nan = C.evaluate("rod_elastica", float("nan"))
    assert nan["holds"] is False and nan["reason"].startswith("no data: ")


# ---------------------------------------------------------------------------- cross-model claims
def _agreement_claim(bound=0.01, limit=0.01):
    return C.Claim("synthetic", "synthetic", bound, limit)


@pytest.mark.parametrize("difference, combined, outcome", [
    (0.0099, 0.0099, "holds"),       # within the bound, error bars that can decide
    (0.0101, 0.0099, "fails"),       # beyond the bound, decidable: no excess allowance any more
    (0.0199, 0.0099, "fails"),       # what the old rule let pass (difference - error bar <= bound)
    (0.0099, 0.0101, "undecided"),   # within the bound, error bars too wide
    (0.0190, 0.0101, "undecided"),   # beyond the bound but within bound + error bar
    (0.0202, 0.0101, "fails"),       # beyond the bound even past the combined error bar
])
def test_a_cross_model_claim_holds_fails_or_is_undecided(difference, combined, outcome):
    """Issue 28 item 4: holds when |difference| <= bound and the combined error bar <= bound; fails
    when the error bars can decide it, or the difference exceeds bound + error bar; else undecided."""
    assert _agreement_claim().outcome_at(difference, combined) == outcome


def test_the_worst_point_decides_and_a_short_reference_fails(monkeypatch):
    """A claim's outcome is the worst of its points (fails before undecided before holds), and a
    curve whose reference stops short of dW_max fails however well the rest agrees."""
    import numpy as np

    from validation.estimates import Curve, Estimate, MeshResult, Study

    monkeypatch.setitem(C.CLAIMS, "synthetic", _agreement_claim())
    pairs = ((0.001, 0.001, "a"), (0.005, 0.02, "b"), (0.002, 0.001, "c"))
    undecided = C.Agreement(0.005, 0.02, 0.0, 3, "b", pairs=pairs)
    assert C.evaluate("synthetic", undecided)["outcome"] == "undecided"
    failing = C.Agreement(0.02, 0.02, 0.0, 4, "d", pairs=pairs + ((0.02, 0.005, "d"),))
    verdict = C.evaluate("synthetic", failing)
    assert verdict["outcome"] == "fails" and not verdict["holds"] and "at d" in verdict["reason"]

    dw_max = C.shear_limit(1.0, 1 / 6, 0.5)
    model_dw, ref_dw = np.linspace(0.0, dw_max, 50), np.linspace(0.0, 0.411, 20)

    def study(dw, dw1):
        return Study("plate", 0.5, 1 / 6, [MeshResult("m", 1, "elements", dw1, None)], Estimate(dw1, 1e-4), None,
                     Curve(dw, 0.3 + 0 * dw, 1e-4 + 0 * dw), "synthetic")

    a = C.curve_agreement(study(model_dw, 0.26), study(ref_dw, 0.26))
    assert a.difference == 0 and "ends at dW/L = 0.411" in a.short
    verdict = C.evaluate("synthetic", a)
    assert verdict["outcome"] == "fails" and "0.411" in verdict["reason"]
    whole = C.curve_agreement(study(model_dw, 0.26), study(model_dw, 0.26))
    assert whole.short == "" and C.evaluate("synthetic", whole)["outcome"] == "holds"


def test_an_agreement_without_its_points_is_judged_on_its_largest_figures(monkeypatch):
    monkeypatch.setitem(C.CLAIMS, "synthetic", _agreement_claim())
    assert C.evaluate("synthetic", C.Agreement(0.02, 0.005, 0.015))["outcome"] == "fails"
    assert C.evaluate("synthetic", C.Agreement(0.005, 0.005, 0.0))["outcome"] == "holds"


def test_a_claim_without_data_fails():
    verdict = C.evaluate("plate_vs_fem_dW1", None, "no FEM study dL0.5_W0.1667")
    assert verdict["outcome"] == "fails" and verdict["reason"].startswith("no data")


def test_the_force_comparison_is_relative_to_the_reference_force_and_split_by_range():
    """curve_agreement(quantity="force") divides the differences and error bars by the FEM's largest
    |F| on the compared points; force_table gives the whole path and the U branch per scene (a plate
    10 % above the FEM on U with 1 % error bars: difference 0.1 of the scale, excess 0.08)."""
    import numpy as np

    from validation.estimates import Curve, Estimate, MeshResult, Study
    from validation.report_data import force_table

    dw = np.linspace(0.0, 0.6, 61)
    fem_force = 2.0 * dw
    plate_force = np.where(dw < 0.3, 1.1 * fem_force, fem_force)

    def study(model, force):
        return Study(model, 0.5, 1 / 6, [MeshResult("m", 1, "elements", 0.305, 0.5)], Estimate(0.305, 0.001),
                     Estimate(0.5, 0.001), Curve(dw, 0.3 + 0 * dw, 0 * dw), "synthetic",
                     force=Curve(dw, force, 0.01 * np.abs(fem_force)))

    plate, fem = study("plate", plate_force), study("fem", fem_force)
    u = C.curve_agreement(plate, fem, band=0.0, upto=0.285, quantity="force")
    assert u.difference == pytest.approx(0.1) and u.points == 29
    assert u.combined_error_bar == pytest.approx(0.02) and u.excess == pytest.approx(0.08)
    rows = force_table(load=lambda model, c, w: {"plate": plate, "fem": fem}[model] if (c, w) == (0.5, 1 / 6)
                       else None)
    assert [r["range"] for r in rows] == ["path, 0.02 from the thresholds", "U branch"]
    whole, ub = rows
    assert ub["F_scale"] == pytest.approx(2 * 0.28, rel=1e-3) and ub["excess"] == pytest.approx(0.08)
    assert whole["F_scale"] == pytest.approx(1.2, rel=1e-3) and whole["points"] < 61
