"""Warnings where a result lies outside its model's or mesh's validity (ddg.protocol.validity,
issue 18 item 1): the three cases of the issue produce theirs, in summary.json, on the command
line (once) and as Python ValidityWarnings; a clean narrow rod run produces none."""
import json
import warnings

import pytest

import ddg
from ddg.cli import main
from ddg.protocol.validity import ValidityWarning, mesh_warnings, threshold_warnings, width_warnings


def _run(width_ratio, model="rod", resolution=None, **kwargs):
    strip = ddg.Strip.from_ratios(width_ratio, 0.5)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = ddg.simulate(strip, ddg.LoadingProtocol(0.5), model=model, resolution=resolution,
                              branches=False, **kwargs)
    return result, [str(w.message) for w in caught if issubclass(w.category, ValidityWarning)]


def test_a_clean_narrow_rod_run_warns_of_nothing(monkeypatch):
    """W/L = 1/20 on the paper's strip: the map measures the rod's dW1 within 0.0055 L of the shell's;
    the path resolves every state and finds both thresholds."""
    monkeypatch.delenv("DDG_ERROR_MAP", raising=False)
    result, raised = _run(0.05)
    assert result.summary["warnings"] == [] and raised == []
    assert result.summary["dW1_over_L"] is not None and result.summary["dW2_over_L"] is not None


def test_the_rod_on_a_wide_strip_is_told_it_misses_the_width(monkeypatch, tmp_path, capsys):
    """W/L = 1/2: the rod's dW1/L 0.351 against the shell's 0.157 used to print silently. The map has
    this scene: the rod's dW1 error + reference bar 0.195 at its best resolution."""
    monkeypatch.delenv("DDG_ERROR_MAP", raising=False)
    result, raised = _run(0.5, thresholds=False)
    width = [w for w in result.summary["warnings"] if "does not show this 1D model" in w]
    assert len(width) == 1 and "rod at W/L = 0.5" in width[0] and "0.19" in width[0]
    assert width[0] in raised
    # the command line prints it once (the Python warning is silenced there), and stores it
    out = tmp_path / "wide"
    code = main(["simulate", "--model", "rod", "--width-ratio", "0.5", "--no-thresholds", "--no-branches",
                 "--out", str(out), "--quiet"])
    err = capsys.readouterr().err
    assert code == 0 and err.count("does not show this 1D model") == 1 and "ValidityWarning" not in err
    assert any("does not show this 1D model" in w for w in json.loads((out / "summary.json").read_text())["warnings"])


def test_width_warnings_follow_the_map(tmp_path):
    """Narrower than the map: nothing; wider, or another L/b: outside the map, said; no map file:
    no check; a model the map has without dW1 (the Sadowsky ribbon): said with the map's reason."""
    def summary(model, w, lb=1181.1023622047244, c=0.5):
        return {"model": model, "scene": {"width_ratio": w, "compression_ratio": c, "slenderness": lb}}

    assert width_warnings(summary("rod", 0.02)) == []
    assert width_warnings(summary("rod", 0.05)) == []
    assert width_warnings(summary("plate", 0.5)) == []                       # not a 1D model
    outside = width_warnings(summary("rod", 0.05, lb=8000.0))
    assert len(outside) == 1 and "outside the error map" in outside[0] and "L/b = 8000" in outside[0]
    # between L/b = 1181 and 4000: predicted from both, with the margin (0.034 measured on the committed map)
    (between,) = width_warnings(summary("rod", 0.05, lb=2000.0))
    assert "dL0.5_W0.05_Lb1181, dL0.5_W0.05_Lb4000" in between and "margin" in between
    assert width_warnings(summary("rod", 0.3), error_map=tmp_path / "none.csv") == []   # no such map: no check
    ribbon = width_warnings(summary("ribbon", 0.05))
    assert len(ribbon) == 1 and "has no dW1 bound of this model" in ribbon[0] and "not located" in ribbon[0]


def test_missing_map_file_means_no_width_check(tmp_path, monkeypatch):
    import ddg.advise as advise

    monkeypatch.delenv("DDG_ERROR_MAP", raising=False)
    monkeypatch.setattr(advise, "DEFAULT_MAP", tmp_path / "none.csv")
    assert width_warnings({"model": "rod", "scene": {"width_ratio": 0.5, "compression_ratio": 0.5,
                                                      "slenderness": 1181.1}}) == []


@pytest.fixture(scope="module")
def coarse_wide_plate():
    """The issue's case: the plate on 600 triangles at W/L = 1/6 used to print 'converged, path
    complete' with dW2 null and nothing else."""
    strip = ddg.Strip.from_ratios(1 / 6, 0.5)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = ddg.simulate(strip, ddg.LoadingProtocol(0.5), model="plate", resolution=600, branches=False)
    return result, [str(w.message) for w in caught if issubclass(w.category, ValidityWarning)]


def test_a_coarse_plate_says_where_its_mesh_stops_resolving_the_shape(coarse_wide_plate):
    result, raised = coarse_wide_plate
    assert result.converged and result.summary["path_complete"]
    mesh = [w for w in result.summary["warnings"] if "stops resolving the shape" in w]
    resolved = result.summary["resolved_up_to_dW_over_L"]
    assert len(mesh) == 1 and f"{resolved:.4f}" in mesh[0] and mesh[0] in raised
    assert resolved < result.summary["dW_max_over_L"] - 0.1


def test_dW2_null_at_the_end_of_the_path_says_why(coarse_wide_plate):
    result, _ = coarse_wide_plate
    assert result.summary["dW2_over_L"] is None
    why = [w for w in result.summary["warnings"] if w.startswith("dW2 not")]
    assert len(why) == 1 and "never reached S" in why[0] and "folds" in why[0]
    assert f"{result.summary['dW_max_over_L']:.4f}" in why[0]


def test_mesh_and_threshold_rules_on_recorded_rows():
    rows = [{"stage": "compression", "dW_over_L": 0.0, "phase": "U"}]
    rows += [{"stage": "shear", "dW_over_L": x, "phase": p, "max_turn_angle_deg": a, "max_strain": 1e-4}
             for x, p, a in ((0.1, "U", 5.0), (0.2, "US+", 10.0), (0.3, "US+", 45.0), (0.4, "S+", 60.0))]
    summary = {"model": "plate", "resolved_up_to_dW_over_L": 0.2, "path_complete": True, "dW_max_over_L": 0.4,
               "threshold_wall_time_s": 1.0, "dW1_over_L": 0.15, "dW2_over_L": None, "unresolved_thresholds": {},
               "folds_dW_over_L": []}
    (mesh,) = mesh_warnings(summary, rows)
    assert "dW/L = 0.3000" in mesh and "45 deg" in mesh and "dW/L <= 0.2000" in mesh
    (dw2,) = threshold_warnings(summary, rows)
    assert dw2.startswith("dW2 not located: the path reached S at dW/L = 0.4000")
    # reported unresolved already: no second line; a stopped run: its message says why
    assert threshold_warnings({**summary, "unresolved_thresholds": {"dW2_over_L": {}}}, rows) == []
    assert threshold_warnings({**summary, "path_complete": False}, rows) == []
    # thresholds not sought (--no-thresholds): nothing to say
    assert threshold_warnings({**summary, "threshold_wall_time_s": None}, rows) == []


def test_the_cross_section_model_says_where_its_long_wavelength_expansion_ends():
    """The 1D model with its cross-section expands the plate in strains varying over more than a
    width: from the first recorded state whose normal curvature changes by more than
    LONG_WAVELENGTH_LIMIT times its largest value within one width, a warning says so; rows of
    models without that column never warn."""
    from ddg.models.wide_ribbons import LONG_WAVELENGTH_LIMIT

    rows = [{"stage": "shear", "dW_over_L": x, "phase": "U", "max_turn_angle_deg": 5.0, "max_strain": 1e-4,
             "curvature_change_per_width": v} for x, v in ((0.1, 0.3), (0.2, 0.9), (0.3, 1.6), (0.4, 5.5))]
    summary = {"model": "ribbon-cross-section", "resolved_up_to_dW_over_L": 0.4}
    (text,) = mesh_warnings(summary, rows)
    assert "long-wavelength expansion at dW/L = 0.3000" in text and "1.6 times" in text and "up to 5.5" in text
    assert f"limit {LONG_WAVELENGTH_LIMIT:g}" in text
    assert mesh_warnings(summary, [{k: v for k, v in r.items() if k != "curvature_change_per_width"}
                                   for r in rows]) == []
