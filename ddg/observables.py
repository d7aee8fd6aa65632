"""Observables of a converged equilibrium, normalised as in the paper's figures.

H_mid / L: height (z) of the centerline point at s = L/2; F_shear_norm = F_y L / (E b^3)
with F the force the moving clamp applies to the strip (App. E: from the force balance at
the constrained DOFs); F_axial_norm = P L / (E b^3) with P the compressive clamp force;
lambda_min: lowest normalised eigenvalue of the free-DOF Hessian (see the model).
"""
from __future__ import annotations


from .solve.stability import lowest_modes

PATH_COLUMNS = ("stage", "dL_over_L", "dW_over_L", "H_mid_over_L", "F_shear_norm", "energy", "lambda_min", "phase")
EXTRA_COLUMNS = ("F_axial_norm", "stable", "newton_iterations", "branch_switched", "max_turn_angle_deg",
                 "max_strain")

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
        "phase": "",
        "F_axial_norm": -float(force[0]) / strip.force_unit,
        "stable": bool(state.stable),
        "newton_iterations": int(state.iterations),
        "branch_switched": bool(state.branch_switched),
        **model.resolution_indicators(state.q),
    }


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
