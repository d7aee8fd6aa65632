"""Adapted frames of a discrete centerline: parallel transport and reference twist.

Conventions (Bergou et al. 2010; paper section 3.1). Each edge carries a reference frame
{d1, d2, t} with d2 = t x d1, and a material frame {m1, m2, t} rotated from it by the twist
angle theta: m1 = cos(theta) d1 + sin(theta) d2, m2 = t x m1. m1 is the strip's surface
normal. Reference frames are carried from one configuration to the next by parallel
transport in time (the minimal rotation taking the old tangent to the new one); the
reference twist m_ref at an interior node is the signed angle, about t^i, from the
space-parallel transport of d1^{i-1} onto edge i to d1^i (Eq. 5).

The row-wise work is compiled (numba): `rod_frames` computes every frame of a rod state in one
pass, and the array functions below call the same per-row routines.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit


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


# ---------------------------------------------------------------------------- compiled rows
@njit(cache=True, forceinline=True)
def _transport_row(v, t_from, t_to, out):
    """out = P v, the minimal rotation taking unit t_from to unit t_to applied to v:
    P v = c v + b x v + (b . v) / (1 + c) b, b = t_from x t_to, c = t_from . t_to."""
    b0 = t_from[1] * t_to[2] - t_from[2] * t_to[1]
    b1 = t_from[2] * t_to[0] - t_from[0] * t_to[2]
    b2 = t_from[0] * t_to[1] - t_from[1] * t_to[0]
    c = t_from[0] * t_to[0] + t_from[1] * t_to[1] + t_from[2] * t_to[2]
    bv = (b0 * v[0] + b1 * v[1] + b2 * v[2]) / (1.0 + c)
    out[0] = c * v[0] + (b1 * v[2] - b2 * v[1]) + bv * b0
    out[1] = c * v[1] + (b2 * v[0] - b0 * v[2]) + bv * b1
    out[2] = c * v[2] + (b0 * v[1] - b1 * v[0]) + bv * b2


@njit(cache=True, forceinline=True)
def _signed_angle(transported, d1, t):
    """Angle about t from `transported` to d1 (both normal to t)."""
    cx = transported[1] * d1[2] - transported[2] * d1[1]
    cy = transported[2] * d1[0] - transported[0] * d1[2]
    cz = transported[0] * d1[1] - transported[1] * d1[0]
    return math.atan2(cx * t[0] + cy * t[1] + cz * t[2],
                      transported[0] * d1[0] + transported[1] * d1[1] + transported[2] * d1[2])


@njit(cache=True, forceinline=True)
def _unwrap(angle, previous):
    """angle + 2 pi k within pi of previous."""
    shifted = angle - previous + math.pi
    return previous + shifted - 2.0 * math.pi * math.floor(shifted / (2.0 * math.pi)) - math.pi


@njit(cache=True)
def _transport_rows(vectors, t_from, t_to):
    out = np.empty_like(vectors)
    for i in range(vectors.shape[0]):
        _transport_row(vectors[i], t_from[i], t_to[i], out[i])
    return out


@njit(cache=True)
def _reference_twist_rows(d1, tangents, previous, unwrap):
    n = d1.shape[0] - 1
    out = np.empty(n)
    moved = np.empty(3)
    for i in range(n):
        _transport_row(d1[i], tangents[i], tangents[i + 1], moved)
        angle = _signed_angle(moved, d1[i + 1], tangents[i + 1])
        out[i] = _unwrap(angle, previous[i]) if unwrap else angle
    return out


@njit(cache=True)
def rod_frames(x, old_tangents, old_d1, theta, old_ref_twist):
    """All frames of a rod state x (M, 3) with twist angles theta (M - 1,), reference frames
    transported in time from the committed (old_tangents, old_d1, old_ref_twist):
    returns tangents, d1, m1, m2 (M - 1, 3) and m_ref (M - 2,) (Eq. 5, unwrapped)."""
    edges = x.shape[0] - 1
    t = np.empty((edges, 3))
    d1 = np.empty((edges, 3))
    m1 = np.empty((edges, 3))
    m2 = np.empty((edges, 3))
    for i in range(edges):
        e0 = x[i + 1, 0] - x[i, 0]
        e1 = x[i + 1, 1] - x[i, 1]
        e2 = x[i + 1, 2] - x[i, 2]
        inv = 1.0 / math.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
        t[i, 0], t[i, 1], t[i, 2] = e0 * inv, e1 * inv, e2 * inv
        _transport_row(old_d1[i], old_tangents[i], t[i], d1[i])
        # d2 = t x d1; m1 = cos d1 + sin d2; m2 = -sin d1 + cos d2
        a0 = t[i, 1] * d1[i, 2] - t[i, 2] * d1[i, 1]
        a1 = t[i, 2] * d1[i, 0] - t[i, 0] * d1[i, 2]
        a2 = t[i, 0] * d1[i, 1] - t[i, 1] * d1[i, 0]
        c, s = math.cos(theta[i]), math.sin(theta[i])
        m1[i, 0], m1[i, 1], m1[i, 2] = c * d1[i, 0] + s * a0, c * d1[i, 1] + s * a1, c * d1[i, 2] + s * a2
        m2[i, 0], m2[i, 1], m2[i, 2] = -s * d1[i, 0] + c * a0, -s * d1[i, 1] + c * a1, -s * d1[i, 2] + c * a2
    m_ref = _reference_twist_rows(d1, t, old_ref_twist, True)
    return t, d1, m1, m2, m_ref


# ---------------------------------------------------------------------------- array interface
def parallel_transport(vectors: np.ndarray, t_from: np.ndarray, t_to: np.ndarray) -> np.ndarray:
    """Transport `vectors` by the minimal rotation taking unit t_from to unit t_to (row-wise, (n, 3)).

    P v = c v + b x v + (b . v) / (1 + c) b with b = t_from x t_to, c = t_from . t_to;
    undefined for antiparallel tangents (c = -1), which a converging Newton step never makes.
    """
    v, a, b = (np.ascontiguousarray(np.broadcast_to(z, np.broadcast_shapes(vectors.shape, t_from.shape, t_to.shape)),
                                    dtype=float).reshape(-1, 3) for z in (vectors, t_from, t_to))
    shape = np.broadcast_shapes(vectors.shape, t_from.shape, t_to.shape)
    return _transport_rows(v, a, b).reshape(shape)


def material_frame(d1: np.ndarray, tangents: np.ndarray, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(m1, m2) from the reference director d1, tangents and twist angles theta."""
    d2 = cross(tangents, d1)
    c = np.cos(theta)[:, None]
    s = np.sin(theta)[:, None]
    return c * d1 + s * d2, -s * d1 + c * d2


def reference_twist(d1: np.ndarray, tangents: np.ndarray, previous: np.ndarray | None = None) -> np.ndarray:
    """Reference twist m_ref at the interior nodes (Eq. 5), unwrapped to lie within pi of `previous`."""
    d1 = np.ascontiguousarray(d1, dtype=float)
    tangents = np.ascontiguousarray(tangents, dtype=float)
    unwrap = previous is not None
    prev = np.ascontiguousarray(previous, dtype=float) if unwrap else np.zeros(len(d1) - 1)
    return _reference_twist_rows(d1, tangents, prev, unwrap)
