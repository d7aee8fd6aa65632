"""Finite-difference checks of the discrete rod's energies, gradients and Hessians.

Every check is made at generic deformed, twisted states (reached through several committed
random perturbations, so that reference frames and reference twist are non-trivial), never
only at the flat rest state where many terms vanish.

Conventions used throughout:

* The reference frames are state. A finite-difference check at q first commits q; then
  E(q +- eps e_i) is a smooth function of the step and its central differences must match
  the analytic gradient. The gradient at q + eps e_i uses frames transported from q, so its
  Jacobian differs from the Hessian by a (holonomy) antisymmetric part; the Hessian must
  match the symmetric part (J + J^T) / 2.
* DOFs are compared in natural units: positions in units of the edge spacing h, twist
  angles in radians. Gradients are then energies, Hessians energies, and one relative
  tolerance applies to all entries.
"""
from __future__ import annotations

import numpy as np
import pytest

from ddg import Strip
from ddg.energies.rod_bending import bending_density
from ddg.energies.rod_curvature import material_curvatures, strain_derivatives, turning_chi
from ddg.energies.rod_twist import discrete_twist, twisting_density
from ddg.energies.stretch import stretching_energy, two_node_blocks
from ddg.models.rod import RodModel
from rod_states import rod_dof_scale, twisted_rod_state

# Moderate stiffness contrast: EA h^2 / EI1 ~ 50, EI1 / EI2 = 25, EI2 / GJ ~ 0.65.
STRIP = Strip(length=0.1, width=0.01, thickness=0.002, young_modulus=1e9, poisson_ratio=0.3)
SEEDS = (0, 1, 2)
RESOLUTIONS = (7, 12)
ENERGIES = ("stretching", "bending", "twisting")

REL_STEP = 1e-6  # central-difference step, relative to the natural scale of each DOF
RTOL = 1e-6  # observed agreement is ~1e-10 .. 1e-9 at this step
ROUNDOFF = 1e-10  # for identities that hold exactly in exact arithmetic


# --------------------------------------------------------------------------- helpers
def rel_err(approx, exact) -> float:
    return float(np.linalg.norm(np.asarray(approx) - exact) / np.linalg.norm(exact))


def assert_symmetric(hess: np.ndarray) -> None:
    """Symmetric to round-off (the band storage keeps only the lower triangle, so an
    asymmetric element Hessian would silently lose its upper half)."""
    sym = np.swapaxes(hess, -1, -2)
    assert np.linalg.norm(hess - sym) <= ROUNDOFF * 1e-3 * np.linalg.norm(hess)






def committed_model_and_state(nodes: int, seed: int) -> tuple[RodModel, np.ndarray]:
    model = RodModel(STRIP, nodes)
    q = twisted_rod_state(model, seed)
    return model, q


def stencil_frames(model: RodModel, q: np.ndarray):
    """Positions, material directors m1, m2 at q (frames transported from the committed state) and m_ref."""
    _, _, m1, m2, m_ref = model.frames(q)
    return model.positions(q), m1, m2, m_ref


def chain_rule(grads: np.ndarray, hessians: np.ndarray, first: np.ndarray, second: np.ndarray):
    """Stencil gradients (n, 11) and Hessians (n, 11, 11) of sum_i e(kappa_n, kappa_g, tau), written out
    densely from the strains' derivatives (n, 3, 11), (n, 3, 11, 11) and e's partials (n, 3), (n, 3, 3):
    the reference the compiled assembly (rod_curvature.add_stencil_terms) is checked against."""
    grad = np.einsum("nc,nca->na", first, grads)
    hess = np.einsum("nc,ncab->nab", first, hessians) + np.einsum("ncd,nca,ndb->nab", second, grads, grads)
    return grad, hess


def stencil_dofs(model: RodModel) -> np.ndarray:
    """(M-2, 11) global DOF indices of the stencils [x_{i-1}, theta^{i-1}, x_i, theta^i, x_{i+1}]."""
    return 4 * np.arange(model.nodes - 2)[:, None] + np.arange(11)[None, :]


def edge_dofs(model: RodModel) -> np.ndarray:
    """(M-1, 6) global DOF indices (x_i, x_{i+1}) of the edges e = x_{i+1} - x_i."""
    return np.concatenate([model.node_dofs[:-1], model.node_dofs[1:]], axis=1)


def scatter(model: RodModel, index: np.ndarray, grad: np.ndarray, hess: np.ndarray | None):
    """Assemble element gradients (n, k) and Hessians (n, k, k) into global dense arrays."""
    g = np.zeros(model.n_dof)
    np.add.at(g, index, grad)
    if hess is None:
        return g, None
    H = np.zeros((model.n_dof, model.n_dof))
    np.add.at(H, (index[:, :, None], index[:, None, :]), hess)
    return g, H


def energy_part(model: RodModel, q: np.ndarray, name: str, hessian: bool = True):
    """(energy, gradient, dense Hessian) of one energy, from the low-level energy modules."""
    s = model.strip
    if name == "stretching":
        x = model.positions(q)
        e, ge, he = stretching_energy(x[1:] - x[:-1], model.rest_edge_lengths, model.stretch_stiffness)
        grad, hess = two_node_blocks(ge, he)
        index = edge_dofs(model)
    else:
        x, m1, m2, m_ref = stencil_frames(model, q)
        (kn, kg), (_, grads, hessians) = material_curvatures(x, m1, m2), strain_derivatives(x, m1, m2)
        index = stencil_dofs(model)
        if name == "bending":
            e, first, second = bending_density(kn, kg, model.voronoi_lengths, s.bending_stiffness,
                                               s.geodesic_bending_stiffness)
        elif name == "twisting":
            tau = discrete_twist(q[model.theta_dofs], m_ref)
            e, first, second = twisting_density(tau, model.voronoi_lengths, s.twisting_stiffness)
        else:
            raise ValueError(name)
        grad, hess = chain_rule(grads, hessians, first, second)
    G, H = scatter(model, index, grad, hess if hessian else None)
    return float(e.sum()), G, H


def finite_differences(func, q: np.ndarray, scale: np.ndarray):
    """Central differences, in scaled DOFs, of func(q) -> (value, vector).

    Returns (d value / dz, d vector / dz) with z = q / scale, i.e. the FD gradient of the
    value (n,) and the FD Jacobian of the vector, with the vector also multiplied by scale.
    """
    n = q.size
    d_value = np.zeros(n)
    jac = None
    for i in range(n):
        step = np.zeros(n)
        step[i] = REL_STEP * scale[i]
        vp, gp = func(q + step)
        vm, gm = func(q - step)
        d_value[i] = (vp - vm) / (2.0 * REL_STEP)
        if gp is not None:
            if jac is None:
                jac = np.zeros((np.size(gp), n))
            jac[:, i] = (np.ravel(gp) - np.ravel(gm)) / (2.0 * REL_STEP)
    return d_value, jac


def model_energy_and_gradient(model: RodModel):
    def func(q):
        ev = model.evaluate(q, gradient=True, hessian=False)
        return ev.energy, ev.gradient * rod_dof_scale(model)

    return func


# --------------------------------------------------------------------------- rest state
@pytest.mark.parametrize("nodes", RESOLUTIONS)
def test_flat_rest_state_has_zero_energy_and_zero_forces(nodes):
    """The straight, untwisted, unstretched strip is stress free: E = 0 and dE/dq = 0."""
    model = RodModel(STRIP, nodes)
    q = model.reset()
    ev = model.evaluate(q)
    ea, h = STRIP.stretching_stiffness, model.centerline.spacing
    assert ev.energy == pytest.approx(0.0, abs=1e-24 * ea * h)  # strain below 1e-12
    for name in ENERGIES:
        assert ev.parts[name] == pytest.approx(0.0, abs=1e-24 * ea * h), name
    assert np.max(np.abs(ev.gradient)) < 1e-12 * ea


def test_random_states_are_generic():
    """The states used below are genuinely 3-D and twisted, with non-zero reference twist."""
    for nodes in RESOLUTIONS:
        for seed in SEEDS:
            model, q = committed_model_and_state(nodes, seed)
            x, m1, m2, m_ref = stencil_frames(model, q)
            kappa_n, kappa_g = material_curvatures(x, m1, m2)
            theta = q[model.theta_dofs]
            # centerline not contained in any plane
            singular = np.linalg.svd(x - x.mean(axis=0), compute_uv=False)
            assert singular[2] > 0.05 * singular[1]
            # both curvatures, reference twist and twist are all generically non-zero
            assert np.all(np.abs(m_ref) > 0) and np.linalg.norm(m_ref) > 1e-2
            # (discrete curvatures are integrated, dimensionless: 2 tan(turning angle / 2))
            assert np.linalg.norm(kappa_n) > 0.1 and np.linalg.norm(kappa_g) > 0.1
            assert np.linalg.norm(theta[1:] - theta[:-1] + m_ref) > 0.3
            # and the turning angles stay well below pi (transport is well defined)
            assert np.min(turning_chi(x)) > 0.2


# --------------------------------------------------------------------------- stretching alone
@pytest.mark.parametrize("seed", SEEDS)
def test_stretching_energy_derivatives_with_respect_to_edge_vector(seed):
    """dE/de and d2E/de2 of 1/2 k (|e| - l)^2 match central differences for stretched and compressed edges."""
    rng = np.random.default_rng(seed)
    n = 8
    edges = rng.standard_normal((n, 3))
    rest = np.linalg.norm(edges, axis=1) * rng.uniform(0.6, 1.4, n)  # both tension and compression
    stiffness = rng.uniform(0.5, 2.0, n)
    energy, grad, hess = stretching_energy(edges, rest, stiffness)
    assert energy == pytest.approx(0.5 * stiffness * (np.linalg.norm(edges, axis=1) - rest) ** 2, rel=1e-14)
    eps = REL_STEP
    for k in range(3):
        step = np.zeros((n, 3))
        step[:, k] = eps
        ep, gp, _ = stretching_energy(edges + step, rest, stiffness)
        em, gm, _ = stretching_energy(edges - step, rest, stiffness)
        assert rel_err((ep - em) / (2 * eps), grad[:, k]) < RTOL
        assert rel_err((gp - gm) / (2 * eps), hess[:, :, k]) < RTOL
    assert_symmetric(hess)


def test_two_node_blocks_map_edge_derivatives_to_end_nodes():
    """With e = x_j - x_i, the 6-DOF gradient is (-g, +g) and the Hessian [[H, -H], [-H, H]]."""
    rng = np.random.default_rng(3)
    n = 5
    xi, xj = rng.standard_normal((n, 3)), rng.standard_normal((n, 3))
    rest, k = rng.uniform(0.5, 2.0, n), rng.uniform(0.5, 2.0, n)
    _, ge, he = stretching_energy(xj - xi, rest, k)
    grad, hess = two_node_blocks(ge, he)
    x = np.concatenate([xi, xj], axis=1)  # (n, 6)

    eps = REL_STEP
    for a in range(6):
        step = np.zeros((n, 6))
        step[:, a] = eps
        xp, xm = x + step, x - step
        ep, gp, hp = stretching_energy(xp[:, 3:] - xp[:, :3], rest, k)
        em, gm, hm = stretching_energy(xm[:, 3:] - xm[:, :3], rest, k)
        assert rel_err((ep - em) / (2 * eps), grad[:, a]) < RTOL
        jac = (two_node_blocks(gp, hp)[0] - two_node_blocks(gm, hm)[0]) / (2 * eps)
        assert rel_err(jac, hess[:, :, a]) < RTOL
    # a rigid translation of the edge costs nothing
    assert np.allclose(grad[:, :3] + grad[:, 3:], 0.0, atol=0.0)


# --------------------------------------------------------------------------- curvatures and twist
@pytest.mark.parametrize("nodes", RESOLUTIONS)
@pytest.mark.parametrize("seed", SEEDS)
def test_curvature_and_twist_derivatives_match_finite_differences(nodes, seed):
    """kappa_n, kappa_g and tau: stencil gradients match FD of the values, Hessians the
    symmetrised FD Jacobian of the gradients (frames transported from the committed state)."""
    model, q = committed_model_and_state(nodes, seed)
    scale = rod_dof_scale(model)
    index = stencil_dofs(model)
    sscale = scale[index]  # (n, 11)
    n_st = nodes - 2

    def quantities(qq):
        x, m1, m2, m_ref = stencil_frames(model, qq)
        strains, grads, hessians = strain_derivatives(x, m1, m2)
        tau = discrete_twist(qq[model.theta_dofs], m_ref)
        return {"kappa_n": (strains[:, 0], grads[:, 0], hessians[:, 0]),
                "kappa_g": (strains[:, 1], grads[:, 1], hessians[:, 1]),
                "tau": (tau, grads[:, 2], hessians[:, 2])}

    base = quantities(q)
    # the curvatures returned with their derivatives are those of material_curvatures
    kn0, kg0 = material_curvatures(*stencil_frames(model, q)[:3])
    assert rel_err(base["kappa_n"][0], kn0) < ROUNDOFF and rel_err(base["kappa_g"][0], kg0) < ROUNDOFF

    # FD over all global DOFs: the value vectors and the (scaled) stencil gradients
    values = {name: np.zeros((n_st, model.n_dof)) for name in base}
    grads = {name: np.zeros((n_st, 11, model.n_dof)) for name in base}
    for i in range(model.n_dof):
        step = np.zeros(model.n_dof)
        step[i] = REL_STEP * scale[i]
        plus, minus = quantities(q + step), quantities(q - step)
        for name in base:
            values[name][:, i] = (plus[name][0] - minus[name][0]) / (2 * REL_STEP)
            grads[name][:, :, i] = (plus[name][1] - minus[name][1]) * sscale / (2 * REL_STEP)

    rows = np.arange(n_st)[:, None]
    for name, (value, grad, hess) in base.items():
        # gradient: the full Jacobian of the value vector is zero outside each stencil
        jac = np.zeros((n_st, model.n_dof))
        jac[rows, index] = grad * sscale
        assert rel_err(values[name], jac) < RTOL, name
        # Hessian: symmetrised stencil-local Jacobian of the gradient
        fd = grads[name][rows[:, :, None], np.arange(11)[None, :, None], index[:, None, :]]
        fd_sym = 0.5 * (fd + fd.transpose(0, 2, 1))
        h = hess * sscale[:, :, None] * sscale[:, None, :]
        assert_symmetric(h)
        assert rel_err(fd_sym, h) < RTOL, name


# --------------------------------------------------------------------------- each energy
@pytest.mark.parametrize("name", ENERGIES)
@pytest.mark.parametrize("nodes", RESOLUTIONS)
@pytest.mark.parametrize("seed", SEEDS)
def test_each_energy_gradient_and_hessian_match_finite_differences(name, nodes, seed):
    """Stretching, bending and twisting separately: gradient = FD of the energy, Hessian =
    symmetrised FD Jacobian of that energy's own gradient."""
    model, q = committed_model_and_state(nodes, seed)
    scale = rod_dof_scale(model)
    energy, grad, hess = energy_part(model, q, name)
    assert energy > 0.0

    def func(qq):
        e, g, _ = energy_part(model, qq, name, hessian=False)
        return e, g * scale

    fd_grad, fd_jac = finite_differences(func, q, scale)
    assert rel_err(fd_grad, grad * scale) < RTOL
    hess_scaled = hess * np.outer(scale, scale)
    assert_symmetric(hess)
    assert rel_err(0.5 * (fd_jac + fd_jac.T), hess_scaled) < RTOL


@pytest.mark.parametrize("nodes", RESOLUTIONS)
@pytest.mark.parametrize("seed", SEEDS)
def test_model_assembles_exactly_the_three_energies(nodes, seed):
    """RodModel.evaluate (compiled passes writing straight into the band) equals the sum of the
    stretching, bending and twisting energies assembled densely from their own derivatives, part by part."""
    model, q = committed_model_and_state(nodes, seed)
    ev = model.evaluate(q)
    parts = {name: energy_part(model, q, name) for name in ENERGIES}
    for name in ENERGIES:
        assert ev.parts[name] == pytest.approx(parts[name][0], rel=1e-13), name
    assert ev.energy == pytest.approx(sum(ev.parts.values()), rel=1e-15)
    grad = sum(p[1] for p in parts.values())
    hess = sum(p[2] for p in parts.values())
    assert rel_err(ev.gradient, grad) < 1e-13
    assert rel_err(ev.hessian.to_dense(), hess) < 1e-13
    # the gradient-only path (no fused Hessian) gives the same energy and gradient
    ev_g = model.evaluate(q, gradient=True, hessian=False)
    assert ev_g.energy == pytest.approx(ev.energy, rel=1e-14)
    assert rel_err(ev_g.gradient, ev.gradient) < 1e-13
    ev_e = model.evaluate(q, gradient=False, hessian=False)
    assert ev_e.energy == pytest.approx(ev.energy, rel=1e-14) and ev_e.gradient is None


# --------------------------------------------------------------------------- total energy
@pytest.mark.parametrize("nodes", RESOLUTIONS)
@pytest.mark.parametrize("seed", SEEDS)
def test_total_gradient_and_hessian_match_finite_differences(nodes, seed):
    """The model's gradient is the FD gradient of its energy and its banded Hessian the
    symmetrised FD Jacobian of its gradient, at a committed generic state."""
    model, q = committed_model_and_state(nodes, seed)
    scale = rod_dof_scale(model)
    ev = model.evaluate(q)
    hess = ev.hessian.to_dense()
    fd_grad, fd_jac = finite_differences(model_energy_and_gradient(model), q, scale)
    assert rel_err(fd_grad, ev.gradient * scale) < RTOL
    assert rel_err(0.5 * (fd_jac + fd_jac.T), hess * np.outer(scale, scale)) < RTOL
    assert np.array_equal(hess, hess.T)
    # evaluating did not move the committed frames: a second evaluation is identical
    assert model.evaluate(q).energy == ev.energy


# --------------------------------------------------------------------------- stiffness pairing
def _planar_arc(model: RodModel, turning: float, plane_axis: int) -> np.ndarray:
    """Inextensible polygon with constant turning angle, tangent angles symmetric about +x,
    bent in the x-z plane (plane_axis=2) or the x-y plane (plane_axis=1)."""
    h = model.centerline.spacing
    edges = model.nodes - 1
    phi = turning * (np.arange(edges) - 0.5 * (edges - 1))
    t = np.zeros((edges, 3))
    t[:, 0], t[:, plane_axis] = np.cos(phi), np.sin(phi)
    x = np.zeros((model.nodes, 3))
    x[1:] = h * np.cumsum(t, axis=0)
    q = model.reset()
    q[model.node_dofs] = x
    return q


@pytest.mark.parametrize("nodes", RESOLUTIONS)
@pytest.mark.parametrize("plane_axis, stiffness_name", [(2, "bending_stiffness"), (1, "geodesic_bending_stiffness")])
def test_planar_arc_costs_its_bending_stiffness(nodes, plane_axis, stiffness_name):
    """An arc bent towards the normal m1 (x-z plane) has only kappa_n and costs EI2; an arc bent in
    the plane of the strip (x-y plane) has only kappa_g and costs EI1 = E b W^3 / 12. Energy
    sum EI kappa^2 / (2 dl) with kappa = 2 tan(phi/2); no twist, no stretch."""
    model = RodModel(STRIP, nodes)
    turning = 1.6 / (nodes - 2)
    q = _planar_arc(model, turning, plane_axis=plane_axis)
    x, m1, m2, m_ref = stencil_frames(model, q)
    kappa_n, kappa_g = material_curvatures(x, m1, m2)
    bent, unbent = (kappa_n, kappa_g) if plane_axis == 2 else (kappa_g, kappa_n)
    assert np.allclose(np.abs(bent), 2 * np.tan(turning / 2), rtol=1e-12)
    assert np.max(np.abs(unbent)) < 1e-12 * np.max(np.abs(bent))
    assert np.max(np.abs(m_ref)) < 1e-13
    ev = model.evaluate(q)
    stiffness = getattr(STRIP, stiffness_name)
    expected = (nodes - 2) * stiffness / (2 * model.centerline.spacing) * (2 * np.tan(turning / 2)) ** 2
    assert ev.parts["bending"] == pytest.approx(expected, rel=1e-12)
    assert ev.parts["twisting"] < 1e-24 * expected
    assert ev.parts["stretching"] < 1e-20 * expected


@pytest.mark.parametrize("nodes", RESOLUTIONS)
def test_uniform_twist_costs_GJ(nodes):
    """A straight strip twisted uniformly by alpha per edge: tau = alpha at every interior
    node, E = (M-2) GJ alpha^2 / (2 h), and no bending."""
    model = RodModel(STRIP, nodes)
    alpha = 0.4
    q = model.reset()
    q[model.theta_dofs] = alpha * np.arange(nodes - 1)
    ev = model.evaluate(q)
    expected = (nodes - 2) * STRIP.twisting_stiffness * alpha**2 / (2 * model.centerline.spacing)
    assert ev.parts["twisting"] == pytest.approx(expected, rel=1e-13)
    assert ev.parts["bending"] == 0.0
    # the twisting moments are equal and opposite at the two ends, zero inside
    moments = ev.gradient[model.theta_dofs]
    k = STRIP.twisting_stiffness / model.centerline.spacing
    assert moments[0] == pytest.approx(-k * alpha, rel=1e-13)
    assert moments[-1] == pytest.approx(k * alpha, rel=1e-13)
    assert np.max(np.abs(moments[1:-1])) < 1e-13 * k * alpha


@pytest.mark.parametrize("nodes", RESOLUTIONS)
def test_uniform_extension_costs_EA(nodes):
    """Stretching the straight strip by a strain eps: E = (M-1) EA h eps^2 / 2, tension EA eps."""
    model = RodModel(STRIP, nodes)
    strain = 1e-3
    q = model.reset()
    q[model.node_dofs] *= 1.0 + strain
    ev = model.evaluate(q)
    h = model.centerline.spacing
    expected = (nodes - 1) * 0.5 * STRIP.stretching_stiffness * h * strain**2
    assert ev.parts["stretching"] == pytest.approx(expected, rel=1e-9)
    assert ev.parts["bending"] == 0.0 and ev.parts["twisting"] == 0.0
    # end forces: -EA eps on x_0, +EA eps on x_{M-1} (dE/dx), zero on interior nodes
    forces = ev.gradient[model.node_dofs]
    assert forces[-1] == pytest.approx([STRIP.stretching_stiffness * strain, 0, 0], rel=1e-9)
    assert forces[0] == pytest.approx([-STRIP.stretching_stiffness * strain, 0, 0], rel=1e-9)
    assert np.max(np.abs(forces[1:-1])) < 1e-9 * STRIP.stretching_stiffness * strain


# --------------------------------------------------------------------------- rigid motions
def _rotation(seed: int) -> np.ndarray:
    a = np.random.default_rng(100 + seed).standard_normal((3, 3))
    r, upper = np.linalg.qr(a)
    r = r * np.sign(np.diag(upper))
    if np.linalg.det(r) < 0:
        r[:, 0] *= -1
    return r


@pytest.mark.parametrize("nodes", RESOLUTIONS)
@pytest.mark.parametrize("seed", SEEDS)
def test_rigid_rotation_and_translation_leave_the_energy_unchanged(nodes, seed):
    """Two rods reach the same deformed state, one in a rotated and translated copy of space
    (rotated rest frames, rotated perturbations, same twist increments): equal energy and
    parts; gradient and Hessian rotate with the positions."""
    rot = _rotation(seed)
    shift = np.array([0.3, -0.2, 0.05])
    a, b = RodModel(STRIP, nodes), RodModel(STRIP, nodes)
    qa = a.reset()
    qb = b.reset()
    t0, d10, ref0 = b.save_frames()
    b.restore_frames((t0 @ rot.T, d10 @ rot.T, ref0))
    qb[b.node_dofs] = qb[b.node_dofs] @ rot.T + shift

    rng = np.random.default_rng(seed)
    h = a.centerline.spacing
    for _ in range(3 + seed % 3):
        dx = 0.085 * h * rng.standard_normal((nodes, 3))
        dtheta = 0.3 * rng.standard_normal(nodes - 1)
        qa, qb = qa.copy(), qb.copy()
        qa[a.node_dofs] += dx
        qb[b.node_dofs] += dx @ rot.T
        qa[a.theta_dofs] += dtheta
        qb[b.theta_dofs] += dtheta
        a.commit(qa)
        b.commit(qb)

    ea, eb = a.evaluate(qa), b.evaluate(qb)
    assert eb.energy == pytest.approx(ea.energy, rel=ROUNDOFF)
    for name in ENERGIES:
        assert eb.parts[name] == pytest.approx(ea.parts[name], rel=ROUNDOFF), name

    # forces rotate with the body, twisting moments are unchanged
    rotated = ea.gradient.copy()
    rotated[a.node_dofs] = ea.gradient[a.node_dofs] @ rot.T
    assert rel_err(eb.gradient, rotated) < ROUNDOFF
    big_q = np.eye(a.n_dof)
    for i in range(nodes):
        big_q[np.ix_(a.node_dofs[i], a.node_dofs[i])] = rot
    assert rel_err(eb.hessian.to_dense(), big_q @ ea.hessian.to_dense() @ big_q.T) < ROUNDOFF


@pytest.mark.parametrize("nodes", RESOLUTIONS)
@pytest.mark.parametrize("seed", SEEDS)
def test_internal_forces_and_moments_are_balanced(nodes, seed):
    """At any state, the gradient is orthogonal to rigid motions: the nodal forces sum to
    zero (translations) and the gradient vanishes along an infinitesimal rigid rotation
    omega, which moves x_i by omega x x_i and, since reference frames are transported
    without twist, turns each material frame by the extra angle omega . t^e."""
    model, q = committed_model_and_state(nodes, seed)
    ev = model.evaluate(q)
    forces = ev.gradient[model.node_dofs]
    assert np.linalg.norm(forces.sum(axis=0)) < ROUNDOFF * np.linalg.norm(forces)

    scale = rod_dof_scale(model)
    tangents = model.frames(q)[0]
    x = model.positions(q)
    x = x - x.mean(axis=0)  # rotation about the centroid (translations already checked)
    for omega in np.eye(3):
        v = np.zeros(model.n_dof)
        v[model.node_dofs] = np.cross(omega, x)
        v[model.theta_dofs] = tangents @ omega
        # in scaled DOFs, |g . v| relative to |g| |v|
        gs, vs = ev.gradient * scale, v / scale
        assert abs(gs @ vs) < ROUNDOFF * np.linalg.norm(gs) * np.linalg.norm(vs)
