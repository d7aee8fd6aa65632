"""Discrete centerline of the strip and the rod's clamp convention.

M nodes x_0 .. x_{M-1}, M-1 edges of equal rest length h = L / (M - 2). The first and
last edges are the clamped ones and *straddle* the clamp points: the clamp at s = 0 is the
midpoint of edge 0 and the clamp at s = L the midpoint of edge M-2. Edge tangents then
sample the centerline at s = 0, h, ..., L exactly (edge e at s = e h), the curvature at node
i sits at s = (i - 1/2) h between them, and the free length between the clamp points is
exactly L. (Counting the rigid edges inside L instead shortens the free rod by 2h and
biases H_mid by O(h), docs/physics/conventions.md; with the straddling convention the error of
the clamped elastica falls as O(h^2).) The rest configuration lies along +x with the clamp
at s = 0 at the origin; nodes sit at x = (i - 1/2) h.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..limits import InputError

MIN_NODES = 7


@dataclass(frozen=True)
class Centerline:
    length: float
    nodes: int

    def __post_init__(self) -> None:
        if not isinstance(self.nodes, (int, np.integer)) or isinstance(self.nodes, bool):
            raise InputError(f"resolution M = {self.nodes!r} is not an integer node count; allowed: an integer >= "
                             f"{MIN_NODES}")
        if self.nodes < MIN_NODES:
            raise InputError(f"resolution M = {self.nodes!r} nodes is too small; allowed: an integer >= {MIN_NODES}")

    @property
    def spacing(self) -> float:
        return self.length / (self.nodes - 2)

    @property
    def edges(self) -> int:
        return self.nodes - 1

    @property
    def node_arclength(self) -> np.ndarray:
        """Rest arclength of each node measured from the clamp point at s = 0."""
        return (np.arange(self.nodes) - 0.5) * self.spacing

    @property
    def edge_arclength(self) -> np.ndarray:
        """Rest arclength of each edge midpoint (s = 0 and s = L for the clamped edges)."""
        return np.arange(self.edges) * self.spacing

    def rest_positions(self) -> np.ndarray:
        x = np.zeros((self.nodes, 3))
        x[:, 0] = self.node_arclength
        return x

    def interpolate_at(self, values: np.ndarray, s: float) -> np.ndarray:
        """Linear interpolation of nodal values (nodes, k) at rest arclength s (exact to O(h^2))."""
        sn = self.node_arclength
        j = int(np.clip(np.searchsorted(sn, s) - 1, 0, self.nodes - 2))
        w = (s - sn[j]) / self.spacing
        return (1.0 - w) * values[j] + w * values[j + 1]


def first_mode_profile(length: float, compression: float, s: np.ndarray, direction: int = 1, samples: int = 4001):
    """Inextensible first-mode shape with chord L - dL: (x(s), z(s)) at rest arclengths s in [0, L].

    Tangent angle phi(s) = phi0 sin(2 pi s / L); the chord is L J0(phi0), so phi0 solves
    J0(phi0) = 1 - dL / L. Used as the plate's starting guess for compression (the rod uses the
    discrete version of the same shape, RodModel.buckled_guess).
    """
    from scipy.optimize import brentq
    from scipy.special import j0

    ratio = compression / length
    if not 0.0 <= ratio < 1.0:
        raise InputError(f"compression dL/L = {ratio:g} outside the allowed range [0, 1)")
    phi0 = brentq(lambda p: j0(p) - (1.0 - ratio), 0.0, 2.404825557695773) if ratio > 0 else 0.0
    grid = np.linspace(0.0, length, samples)
    phi = direction * phi0 * np.sin(2.0 * np.pi * grid / length)
    step = grid[1] - grid[0]
    x = np.r_[0.0, np.cumsum(0.5 * step * (np.cos(phi[1:]) + np.cos(phi[:-1])))]
    z = np.r_[0.0, np.cumsum(0.5 * step * (np.sin(phi[1:]) + np.sin(phi[:-1])))]
    s = np.asarray(s, dtype=float)
    return np.interp(s, grid, x), np.interp(s, grid, z)
