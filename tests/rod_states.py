"""Test helper: generic deformed, twisted rod states for finite-difference checks (one copy for
the rod, ribbon and model-level derivative tests)."""
from __future__ import annotations

import numpy as np


def rod_dof_scale(model) -> np.ndarray:
    """Natural size of each DOF: the spacing h for positions, 1 rad for twist angles, the model's
    own unit for cross-section modes (1 / W for the transverse curvature)."""
    scale = np.full(model.n_dof, model.centerline.spacing)
    scale[model.theta_dofs] = 1.0
    fields = model.field_dofs
    if fields.size:
        scale[fields] = model.length_scale()[fields]
    return scale


def twisted_rod_state(model, seed: int) -> np.ndarray:
    """A generic 3-D twisted state reached from rest through 3-5 random perturbations, each
    committed: positions by std 0.085 h per coordinate (~0.15 h per step), twist angles by std
    0.3 rad, so tangents leave the plane, frames are transported along non-planar paths and the
    reference twist is non-zero; cross-section modes (if any) by std 0.3 of their unit, except on
    the clamped edges; q is committed on return."""
    rng = np.random.default_rng(seed)
    h = model.centerline.spacing
    q = model.reset()
    for _ in range(3 + seed % 3):
        dq = np.zeros(model.n_dof)
        dq[model.node_dofs] = 0.085 * h * rng.standard_normal((model.nodes, 3))
        dq[model.theta_dofs] = 0.3 * rng.standard_normal(model.nodes - 1)
        fields = model.field_dofs[1:-1]
        if fields.size:
            dq[fields] = 0.3 * rng.standard_normal(fields.shape) * model.length_scale()[fields]
        q = q + dq
        model.commit(q)
    return q


def compressed_state(follower, ratio: float = 0.5, steps: int = 20):
    """The follower's model compressed to dL/L = ratio in `steps` equal recorded steps, from the
    first buckled state (PathFollower.start_compression then advance): the converged State."""
    L = follower.model.strip.length
    state = follower.start_compression(ratio * L / steps)
    for k in range(2, steps + 1):
        state = follower.advance(state, ratio * L * k / steps, 0.0)
    return state
