"""The ribbon reconciliation (validation.ribbon_reconciliation): Panda and Jawed's scene as our Strip
takes it, the fixed list of runs, and the stored study read back into its report."""
from __future__ import annotations

import csv

import pytest

from validation.reference import ROOT
from validation.ribbon_reconciliation import RUNS, ZETAS, fem_rows, report, strip_of, zeta_over_length

STUDY = ROOT / "data" / "ribbon_reconciliation"


def test_their_strip_is_a_tenth_of_a_metre_a_millimetre_thick_compressed_by_a_quarter():
    """Their nominal scene: L = 0.1 m, b = 1 mm, dL = 0.025 m, nu within 0.001 of their 0.5; the
    Sano-Wada zeta / L = sqrt((1 - nu) / 60) (W/L)^2 L/b is 0.254 at W/L = 1/6 there and 4.236 on
    ours (the 1181 of the paper's strip, nu = 0)."""
    strip = strip_of("PJ", 1 / 6)
    assert strip.length == pytest.approx(0.1) and strip.thickness == pytest.approx(1e-3)
    assert strip.design_compression_ratio * strip.length == pytest.approx(0.025)
    assert 0.5 - strip.poisson_ratio <= 1.001e-3
    assert zeta_over_length(strip) == pytest.approx(0.254, abs=5e-4)
    assert zeta_over_length(strip_of("ours", 1 / 6)) == pytest.approx(4.236, abs=5e-4)
    span = strip_of("PJ-span", 1 / 6)
    assert span.width / span.length == pytest.approx((1 / 6) / 0.807)


def test_the_runs_have_distinct_names():
    names = [r.name for r in RUNS]
    assert len(set(names)) == len(names)


def _stored_rows():
    with open(STUDY / "runs.csv", newline="") as fh:
        return list(csv.DictReader(fh))


def test_the_stored_study_has_every_run_and_its_report_is_regenerated_from_it():
    rows = _stored_rows()
    assert [r["name"] for r in rows] == [r.name for r in RUNS]
    assert report(rows, fem_rows(STUDY / "fem")) == (STUDY / "reconciliation.md").read_text()


def test_the_quartic_term_removes_the_pitchfork_between_zeta_of_a_third_and_one_length():
    """The finding docs/findings/models.md draws: on both strips (W/L = 1/6) the regularised Sadowsky
    energy has a dW1 up to zeta / L = 0.3 and none from 1 on."""
    rows = {r["name"]: r for r in _stored_rows()}
    for scene in ("PJ", "ours"):
        found = {z: rows[f"{scene}_W6_zeta_M101_z{z:g}"]["dW1_over_L"] not in ("", "None") for z in ZETAS}
        assert all(found[z] for z in ZETAS if z <= 0.3) and not any(found[z] for z in ZETAS if z >= 1.0)
