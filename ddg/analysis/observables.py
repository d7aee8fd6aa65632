"""Observables of a converged equilibrium, normalised as in the paper's figures.

H_mid / L: height (z) of the centerline point at s = L/2; F_shear_norm = F_y L / (E b^3)
with F the force the moving clamp applies to the strip (App. E: from the force balance at
the constrained DOFs); F_axial_norm = P L / (E b^3) with P the compressive clamp force;
lambda_min: lowest normalised eigenvalue of the free-DOF Hessian (see the model);
stretching_share: the stretching (membrane) part of the elastic energy over the whole, the
measure of membrane locking (a thin strip stores almost all its energy in bending).
"""
from __future__ import annotations


from ..solve.stability import lowest_modes
from ..solve.state import phase_label

PATH_COLUMNS = ("stage", "dL_over_L", "dW_over_L", "H_mid_over_L", "F_shear_norm", "energy", "lambda_min", "phase")
EXTRA_COLUMNS = ("F_axial_norm", "stable", "newton_iterations", "branch_switched", "max_turn_angle_deg",
                 "max_strain", "negative_eigenvalues", "stretching_share", "curvature_change_per_width")

#: Beyond this angle between neighbouring elements (edges of the rod, triangles of the plate) the
#: discretisation no longer resolves the shape (e.g. the conical singularities that form at the
#: clamps near dW_max); summary.json reports the last dW/L recorded below it.
RESOLVED_TURN_ANGLE_DEG = 30.0


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
        "stretching_share": stretching_share(ev),
    }


def stretching_share(evaluation) -> float:
    """Stretching energy over the elastic energy (0 in the unloaded state)."""
    energy = float(evaluation.energy)
    return float(evaluation.parts.get("stretching", 0.0)) / energy if energy > 0.0 else 0.0


def negative_eigenvalues(model, hessian) -> int | None:
    """The number of unstable directions of an equilibrium: negative eigenvalues of the free-DOF
    Hessian, 0 where its Cholesky succeeds, else the negative pivots of its LDL^T (Sylvester's law
    of inertia; ddg.solve.band_ldlt). None where a pivot is zero to rounding (a critical point)."""
    from ..solve.band_ldlt import UnreliablePivot

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
    strain above RESOLVED_STRAIN (how the turn relates to the thresholds' error on coarse rods:
    docs/findings/measured.md)."""
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
