"""Polynomial extrapolation of a branch of equilibria from its last solved points: the predictors
of load-controlled continuation (ddg.solve.continuation, in the load) and of pseudo-arclength
continuation (ddg.solve.arclength, in arclength).

Near a smooth branch the predictor's error falls as h^k for k points a step h apart, and Newton
from it needs about log2(log(error / tolerance)) iterations, so a higher order pays while the
polynomial stays well conditioned. Five points serve arclength (ARCLENGTH_PREDICTOR_POINTS) and
four the load path (LOAD_PREDICTOR_POINTS), the counts that took the fewest Newton iterations on
the rod's default path (docs/findings/measured.md).
"""
from __future__ import annotations

import numpy as np

#: Points of the load path's predictor (a cubic through the last four equilibria on the load line).
LOAD_PREDICTOR_POINTS = 4
#: Points of the arclength predictor (a quartic in arclength through the last five).
ARCLENGTH_PREDICTOR_POINTS = 5


def lagrange_weights(nodes, target: float) -> np.ndarray:
    """Weights w_i with p(target) = sum_i w_i y_i for the polynomial p through the points
    (nodes_i, y_i); the nodes must be distinct."""
    nodes = np.asarray(nodes, dtype=float)
    weights = np.ones(nodes.size)
    for i in range(nodes.size):
        for j in range(nodes.size):
            if j != i:
                weights[i] *= (target - nodes[j]) / (nodes[i] - nodes[j])
    return weights


def extrapolate(nodes, values, target: float):
    """The polynomial through (nodes_i, values_i) evaluated at target (values: arrays or floats)."""
    return sum(w * v for w, v in zip(lagrange_weights(nodes, target), values))
