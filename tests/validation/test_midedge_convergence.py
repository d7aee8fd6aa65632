"""The mid-edge convergence study's machinery (validation.midedge_convergence): the observed order
of three runs at any spacings, the graded mesh, the fixed list of runs."""
from __future__ import annotations

import numpy as np
import pytest

from ddg.geometry.plate_mesh import ghost_clamp_mesh
from validation.midedge_convergence import RUNS, graded, observed_order


@pytest.mark.parametrize("p", [0.7, 1.3, 2.0, 3.5])
def test_observed_order_recovers_the_power_of_an_exact_error_law(p):
    """v = a + C h^p on three unequally refined meshes gives back p; differences of both signs none."""
    h = np.array([1 / 8, 1 / 12, 1 / 28])
    assert observed_order(h, 0.27 + 0.4 * h**p) == pytest.approx(p, rel=1e-6)
    assert observed_order(h, [0.27, 0.26, 0.265]) is None


def test_graded_rows_are_finer_at_the_free_edges_and_keep_the_mesh():
    """g = 0.5 makes the edge row 0.65 of the uniform spacing on 8 rows (its limit on fine meshes is
    1 - g = 0.5) and the centre row wider; the centre line, the clamps and the areas' sum stay."""
    mesh = ghost_clamp_mesh(1.0, 1 / 6, rows=8)
    g = graded(mesh, 0.5)
    y = np.unique(np.round(g.nodes[g.nodes[:, 0] == 0.5, 1], 12))
    uniform = np.unique(np.round(mesh.nodes[mesh.nodes[:, 0] == 0.5, 1], 12))
    h = uniform[1] - uniform[0]
    assert y[1] - y[0] < 0.66 * h and y[len(y) // 2 + 1] - y[len(y) // 2] > 1.2 * h
    assert 0.0 in y and np.array_equal(g.nodes[:, 0], mesh.nodes[:, 0])
    assert g.triangle_areas.min() > 0 and g.triangle_areas.sum() == pytest.approx(mesh.triangle_areas.sum())
    assert np.array_equal(g.clamped_left, mesh.clamped_left)


def test_the_runs_have_distinct_names():
    names = [r.name for r in RUNS]
    assert len(set(names)) == len(names)
