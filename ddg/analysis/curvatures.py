"""Centerline curvatures along the arclength for the rod, the ribbon and the plate (Figs. A.12-A.14).

For a framed centerline (nodes x_k, material directors m1 (the strip normal) and m2 = t x m1 per
edge) the curvatures at interior nodes are those of the rod (Eqs. 3-5): the out-of-plane
bending kappa^(2) = kb . (m2^{k-1} + m2^k)/2, the geodesic kappa^(1) = -kb . (m1^{k-1} + m1^k)/2,
and the twist tau, the angle about t^k from the parallel transport of m1^{k-1} onto edge k to
m1^k. They are integrated (dimensionless); divided by the Voronoi length they are curvatures,
reported times L as in the paper's figures.

- rod and ribbon: their own material frames and discrete twist (Eq. 5);
- plate: the material line w = 0 sampled at `stations` points, m1 the surface normal at each
  edge midpoint (s, 0) from the vertex normals, projected normal to t (section 4.3, App. F).
"""
from __future__ import annotations

import numpy as np

from ..energies.hinge_bending import triangle_normals
from ..energies.rod_curvature import material_curvatures
from ..geometry.frames import cross, reference_twist, rowdot, unit
from ..limits import InputError
from .rod_strains import rod_curvatures  # noqa: F401  (re-exported: the rod's profile)

CURVATURE_COLUMNS = ("model", "step", "dL_over_L", "dW_over_L", "s_over_L", "k1_L", "k2_L", "tau_L")


def framed_curve_curvatures(x: np.ndarray, m1: np.ndarray):
    """Integrated (kappa^(1), kappa^(2), tau) at the interior nodes of a polyline x (n, 3) whose
    edges carry unit normals m1 (n - 1, 3) perpendicular to them (Eqs. 3-5 with theta = 0)."""
    t = unit(x[1:] - x[:-1])
    m2 = cross(t, m1)
    kappa_n, kappa_g = material_curvatures(x, m1, m2)
    return kappa_g, kappa_n, reference_twist(m1, t)


def plate_vertex_normals(model, q: np.ndarray) -> np.ndarray:
    """Unit normals (N, 3) at the plate's nodes: area-weighted means of the deformed normals of
    the triangles around each node, oriented as the rest normal +z."""
    mesh = model.mesh
    normals, double_area = triangle_normals(model.positions(q), mesh.triangles)
    rest = mesh.nodes[mesh.triangles]
    rest_z = ((rest[:, 1, 0] - rest[:, 0, 0]) * (rest[:, 2, 1] - rest[:, 0, 1])
              - (rest[:, 1, 1] - rest[:, 0, 1]) * (rest[:, 2, 0] - rest[:, 0, 0]))
    weighted = (np.sign(rest_z) * double_area)[:, None] * normals
    summed = np.zeros((mesh.node_count, 3))
    for corner in range(3):
        np.add.at(summed, mesh.triangles[:, corner], weighted)
    return unit(summed)


def plate_centerline_frame(model, q: np.ndarray, stations):
    """Points x (K, 3) of the plate's line w = 0 at K stations (a count, spread over s = 0..L, or
    the rest arclengths s in metres) and, per edge between them, m1: the surface normal at the
    edge midpoint (s, 0), interpolated linearly from the vertex normals (a continuous normal
    field; the normal of the one triangle holding the point would put all the twist on the
    hinges the line crosses), made normal to the edge. Returns x, m1, s / L."""
    L = model.strip.length
    s = np.linspace(0.0, L, stations) if np.ndim(stations) == 0 else np.asarray(stations, dtype=float)
    x = plate_points(model, q, s, np.zeros_like(s))
    mid = 0.5 * (s[1:] + s[:-1])
    nodes, weights = model.mesh.interpolation_matrix(np.stack([mid, np.zeros_like(mid)], axis=1))
    normals = np.einsum("qk,qkc->qc", weights, plate_vertex_normals(model, q)[nodes])
    t = unit(x[1:] - x[:-1])
    m1 = unit(normals - rowdot(normals, t)[:, None] * t)
    return x, m1, s / L


def plate_points(model, q, s, y):
    """Deformed positions of the material points with rest coordinates (s, y)."""
    nodes, weights = model.mesh.interpolation_matrix(np.stack([s, y], axis=1))
    return np.einsum("qk,qkc->qc", weights, model.positions(q)[nodes])


def default_plate_stations(model) -> int:
    """About one station per two columns of triangles: the line w = 0 interpolated through a
    structured mesh kinks where it crosses alternate columns, which a station per column turns
    into a zigzag of kappa^(2) (docs/findings/measured.md); two columns smooth it."""
    side = np.sqrt(4.0 * np.mean(model.mesh.triangle_areas) / np.sqrt(3.0))
    return max(11, int(round(0.5 * model.strip.length / (0.5 * np.sqrt(3.0) * side))) + 1)


def plate_curvatures(model, q: np.ndarray, stations: int | None = None) -> dict:
    """Curvatures of the plate's centerline (w = 0) at q, as rod_curvatures."""
    stations = default_plate_stations(model) if stations is None else stations
    if not (isinstance(stations, (int, np.integer)) and stations >= 5):
        raise InputError(f"stations = {stations!r} must be an integer >= 5")
    x, m1, s = plate_centerline_frame(model, q, stations)
    k1, k2, tau = framed_curve_curvatures(x, m1)
    ds = (s[1] - s[0])
    return {"s_over_L": s[1:-1], "k1_L": k1 / ds, "k2_L": k2 / ds, "tau_L": tau / ds}


def centerline_curvatures(model, q: np.ndarray, stations: int | None = None) -> dict:
    """k1 L, k2 L, tau L along s/L for any model (rod, ribbon, plate)."""
    if hasattr(model, "mesh"):
        return plate_curvatures(model, q, stations)
    return rod_curvatures(model, q)


def inflection_jumps(profile: dict, window: int = 6) -> list[dict]:
    """At each sign change of k2 (an inflection point, away from the clamps): the jumps of k2 and
    tau across it, relative to the typical step of each between neighbouring nodes nearby
    (median over `window` steps either side). A smooth profile gives ratios ~1; a jump, >> 1."""
    k2, tau, s = profile["k2_L"], profile["tau_L"], profile["s_over_L"]
    out = []
    sign_changes = np.flatnonzero(np.sign(k2[1:]) * np.sign(k2[:-1]) < 0)
    for i in sign_changes:
        if s[i] < 0.1 or s[i] > 0.9:
            continue
        lo, hi = max(0, i - window), min(len(k2) - 1, i + window + 1)
        steps = np.r_[lo:i, i + 1:hi]
        d_k2, d_tau = np.abs(np.diff(k2)), np.abs(np.diff(tau))
        ratio = lambda d: float(d[i] / np.median(d[steps])) if np.median(d[steps]) > 0 else float("nan")  # noqa: E731
        out.append({"s_over_L": float(0.5 * (s[i] + s[i + 1])),
                    "k2_jump_ratio": ratio(d_k2), "tau_jump_ratio": ratio(d_tau),
                    "tau_at_inflection_L": float(0.5 * (tau[i] + tau[i + 1])),
                    "k2_jump_L": float(k2[i + 1] - k2[i]), "tau_jump_L": float(tau[i + 1] - tau[i])})
    return out
