"""The Discrete Elastic Plate's energies: derivatives, invariances and continuum limits.

* Hinge bending (Eq. 11b), E_b = sum_h c_h |n_a - n_b|^2, and edge stretching (Eq. 11a),
  E_s = sum_e 1/2 k_e (|e| - |e_bar|)^2 with k_e = E b (A_a + A_b) / |e_bar|^2, are assembled
  here to global (3N) gradients and dense Hessians (dof 3 * node + k) and checked against
  central differences at generic deformed states, for rigid-motion invariance and at the flat
  rest state.
* Continuum limits on structured meshes, against closed forms derived in the docstrings of
  the helpers below: a uniformly stretched plate is an isotropic membrane with Y = E b and
  Poisson ratio 1/3; a plate rolled onto a cylinder has the bending stiffness D_eff =
  sqrt(3) c, whatever the direction of the cylinder's axis; on a sphere the energy is 4/3 of
  the cylinder's at the same curvature (Gaussian modulus -4/3 D_eff, a bending Poisson
  ratio of -1/3).
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from ddg.energies.hinge_bending import hinge_bending_energy, hinge_stiffness
from ddg.energies.stretch import stretching_energy, two_node_blocks
from ddg.geometry.plate_mesh import structured_mesh

YOUNG, THICKNESS = 2.0e9, 1.0e-3  # only ratios matter; E b and E b^3 / 12 set the scales
SEEDS = (0, 1, 2)
REL_STEP = 1e-6  # central-difference step, relative to the mesh spacing
FD_RTOL = 1e-6  # observed agreement ~1e-9 at this step (truncation ~ step^2, round-off ~ 1e-16 / step)
ROUNDOFF = 1e-12  # identities that hold exactly in exact arithmetic


# --------------------------------------------------------------------------- assembly
def element_dofs(elements: np.ndarray) -> np.ndarray:
    """(M, k) node indices -> (M, 3k) dof indices 3 * node + coordinate."""
    return (3 * elements[:, :, None] + np.arange(3)).reshape(len(elements), -1)


def assemble_vector(n_nodes: int, elements: np.ndarray, blocks: np.ndarray) -> np.ndarray:
    out = np.zeros(3 * n_nodes)
    np.add.at(out, element_dofs(elements), blocks)
    return out


def assemble_matrix(n_nodes: int, elements: np.ndarray, blocks: np.ndarray) -> np.ndarray:
    dofs = element_dofs(elements)
    out = np.zeros((3 * n_nodes, 3 * n_nodes))
    np.add.at(out, (dofs[:, :, None], dofs[:, None, :]), blocks)
    return out


def rest_lengths(mesh, edges: np.ndarray) -> np.ndarray:
    return np.linalg.norm(mesh.nodes[edges[:, 1]] - mesh.nodes[edges[:, 0]], axis=1)


def membrane_spring_stiffness(mesh, young: float = YOUNG, thickness: float = THICKNESS) -> np.ndarray:
    """k_e = E b (A_a + A_b) / |e_bar|^2 (sqrt(3)/2 E b on an interior equilateral edge, Eq. 11a)."""
    return young * thickness * mesh.edge_triangle_areas / rest_lengths(mesh, mesh.edges) ** 2


def plate_hinge_stiffness(mesh, bending_stiffness: float) -> np.ndarray:
    hinge_edges = mesh.hinge_edges
    return hinge_stiffness(rest_lengths(mesh, mesh.edges[hinge_edges]), mesh.edge_triangle_areas[hinge_edges],
                           bending_stiffness)


def cross_matrix(n: int, mesh, cross: np.ndarray) -> np.ndarray:
    """Dense C + C^T of the hinge cross blocks (rows: triangle a's coordinates, columns: b's)."""
    rows = (3 * mesh.triangles[mesh.hinge_triangles[:, 0]][:, :, None] + np.arange(3)).reshape(-1, 9)
    cols = (3 * mesh.triangles[mesh.hinge_triangles[:, 1]][:, :, None] + np.arange(3)).reshape(-1, 9)
    out = np.zeros((3 * n, 3 * n))
    np.add.at(out, (rows[:, :, None], cols[:, None, :]), cross)
    return out + out.T


def bending(mesh, x: np.ndarray, stiffness: np.ndarray, derivatives: bool = True):
    """(total energy, global gradient (3N,), global Hessian (3N, 3N)) of the hinge energy."""
    energy, grad, hess_tri, cross = hinge_bending_energy(x, mesh.triangles, mesh.hinge_triangles, stiffness,
                                                         gradient=derivatives, hessian=derivatives)
    if not derivatives:
        return energy.sum(), None, None
    n = mesh.node_count
    hess = assemble_matrix(n, mesh.triangles, hess_tri) + cross_matrix(n, mesh, cross)
    return energy.sum(), assemble_vector(n, mesh.triangles, grad), hess


def stretching(mesh, x: np.ndarray, stiffness: np.ndarray, derivatives: bool = True):
    """Same for the edge springs; edge (i, j) has e = x_j - x_i."""
    edges = mesh.edges
    energy, grad_e, hess_e = stretching_energy(x[edges[:, 1]] - x[edges[:, 0]], rest_lengths(mesh, edges), stiffness,
                                               gradient=derivatives, hessian=derivatives)
    if not derivatives:
        return energy.sum(), None, None
    grad, hess = two_node_blocks(grad_e, hess_e)
    n = mesh.node_count
    return energy.sum(), assemble_vector(n, edges, grad), assemble_matrix(n, edges, hess)


def total(mesh, x, c_bend, k_stretch, derivatives=True):
    eb, gb, hb = bending(mesh, x, c_bend, derivatives)
    es, gs, hs = stretching(mesh, x, k_stretch, derivatives)
    if not derivatives:
        return eb + es, None, None
    return eb + es, gb + gs, hb + hs


# --------------------------------------------------------------------------- states
def flat(mesh) -> np.ndarray:
    return np.c_[mesh.nodes, np.zeros(mesh.node_count)]


def spacing(mesh) -> float:
    return float(np.median(rest_lengths(mesh, mesh.edges)))


def deformed_state(mesh, seed: int) -> np.ndarray:
    """A generic large deformation: the part x > L/3 rolled through 1.5 rad onto a cylinder
    of radius L/3, the whole plate twisted by 0.6 rad about its axis, then every node moved
    by a random 3D vector (std 0.02 L per component, so typical moves ~5 % of L)."""
    rng = np.random.default_rng(seed)
    length = mesh.length
    X, Y = mesh.nodes.T
    radius, start = length / 3.0, length / 3.0
    arc = np.clip(X - start, 0.0, None)
    x = np.where(X > start, start + radius * np.sin(arc / radius), X)
    z = np.where(X > start, radius * (1.0 - np.cos(arc / radius)), 0.0)
    twist = 0.6 * X / length
    pos = np.stack([x, Y * np.cos(twist), z + Y * np.sin(twist)], axis=1)
    return pos + 0.02 * length * rng.standard_normal(pos.shape)


def random_hinge_stiffness(mesh, rng) -> np.ndarray:
    return rng.uniform(0.5, 2.0, len(mesh.hinges)) * YOUNG * THICKNESS**3 / 12.0


def random_spring_stiffness(mesh, rng) -> np.ndarray:
    return rng.uniform(0.5, 2.0, len(mesh.edges)) * membrane_spring_stiffness(mesh)


@pytest.fixture(scope="module")
def small_mesh():
    return structured_mesh(1.0, 0.3, 40)


# --------------------------------------------------------------------------- finite differences
def central_differences(function, x: np.ndarray, step: float) -> np.ndarray:
    """d function / d x_i by central differences, stacked along the first axis (i over x.ravel())."""
    q = x.ravel().copy()
    rows = []
    for i in range(len(q)):
        q[i] += step
        plus = function(q.reshape(x.shape))
        q[i] -= 2 * step
        minus = function(q.reshape(x.shape))
        q[i] += step
        rows.append((plus - minus) / (2 * step))
    return np.array(rows)


def fd_gradient(energy, x: np.ndarray, step: float) -> np.ndarray:
    return central_differences(energy, x, step)


def fd_hessian(gradient, x: np.ndarray, step: float) -> np.ndarray:
    return central_differences(gradient, x, step).T


def max_rel_err(approx: np.ndarray, exact: np.ndarray) -> float:
    return float(np.max(np.abs(approx - exact)) / np.max(np.abs(exact)))


ENERGIES = {"bending": (bending, random_hinge_stiffness), "stretching": (stretching, random_spring_stiffness)}


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("name", sorted(ENERGIES))
def test_gradient_and_hessian_match_central_differences(small_mesh, name, seed):
    evaluate, make_stiffness = ENERGIES[name]
    rng = np.random.default_rng(100 + seed)
    stiffness = make_stiffness(small_mesh, rng)
    x = deformed_state(small_mesh, seed)
    _, grad, hess = evaluate(small_mesh, x, stiffness)
    step = REL_STEP * spacing(small_mesh)

    fd_g = fd_gradient(lambda y: evaluate(small_mesh, y, stiffness, derivatives=False)[0], x, step)
    assert max_rel_err(grad, fd_g) < FD_RTOL
    fd_h = fd_hessian(lambda y: evaluate(small_mesh, y, stiffness)[1], x, step)
    assert max_rel_err(hess, fd_h) < FD_RTOL
    assert np.max(np.abs(hess - hess.T)) <= ROUNDOFF * np.max(np.abs(hess))


def test_deformed_states_are_far_from_flat(small_mesh):
    """The finite-difference states must exercise every term: all hinges bent, triangles
    sheared and out of plane, but none close to degenerate (which would make the differences
    ill-conditioned rather than the derivatives wrong)."""
    for seed in SEEDS:
        x = deformed_state(small_mesh, seed)
        p = x[small_mesh.triangles]
        double_area = np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
        ratio = 0.5 * double_area / small_mesh.triangle_areas
        assert ratio.min() > 0.1 and ratio.max() > 1.2  # stretched and compressed, none collapsed
        n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]) / double_area[:, None]
        cos_angle = np.einsum("hi,hi->h", n[small_mesh.hinge_triangles[:, 0]], n[small_mesh.hinge_triangles[:, 1]])
        angle = np.degrees(np.arccos(np.clip(cos_angle, -1.0, 1.0)))
        assert np.median(angle) > 5.0 and np.mean(angle > 1.0) > 0.9


# --------------------------------------------------------------------------- invariances
@pytest.mark.parametrize("seed", SEEDS)
def test_rigid_motion_leaves_energy_unchanged_and_forces_balanced(small_mesh, seed):
    rng = np.random.default_rng(200 + seed)
    c_bend, k_stretch = random_hinge_stiffness(small_mesh, rng), random_spring_stiffness(small_mesh, rng)
    x = deformed_state(small_mesh, seed)
    energy, grad, hess = total(small_mesh, x, c_bend, k_stretch)
    assert energy > 0

    rotation = Rotation.random(random_state=rng).as_matrix()
    moved = x @ rotation.T + rng.normal(size=3)
    energy_moved, grad_moved, _ = total(small_mesh, moved, c_bend, k_stretch)
    assert abs(energy_moved - energy) <= 1e-12 * energy
    # forces rotate with the body
    f, f_moved = grad.reshape(-1, 3), grad_moved.reshape(-1, 3)
    assert np.max(np.abs(f_moved - f @ rotation.T)) <= ROUNDOFF * np.max(np.abs(f))

    # no net force or torque: the internal forces of a free body are self-equilibrated
    assert np.linalg.norm(f.sum(axis=0)) <= ROUNDOFF * np.abs(f).sum()
    torque = np.cross(x, f).sum(axis=0)
    assert np.linalg.norm(torque) <= ROUNDOFF * np.sum(np.linalg.norm(x, axis=1) * np.linalg.norm(f, axis=1))

    # the Hessian annihilates rigid translations, and maps an infinitesimal rotation
    # omega x x_i to omega x f_i (differentiate f(R x) = R f(x)) -- away from equilibrium too
    scale = np.linalg.norm(hess, 2)
    for axis in np.eye(3):
        translation = np.tile(axis, small_mesh.node_count)
        assert np.linalg.norm(hess @ translation) <= ROUNDOFF * scale * np.linalg.norm(translation)
    omega = rng.normal(size=3)
    spin = np.cross(omega, x).ravel()
    expected = np.cross(omega, f).ravel()
    assert np.linalg.norm(hess @ spin - expected) <= ROUNDOFF * scale * np.linalg.norm(spin)


# --------------------------------------------------------------------------- flat state
def test_flat_plate_is_a_stress_free_minimum(small_mesh):
    rng = np.random.default_rng(3)
    c_bend, k_stretch = random_hinge_stiffness(small_mesh, rng), random_spring_stiffness(small_mesh, rng)
    x = flat(small_mesh)
    for evaluate, stiffness in ((bending, c_bend), (stretching, k_stretch)):
        energy, grad, hess = evaluate(small_mesh, x, stiffness)
        assert energy == 0.0
        assert np.max(np.abs(grad)) == 0.0
        eig = np.linalg.eigvalsh(hess)
        assert eig.min() >= -ROUNDOFF * eig.max()  # a minimum: positive semi-definite

    # bending at the flat state: in-plane motions leave every normal at +z, and the only
    # out-of-plane motions without a bent hinge are the three rigid ones, w = a + b x + c y
    _, _, hess = bending(small_mesh, x, c_bend)
    in_plane = np.r_[np.arange(0, hess.shape[0], 3), np.arange(1, hess.shape[0], 3)]
    assert np.max(np.abs(hess[np.ix_(in_plane, in_plane)])) == 0.0
    out_of_plane = np.arange(2, hess.shape[0], 3)
    eig = np.linalg.eigvalsh(hess[np.ix_(out_of_plane, out_of_plane)])
    assert np.all(np.abs(eig[:3]) <= ROUNDOFF * eig.max()) and eig[3] > 1e-6 * eig.max()

    # a small random deflection w costs the positive energy 1/2 w^T H w (hinge angles ~1e-4,
    # so quartic terms are ~1e-8 relative)
    w = np.zeros_like(x)
    w[:, 2] = 1e-5 * small_mesh.length * rng.standard_normal(small_mesh.node_count)
    energy = bending(small_mesh, x + w, c_bend, derivatives=False)[0]
    assert energy > 0
    assert energy == pytest.approx(0.5 * w.ravel() @ hess @ w.ravel(), rel=1e-6)
    assert stretching(small_mesh, x + w, k_stretch, derivatives=False)[0] > 0


# --------------------------------------------------------------------------- continuum limits
# A plate with W/L = 4 / (3 sqrt(3)) and n_y = 2 (mod 4) rows of triangles: the structured mesh's
# column count n = nearest odd to 2 L n_y / (sqrt(3) W) = 3 n_y / 2 is then exact, so the
# interior triangles are exactly equilateral and the only discretisation error is the edge
# rows of half triangles (and, for bending, the missing hinges at the boundary): O(1 / n_y).
# The target count T = 3 n_y^2 makes structured_mesh pick that n_y.
EQUILATERAL_ASPECT = 4.0 / (3.0 * math.sqrt(3.0))
ROW_COUNTS = (10, 22, 46, 90)


def equilateral_plate(n_y: int):
    mesh = structured_mesh(1.0, EQUILATERAL_ASPECT, 3 * n_y**2)
    lengths = rest_lengths(mesh, mesh.edges)
    h_y = mesh.width / n_y
    # precondition: every edge is a lattice edge h_y, or a leg of a boundary-row half triangle:
    # h_y / 2 across the strip or h_x = sqrt(3)/2 h_y along its edge
    full = np.isclose(lengths, h_y, rtol=1e-12, atol=0)
    boundary_legs = np.isclose(lengths, 0.5 * h_y, rtol=1e-12, atol=0) | np.isclose(lengths, math.sqrt(3) / 2 * h_y,
                                                                                     rtol=1e-12, atol=0)
    assert np.all(full | boundary_legs), "the structured mesh is not equilateral for this plate: pick another family"
    return mesh


def column_strips(mesh) -> tuple[int, float]:
    """Number of strips between the structured mesh's node columns, and their width h_x."""
    columns = np.unique(np.round(mesh.nodes[:, 0], 12))
    return len(columns) - 1, float(np.mean(np.diff(columns)))


def mesh_area(mesh) -> float:
    return (mesh.length + 2 * mesh.clamp_depth) * mesh.width


def membrane_energy_density(young: float, thickness: float, ex: float, ey: float) -> float:
    """Isotropic membrane, Y = E b, nu = 1/3: Y / (2 (1 - nu^2)) (ex^2 + ey^2 + 2 nu ex ey).

    Derivation for the springs: k_e splits into one term E b A / |e_bar|^2 per adjacent
    triangle, so each triangle stores A E b / 2 sum over its edges of (t^T eps t)^2 (small
    strain). For the three edge directions of an equilateral triangle sum cos^4 = sum sin^4 =
    9/8 and sum cos^2 sin^2 = 3/8, giving the density (9/16) E b (ex^2 + ey^2 + 2/3 ex ey + 4/3
    exy^2): Y = E b, nu = 1/3.
    """
    nu = 1.0 / 3.0
    return young * thickness / (2.0 * (1.0 - nu**2)) * (ex**2 + ey**2 + 2.0 * nu * ex * ey)


def structured_mesh_stretch_energy(mesh, n_y: int, ex: float, ey: float) -> float:
    """Small-strain energy of the structured mesh itself (any aspect, from its construction).

    Each column strip (width h_x) holds 2 n_y - 1 full triangles of area h_x h_y / 2 with
    edges h_y (along y, strain ey) and (h_x, +-h_y/2) (strain s), and 2 half triangles of
    area h_x h_y / 4 on the edges y = +-W/2 with legs h_x (ex), h_y / 2 (ey) and hypotenuse
    (h_x, h_y / 2) (s), s = (ex h_x^2 + ey h_y^2 / 4) / (h_x^2 + h_y^2 / 4). Each triangle
    stores A E b / 2 sum (edge strain)^2.
    """
    strips, h_x = column_strips(mesh)
    h_y = mesh.width / n_y
    s = (ex * h_x**2 + ey * h_y**2 / 4) / (h_x**2 + h_y**2 / 4)
    full = (2 * n_y - 1) * 0.5 * h_x * h_y * (ey**2 + 2 * s**2)
    half = 2 * 0.25 * h_x * h_y * (ex**2 + ey**2 + s**2)
    return 0.5 * YOUNG * THICKNESS * strips * (full + half)


def boundary_row_stretch_error(ex: float, ey: float, n_y: int) -> float:
    """Relative excess over the membrane law on an exactly equilateral structured mesh.

    A fraction 1 / (2 n_y) of the area is in half triangles (legs h_x = sqrt(3)/2 h_y and
    h_y / 2, hypotenuse at 30 degrees with strain s = 3/4 ex + 1/4 ey) of density
    E b / 2 (ex^2 + ey^2 + s^2) instead of the law's.
    """
    s = 0.75 * ex + 0.25 * ey
    half = 0.5 * YOUNG * THICKNESS * (ex**2 + ey**2 + s**2)
    return (half / membrane_energy_density(YOUNG, THICKNESS, ex, ey) - 1.0) / (2 * n_y)


def stretched(mesh, ex: float, ey: float) -> np.ndarray:
    x = flat(mesh)
    x[:, 0] *= 1.0 + ex
    x[:, 1] *= 1.0 + ey
    return x


def slope(resolution, error) -> float:
    """Least-squares slope of log |error| against log resolution."""
    return float(np.polyfit(np.log(resolution), np.log(np.abs(error)), 1)[0])


def richardson_limit(n_y, value) -> float:
    """Extrapolate value = limit + a / n_y from the two finest meshes."""
    (n1, n2), (v1, v2) = n_y[-2:], value[-2:]
    return (n2 * v2 - n1 * v1) / (n2 - n1)


def test_equal_biaxial_stretch_is_exact_on_any_mesh():
    """Equal biaxial strain e stretches every edge by e |e_bar| exactly, so the energy is
    1/2 E b e^2 sum_e (A_a + A_b) = 3/2 E b e^2 * area on any triangulation -- the law's
    (9/16) (2 + 2/3) = 3/2: the membrane's area modulus is exact, boundary rows included."""
    for width, target in ((0.5, 500), (0.05, 2000), (EQUILATERAL_ASPECT, 300)):
        mesh = structured_mesh(1.0, width, target)
        k = membrane_spring_stiffness(mesh)
        for strain in (1e-4, -3e-3):
            energy = stretching(mesh, stretched(mesh, strain, strain), k, derivatives=False)[0]
            law = membrane_energy_density(YOUNG, THICKNESS, strain, strain) * mesh_area(mesh)
            assert energy == pytest.approx(law, rel=1e-10)  # round-off ~1e-16 / strain


STRAINS = ((1e-4, 0.0), (0.0, 1e-4), (1e-4, -5e-5))


@pytest.mark.parametrize("ex, ey", STRAINS)
def test_uniform_stretch_converges_to_membrane_law(ex, ey):
    """Energy / area -> (9/16) E b (ex^2 + ey^2 + 2/3 ex ey) like 1 / n_y, with the derived
    boundary-row coefficient; nonlinearity adds a relative O(strain) ~ 1e-4."""
    errors = []
    for n_y in ROW_COUNTS:
        mesh = equilateral_plate(n_y)
        k = membrane_spring_stiffness(mesh)
        interior = mesh.edge_triangle_areas > 1.5 * mesh.triangle_areas.max()
        assert np.allclose(k[interior], math.sqrt(3) / 2 * YOUNG * THICKNESS, rtol=1e-12)  # Eq. (11a)
        energy = stretching(mesh, stretched(mesh, ex, ey), k, derivatives=False)[0]
        error = energy / (membrane_energy_density(YOUNG, THICKNESS, ex, ey) * mesh_area(mesh)) - 1.0
        assert error == pytest.approx(boundary_row_stretch_error(ex, ey, n_y), abs=max(abs(ex), abs(ey)))
        errors.append(error)
    assert np.all(np.diff(np.abs(errors)) < 0)
    assert slope(ROW_COUNTS, errors) == pytest.approx(-1.0, abs=0.05)
    assert abs(errors[-1]) < 4e-3  # 0.30 / n_y at most for these strains


@pytest.mark.parametrize("width", (1 / 20, 1 / 6, 1 / 2))
@pytest.mark.parametrize("target", (500, 2000, 8000))
def test_uniform_stretch_on_generic_aspect_matches_mesh_geometry(width, target):
    """At a generic W/L the rounding of the column count makes interior triangles slightly
    non-equilateral (h_x / (sqrt(3)/2 h_y) = n* / n, |n - n*| <= 1) and the error against the
    law is not monotone in the triangle count; it is exactly what the geometry predicts."""
    mesh = structured_mesh(1.0, width, target)
    middle = np.isclose(mesh.nodes[:, 0], 0.5 * mesh.length, rtol=0, atol=1e-12)
    n_y = int(middle.sum()) - 1
    k = membrane_spring_stiffness(mesh)
    for ex, ey in STRAINS:
        energy = stretching(mesh, stretched(mesh, ex, ey), k, derivatives=False)[0]
        assert energy == pytest.approx(structured_mesh_stretch_energy(mesh, n_y, ex, ey), rel=max(abs(ex), abs(ey)))


def roll_onto_cylinder(mesh, curvature: float, axis: str) -> np.ndarray:
    """Isometric map onto a cylinder of radius 1/k; axis "y" bends along the length (x' = R
    sin(x/R), z = R (1 - cos(x/R))), axis "x" across the width."""
    x = flat(mesh)
    radius = 1.0 / curvature
    along = 0 if axis == "y" else 1
    s = x[:, along].copy()
    x[:, along] = radius * np.sin(s / radius)
    x[:, 2] = radius * (1.0 - np.cos(s / radius))
    return x


def cover_sphere(mesh, curvature: float) -> np.ndarray:
    """Azimuthal equidistant map about the plate's centre onto a sphere of radius 1/k
    (radial lines keep their length; hoop strain O((k r)^2), negligible for k r < 0.01)."""
    p = mesh.nodes - [0.5 * mesh.length, 0.0]
    r, phi = np.linalg.norm(p, axis=1), np.arctan2(p[:, 1], p[:, 0])
    radius = 1.0 / curvature
    return np.stack([radius * np.sin(r / radius) * np.cos(phi), radius * np.sin(r / radius) * np.sin(phi),
                     radius * (1.0 - np.cos(r / radius))], axis=1)


CURVATURE = 0.01  # 1/L: hinge angles ~ k h, nonlinear corrections ~ (k h)^2 / 12, negligible


def cylinder_bending_error(stiffness_of, bending_stiffness, axis):
    errors = []
    for n_y in ROW_COUNTS:
        mesh = equilateral_plate(n_y)
        energy = bending(mesh, roll_onto_cylinder(mesh, CURVATURE, axis), stiffness_of(mesh), derivatives=False)[0]
        errors.append(energy / (0.5 * bending_stiffness * CURVATURE**2 * mesh_area(mesh)) - 1.0)
    return np.array(errors)


@pytest.mark.parametrize("axis", ("y", "x"))
def test_cylinder_bending_converges_to_plate_stiffness(axis):
    """hinge_stiffness(|e_bar|, A_a + A_b, D) rolled onto a cylinder stores D k^2 / 2 per area
    in the limit, for bending along the length and across the width alike.

    Derivation of D_eff = sqrt(3) c on an equilateral lattice (side l): the four vertices of
    a hinge lie on z = 1/2 X^T K X; with d1 the edge and d2 the other diagonal of the rhombus
    (|d2| = sqrt(3) l), the hinge angle is theta = (d1^T K d1 - d2^T K d2) / (2 sqrt(3) l),
    i.e. (4 t^T K t - 3 tr K) l / (2 sqrt(3)) for an edge along t. Summing c theta^2 over the
    2 / (sqrt(3) l^2) hinges per area in each of the three directions gives the density
    (sqrt(3) c / 2) (k1^2 + k2^2 - 2/3 k1 k2): a cylinder stores sqrt(3) c k^2 / 2 whatever its
    axis, and c = D / sqrt(3) (what hinge_stiffness gives there) stores D k^2 / 2. (Across
    edges parallel to the cylinder axis theta = sqrt(3)/2 k l, not k l / sqrt(3) as the
    distance of the centroids would suggest, and it vanishes across the other two.)
    The error is O(1 / n_y): hinges are missing along the free boundary.
    """
    errors = cylinder_bending_error(lambda mesh: plate_hinge_stiffness(mesh, 1.0), 1.0, axis)
    assert np.all(errors < 0) and np.all(np.diff(np.abs(errors)) < 0)
    assert slope(ROW_COUNTS, errors) == pytest.approx(-1.0, abs=0.05)
    assert abs(errors[-1]) < 0.01
    assert richardson_limit(ROW_COUNTS, 1.0 + errors) == pytest.approx(1.0, abs=1e-3)
    if axis == "y":
        # only the hinges across the interior node columns bend, by k h_x each, and each
        # column stores D k^2 / 2 * h_x W; there is one column fewer than column strips
        strips = np.array([column_strips(equilateral_plate(n_y))[0] for n_y in ROW_COUNTS])
        assert errors == pytest.approx(-1.0 / strips, rel=1e-5)


@pytest.mark.parametrize("axis", ("y", "x"))
def test_paper_hinge_constant_gives_plate_bending_stiffness(axis):
    """The paper's constant c = E b^3 / (12 sqrt(3)) on every hinge gives D_eff = sqrt(3) c =
    E b^3 / 12 in the limit (not 2/3 of it), in both directions."""
    plate_d = YOUNG * THICKNESS**3 / 12.0
    c = plate_d / math.sqrt(3.0)
    errors = cylinder_bending_error(lambda mesh: np.full(len(mesh.hinges), c), plate_d, axis)
    assert abs(errors[-1]) < 0.01
    assert richardson_limit(ROW_COUNTS, 1.0 + errors) == pytest.approx(1.0, abs=1e-3)


def test_sphere_stores_four_thirds_of_the_cylinder_energy():
    """Gaussian modulus: with k1 = k2 = k the density (sqrt(3) c / 2)(k1^2 + k2^2 - 2/3 k1 k2)
    is 4/3 of the cylinder's D_eff k^2 / 2 -- the hinge energy is D_eff/2 (2H)^2 - 4/3 D_eff K,
    a bending Poisson ratio of -1/3 (a Poisson-0 plate would store twice the cylinder's)."""
    c = 1.0 / math.sqrt(3.0)  # D_eff = 1
    ratios = []
    for n_y in ROW_COUNTS:
        mesh = equilateral_plate(n_y)
        stiffness = np.full(len(mesh.hinges), c)
        energy = bending(mesh, cover_sphere(mesh, CURVATURE), stiffness, derivatives=False)[0]
        ratios.append(energy / (0.5 * CURVATURE**2 * mesh_area(mesh)))
    errors = np.array(ratios) / (4.0 / 3.0) - 1.0
    assert np.all(np.diff(np.abs(errors)) < 0)
    assert slope(ROW_COUNTS, errors) == pytest.approx(-1.0, abs=0.05)
    assert abs(errors[-1]) < 0.01
    assert richardson_limit(ROW_COUNTS, ratios) == pytest.approx(4.0 / 3.0, rel=1e-3)
