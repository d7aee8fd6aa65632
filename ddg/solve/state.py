"""An equilibrium of the loading path and the symmetry measures that name its phase.

Shared by every solver module (continuation, arclength, thresholds, branches) and by the
post-processing above them; it imports nothing of ddg but numpy, so it sits below them all.

The scene is invariant under the half turn about the vertical axis through the midpoint c
between the clamp points; U keeps that symmetry, S the point reflection through c, US neither
(paper section 4).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

#: Largest deviation from a symmetry, relative to L, for a shape to count as having it. The
#: solver's equilibria are symmetric to ~1e-9 L; just past the pitchfork the asymmetric part of
#: US grows as sqrt(dW - dW1), above this within 1e-6 L of dW1 (the thresholds themselves come
#: from stability, ddg.solve.thresholds, not from these labels).
SYMMETRY_TOLERANCE = 1e-4


@dataclass
class State:
    """A converged equilibrium at the clamp displacement (compression dL, shear dW), in m."""
    q: np.ndarray
    evaluation: object
    compression: float
    shear: float
    stable: bool
    iterations: int = 0
    branch_switched: bool = False
    frames: object = None  # the model's reference frames at this state (rod), where kept
    #: where the path reached this state by a snap past a fold (PathFollower.advance): the Snapshot
    #: of the last state before it, on the branch that folds, within a hard substep of the fold
    snapped_from: object = None


@dataclass
class Snapshot:
    """A recorded equilibrium with the model's frame state, to restart continuation from."""
    state: State
    frames: object

    @classmethod
    def take(cls, model, state: State) -> "Snapshot":
        return cls(state, model.save_frames())


def symmetry_defects(model, q: np.ndarray, compression: float, shear: float) -> tuple[float, float]:
    """Deviations (relative to L) of the deformed strip from the two symmetries of the scene.

    With c the midpoint between the clamp points, the material point (s, w) is paired with
    (L - s, -w) (model.symmetry_partners). U is invariant under the half turn about the vertical
    axis through c (r -> R_z(pi) (r - c) + c: mirror symmetry of the U about its mid-plane); S
    under the point reflection through c (r -> 2 c - r, which puts the midpoint at H = 0); US
    under neither (section 4 of the paper).
    """
    L = model.strip.length
    a, b, c = _partners(model, q, compression, shear)
    point = 2 * c - b
    return (float(np.max(np.linalg.norm(a - _half_turn(b, c), axis=1))) / L,
            float(np.max(np.linalg.norm(a - point, axis=1))) / L)


def _partners(model, q, compression, shear):
    x = model.positions(q)
    nodes, partners = model.symmetry_partners()
    c = np.array([0.5 * (model.strip.length - compression), 0.5 * shear, 0.0])
    return x[nodes], x[partners], c


def _half_turn(b: np.ndarray, c: np.ndarray) -> np.ndarray:
    return np.stack([2 * c[0] - b[:, 0], 2 * c[1] - b[:, 1], b[:, 2]], axis=1)


def half_turn_odd_part(model, q: np.ndarray, compression: float, shear: float) -> np.ndarray:
    """The part of the shape that the half turn reverses (relative to L): (x(p) - R x(p')) / 2 over
    the symmetry partners p, p' (flattened). Zero on U; the half turn maps US+ to US- and S+ to S-,
    and flips this vector: its orientation relative to a neighbouring state's names the branch
    (BranchOrientation)."""
    a, b, c = _partners(model, q, compression, shear)
    return (0.5 * (a - _half_turn(b, c)) / model.strip.length).ravel()


class BranchOrientation:
    """The + / - of US and S kept along a continuous path (the sign of rise() alone turns S+ into
    S- near dW_max, where the lobes of S flatten and the out-of-plane profile reverses
    continuously while the path is one smooth branch: docs/findings/measured.md). The first
    asymmetric state after U (or after the start) takes the sign of phase_label (rise()); every
    later one keeps its predecessor's sign if their half-turn-odd parts (half_turn_odd_part) point
    the same way (positive inner product), else the opposite one: a label changes only where the
    shape jumps to the mirror branch. Back on U (or flat) the memory is cleared."""

    def __init__(self):
        self._last: tuple[str, np.ndarray] | None = None

    def label(self, phase: str, odd_part: Callable[[], np.ndarray]) -> str:
        """The oriented label of a state whose phase_label is `phase`; odd_part() is called only
        for US and S."""
        base = phase.rstrip("+-")
        if base in ("", "U"):
            self._last = None
            return phase
        odd = np.asarray(odd_part(), dtype=float)
        if self._last is None:
            sign = phase[-1]
        else:
            previous, before = self._last
            same = float(np.dot(odd, before)) >= 0.0
            sign = previous if same else ("-" if previous == "+" else "+")
        self._last = (sign, odd)
        return base + sign


def rise(model, q: np.ndarray) -> float:
    """Height of the highest point of the first half of the centerline minus that of the second
    (m): zero on U and S, of the branch's sign on US+ / US-."""
    z = model.centerline_positions(q, 101)[0][:, 2]
    return float(np.max(z[:50]) - np.max(z[51:]))


def phase_label(model, q: np.ndarray, compression: float, shear: float) -> str:
    """U, US+, US-, S+ or S- from the symmetries of the shape; '' before buckling (flat strip).

    The sign says which side rises: + when the highest point of the centerline lies in its first
    half (s < L/2). (Comparing fixed stations such as s = L/4 and 3L/4 fails on S near dW_max,
    where the lobes move towards the clamps.)"""
    L = model.strip.length
    mirror, point = symmetry_defects(model, q, compression, shear)
    flat = compression == 0.0 and abs(float(model.midpoint(q)[2])) < SYMMETRY_TOLERANCE * L
    return phase_from_measures(mirror, point, lambda: rise(model, q), flat)


def phase_from_measures(half_turn_defect: float, point_defect: float, rise_of: Callable[[], float],
                        flat: bool) -> str:
    """The phase rule from its measures, for every model (each computes the measures on its own
    discretisation; the FEM shell from its symmetric mesh): '' for the flat strip, U if the
    half-turn defect is below SYMMETRY_TOLERANCE, else S if the point-reflection defect is, US
    otherwise; + when rise_of() (called only then) >= 0."""
    if flat:
        return ""
    if half_turn_defect < SYMMETRY_TOLERANCE:
        return "U"
    sign = "+" if rise_of() >= 0.0 else "-"
    return ("S" if point_defect < SYMMETRY_TOLERANCE else "US") + sign


def phase_of(model, state: State) -> str:
    """phase_label of a State."""
    return phase_label(model, state.q, state.compression, state.shear)


def asymmetry(model, state: State) -> float:
    """rise() of a State: zero on U and S, of the branch's sign on US+ / US-."""
    return rise(model, state.q)


def crosses(measure, seed: State, phase: str, model):
    """Stop condition for a branch tracer: the state has `phase` (U or S: the junction, kept), or
    `measure` changed sign from the seed's (the tracer went through the junction onto the mirror
    branch: dropped)."""
    reference = measure(seed)

    def stop(state: State):
        if phase_of(model, state).rstrip("+-") == phase:
            return True
        return "drop" if measure(state) * reference < 0 else False

    return stop
