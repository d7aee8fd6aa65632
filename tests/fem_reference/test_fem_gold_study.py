"""The gold data's error bars (fem_reference.convergence.estimate, issue 16 item 1): exact on a
quantity that converges at a known order, honest where the meshes are not asymptotic.

No dolfinx needed: the estimates are checked on synthetic mesh sequences and on stored run
folders written here.
"""
import json
import math

import pytest

from fem_reference.convergence import (GCI_SAFETY, GCI_SAFETY_LOW_ORDER, NON_ASYMPTOTIC_FACTOR, estimate,
                                       order_from_ratios)

MESHES = [40, 60, 90]


def converging(exact: float, constant: float, order: float, meshes=MESHES):
    return [exact + constant * (1.0 / n) ** order for n in meshes]


@pytest.mark.parametrize("order", [1.5, 2.0, 3.0])
def test_a_quantity_converging_at_order_p_is_extrapolated_exactly(order):
    e = estimate(converging(0.25, 30.0, order), MESHES)
    assert e["asymptotic"] and e["order"] == pytest.approx(order, rel=1e-9)
    assert e["value"] == pytest.approx(0.25, abs=1e-12)
    # Roache's grid convergence index: 1.25 times the finest mesh's own error
    fine_error = 30.0 * (1.0 / 90) ** order
    assert e["error_bar"] == pytest.approx(GCI_SAFETY * fine_error, rel=1e-9)
    assert abs(e["finest"] - e["value"]) < e["error_bar"]


@pytest.mark.parametrize("order", [1.0, 1.2, 1.49])
def test_a_low_order_gets_the_safety_factor_three(order):
    """Issue 28: an order below 1.5 is not a confirmed one; Roache's factor 3, not 1.25."""
    e = estimate(converging(0.25, 30.0, order), MESHES)
    assert e["asymptotic"] and e["value"] == pytest.approx(0.25, abs=1e-12)
    assert e["error_bar"] == pytest.approx(GCI_SAFETY_LOW_ORDER * 30.0 * (1.0 / 90) ** order, rel=1e-9)
    assert "safety factor 3" in e["basis"]


def test_the_bisection_tolerance_is_added_to_the_error_bar():
    plain, padded = estimate(converging(0.3, 5.0, 2.0), MESHES), estimate(converging(0.3, 5.0, 2.0), MESHES, 1e-4)
    assert padded["error_bar"] == pytest.approx(plain["error_bar"] + 1e-4)


def test_differences_that_change_sign_give_three_times_the_largest():
    """The gold's W/L = 1/6, dL/L = 1/2 dW1 before issue 28: 0.2668 / 0.2636 / 0.2646 had the bar
    |d2| = 0.0010; the rule gives 3 x 0.0032."""
    e = estimate([0.2668, 0.2636, 0.2646], MESHES)
    assert not e["asymptotic"] and "change sign" in e["basis"]
    assert e["value"] == 0.2646 and e["error_bar"] == pytest.approx(NON_ASYMPTOTIC_FACTOR * 0.0032)
    # the independent monotone series of the same scene (0.2685 extrapolated) is within it
    assert abs(0.2685 - e["value"]) < e["error_bar"]


def test_differences_that_grow_give_three_times_the_largest():
    e = estimate([0.250, 0.252, 0.260], MESHES)
    assert not e["asymptotic"] and "do not shrink" in e["basis"]
    assert e["error_bar"] == pytest.approx(3 * 0.008)


def test_a_sequence_that_has_not_begun_to_converge_gets_a_finite_bar():
    """Differences within the bisection bracket (the rod's dW2 at M = 50/100/200, bracket 1e-3 L)
    or an order near 0: no extrapolation to an infinitely far limit, 3 x the largest difference,
    or the distance at order 0.5."""
    noise = estimate([0.5230, 0.5238, 0.52459], MESHES, 1e-3)
    assert noise["error_bar"] == pytest.approx(3 * 0.0008 + 1e-3)
    stalled = estimate([0.30, 0.31, 0.3199], MESHES)
    assert stalled["error_bar"] == pytest.approx(0.0099 / (1.5**0.5 - 1))


@pytest.mark.parametrize("order", [0.5, 0.75, 5.0])
def test_an_order_outside_the_window_is_not_asymptotic(order):
    """Shrinking, one sign, but p outside [1, 4]: the finest value, 3 x the largest difference
    (at p = 0.75 that covers the 2.8 x |d2| an extrapolation would add), and at p below 1 at least
    the distance to the limit at that order (p = 0.5: 4.4 |d2|, more than 3 x 1.22 |d2|)."""
    values = converging(0.25, 30.0, order)
    e = estimate(values, MESHES)
    assert not e["asymptotic"] and e["order"] == pytest.approx(order) and "outside" in e["basis"]
    assert e["value"] == e["finest"]
    d1, d2 = values[1] - values[0], values[2] - values[1]
    to_limit = abs(d2) / (1.5**order - 1) if order < 1 else 0.0
    assert e["error_bar"] == pytest.approx(max(NON_ASYMPTOTIC_FACTOR * abs(d1), to_limit))
    assert abs(e["value"] - 0.25) <= e["error_bar"] * (1 + 1e-9)


def test_only_the_finest_three_meshes_count():
    """A fourth mesh: the estimate is that of the finest three; the coarsest no longer matters."""
    meshes = [27, 40, 60, 90]
    values = [0.9] + converging(0.25, 30.0, 2.0)
    e = estimate(values, meshes)
    assert e["asymptotic"] and e["value"] == pytest.approx(0.25, abs=1e-12)


@pytest.mark.parametrize("order", [1.3, 2.0, 3.5])
def test_unequal_refinement_ratios_give_the_exact_order(order):
    """Meshes refined by 1.5 then 1.5275 (the gold's 144 x 18 -> 216 x 28, sqrt(N)): the order of
    the error model f* + C h^p is recovered exactly (Celik et al. 2008), and so the limit."""
    sizes = [(64 * 8) ** 0.5, (96 * 12) ** 0.5, (144 * 18) ** 0.5, (216 * 28) ** 0.5]
    values = [0.26 + 4.0 * (1.0 / h) ** order for h in sizes]
    e = estimate(values, [64, 96, 144, 216], sizes=sizes)
    assert e["order"] == pytest.approx(order, rel=1e-9) and e["value"] == pytest.approx(0.26, abs=1e-12)
    assert e["meshes"] == [64, 96, 144, 216]


def test_the_order_of_unequal_ratios_reduces_to_the_plain_formula():
    assert order_from_ratios(0.004, 0.001, 2.0, 2.0) == pytest.approx(2.0)
    assert order_from_ratios(0.004, -0.001, 1.5, 1.6) is None        # change of sign
    assert order_from_ratios(0.001, 0.002, 1.5, 1.5) is None         # growing


def test_fewer_meshes_say_so():
    two = estimate([0.25, None, 0.26], MESHES)
    assert two["meshes"] == [40, 90] and two["error_bar"] == pytest.approx(3 * 0.01) and not two["asymptotic"]
    one = estimate([None, math.nan, 0.26], MESHES)
    assert one["error_bar"] is None and one["basis"].startswith("one mesh")
    assert estimate([None, None, None], MESHES) is None


def _stored_run(folder, along, across, dw1, dw2, heights, width=1 / 6, forces=None):
    """A finished gold run folder: summary.json and path.csv with the keys the study reads (the
    clamp force F_shear_norm at each shear step where `forces` is given)."""
    from ddg.output.io import write_path_csv, write_summary_json

    folder.mkdir(parents=True)
    rows = [{"stage": "compression", "dL_over_L": 0.5, "dW_over_L": 0.0, "H_mid_over_L": heights[0], "phase": "U"}]
    rows += [{"stage": "shear", "dL_over_L": 0.5, "dW_over_L": 0.1 * k, "H_mid_over_L": h, "phase": "U"}
             for k, h in enumerate(heights[1:], start=1)]
    if forces is not None:
        rows[0]["F_shear_norm"] = 0.0
        for row, f in zip(rows[1:], forces):
            row["F_shear_norm"] = f
    write_path_csv(folder / "path.csv", rows)
    write_summary_json(folder / "summary.json", {
        "model": "fem", "status": "complete", "converged": True, "message": "path complete",
        "scene": {"width_ratio": width, "compression_ratio": 0.5, "slenderness": 1181.1, "resolution": along},
        "mesh": {"elements_along_L": along, "elements_across_W": across, "triangles": 2 * along * across},
        "n_dof": 100 * along, "recorded_steps": len(rows), "dW1_over_L": dw1, "dW2_over_L": dw2,
        "H_mid_over_L_compressed": heights[0], "wall_time_s": float(along), "newton_iterations": along,
        "threshold_tolerances_over_L": {"dW1": 1e-4, "dW2": 1e-4}})


def test_a_scene_study_from_stored_runs(tmp_path):
    """write_scene_study reads the finished runs of a scene folder and writes richardson.json with
    the same estimates as estimate() on the runs' numbers, and the finest run is the study's last."""
    from fem_reference.gold import finest_run, write_scene_study

    scene = tmp_path / "dL0.5_W0.1667"
    dw1 = converging(0.27, 20.0, 2.0)
    for (along, across), d1 in zip([(40, 8), (60, 12), (90, 18)], dw1):
        heights = [0.37 + 1.0 / along**2, 0.36 + 2.0 / along**2, 0.35 + 3.0 / along**2]
        _stored_run(scene / f"N{along}x{across}", along, across, d1, 0.43, heights)
    study = write_scene_study(scene)
    stored = json.loads((scene / "richardson.json").read_text())
    assert stored["dW1"]["value"] == pytest.approx(0.27, abs=1e-12) and stored["dW1"]["asymptotic"]
    assert stored["dW1"]["error_bar"] == pytest.approx(estimate(dw1, MESHES, 0.5e-4)["error_bar"])
    # dW2 equal on every mesh: no observed order, the spread (zero) plus the bisection bracket
    assert stored["dW2"]["error_bar"] == pytest.approx(1e-4) and not stored["dW2"]["asymptotic"]
    assert [m["along"] for m in study["meshes"]] == MESHES
    assert all(point["asymptotic"] for point in stored["H_mid_curve"])
    assert (scene / "convergence.md").exists()
    assert finest_run(scene).name == "N90x18"
    (scene / "summary.json").write_text("{}")  # a single run of the layout before the studies
    assert finest_run(scene) == scene


def test_the_clamp_force_gets_a_converged_curve_and_the_map_hash_ignores_it(tmp_path):
    """A force converging at order 2 on the three meshes is extrapolated exactly at each dW, in
    F_shear_curve beside H_mid_curve (issue 18: the force claim's error bar); the error map's
    reference hash of the study is that of the same study written without the force keys, so
    adding them leaves the map's rows current. `gold --studies-only` rewrites the study, no run."""
    from types import SimpleNamespace

    from fem_reference.gold import run_gold, write_scene_study
    from validation.error_map import UNREAD_STUDY_KEYS, _study_hash

    scene = tmp_path / "dL0.5_W0.1667"
    for along, across in [(64, 8), (96, 12), (144, 18)]:
        heights = [0.37 + 1.0 / along**2, 0.36 + 2.0 / along**2, 0.35 + 3.0 / along**2]
        forces = [0.5 + 40.0 / along**2, 1.2 - 90.0 / along**2]
        _stored_run(scene / f"N{along}x{across}", along, across, 0.27, 0.43, heights, forces=forces)
    study = write_scene_study(scene)
    force = study["F_shear_curve"]
    assert [round(p["dW_over_L"], 12) for p in force] == [0.1, 0.2]
    assert [p["value"] for p in force] == pytest.approx([0.5, 1.2], abs=1e-12)
    assert all(p["asymptotic"] and p["order"] == pytest.approx(2.0) for p in force)
    assert study["F_shear_curve_away"]["points"] == 2
    plain = tmp_path / "plain.json"
    plain.write_text(json.dumps({k: v for k, v in study.items() if k not in UNREAD_STUDY_KEYS}, indent=2) + "\n")
    assert _study_hash(scene / "richardson.json") == _study_hash(plain)
    (scene / "richardson.json").unlink()
    args = SimpleNamespace(out=str(tmp_path), only=["dL0.5_W0.1667"], levels=None, resolution=None, quiet=True,
                           studies_only=True)
    assert run_gold(args) == 0
    assert json.loads((scene / "richardson.json").read_text())["F_shear_curve"] == force


def test_the_error_map_scenes_are_named_by_their_strip_and_run_only_when_asked():
    """MAP_SCENES (issue 17's held-out and other-L/b references) are named dL<..>_W<..>[_Lb<..>],
    each width has a mesh sequence with exact 1.5 ratios, and the default gold run is the
    paper's ten scenes: a map scene runs only when named with --only."""
    from types import SimpleNamespace

    from fem_reference.gold import (HELD_OUT_SCENES, MAP_SCENES, NEW_MAP_SCENES, all_scenes, check_gold_inputs,
                                    mesh_sequence, scenes)

    names = [name for name, *_ in all_scenes()]
    assert len(names) == len(set(names)) == 10 + len(MAP_SCENES) + len(NEW_MAP_SCENES) + len(HELD_OUT_SCENES)
    assert {"dL0.4_W0.05", "dL0.3333_W0.125", "dL0.5_W0.05_Lb2000", "dL0.3_W0.25"} <= set(names)
    assert "dL0.5_W0.125" in names and "dL0.5_W0.05_Lb300" in names
    for _, _, width, _ in all_scenes():
        meshes = mesh_sequence(width)
        assert all(abs(b[0] / a[0] - 1.5) < 1e-12 and abs(b[1] / a[1] - 1.5) < 1e-12
                   for a, b in zip(meshes, meshes[1:]))
    import tempfile

    with tempfile.TemporaryDirectory() as out:
        default = check_gold_inputs(SimpleNamespace(only=None, levels=None, resolution=None, out=out))
        assert [s[0] for s in default] == [name for name, _, _ in scenes()]
        chosen = check_gold_inputs(SimpleNamespace(only=["dL0.5_W0.05_Lb300"], levels=None, resolution=None,
                                                   out=out))
        assert [(s[0], s[3]) for s in chosen] == [("dL0.5_W0.05_Lb300", 300.0)]


def test_independent_series_are_estimated_and_compared(tmp_path):
    """fem_reference.series: each mesh series of W/L = 1/6, dL/L = 1/2 estimated with the gold's
    rule; two series converging at order 2 to limits 0.005 apart, each with a tiny error bar,
    disagree, and each candidate value is placed inside or outside each series' error bar."""
    from fem_reference import series

    data = tmp_path
    gold = [(64, 8), (96, 12), (144, 18), (216, 28)]
    iso = [(96, 16), (144, 24), (216, 36)]
    for (along, across), limit in [(m, 0.2650) for m in gold] + [(m, 0.2700) for m in iso]:
        h = (along * across) ** -0.5
        _stored_run(data / "fem_gold" / "dL0.5_W0.1667" / f"N{along}x{across}", along, across,
                    limit - 1.0 * h**2, 0.43, [0.37, 0.36, 0.35])
    out = series.write_series(data / "fem_gold" / "dL0.5_W0.1667")
    by_name = {s["name"]: s for s in out["series"]}
    assert by_name["gold"]["dW1"]["value"] == pytest.approx(0.2650, abs=1e-9)
    assert by_name["isotropic"]["dW1"]["value"] == pytest.approx(0.2700, abs=1e-9)
    assert by_name["older isotropic"]["runs"] == []
    pair = next(c for c in out["checks"]
                if c.get("a") == "gold" and c.get("b") == "isotropic" and c["quantity"] == "dW1")
    assert not pair["agree"] and pair["difference"] == pytest.approx(0.005, abs=1e-9)
    placed = {c["candidate"]: c for c in out["checks"] if "candidate" in c}
    assert placed[0.2646]["inside"] == [] and set(placed[0.2685]["outside"]) == {"gold", "isotropic"}
    assert (data / "fem_gold" / "dL0.5_W0.1667" / "series.md").exists()
    assert series.write_series(data / "fem_gold" / "dL0.5_W0.05") is None
