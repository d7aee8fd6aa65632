"""Where the DDG plate's first-order error can come from: its energies on exact smooth
deformations, mode by mode, interior against edge rows.

`python -m validation plate-modes [--out data/plate_modes]` (old spelling
`python -m validation.plate_modes`) imposes on the structured meshes
(ddg.geometry.plate_mesh.structured_mesh: the default, and the exactly equilateral one) one
deformation at a time, each small enough to be
linear (curvature 0.01/L, strain 1e-4), and compares the energy the plate's terms give
(hinges, Eq. 11b; edge springs, Eq. 11a) with the continuum energy the plate stands for (bending
stiffness D = E b^3/12 with bending Poisson ratio -1/3; membrane E b with Poisson ratio 1/3;
fem_reference.shell's "dep" material). Energies are summed over whole column periods in the
middle of the strip (no clamp in the window) and divided by the continuum energy of the same
area: "whole width" counts every hinge or edge, "interior" only those in the whole rows with
|y| < ~W/4.

A ratio that tends to 1 in the interior but not over the whole width at the rate h points at
the free-edge rows (their half-size triangles, their hinge and spring weights); a ratio off
in the interior points at the energy itself.

Writes OUT/modes.csv (one row per width, mesh and mode) and OUT/modes.md (with the fitted
order of |1 - ratio| over the whole width).
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ddg.energies.hinge_bending import hinge_bending_energy
from ddg.geometry.strip import Strip
from ddg.models.plate import PlateModel
from ddg.output.io import atomic_write_text, write_table_csv

from .command_line import output_folder, standalone

WIDTH_RATIOS = (1 / 6, 1 / 2)
TRIANGLES = (500, 2000, 8000, 32000)
#: The continuum the plate stands for (fem_reference.shell: DEP_MEMBRANE_POISSON, DEP_BENDING_POISSON).
BENDING_POISSON, MEMBRANE_POISSON = -1.0 / 3.0, 1.0 / 3.0
CURVATURE = 0.01  # times 1/L: slopes below 0.01 over the strip, the linear regime
STRAIN = 1e-4


def _window(model: PlateModel, points: np.ndarray) -> tuple[np.ndarray, float]:
    """Weights of points (element midpoints) in whole column periods around the middle of the
    strip (1 inside, 1/2 on a bound: the diagonals' midpoints lie on them), and the window's
    length along x."""
    columns = np.unique(np.round(model.mesh.nodes[:, 0], 12))
    first = 2 * (len(columns) // 8)  # from about L/4 to about 3 L/4
    last = first + 2 * (len(columns) // 4)
    xa, xb = 0.5 * (columns[first - 1] + columns[first]), 0.5 * (columns[last - 1] + columns[last])
    tol = 1e-9 * model.strip.length
    x = points[:, 0]
    weight = ((x > xa + tol) & (x < xb - tol)).astype(float)
    weight[(np.abs(x - xa) <= tol) | (np.abs(x - xb) <= tol)] = 0.5
    return weight, xb - xa


def bending_modes(L: float, W: float) -> dict:
    """name -> (positions of reference nodes X (N, 2), continuum energy density / (D k^2))."""
    k = CURVATURE / L
    nu = BENDING_POISSON

    def cylinder_x(X):  # bending along the length (the U): exact isometry
        return np.stack([np.sin(k * X[:, 0]) / k, X[:, 1], (1 - np.cos(k * X[:, 0])) / k], axis=1)

    def cylinder_y(X):  # bending across the width
        return np.stack([X[:, 0], np.sin(k * X[:, 1]) / k, (1 - np.cos(k * X[:, 1])) / k], axis=1)

    def twist(X):
        return np.stack([X[:, 0], X[:, 1], k * (X[:, 0] - 0.5 * L) * X[:, 1]], axis=1)

    def sphere(X):
        return np.stack([X[:, 0], X[:, 1], 0.5 * k * ((X[:, 0] - 0.5 * L) ** 2 + X[:, 1] ** 2)], axis=1)

    # psi_b = D/2 (nu tr(kappa)^2 + (1 - nu) kappa:kappa), over D k^2
    return {"bend along L": (cylinder_x, 0.5), "bend across W": (cylinder_y, 0.5),
            "twist": (twist, 1.0 - nu), "sphere": (sphere, 1.0 + nu)}


def membrane_modes() -> dict:
    """name -> (strain tensor, continuum density / (E b eps^2))."""
    nu, e = MEMBRANE_POISSON, STRAIN

    def density(eps):
        return (eps[0, 0] ** 2 + eps[1, 1] ** 2 + 2 * nu * eps[0, 0] * eps[1, 1]
                + 2 * (1 - nu) * eps[0, 1] ** 2) / (2 * (1 - nu**2)) / e**2

    modes = {"stretch along L": np.array([[e, 0.0], [0.0, 0.0]]), "stretch across W": np.array([[0.0, 0.0], [0.0, e]]),
             "shear": np.array([[0.0, e], [e, 0.0]])}
    return {name: (eps, density(eps)) for name, eps in modes.items()}


#: The structured meshes compared: the default (equally spaced columns, counts rounded) and the
#: exactly equilateral one (ddg.geometry.plate_mesh.equilateral_columns).
MESHES = ("structured", "equilateral")


def measure(width_ratio: float, triangles: int, mesh_kind: str = "structured") -> list[dict]:
    from ddg.geometry.plate_mesh import structured_mesh

    strip = Strip.from_ratios(width_ratio, 0.5)
    L, W, E, b = strip.length, strip.width, strip.young_modulus, strip.thickness
    D = E * b**3 / 12.0
    model = PlateModel(strip, mesh=structured_mesh(L, W, triangles, equilateral=mesh_kind == "equilateral"))
    mesh, X = model.mesh, model.mesh.nodes
    rows_across = len(np.unique(np.round(X[:, 1], 12))) - 1
    columns = np.unique(np.round(X[:, 0], 12))
    # column spacing over that of equilateral triangles: the structured mesh rounds its counts
    aspect = (columns[1] - columns[0]) / (0.5 * math.sqrt(3.0) * 2.0 * W / rows_across)
    base = {"mesh": mesh_kind, "width_ratio": width_ratio, "triangles": mesh.triangle_count,
            "h_over_W": 2.0 / rows_across,
            "aspect_over_equilateral": aspect}
    out = []
    # the interior band: whole rows, |y| < c with c the row boundary nearest W/4; elements whose
    # midpoint lies on it count half
    row = W / rows_across * 2.0  # regular columns' node spacing h_y
    cut = 0.5 * W - row * round(0.25 * W / row)

    def interior_weight(points):
        distance = np.abs(points[:, 1]) - cut
        return np.where(np.abs(distance) < 1e-9 * W, 0.5, (distance < 0).astype(float))

    hinge_nodes = mesh.edges[mesh.hinge_edges]
    hinge_mid = 0.5 * (X[hinge_nodes[:, 0]] + X[hinge_nodes[:, 1]])
    in_window, length = _window(model, hinge_mid)
    interior = interior_weight(hinge_mid)
    on_edge = np.abs(np.abs(X[:, 1]) - 0.5 * W) < 1e-12 * W
    boundary = on_edge[hinge_nodes[:, 0]] | on_edge[hinge_nodes[:, 1]]  # hinges touching a free edge
    k = CURVATURE / L
    for name, (deform, density) in bending_modes(L, W).items():
        energy = hinge_bending_energy(deform(X), mesh.triangles, mesh.hinge_triangles, model.hinge_stiffness,
                                      gradient=False)[0]
        unit = density * D * k**2 * length
        whole = (energy * in_window).sum() / (unit * W)
        at_edges = (energy * in_window * boundary).sum() / (unit * W)
        out.append({**base, "mode": name, "energy": "bending (hinges)", "ratio_whole_width": whole,
                    "ratio_interior": (energy * interior * in_window).sum() / (unit * 2.0 * cut),
                    # the factor on the free-edge hinges that would make the whole width exact
                    "edge_hinge_factor_to_exact": (1.0 - (whole - at_edges)) / at_edges})
    edge_mid = 0.5 * (X[mesh.edges[:, 0]] + X[mesh.edges[:, 1]])
    in_window, length = _window(model, edge_mid)
    interior = interior_weight(edge_mid)
    for name, (eps, density) in membrane_modes().items():
        F = np.eye(2) + eps
        x = X @ F.T
        stretched = np.linalg.norm(x[mesh.edges[:, 1]] - x[mesh.edges[:, 0]], axis=1)
        energy = 0.5 * model.stretch_stiffness * (stretched - model.rest_edge_lengths) ** 2
        unit = density * E * b * STRAIN**2 * length
        out.append({**base, "mode": name, "energy": "stretching (edge springs)",
                    "ratio_whole_width": (energy * in_window).sum() / (unit * W),
                    "ratio_interior": (energy * interior * in_window).sum() / (unit * 2.0 * cut),
                    "edge_hinge_factor_to_exact": math.nan})
    return out


def fitted_order(h: np.ndarray, error: np.ndarray) -> float:
    """Least-squares slope of log |error| against log h (nan with fewer than two nonzero errors)."""
    keep = np.abs(error) > 1e-12
    if keep.sum() < 2:
        return math.nan
    return float(np.polyfit(np.log(h[keep]), np.log(np.abs(error[keep])), 1)[0])


def study(widths=WIDTH_RATIOS, triangles=TRIANGLES, meshes=MESHES) -> tuple[list[dict], list[dict]]:
    rows = [row for kind in meshes for w in widths for t in triangles for row in measure(w, t, kind)]
    orders = []
    for kind in meshes:
        for w in widths:
            for mode in dict.fromkeys(r["mode"] for r in rows):
                sel = [r for r in rows if r["mesh"] == kind and r["width_ratio"] == w and r["mode"] == mode]
                h = np.array([r["h_over_W"] for r in sel])
                whole = np.array([r["ratio_whole_width"] for r in sel])
                inner = np.array([r["ratio_interior"] for r in sel])
                orders.append({"mesh": kind, "width_ratio": w, "mode": mode, "energy": sel[0]["energy"],
                               "finest_whole_width": whole[-1], "finest_interior": inner[-1],
                               "order_whole_width": fitted_order(h, 1.0 - whole),
                               "order_interior": fitted_order(h, 1.0 - inner)})
    return rows, orders


def write(out: Path, rows: list[dict], orders: list[dict]) -> None:
    out.mkdir(parents=True, exist_ok=True)
    write_table_csv(out / "modes.csv", rows)
    lines = ["# DDG plate energies on exact smooth deformations (validation/plate_modes.py)", "",
             "Energy of the plate's terms over the continuum energy they stand for (bending: D, nu_b = -1/3; "
             "membrane: E b, nu = 1/3) in whole column periods mid-strip; `interior`: whole rows with |y| < ~W/4 only. "
             "Orders: "
             "least-squares slope of log|1 - ratio| against log h over "
             f"{', '.join(str(t) for t in TRIANGLES)} target triangles (nan: exact on every mesh).", "",
             "| mesh | W/L | mode | energy | ratio, whole width (finest) | ratio, interior (finest) "
             "| order, whole width | order, interior |", "|---|---|---|---|---:|---:|---:|---:|"]
    for o in orders:
        lines.append(f"| {o['mesh']} | {o['width_ratio']:.4g} | {o['mode']} | {o['energy']} | "
                     f"{o['finest_whole_width']:.4f} | {o['finest_interior']:.4f} | {o['order_whole_width']:.2f} | "
                     f"{o['order_interior']:.2f} |")
    lines += ["", "Per mesh (aspect: column spacing over that of equilateral triangles, from the rounding of the "
              "structured mesh's counts):", "",
              "| mesh | W/L | triangles | h_y/W | aspect | mode | whole width | interior | factor on free-edge hinges "
              "for an exact whole width |",
              "|---|---|---:|---:|---:|---|---:|---:|---:|"]
    for r in rows:
        factor = r["edge_hinge_factor_to_exact"]
        lines.append(f"| {r['mesh']} | {r['width_ratio']:.4g} | {r['triangles']} | {r['h_over_W']:.4f} | "
                     f"{r['aspect_over_equilateral']:.4f} | {r['mode']} | {r['ratio_whole_width']:.5f} | "
                     f"{r['ratio_interior']:.5f} | {'-' if math.isnan(factor) else f'{factor:.3f}'} |")
    atomic_write_text(out / "modes.md", "\n".join(lines) + "\n")


def add_arguments(parser) -> None:
    """The options of `python -m validation plate-modes`."""
    parser.description = __doc__.split("\n")[0]
    parser.add_argument("--out", default="data/plate_modes")


def run(args) -> int:
    """--out checked, then the study (every width, mesh and mode), its files and a line per fitted order."""
    out = output_folder(args.out)   # a file or an unwritable folder: one line, exit 2
    if out is None:
        return 2
    rows, orders = study()
    write(out, rows, orders)
    for o in orders:
        print(f"{o['mesh']:11s} W/L {o['width_ratio']:.4g} {o['mode']:17s} whole {o['finest_whole_width']:.4f} "
              f"(order {o['order_whole_width']:.2f}) interior {o['finest_interior']:.4f}", flush=True)
    return 0


def main(argv=None) -> int:
    """`python -m validation.plate_modes [options]`: the same as `python -m validation plate-modes [options]`."""
    return standalone("plate-modes", add_arguments, run, argv)


if __name__ == "__main__":
    raise SystemExit(main())
