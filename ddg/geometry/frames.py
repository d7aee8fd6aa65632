"""Adapted frames of a discrete centerline: parallel transport and reference twist.

Conventions (Bergou et al. 2010; paper section 3.1). Each edge carries a reference frame
{d1, d2, t} with d2 = t x d1, and a material frame {m1, m2, t} rotated from it by the twist
angle theta: m1 = cos(theta) d1 + sin(theta) d2, m2 = t x m1. m1 is the strip's surface
normal. Reference frames are carried from one configuration to the next by parallel
transport in time (the minimal rotation taking the old tangent to the new one); the
reference twist m_ref at an interior node is the signed angle, about t^i, from the
space-parallel transport of d1^{i-1} onto edge i to d1^i (Eq. 5).
"""
from __future__ import annotations

import numpy as np


def rowdot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.einsum("...i,...i->...", a, b)


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise cross product (faster than np.cross for (n, 3) arrays)."""
    out = np.empty(a.shape if a.shape == b.shape else np.broadcast_shapes(a.shape, b.shape))
    out[..., 0] = a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1]
    out[..., 1] = a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2]
    out[..., 2] = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    return out


def unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def parallel_transport(vectors: np.ndarray, t_from: np.ndarray, t_to: np.ndarray) -> np.ndarray:
    """Transport `vectors` by the minimal rotation taking unit t_from to unit t_to (row-wise).

    P v = c v + b x v + (b . v) / (1 + c) b with b = t_from x t_to, c = t_from . t_to;
    undefined for antiparallel tangents (c = -1), which a converging Newton step never makes.
    """
    b = cross(t_from, t_to)
    c = rowdot(t_from, t_to)
    return (
        c[..., None] * vectors
        + cross(b, vectors)
        + (rowdot(b, vectors) / (1.0 + c))[..., None] * b
    )


def material_frame(d1: np.ndarray, tangents: np.ndarray, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(m1, m2) from the reference director d1, tangents and twist angles theta."""
    d2 = cross(tangents, d1)
    c = np.cos(theta)[:, None]
    s = np.sin(theta)[:, None]
    m1 = c * d1 + s * d2
    m2 = -s * d1 + c * d2
    return m1, m2


def reference_twist(d1: np.ndarray, tangents: np.ndarray, previous: np.ndarray | None = None) -> np.ndarray:
    """Reference twist m_ref at the interior nodes (Eq. 5), unwrapped to lie within pi of `previous`."""
    transported = parallel_transport(d1[:-1], tangents[:-1], tangents[1:])
    t = tangents[1:]
    angle = np.arctan2(rowdot(cross(transported, d1[1:]), t), rowdot(transported, d1[1:]))
    if previous is not None:
        angle = previous + np.remainder(angle - previous + np.pi, 2.0 * np.pi) - np.pi
    return angle
