"""Cross-model data: the mesh studies of the FEM shell (data/fem_gold) and of the DDG plate
(data/plate_gold) that the claims compare (validation/claims.py, validation/estimates.py). Reads
the stored studies (dolfinx not needed); checks that the stored plate runs are this code's, the
observed convergence orders, and states the plate's unmet order target on the wide scenes (strict
expected failures whose reasons are computed from the studies they assert on)."""
from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest


GOLD = Path(__file__).resolve().parents[2] / "data" / "fem_gold" / "dL0.5_W0.1667"
PLATE_GOLD = Path(__file__).resolve().parents[2] / "data" / "plate_gold"


def _study(model, c, w):
    from validation.estimates import load_study

    study = load_study(model, c, w)
    if study is None:
        pytest.skip(f"no stored {model} study of dL/L = {c}, W/L = {w:.4g}")
    return study


def test_a_stored_plate_study_run_is_what_the_code_computes(tmp_path):
    """The committed plate study data are this code's: the coarsest run of dL/L = 1/4, W/L = 1/6
    (8 rows, about 12 s), rerun as validation.plate_gold runs it, gives the stored thresholds within
    their bisection tolerances (1e-4 L for dW1, 1e-3 L for dW2) and the stored compressed height."""
    import ddg
    from ddg.geometry.plate_mesh import equilateral_mesh

    stored = PLATE_GOLD / "dL0.25_W0.1667" / "R8" / "summary.json"
    if not stored.exists():
        pytest.skip(f"no stored plate run {stored}")
    summary = json.loads(stored.read_text())
    strip = ddg.Strip.from_ratios(1 / 6, 1 / 4)
    result = ddg.simulate(strip, ddg.LoadingProtocol(1 / 4), model="plate", branches=False,
                          mesh=equilateral_mesh(strip.length, strip.width, 8))
    assert result.summary["mesh"]["triangles"] == summary["mesh"]["triangles"]
    assert result.summary["H_mid_over_L_compressed"] == pytest.approx(summary["H_mid_over_L_compressed"], abs=1e-9)
    assert result.summary["dW1_over_L"] == pytest.approx(summary["dW1_over_L"], abs=1e-4)
    assert result.summary["dW2_over_L"] == pytest.approx(summary["dW2_over_L"], abs=1e-3)


#: Observed orders a threshold of a second-order discretisation may show (the zero of an eigenvalue
#: can converge at up to twice the displacements' order); fem_reference.convergence.ASYMPTOTIC_ORDERS.
ORDER_WINDOW = (1.5, 4.0)


@pytest.mark.parametrize("scene", [(0.5, 1 / 20), (0.5, 1 / 12), (0.25, 1 / 20), (0.25, 1 / 12)])
def test_plate_dW1_converges_at_second_order_on_the_narrow_scenes(scene):
    """Measured on 8/12/18 rows: orders 3.45 (dL/L = 1/2, W/L = 1/20), 1.82 (1/2, 1/12), 2.09 (1/4, 1/20),
    2.15 (1/4, 1/12); error bars 0.0002-0.0031 L."""
    dw1 = _study("plate", *scene).dW1
    assert dw1.asymptotic and ORDER_WINDOW[0] <= dw1.order <= ORDER_WINDOW[1], dw1
    assert dw1.error_bar < 0.005, dw1


@pytest.mark.parametrize("scene", [(0.5, 1 / 20), (0.5, 1 / 12), (0.5, 1 / 6), (0.25, 1 / 20), (0.25, 1 / 12)])
def test_plate_H_mid_converges_at_second_order_on_U(scene):
    """H_mid on U (0.05 < dW/L < dW1 - 0.02), point by point on 8/12/18 rows: median observed order
    3.00, 2.43, 1.99, 2.49, 2.33 on the scenes in order (16-39 asymptotic points each; at W/L = 1/2,
    dL/L = 1/2 it is 1.44 on 18 points, below the target, and not asserted here)."""
    orders, points = _study("plate", *scene).u_branch_orders()
    assert len(orders) >= 10, (len(orders), points)
    assert ORDER_WINDOW[0] <= np.median(orders) <= ORDER_WINDOW[1], np.median(orders)


def test_fem_dW1_converges_on_the_narrow_scene():
    """FEM on 64/96/144 elements at W/L = 1/20, dL/L = 1/2: dW1 0.3355/0.3444/0.3485, order 1.84."""
    dw1 = _study("fem", 0.5, 1 / 20).dW1
    assert dw1.asymptotic and ORDER_WINDOW[0] <= dw1.order <= ORDER_WINDOW[1], dw1


def _unmet(request, reason: str) -> None:
    """Mark the running test a strict expected failure (a target not met) with `reason`, computed from
    the studies it asserts on, so the figures cannot go stale; only an AssertionError is the miss."""
    request.applymarker(pytest.mark.xfail(strict=True, raises=AssertionError, reason=reason))


def _scene_text(study) -> str:
    return f"W/L = 1/{round(1 / study.width_ratio)}, dL/L = {study.compression_ratio:g}"


def _sequence(study) -> str:
    """The study's dW1 on its meshes: "0.2517/0.2503/0.2572 on R8/R12/R18"."""
    values = "/".join("none" if m.dW1 is None else f"{m.dW1:.4f}" for m in study.meshes)
    return f"{values} on {'/'.join(m.label for m in study.meshes)}"


def _order_text(estimate) -> str:
    if estimate.order is None:
        return f"no observed order ({estimate.basis})"
    return f"observed order {estimate.order:.2f}{'' if estimate.asymptotic else ', not asymptotic'}"


@pytest.mark.parametrize("width", [1 / 6, 1 / 2])
def test_plate_dW1_converges_at_order_1_8_on_the_wide_scenes(request, width):
    study = _study("plate", 0.5, width)
    dw1 = study.dW1
    _unmet(request, f"issue 16 item 3 target not met at {_scene_text(study)}: the plate's dW1 is {_sequence(study)}: "
                    f"{_order_text(dw1)}; target order 1.8")
    assert dw1.asymptotic and dw1.order >= 1.8, dw1


def test_gold_scene_converges_with_the_mesh(tmp_path):
    """The stored whole paths of the cross-model scene on 60 / 90 / 120 elements (data/fem_fine,
    data/fem_gold): dW1 and dW2 move less from each mesh to the next, and the convergence table
    built from them (python -m fem_reference convergence-table) has finite observed orders and
    puts the 120-element gold run within 0.005 L of the extrapolated dW1 and dW2."""
    from types import SimpleNamespace

    from fem_reference.convergence import table_from_runs

    data = GOLD.parents[1]
    runs = [data / "fem_fine" / "dL0.5_W0.1667_N60", data / "fem_fine" / "dL0.5_W0.1667_N90", GOLD]
    if not all((d / "summary.json").exists() for d in runs):
        pytest.skip("the stored FEM runs of the convergence table are missing")
    assert table_from_runs(SimpleNamespace(runs=[str(d) for d in runs], out=str(tmp_path))) == 0
    table = list(csv.DictReader(open(tmp_path / "thresholds.csv")))
    meshes, extrapolated = table[:-1], table[-1]
    assert [int(t["resolution"]) for t in meshes] == [60, 90, 120]
    for key in ("dW1_over_L", "dW2_over_L"):
        values = [float(t[key]) for t in meshes]
        assert abs(values[2] - values[1]) < abs(values[1] - values[0]), (key, values)
        assert abs(float(meshes[-1][key]) - float(extrapolated[key])) < 0.005, key
    for key in ("order_dW1", "order_dW2"):
        assert np.isfinite(float(extrapolated[key])), key


def test_plate_H_mid_converges_at_order_1_8_on_U_at_one_half(request):
    study = _study("plate", 0.5, 1 / 2)
    orders, _ = study.u_branch_orders()
    median = f"{np.median(orders):.2f}" if len(orders) else "none"
    _unmet(request, f"issue 16 item 3 target not met at {_scene_text(study)}: the plate's H_mid on U "
                    f"({'/'.join(m.label for m in study.meshes)}) has a median observed order of {median} over "
                    f"its {len(orders)} asymptotic points; target 1.8 (W/L = 1/6 is asserted above)")
    assert len(orders) >= 10 and np.median(orders) >= 1.8, np.median(orders)


def _mesh_near(study, triangles):
    """The study's mesh whose triangle count is nearest `triangles`."""
    return min(study.meshes, key=lambda m: abs(m.size - triangles))


def _near_2000_figures(model, study, fem, meshes) -> str:
    """dW1 of the given meshes of a study against the FEM's converged value."""
    def one(m):
        if m.dW1 is None:
            return f"none on {m.label} ({m.size} triangles)"
        return f"{m.dW1:.4f} on {m.label} ({m.size} triangles), {m.dW1 - fem.dW1.value:+.4f} from the FEM's"
    return (f"issue 16 item 3 target not met at {_scene_text(study)}: the {model} dW1/L is "
            + "; ".join(one(m) for m in meshes)
            + f" {fem.dW1.value:.4f} +- {fem.dW1.error_bar:.4f} ({len(fem.meshes)} meshes); bound 0.005")


@pytest.mark.parametrize("model", ["plate", "plate-midedge"])
def test_plate_dW1_at_2000_triangles_within_0_005_of_the_fem(request, model):
    fem, study = _study("fem", 0.5, 1 / 6), _study(model, 0.5, 1 / 6)
    mesh = _mesh_near(study, 2000)
    _unmet(request, _near_2000_figures(model, study, fem, [mesh]))
    assert abs(mesh.size - 2000) < 300 and mesh.dW1 is not None
    assert abs(mesh.dW1 - fem.dW1.value) <= 0.005, (mesh.label, mesh.dW1, fem.dW1.value)


def test_plate_dW1_near_2000_triangles_within_0_005_of_the_fem_at_one_half(request):
    fem, study = _study("fem", 0.5, 1 / 2), _study("plate", 0.5, 1 / 2)
    mesh = _mesh_near(study, 2000)
    nearest = sorted(study.meshes, key=lambda m: abs(m.size - 2000))[:2]   # the study's meshes either side
    _unmet(request, _near_2000_figures("plate", study, fem, sorted(nearest, key=lambda m: m.size)))
    assert abs(mesh.size - 2000) < 800 and mesh.dW1 is not None
    assert abs(mesh.dW1 - fem.dW1.value) <= 0.005, (mesh.label, mesh.dW1, fem.dW1.value)
