"""Cross-model data: the mesh studies of the FEM shell (data/fem_gold) and of the DDG plate
(data/plate_gold) that the claims compare (validation/claims.py, validation/estimates.py). Reads
the stored studies (dolfinx not needed); checks that the stored plate runs are this code's, the
observed convergence orders, and states the plate's unmet order target on the wide scenes."""
from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest


GOLD = Path(__file__).resolve().parents[1] / "data" / "fem_gold" / "dL0.5_W0.1667"
PLATE_GOLD = Path(__file__).resolve().parents[1] / "data" / "plate_gold"


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


@pytest.mark.xfail(strict=True, reason=(
    "issue 16 item 3 target not met: the plate's dW1 on 8/12/18 rows is 0.2517/0.2503/0.2572 at W/L = 1/6 "
    "and 0.1298/0.1334/0.1457 (16/24/36 rows) at W/L = 1/2, dL/L = 1/2: no observed order (differences "
    "change sign or grow)"))
@pytest.mark.parametrize("width", [1 / 6, 1 / 2])
def test_plate_dW1_converges_at_order_1_8_on_the_wide_scenes(width):
    dw1 = _study("plate", 0.5, width).dW1
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


@pytest.mark.xfail(strict=True, reason=(
    "issue 16 item 3 target not met at W/L = 1/2, dL/L = 1/2: the plate's H_mid on U (16/24/36 rows) has a "
    "median observed order of 1.44 over its 18 asymptotic points (1.99 at W/L = 1/6, asserted above)"))
def test_plate_H_mid_converges_at_order_1_8_on_U_at_one_half():
    orders, _ = _study("plate", 0.5, 1 / 2).u_branch_orders()
    assert len(orders) >= 10 and np.median(orders) >= 1.8, np.median(orders)


def _mesh_near(study, triangles):
    """The study's mesh whose triangle count is nearest `triangles`."""
    return min(study.meshes, key=lambda m: abs(m.size - triangles))


@pytest.mark.xfail(strict=True, reason=(
    "issue 16 item 3 target not met at W/L = 1/6, dL/L = 1/2: at about 2000 triangles dW1/L is 0.2503 for the "
    "paper's plate (2100 triangles) and 0.2715 for the mid-edge plate (2150), 0.0151 and 0.0061 from the FEM's "
    "0.2654 +- 0.0031 (four meshes, issue 28)"))
@pytest.mark.parametrize("model", ["plate", "plate-midedge"])
def test_plate_dW1_at_2000_triangles_within_0_005_of_the_fem(model):
    fem, study = _study("fem", 0.5, 1 / 6), _study(model, 0.5, 1 / 6)
    mesh = _mesh_near(study, 2000)
    assert abs(mesh.size - 2000) < 300 and mesh.dW1 is not None
    assert abs(mesh.dW1 - fem.dW1.value) <= 0.005, (mesh.label, mesh.dW1, fem.dW1.value)


@pytest.mark.xfail(strict=True, reason=(
    "issue 16 item 3 target not met at W/L = 1/2, dL/L = 1/2: the paper's plate's dW1/L is 0.1298 on 1254 "
    "triangles and 0.1334 on 2744 (the study meshes nearest 2000), 0.0268 and 0.0232 below the FEM's "
    "0.1566 +- 0.0008"))
def test_plate_dW1_near_2000_triangles_within_0_005_of_the_fem_at_one_half():
    fem, study = _study("fem", 0.5, 1 / 2), _study("plate", 0.5, 1 / 2)
    mesh = _mesh_near(study, 2000)
    assert abs(mesh.size - 2000) < 800 and mesh.dW1 is not None
    assert abs(mesh.dW1 - fem.dW1.value) <= 0.005, (mesh.label, mesh.dW1, fem.dW1.value)
