"""How well the plate is described by its centerline (paper section 4.3, Figs. 9-10; App. F, Fig. F.19).

Centerline approximation, Eq. (12): the plate node at rest coordinates (s_k, w) is placed at
x^c = x^p_k + w (m2^k + m2^{k-1}) / 2, with x^p_k the deformed point (s_k, 0) of the plate's
material line w = 0 and m2 = t x m1 of the edges on either side (m1: the plate's surface normal,
ddg.analysis.curvatures.plate_centerline_frame). Its error field is delta(s, w) = |x^c - x^p| / L, Eq. (13),
and the mean error the average of delta over all plate nodes (Fig. 10).

w is measured along m2 at rest: with m1 = +z and t = +x, m2 = t x m1 = -y, so w = -y in the
mesh's rest coordinates. Stations s_k are the columns of the mesh (the distinct rest x of its
nodes) when the nodes stand in columns (structured meshes), else a uniform grid, with x^p and the
averaged m2 interpolated linearly in s between stations.

Edge reconstructions (App. F): rod-based x_edge = x_center + W/2 m2 (F.1); ribbon-based
x_edge = x_center + W/2 (eta t + m2) with eta = tau / kappa^(2) (F.2), along the generator of a
developable ribbon (the null direction of the second fundamental form, with kappa^(2) = t'.m1
and tau = m1'.m2 in our conventions).
"""
from __future__ import annotations

import numpy as np

from .curvatures import plate_points, framed_curve_curvatures, plate_centerline_frame
from ..geometry.frames import cross, unit

PAPER_WIDTH_RATIOS = (1 / 2, 1 / 3, 1 / 6, 1 / 12, 1 / 20)  # L/W in {2, 3, 6, 12, 20}
PAPER_SHEAR_RATIOS = (0.1, 0.3, 0.5)


def plate_stations(model) -> np.ndarray:
    """Rest arclengths s_k (m) of the centerline stations: the mesh columns if the nodes stand in
    columns (at most N / 2 distinct x), else a grid of the mean triangle side (unstructured)."""
    L = model.strip.length
    _, first = np.unique(np.round(model.mesh.nodes[:, 0] / (1e-9 * L)), return_index=True)
    x = model.mesh.nodes[first, 0]  # the nodes' own x: rounded values may fall off the mesh
    if len(x) <= 0.5 * model.mesh.node_count:
        return x
    side = np.sqrt(4.0 * np.mean(model.mesh.triangle_areas) / np.sqrt(3.0))
    lo, hi = model.mesh.nodes[:, 0].min(), model.mesh.nodes[:, 0].max()
    return np.linspace(lo, hi, int(np.ceil((hi - lo) / side)) + 1)


def centerline_frame(model, q: np.ndarray, stations: np.ndarray | None = None) -> dict:
    """The plate's framed centerline at the stations: points x^p_k, per-edge t, m1, m2, the
    node-averaged (m2^k + m2^{k-1}) / 2 and t of Eq. (12) (one-sided at the ends), and the
    integrated kappa^(2), tau at interior stations."""
    s = plate_stations(model) if stations is None else np.asarray(stations, dtype=float)
    x, m1, _ = plate_centerline_frame(model, q, s)
    t = unit(x[1:] - x[:-1])
    m2 = cross(t, m1)
    m2_node = np.concatenate([m2[:1], 0.5 * (m2[1:] + m2[:-1]), m2[-1:]])
    t_node = unit(np.concatenate([t[:1], 0.5 * (t[1:] + t[:-1]), t[-1:]]))
    _, kappa2, tau = framed_curve_curvatures(x, m1)
    return {"s": s, "x": x, "t": t, "m1": m1, "m2": m2, "m2_node": m2_node, "t_node": t_node,
            "kappa2": np.r_[np.nan, kappa2, np.nan], "tau": np.r_[np.nan, tau, np.nan]}


def _at(s_grid, values, s):
    """Linear interpolation in s of per-station vectors (K, 3) at points s (n,)."""
    return np.stack([np.interp(s, s_grid, values[:, c]) for c in range(values.shape[1])], axis=1)


def centerline_error_field(model, q: np.ndarray) -> dict:
    """delta(s, w) of Eq. (13) at every plate node: the distance from the Eq. (12) approximation
    to the plate's deformed node, over L. Returns s/L, w/L, delta per node and its mean and max."""
    L = model.strip.length
    frame = centerline_frame(model, q)
    rest = model.mesh.nodes
    s, w = rest[:, 0], -rest[:, 1]
    approx = _at(frame["s"], frame["x"], s) + w[:, None] * _at(frame["s"], frame["m2_node"], s)
    delta = np.linalg.norm(approx - model.positions(q), axis=1) / L
    return {"s_over_L": s / L, "w_over_L": w / L, "delta": delta, "mean": float(delta.mean()),
            "max": float(delta.max())}


def edge_reconstruction(model, q: np.ndarray) -> dict:
    """The plate's edge w = +W/2 (rest y = -W/2) against its rod-based (F.1) and ribbon-based (F.2)
    reconstructions from the centerline, at the interior stations. Distances over L per
    station, their means and maxima, and eta = tau / kappa^(2)."""
    L, W = model.strip.length, model.strip.width
    frame = centerline_frame(model, q)
    inner = slice(1, -1)
    s = frame["s"][inner]
    keep = (s >= 0.0) & (s <= L)
    s = s[keep]
    centre = frame["x"][inner][keep]
    m2 = frame["m2_node"][inner][keep]
    t = frame["t_node"][inner][keep]
    eta = (frame["tau"][inner] / frame["kappa2"][inner])[keep]
    plate_edge = plate_points(model, q, s, np.full_like(s, -0.5 * W))
    rod_edge = centre + 0.5 * W * m2
    ribbon_edge = centre + 0.5 * W * (eta[:, None] * t + m2)
    rod_err = np.linalg.norm(rod_edge - plate_edge, axis=1) / L
    ribbon_err = np.linalg.norm(ribbon_edge - plate_edge, axis=1) / L
    return {"s_over_L": s / L, "eta": eta, "plate_edge": plate_edge, "rod_edge": rod_edge, "ribbon_edge": ribbon_edge,
            "rod_error": rod_err, "ribbon_error": ribbon_err,
            "rod_mean": float(rod_err.mean()), "rod_max": float(rod_err.max()),
            "ribbon_mean": float(ribbon_err.mean()), "ribbon_max": float(ribbon_err.max())}
