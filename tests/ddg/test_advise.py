"""ddg.advise (rule v3), `python -m ddg advise` and `simulate --model auto`: the box about a scene
over dL/L, W/L and relative L/b, the plates keyed by element size, each quantity on its own, the
choice's label when nothing is within, outside the map, nu, the refused inputs, the committed map's
choices, and the `auto` block of a real (tiny) run."""
import csv
import json

import pytest

import ddg
from ddg.advise import (QUANTITIES, RULE_V1_MARGIN, Scene, basis_scenes, check_quantities, check_tolerance, choose,
                        load_map, parse_rows, predictions)
from ddg.cli import main

COLUMNS = ["scene", "compression_ratio", "width_ratio", "slenderness", "model", "resolution", "resolution_label",
           "wall_time_s", "reason"] + [f"{q}_{k}" for q in QUANTITIES for k in ("error", "ref_error_bar", "bound")]
LB = 1181.1023622047244   # the paper's L/b at dL/L = 1/2
LB4 = 787.4015748031495   # and at dL/L = 1/4 (its L is shorter: L = 75 mm / (1 - dL/L))


def _row(c, w, lb, model, res, label, wall, bounds, reason=""):
    row = {"scene": f"dL{c:g}_W{w:.4g}_Lb{lb:.0f}", "compression_ratio": c, "width_ratio": w, "slenderness": lb,
           "model": model, "resolution": res, "resolution_label": label, "wall_time_s": wall, "reason": reason}
    for q, b in zip(QUANTITIES, bounds):
        row.update({f"{q}_error": "" if b is None else b, f"{q}_ref_error_bar": "" if b is None else 0.0,
                    f"{q}_bound": "" if b is None else b})
    return row


def synthetic_rows():
    """Three scenes at dL/L = 1/2: W/L = 1/20 at L/b 300 and 1181, W/L = 1/6 at 1181; a rod (1 s) that
    is good when narrow, a plate on 12 rows (100 s) good everywhere, a FEM mesh (never chosen)."""
    return [
        _row(0.5, 0.05, LB, "rod", 100, "M100", 1.0, (0.004, 0.008, 0.006)),
        _row(0.5, 0.05, 300.0, "rod", 100, "M100", 1.2, (0.006, 0.003, 0.005)),
        _row(0.5, 1 / 6, LB, "rod", 100, "M100", 0.9, (0.09, 0.09, 0.2)),
        _row(0.5, 0.05, LB, "plate", 12, "R12", 100.0, (0.003, 0.005, 0.004)),
        _row(0.5, 0.05, 300.0, "plate", 12, "R12", 90.0, (0.002, None, 0.004), reason="dW2 null"),
        _row(0.5, 1 / 6, LB, "plate", 12, "R12", 120.0, (0.007, 0.009, 0.008)),
        _row(0.5, 0.05, LB, "fem", 64, "N64x8", 80.0, (0.001, 0.001, 0.001)),
        _row(0.5, 1 / 6, LB, "fem", 64, "N64x8", 80.0, (0.001, 0.001, 0.001)),
    ]


@pytest.fixture
def map_csv(tmp_path):
    path = tmp_path / "map.csv"
    with open(path, "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=COLUMNS)
        writer.writeheader()
        writer.writerows(synthetic_rows())
    return path


def test_bracketing_in_width_and_slenderness(map_csv):
    rows = load_map(map_csv)
    basis, why = basis_scenes(rows, Scene(0.5, 0.1, LB))
    assert why == "" and sorted(round(s.width_ratio, 4) for s in basis) == [0.05, 0.1667]
    basis, _ = basis_scenes(rows, Scene(0.5, 0.05, LB))          # on a map width: that scene alone
    assert [s.slenderness for s in basis] == [pytest.approx(LB)]
    basis, _ = basis_scenes(rows, Scene(0.5, 0.05, 600.0))       # between two L/b at that width
    assert sorted(s.slenderness for s in basis) == [300.0, pytest.approx(LB)]
    for scene, text in [(Scene(0.5, 0.5, LB), "W/L = 0.5 is outside"), (Scene(0.25, 0.05, LB4), "dL/L = 0.25"),
                        (Scene(0.5, 0.05, 4000.0), "L/b = 4000"), (Scene(0.5, 0.1, 300.0), "L/b = 300")]:
        basis, why = basis_scenes(rows, scene)
        assert basis == [] and text in why


def test_a_compression_between_the_maps_is_bracketed_at_the_papers_relative_thickness():
    """dL/L = 0.4 between the map's 1/4 and 1/2: the paper's strip there (L/b 984) lies between the
    paper's strips of both (787 and 1181 in L/b, all three b = 0.127 mm), so its basis is those two; a
    rod measured at 0.004 and 0.010 is predicted at the worse, 0.010. Four times thinner than the
    paper's at 0.4 is outside (the map has only the paper's thickness at 1/4)."""
    rows = parse_rows([_row(0.5, 0.05, LB, "rod", 100, "M100", 1.0, (0.004, 0.004, 0.004)),
                       _row(0.25, 0.05, LB4, "rod", 100, "M100", 1.5, (0.010, 0.002, 0.003))])
    scene = Scene(0.4, 0.05, ddg.Strip.from_ratios(0.05, 0.4).slenderness)
    assert scene.relative_slenderness == pytest.approx(1.0) and 900 < scene.slenderness < 1000
    basis, why = basis_scenes(rows, scene)
    assert why == "" and sorted(s.compression_ratio for s in basis) == [0.25, 0.5]
    c = choose(0.05, 0.4, None, 0.02, rows=rows, margin=RULE_V1_MARGIN)
    assert (c.model, c.within, c.inside_map) == ("rod", True, True)
    assert c.predicted_errors == {"dW1": 0.010, "dW2": 0.004, "H_mid": 0.004} and c.wall_time_s == 1.5
    basis, why = basis_scenes(rows, Scene(0.4, 0.05, 4 * scene.slenderness))
    assert basis == [] and "L/b = 3937" in why and "4 times the paper's" in why
    basis, why = basis_scenes(rows, Scene(0.6, 0.05, ddg.Strip.from_ratios(0.05, 0.6).slenderness))
    assert basis == [] and "dL/L = 0.6 is outside the map's compressions (0.25, 0.5)" in why


def plate_studies():
    """The plate at W/L = 1/6 on 8/12/18 rows and at 1/3 on 16/24/36 (dL/L = 1/2): the same three
    element sizes h/L = 1/48, 1/72, 1/108 on both, bounds falling with h, cost rising (1.5 times
    both at 1/3)."""
    rows = []
    for w, base in ((1 / 6, 8), (1 / 3, 16)):
        for k, (bound, wall) in enumerate(((0.04, 10.0), (0.02, 40.0), (0.012, 160.0))):
            n = int(base * 1.5**k)
            scale = 1.0 if w < 0.2 else 1.5
            rows.append(_row(0.5, w, LB, "plate", n, f"R{n}", wall * scale, (bound * scale,) * 3))
    return parse_rows(rows)


def test_plates_are_keyed_by_element_size_not_rows():
    """Issue 32: R12 at W/L = 1/6 and R24 at 1/3 have the same element size (h/L = 1/72), so at W/L =
    1/4 the plate on 18 rows (h/L = 1/72 too) is predicted from them: the worse bound of the two, the
    larger cost. At W/L = 1/5 the sizes measured give 10 and 14 rows; 10 rows (h/L = 1/50) lies
    between the measured 1/72 and 1/48 at both scenes: the largest bound of the four meshes."""
    rows = plate_studies()
    found = {p.label: p for p in predictions(rows, *_basis(rows, 0.25), margin=RULE_V1_MARGIN.value)}
    assert set(found) == {"R12", "R18"}      # 1/108 would be 28 rows at 1/4: h/L = 1/112, finer than measured
    p = found["R18"]
    assert p.element_size == pytest.approx(1 / 72) and p.errors["dW1"] == pytest.approx(0.03)
    assert p.wall_time_s == pytest.approx(60.0)
    assert p.meshes == {"dL0.5_W0.1667_Lb1181": ["R12"], "dL0.5_W0.3333_Lb1181": ["R24"]}
    found = {p.label: p for p in predictions(rows, *_basis(rows, 0.2), margin=RULE_V1_MARGIN.value)}
    assert set(found) == {"R10", "R14"}
    p = found["R10"]
    assert p.meshes == {"dL0.5_W0.1667_Lb1181": ["R12", "R8"], "dL0.5_W0.3333_Lb1181": ["R24", "R16"]}
    assert p.errors["H_mid"] == pytest.approx(0.06) and p.wall_time_s == pytest.approx(60.0)
    c = choose(0.25, 0.5, None, 0.031, rows=rows, margin=RULE_V1_MARGIN)
    assert (c.model, c.label, c.resolution, c.within) == ("plate", "R18", 18, True)
    assert c.element_size == pytest.approx(1 / 72) and c.auto_block()["element_size_over_L"] == pytest.approx(1 / 72)


def test_no_element_size_outside_the_measured_ones_is_offered():
    """Without the plate on 8 rows at W/L = 1/6, h/L = 1/48 is measured at 1/3 only: at 1/4 the plate
    on 12 rows is not offered, since 1/6 has no mesh that coarse (no extrapolation in h)."""
    rows = [r for r in plate_studies() if r["resolution_label"] != "R8"]
    assert {p.label for p in predictions(rows, *_basis(rows, 0.25))} == {"R18"}


def _basis(rows, width_ratio, compression_ratio=0.5):
    scene = Scene(compression_ratio, width_ratio, ddg.Strip.from_ratios(width_ratio, compression_ratio).slenderness)
    basis, why = basis_scenes(rows, scene)
    assert basis, why
    return basis, scene


def test_a_missing_quantity_makes_only_that_candidates_quantity_unknown(map_csv):
    # the plate at L/b = 300 has no dW2: its dW2 is unknown there, its dW1 is not, and the rod is unaffected
    c = choose(0.05, 0.5, 300.0, 0.004, quantities="dW1,dW2", path=map_csv)
    plate = next(p for p in c.candidates if p.model == "plate")
    assert plate.errors["dW2"] is None and "dW2 missing" in plate.why["dW2"] and plate.errors["dW1"] == 0.002
    assert not c.within and c.model == "rod" and c.unknown == {}     # the rod is the most accurate on both
    c = choose(0.05, 0.5, 300.0, 0.004, quantities="dW1", path=map_csv)
    assert (c.model, c.within) == ("plate", True)


def test_a_quantity_no_candidate_knows_is_unknown_not_a_veto():
    """Issue 32: where the reference stops short every model's H_mid bound is missing; the choice is
    then made on dW1 and dW2 and says H_mid is unknown, instead of finding no model within even 1."""
    rows = parse_rows([_row(0.5, 0.1, LB, "rod", 100, "M100", 1.0, (0.004, 0.006, None), reason="H_mid: stops"),
                       _row(0.5, 0.1, LB, "plate", 12, "R12", 90.0, (0.002, 0.003, None), reason="H_mid: stops")])
    c = choose(0.1, 0.5, None, 0.01, rows=rows)
    assert (c.model, c.within) == ("rod", True) and set(c.unknown) == {"H_mid"}
    assert "H_mid: no candidate's error is known here" in c.reason and "H_mid: stops" in c.reason
    block = c.auto_block()
    assert block["within_tolerance"] and list(block["unknown_quantities"]) == ["H_mid"]


def test_nothing_within_gives_the_most_accurate_labelled_with_its_predicted_error(map_csv):
    """Issue 32: the fallback is not a mesh pair presented as the error: it is the most accurate
    candidate, labelled as not meeting the tolerance, with its predicted error (map bound: model and
    mesh error together). The FEM is never chosen, even where it alone is within."""
    c = choose(1 / 6, 0.5, None, 0.005, path=map_csv)
    assert (c.model, c.label, c.within, c.inside_map) == ("plate", "R12", False, True)
    assert c.predicted_errors == {"dW1": 0.007, "dW2": 0.009, "H_mid": 0.008} and c.worst() == 0.009
    assert c.verdict() == "NOT WITHIN THE TOLERANCE 0.005: the most accurate candidate, predicted 0.0090"
    block = c.auto_block()
    assert block["safe_choice"] and not block["within_tolerance"] and block["predicted_errors"]["dW2"] == 0.009
    assert "NOT within the tolerance" in c.reason


def test_prediction_is_the_worst_bracketing_scene_and_the_cheapest_within_wins(map_csv):
    # W/L = 0.1 lies between 1/20 (rod 0.008 at worst) and 1/6 (rod 0.2): the rod is predicted at 0.2. The
    # plate on 12 rows has h/L = 1/240 at 1/20 and 1/72 at 1/6: no element size is measured at both, so
    # the plate is no candidate there, and the rod, the only one, is not within
    c = choose(0.1, 0.5, None, 0.01, path=map_csv)
    assert (c.model, c.label, c.within, c.inside_map) == ("rod", "M100", False, True)
    assert c.predicted_errors == {"dW1": 0.09, "dW2": 0.09, "H_mid": 0.2}
    assert c.wall_time_s == 1.0 and len(c.basis_scenes) == 2 and [p.model for p in c.candidates] == ["rod"]
    # on the narrow scene itself the rod is within 0.01 and 100 times cheaper
    c = choose(0.05, 0.5, None, 0.01, path=map_csv)
    assert (c.model, c.label) == ("rod", "M100") and c.predicted_errors["dW2"] == 0.008
    # between L/b 300 and 1181: the worst of the two rods
    c = choose(0.05, 0.5, 600.0, 0.01, path=map_csv)
    assert c.model == "rod" and c.predicted_errors == {"dW1": 0.006, "dW2": 0.008, "H_mid": 0.006}


def test_outside_the_map_runs_the_most_accurate_model_with_an_unknown_error(map_csv):
    c = choose(0.5, 0.5, None, 0.05, path=map_csv)
    assert not c.within and not c.inside_map and "outside the error map" in c.reason and "extrapolated" in c.reason
    # at the nearest map scene, W/L = 1/6, the plate's largest bound 0.009 beats the rod's 0.2; its element
    # size there, h/L = (1/6)/12, is 36 rows across W/L = 1/2
    assert (c.model, c.label, c.resolution) == ("plate", "R36", 36) and "dL0.5_W0.1667_Lb1181" in c.reason
    assert c.predicted_errors == {q: None for q in QUANTITIES} and c.verdict() == "OUTSIDE THE MAP: error unknown"
    block = c.auto_block()
    assert block["safe_choice"] and block["inside_map"] is False and block["chosen_model"] == "plate"
    assert set(block) >= {"chosen_model", "resolution", "reason", "predicted_errors", "basis_scenes", "map_file",
                          "verdict", "within_tolerance", "rule"}


def test_a_poisson_ratio_the_map_lacks_is_refused(map_csv, tmp_path, capsys):
    """Issue 32: the map is at nu = 0; nu = 0.25 moves the rod's dW1 by 0.0078, so no error can be
    predicted: refused with one line, exit 2, before any work."""
    with pytest.raises(ddg.InputError, match=r"poisson_ratio = 0.25: the error map is measured at nu = 0 only"):
        choose(0.05, 0.5, None, 0.01, path=map_csv, poisson_ratio=0.25)
    assert choose(0.05, 0.5, None, 0.01, path=map_csv, poisson_ratio=0.0).model == "rod"
    for args in (ADVISE + ["--tolerance", "0.01", "--poisson-ratio", "0.25", "--error-map", str(map_csv)],
                 AUTO + ["--model", "auto", "--tolerance", "0.01", "--poisson-ratio", "0.25", "--error-map",
                         str(map_csv), "--out", str(tmp_path / "o")]):
        assert main(args) == 2
        err = capsys.readouterr().err
        assert err.startswith("error: poisson_ratio = 0.25") and err.count("\n") == 1
    assert not (tmp_path / "o").exists()
    strip = ddg.Strip.from_ratios(0.05, 0.5, poisson_ratio=0.3)
    with pytest.raises(ddg.InputError, match="poisson_ratio = 0.3"):
        ddg.simulate(strip, ddg.LoadingProtocol(0.5, 0.05, 3, 2), model="auto", tolerance=0.01, error_map=map_csv)


def three_widths(plate_bounds=(0.003, 0.012, 0.008)):
    """A plate at W/L = 1/20, 1/12 and 1/6 (dL/L = 1/2, the paper's L/b), each on 12 rows (element
    sizes differ: each scene's own mesh only): 1/12 is bracketed by the others."""
    return [_row(0.5, w, LB, "rod", 100, "M100", 100.0, (b, b, b)) for w, b in zip((0.05, 1 / 12, 1 / 6), plate_bounds)]


def test_the_margin_is_the_worst_leave_one_out_ratio_on_the_fitting_scenes():
    """W/L = 1/12 predicted from 1/20 and 1/6 with margin 1 is 0.008, measured 0.012: the margin is
    1.5, and a scene between 1/12 and 1/6 is predicted at 1.5 times the worse of the two."""
    from ddg.advise import cross_validated_margin

    rows = parse_rows(three_widths())
    margin = cross_validated_margin(rows)
    assert margin.value == pytest.approx(1.5) and (margin.scenes, margin.compared) == (1, 3)
    assert "rod M100" in margin.worst and "dL0.5_W0.08333_Lb1181" in margin.worst
    c = choose(0.1, 0.5, None, 0.05, rows=rows)
    assert c.predicted_errors == pytest.approx({"dW1": 0.018, "dW2": 0.018, "H_mid": 0.018})
    block = c.auto_block()
    assert block["margin"] == pytest.approx(1.5) and "leave-one-out" in block["margin_basis"]
    assert choose(0.1, 0.5, None, 0.05, rows=rows, margin=RULE_V1_MARGIN).predicted_errors["dW1"] == 0.012


def test_the_margin_cross_validates_the_plates_at_the_rows_measured_there():
    """The left-out scene's plate meshes are predicted at their own rows: W/L = 1/4 between 1/6 and 1/3
    on 12/18/24 rows, its R18 measured 0.09 against the predicted 0.03 (worse of 1/6's R12 and 1/3's R24)."""
    from ddg.advise import cross_validated_margin

    rows = plate_studies() + parse_rows([_row(0.5, 0.25, LB, "plate", 18, "R18", 50.0, (0.09, 0.01, 0.01))])
    margin = cross_validated_margin(rows)
    assert margin.value == pytest.approx(3.0) and "plate R18 dW1 at dL0.5_W0.25_Lb1181" in margin.worst


def test_the_margin_is_at_least_one_and_ignores_held_out_rows():
    from ddg.advise import cross_validated_margin

    assert cross_validated_margin(parse_rows(three_widths((0.003, 0.002, 0.008)))).value == 1.0
    lone = cross_validated_margin(parse_rows(three_widths()[:2]))
    assert (lone.value, lone.compared) == (1.0, 0) and "nothing to cross-validate" in lone.text()
    held = _row(0.5, 0.125, LB, "rod", 100, "M100", 100.0, (0.5, 0.5, 0.5))
    held["role"] = "held-out"
    assert cross_validated_margin(parse_rows(three_widths() + [held])).value == pytest.approx(1.5)


def test_an_empty_or_missing_default_map_is_outside(tmp_path, monkeypatch):
    import ddg.advise as advise

    monkeypatch.delenv(advise.MAP_ENV, raising=False)
    monkeypatch.setattr(advise, "DEFAULT_MAP", tmp_path / "none.csv")
    c = choose(0.05, 0.5, None, 0.01)
    assert not c.within and not c.inside_map and "has no rows" in c.reason
    assert (c.model, c.resolution) == (advise.FALLBACK_MODEL, advise.FALLBACK_ROWS)


def test_checks():
    assert check_tolerance("0.01") == 0.01 and check_tolerance(1) == 1.0
    for bad in (0, -0.1, 1.5, "abc", float("nan"), float("inf"), None, True):
        with pytest.raises(ddg.InputError):
            check_tolerance(bad)
    assert check_quantities(None) == QUANTITIES and check_quantities("dW1, H_mid") == ("dW1", "H_mid")
    for bad in ("dW3", "", ["dW1", 3]):
        with pytest.raises(ddg.InputError):
            check_quantities(bad)


ADVISE = ["advise", "--width-ratio", "0.05", "--compression-ratio", "0.5"]
AUTO = ["simulate", "--width-ratio", "0.05", "--compression-ratio", "0.5", "--shear-ratio", "0.05",
        "--compression-steps", "3", "--shear-steps", "2", "--quiet"]


@pytest.mark.parametrize("args, named", [
    (ADVISE + ["--tolerance", "0"], "tolerance = '0' outside the allowed range (0, 1]"),
    (ADVISE + ["--tolerance=-0.5"], "tolerance = '-0.5' outside"),
    (ADVISE + ["--tolerance", "abc"], "tolerance = 'abc' is not a number; allowed (0, 1]"),
    (ADVISE + ["--tolerance", "nan"], "'nan' outside"),
    (ADVISE + ["--tolerance", "2"], "'2' outside"),
    (ADVISE, "--tolerance is required"),
    (ADVISE + ["--tolerance", "0.01", "--quantities", "dW1,kappa"], "quantity 'kappa' is not in the error map"),
    (ADVISE + ["--tolerance", "0.01", "--error-map", "/nonexistent/map.csv"], "'/nonexistent/map.csv'"),
    (AUTO + ["--model", "auto"], "--model auto needs --tolerance"),
    (AUTO + ["--model", "rod", "--tolerance", "0.01"], "--tolerance '0.01' applies to --model auto only"),
    (AUTO + ["--model", "auto", "--tolerance", "0"], "tolerance = '0' outside"),
    (AUTO + ["--model", "auto", "--tolerance", "0.01", "--quantities", "dW9"], "quantity 'dW9'"),
    (AUTO + ["--model", "auto", "--tolerance", "0.01", "--resolution", "50"], "--resolution 50 does not apply"),
])
def test_refused_inputs_exit_2_with_one_line(args, named, tmp_path, capsys):
    code = main(args + (["--out", str(tmp_path / "o")] if args[0] == "simulate" else []))
    assert code == 2
    err = capsys.readouterr().err
    assert err.startswith("error:") and err.count("\n") == 1 and named in err
    assert not (tmp_path / "o" / "path.csv").exists()


def test_api_refuses_auto_without_tolerance_and_tolerance_without_auto():
    strip = ddg.Strip.from_ratios(0.05, 0.5)
    protocol = ddg.LoadingProtocol(0.5, 0.05, 3, 2)
    with pytest.raises(ddg.InputError, match="needs a tolerance"):
        ddg.simulate(strip, protocol, model="auto")
    with pytest.raises(ddg.InputError, match="apply to model='auto' only"):
        ddg.simulate(strip, protocol, model="rod", tolerance=0.01)
    with pytest.raises(ddg.InputError, match="tolerance = -1"):
        ddg.simulate(strip, protocol, model="auto", tolerance=-1)


def test_auto_run_writes_its_choice_into_summary(map_csv, tmp_path, capsys):
    out = tmp_path / "run"
    code = main(AUTO + ["--model", "auto", "--tolerance", "0.1", "--error-map", str(map_csv), "--out", str(out),
                        "--no-thresholds"])
    assert code == 0
    summary = json.loads((out / "summary.json").read_text())
    auto = summary["auto"]
    assert summary["model"] == "rod" and summary["scene"]["resolution"] == 100
    assert (auto["chosen_model"], auto["resolution"], auto["safe_choice"]) == ("rod", 100, False)
    assert auto["predicted_errors"] == {"dW1": 0.004, "dW2": 0.008, "H_mid": 0.006}
    assert auto["basis_scenes"] == ["dL0.5_W0.05_Lb1181"] and auto["map_file"] == str(map_csv)
    assert "cheapest" in auto["reason"] and auto["tolerance"] == 0.1
    assert "auto: rod M100" in capsys.readouterr().err


def test_api_auto_returns_the_chosen_models_result(map_csv):
    strip = ddg.Strip.from_ratios(0.05, 0.5)
    result = ddg.simulate(strip, ddg.LoadingProtocol(0.5, 0.05, 3, 2), model="auto", tolerance=0.1,
                          quantities="dW1", error_map=map_csv, thresholds=False)
    assert result.summary["model"] == "rod" and result.summary["auto"]["quantities"] == ["dW1"]


# ------------------------------------------------------------------------------ the committed map
def _committed():
    from ddg.advise import DEFAULT_MAP

    if not DEFAULT_MAP.exists():
        pytest.skip("no committed error map (python -m validation.error_map --out data/error_map)")
    return load_map(DEFAULT_MAP)


def test_committed_map_narrow_strip_at_lb_300(monkeypatch):
    """Issue 17: `auto` picks the rod for W/L = 1/20 at L/b = 300 and tolerance 0.01 *if the map says so*.
    The committed map measures the rod there (M = 50/100/200) at dW1 error + reference error bar
    0.0226-0.0233 (rod dW1 0.3563-0.3570 against the FEM's 0.3392 +- 0.0055, a three-mesh study since
    issue 28): not within 0.01, so the rod is not chosen; whatever is chosen is predicted within 0.01
    or labelled as not within."""
    monkeypatch.delenv("DDG_ERROR_MAP", raising=False)
    rows = _committed()
    rods = [r for r in rows if r["model"] == "rod" and r["scene"] == "dL0.5_W0.05_Lb300"]
    assert rods, "the committed map has the rod at L/b = 300"
    rod_within = any(r["dW1_bound"] is not None and max(r[f"{q}_bound"] or 1.0 for q in QUANTITIES) <= 0.01
                     for r in rods)
    c = choose(0.05, 0.5, 300.0, 0.01, runnable=set(ddg.api.DEFAULT_RESOLUTION))
    assert (c.model == "rod") == rod_within
    assert not rod_within   # what the committed map says (see the docstring)
    assert not c.within or all(c.predicted_errors[q] <= 0.01 for q in QUANTITIES)


def test_committed_map_wide_strip_gets_a_plate(monkeypatch):
    monkeypatch.delenv("DDG_ERROR_MAP", raising=False)
    _committed()
    for compression in (0.5, 0.25):
        c = choose(0.5, compression, None, 0.01, runnable=set(ddg.api.DEFAULT_RESOLUTION))
        assert c.model in ("plate", "plate-midedge")
        assert not c.within or all(c.predicted_errors[q] <= 0.01 for q in QUANTITIES)


def test_committed_map_default_scene_at_0_02_gets_a_model_predicted_within_at_under_30_s(monkeypatch):
    """Issue 32: at the default scene (W/L = 1/20, dL/L = 1/2, the paper's strip) and tolerance 0.02
    the choice is predicted within 0.02 on all three quantities, at a map cost under 30 s (the
    measured wall time of that run is benchmarks/results/auto_choice.md's, not asserted here). On
    the committed map: ribbon-cross-section M201, predicted 0.0051 / 0.0022 / 0.0164, 19.8 s; the
    rod misses on dW2 (0.0486) and H_mid (0.0942), the mid-edge plate on 8 rows is within at 130 s."""
    monkeypatch.delenv("DDG_ERROR_MAP", raising=False)
    _committed()
    c = choose(0.05, 0.5, None, 0.02, runnable=set(ddg.api.DEFAULT_RESOLUTION))
    assert c.within and c.inside_map and c.unknown == {}
    assert all(c.predicted_errors[q] <= 0.02 for q in QUANTITIES) and c.wall_time_s < 30.0, (c.model, c.label)


def test_a_choice_outside_the_map_runs_one_model_and_says_its_error_is_unknown(map_csv, tmp_path, monkeypatch):
    """Issue 32: no mesh pair whose difference would be presented as the error: outside the map one run
    of the chosen candidate (here replaced by a tiny rod, to stay fast: what is checked is the call
    and the summary, not the plate), its summary saying the error is unknown and why."""
    import ddg.api as api

    calls = []
    real = api.run_candidate

    def fake(strip, protocol, model, resolution, out=None, **kwargs):
        calls.append((model, resolution, None if out is None else str(out)))
        return real(strip, protocol, "rod", 10, out=out, **kwargs)

    monkeypatch.setattr(api, "run_candidate", fake)
    strip = ddg.Strip.from_ratios(0.5, 0.5)
    out = tmp_path / "outside"
    result = ddg.simulate(strip, ddg.LoadingProtocol(0.5, 0.05, 3, 2), model="auto", tolerance=0.01,
                          error_map=map_csv, thresholds=False, out=out)
    assert calls == [("plate", 36, str(out))] and not (out / "auto_pair").exists()
    auto = json.loads((out / "summary.json").read_text())["auto"]
    assert auto == json.loads(json.dumps(result.summary["auto"]))
    assert auto["safe_choice"] and not auto["inside_map"] and not auto["within_tolerance"] and "pair" not in auto
    assert auto["resolution"] == 36 and auto["verdict"] == "OUTSIDE THE MAP: error unknown"
    assert auto["predicted_errors"] == {q: None for q in QUANTITIES} and "outside the error map" in auto["reason"]
