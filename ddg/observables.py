"""Observables of a converged equilibrium, normalised as in the paper's figures.

H_mid / L: height (z) of the centerline point at s = L/2; F_shear_norm = F_y L / (E b^3)
with F the force the moving clamp applies to the strip (App. E: from the force balance at
the constrained DOFs); F_axial_norm = P L / (E b^3) with P the compressive clamp force;
lambda_min: lowest normalised eigenvalue of the free-DOF Hessian (see the model).
"""
from __future__ import annotations


import numpy as np

from .solve.stability import lowest_modes

PATH_COLUMNS = ("stage", "dL_over_L", "dW_over_L", "H_mid_over_L", "F_shear_norm", "energy", "lambda_min", "phase")
EXTRA_COLUMNS = ("F_axial_norm", "stable", "newton_iterations", "branch_switched", "max_turn_angle_deg",
                 "max_strain", "negative_eigenvalues")

#: Beyond this angle between neighbouring elements (edges of the rod, triangles of the plate) the
#: discretisation no longer resolves the shape (e.g. the conical singularities that form at the
#: clamps near dW_max); summary.json reports the last dW/L recorded below it.
RESOLVED_TURN_ANGLE_DEG = 30.0


#: Largest deviation from a symmetry, relative to L, for a shape to count as having it. The
#: solver's equilibria are symmetric to ~1e-9 L; just past the pitchfork the asymmetric part of
#: US grows as sqrt(dW - dW1), above this within 1e-6 L of dW1 (the thresholds themselves come
#: from stability, ddg.solve.thresholds, not from these labels).
SYMMETRY_TOLERANCE = 1e-4


def symmetry_defects(model, q: np.ndarray, compression: float, shear: float) -> tuple[float, float]:
    """Deviations (relative to L) of the deformed strip from the two symmetries of the scene.

    With c the midpoint between the clamp points, the material point (s, w) is paired with
    (L - s, -w) (model.symmetry_partners). U is invariant under the half turn about the vertical
    axis through c (r -> R_z(pi) (r - c) + c: mirror symmetry of the U about its mid-plane); S
    under the point reflection through c (r -> 2 c - r, which puts the midpoint at H = 0); US
    under neither (section 4 of the paper).
    """
    L = model.strip.length
    x = model.positions(q)
    nodes, partners = model.symmetry_partners()
    c = np.array([0.5 * (L - compression), 0.5 * shear, 0.0])
    a, b = x[nodes], x[partners]
    half_turn = np.stack([2 * c[0] - b[:, 0], 2 * c[1] - b[:, 1], b[:, 2]], axis=1)
    point = 2 * c - b
    return (float(np.max(np.linalg.norm(a - half_turn, axis=1))) / L,
            float(np.max(np.linalg.norm(a - point, axis=1))) / L)


def phase_label(model, q: np.ndarray, compression: float, shear: float) -> str:
    """U, US+, US-, S+ or S- from the symmetries of the shape; '' before buckling (flat strip).

    The sign says which side rises: + when the highest point of the centerline lies in its first
    half (s < L/2). (Comparing fixed stations such as s = L/4 and 3L/4 fails on S near dW_max,
    where the lobes move towards the clamps.)"""
    L = model.strip.length
    mirror, point = symmetry_defects(model, q, compression, shear)
    z = model.centerline_positions(q, 101)[0][:, 2]
    rise = float(np.max(z[:50]) - np.max(z[51:]))
    if compression == 0.0 and abs(float(model.midpoint(q)[2])) < SYMMETRY_TOLERANCE * L:
        return ""
    if mirror < SYMMETRY_TOLERANCE:
        return "U"
    sign = "+" if rise >= 0.0 else "-"
    return ("S" if point < SYMMETRY_TOLERANCE else "US") + sign


def observe(model, state, stage: str, eigenvalues: bool = True) -> dict:
    strip = model.strip
    L = strip.length
    ev = state.evaluation
    force = model.clamp_force(ev.gradient)
    lam = float(lowest_modes(model, ev.hessian, 1)[0]) if eigenvalues else float("nan")
    return {
        "stage": stage,
        "dL_over_L": state.compression / L,
        "dW_over_L": state.shear / L,
        "H_mid_over_L": float(model.midpoint(state.q)[2]) / L,
        "F_shear_norm": float(force[1]) / strip.force_unit,
        "energy": float(ev.energy),
        "lambda_min": lam,
        "phase": phase_label(model, state.q, state.compression, state.shear),
        "F_axial_norm": -float(force[0]) / strip.force_unit,
        "stable": bool(state.stable),
        "newton_iterations": int(state.iterations),
        "branch_switched": bool(state.branch_switched),
        **model.resolution_indicators(state.q),
        "negative_eigenvalues": negative_eigenvalues(model, ev.hessian),
    }


def negative_eigenvalues(model, hessian) -> int | None:
    """The number of unstable directions of an equilibrium: negative eigenvalues of the free-DOF
    Hessian, 0 where its Cholesky succeeds, else the negative pivots of its LDL^T (Sylvester's law
    of inertia; ddg.solve.band_ldlt). None where a pivot is zero to rounding (a critical point)."""
    from .solve.band_ldlt import UnreliablePivot

    try:
        return int(model.free_matrix(hessian).inertia()[0])
    except UnreliablePivot:
        return None


#: Largest stretching strain of a resolved state: the strips are inextensible to ~1e-4 (bending
#: strains b kappa / 2 ~ 1e-3); a membrane strain of 2 % means the discretisation (too few
#: elements for the shape) or the loading (near the shear limit) forces stretching the
#: continuum would not need, and is beyond the small-strain elasticity the energies assume.
RESOLVED_STRAIN = 0.02


def unresolved_reason(rows: list[dict], shear_ratio: float) -> str | None:
    """Why the recorded states up to |dW/L| = shear_ratio (the compression and the first shear
    state past it included) are not resolved by the discretisation, or None if they are: the
    largest turn between neighbouring elements above RESOLVED_TURN_ANGLE_DEG, or the largest
    strain above RESOLVED_STRAIN. Measured on the rod (dL/L = 1/2): turns up to dW1 of 96, 60,
    43, 30 and 20 degrees at M = 7, 10, 14, 20 and 30, with dW1/L errors 0.055, 0.003, 0.007,
    0.004, 0.002 against M = 100."""
    past = False
    worst_turn = worst_strain = None
    for row in rows:
        if row["stage"] == "shear" and abs(row["dW_over_L"]) > shear_ratio:
            if past:
                break
            past = True
        if worst_turn is None or row.get("max_turn_angle_deg", 0.0) > worst_turn.get("max_turn_angle_deg", 0.0):
            worst_turn = row
        if worst_strain is None or row.get("max_strain", 0.0) > worst_strain.get("max_strain", 0.0):
            worst_strain = row
    if worst_turn is None:
        return None

    def where(row):
        return f"dL/L = {row['dL_over_L']:.4g}, dW/L = {abs(row['dW_over_L']):.4g}"

    turn, strain = worst_turn.get("max_turn_angle_deg", 0.0), worst_strain.get("max_strain", 0.0)
    if turn > RESOLVED_TURN_ANGLE_DEG:
        return (f"neighbouring elements turn by up to {turn:.0f} degrees (at {where(worst_turn)}; resolved up to "
                f"{RESOLVED_TURN_ANGLE_DEG:g}); refine the resolution")
    if strain > RESOLVED_STRAIN:
        return (f"the strain reaches {strain:.3g} (at {where(worst_strain)}; resolved up to {RESOLVED_STRAIN:g}); "
                "refine the resolution")
    return None


def resolved_up_to(rows: list[dict]):
    """Last dW/L of the shear stage before the largest angle between neighbouring elements first
    exceeds RESOLVED_TURN_ANGLE_DEG (None if no shear step was recorded below it)."""
    last = None
    for row in rows:
        if row["stage"] != "shear":
            continue
        if row.get("max_turn_angle_deg", 0.0) > RESOLVED_TURN_ANGLE_DEG:
            break
        last = row["dW_over_L"]
    return last
