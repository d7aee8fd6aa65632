"""The report's verdicts in words (validation/verdicts.py, worded by templates/sentences.j2): the
material's share of the plate's gap, the mesh trend, the reading of the paper's quoted values, the
claims that do not hold and the rows that disagree with the paper; each outcome on both sides of its
boundaries, with the numbers in the sentence."""
import pytest

from validation import claims as C


def _material(effect_dw1, gap_dw1, effect_h, gap_h, own_dw1=0.003, own_h=0.005):
    from validation.verdicts import MaterialCheck

    return MaterialCheck(fem_dep_vs_nu0_dW1=effect_dw1, plate_vs_fem_gold_dW1=gap_dw1, fem_dep_vs_nu0_curve=effect_h,
                         plate_vs_fem_gold_curve=gap_h, plate_vs_fem_dep_dW1=own_dw1, plate_vs_fem_dep_curve=own_h,
                         fem_dep_resolution=90, plate_triangles=5740)


def test_material_sentence_follows_the_share_of_the_gap():
    """The verdict on the plate's material follows the size of its effect against the gap,
    each side of each boundary (1/3, 2/3, 3/2 of the gap), with the numbers in the sentence."""
    from validation.report import material_sentence

    for share, verdict in ((0.30, "does not explain"), (0.36, "may explain part of"), (0.64, "may explain part of"),
                           (0.70, "may explain most of"), (1.4, "may explain most of"), (1.6, "may explain all of")):
        text = material_sentence(_material(0.0004, 0.0064, share * 0.01, 0.01))
        assert f"the material {verdict} the H_mid gap" in text, (share, text)
        assert f"the material changes the shell by {share * 0.01:.4f} L" in text and f"({100 * share:.0f} %)" in text
        assert "the material does not explain the dW1/L gap" in text  # 0.0004 of 0.0064
    # the committed quick snapshot (validation/results/quick/summary.json): the material moves the shell's
    # H_mid by 0.0071 L against the plate's 0.0098 L gap, which the old fixed sentence called "not the cause"
    text = material_sentence(_material(0.000373, 0.006437, 0.007095, 0.009754, 0.003456, 0.005033))
    assert "the material may explain most of the H_mid gap" in text and "not the cause" not in text
    assert "0.0071 L" in text and "0.0098 L" in text
    assert "0.0050 L in H_mid (closer than its 0.0098 L to the nu = 0 shell)" in text
    far = material_sentence(_material(0.0004, 0.0064, 0.0071, 0.009754, 0.0070, 0.0120))
    assert "0.0070 in dW1/L (not closer than its 0.0064" in far and "0.0120 L in H_mid (not closer than" in far
    no_gap = material_sentence(_material(0.0004, 0.0, 0.0071, 0.009754))
    assert "in dW1/L the material changes the shell by 0.0004; the plate has no gap to explain" in no_gap
    assert "dW1/L gap" not in no_gap and "the material may explain most of the H_mid gap" in no_gap


def test_share_of_gap_levels_each_side_of_their_boundaries():
    from validation.verdicts import ShareOfGap

    for share, level in ((0.33, "small"), (0.34, "part"), (0.66, "part"), (0.67, "most"), (1.5, "most"),
                         (1.51, "all")):
        assert ShareOfGap("H_mid", " L", share * 0.01, 0.01).level == level, share
    assert ShareOfGap("H_mid", " L", 0.001, 0.0).level == "no gap"


def test_mesh_trend_sentence_says_whether_the_distance_falls_at_every_refinement():
    from validation.report import mesh_trend_sentence

    falling = mesh_trend_sentence([(5740, 0.2575), (546, 0.2453), (2100, 0.2532)], 0.2640)
    assert falling.endswith("falls at every refinement.") and "0.2453 (546 triangles), 0.2532 (2100" in falling
    # the quick snapshot's plate dW1 at 1000 and 2000 triangles: its error grows from 0.0108 to 0.0131
    rising = mesh_trend_sentence([(546, 0.2453), (1050, 0.2532), (2100, 0.2509), (5740, 0.2575)], 0.2640)
    assert "does not fall at every refinement (it grows from 1050 to 2100 triangles)" in rising


def test_paper_reading_sentence_counts_the_quoted_values_above_the_onset():
    from validation.report import paper_reading_sentence

    def row(paper, ours, width=0.05):
        return {"model": "fem", "paper_dW1": paper, "dW1_over_L": ours, "width_ratio": width, "compression_ratio": 0.5}

    every = paper_reading_sentence([row(0.36, 0.3373), row(0.27, 0.264, 1 / 6)])
    assert "at 2 of them" in every and every.endswith("leaves U late after the pitchfork would give.")
    assert "+6.7 % at W/L = 1/20, dL/L = 1/2" in every
    some = paper_reading_sentence([row(0.36, 0.3373), row(0.17, 0.18, 0.5)])
    assert "at 1 of them" in some and some.endswith("could explain at most those 1.") and "-5.6 %" in some
    none = paper_reading_sentence([row(0.30, 0.3373)])
    assert "at 0 of them" in none and none.endswith("does not explain the differences.")
    assert paper_reading_sentence([row(0.36, None)]).startswith("No FEM dW1")


def test_claims_sentence_names_every_claim_that_does_not_hold():
    from validation.report import claims_sentence

    good = [C.evaluate("rod_elastica", 1e-4), C.evaluate("ribbon_elastica", 1e-4)]
    assert claims_sentence(good) == "All 2 claims hold: each measured value is at or below its bound."
    bad = good + [C.evaluate("fem_elastica", 1.0), C.evaluate("plate_elastica", None, "no plate run")]
    text = claims_sentence(bad)
    assert text.startswith("**2 of 4 claims do not hold (2 fail, 0 undecided): ") and "All" not in text
    assert "fem_elastica (fails: measured 1 > bound 0.0003)" in text
    assert "plate_elastica (fails: no data: no plate run)" in text
    undecided = C.evaluate("plate_vs_fem_dW1", C.Agreement(0.005, 0.03, 0.0, pairs=((0.005, 0.03, "here"),)))
    text = claims_sentence(good + [undecided])
    assert text.startswith("**1 of 3 claims do not hold (0 fail, 1 undecided): plate_vs_fem_dW1 (undecided: ")


def test_paper_disagreements_are_the_rows_beyond_the_stated_limit():
    from validation.verdicts import PAPER_DISAGREEMENT, paper_disagreements

    def row(diff):
        return {"model": "rod", "width_ratio": 0.05, "compression_ratio": 0.5,
                "dW1_over_L": None if diff is None else 0.36 * (1 + diff), "paper_dW1": 0.36,
                "dW1_rel_diff_vs_paper": diff, "dW2_rel_diff_vs_paper": None}

    listed = paper_disagreements([row(0.99 * PAPER_DISAGREEMENT), row(-1.01 * PAPER_DISAGREEMENT), row(None)])
    assert [d["rel_diff"] for d in listed] == [-1.01 * PAPER_DISAGREEMENT]
    assert listed[0]["percent"] == pytest.approx(-101 * PAPER_DISAGREEMENT)
