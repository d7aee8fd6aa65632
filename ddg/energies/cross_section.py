"""The cross-section as a field: a strip's energy per unit length when its cross-section bends (the
long-wavelength reduction of Audoly and Neukirch 2021, JMPS, with the cross-section kept as an
unknown field along the strip instead of eliminated point by point). Every term derived, its limits
and why a field: docs/physics/cross_section.rst; the labels F, X, X' and V are this module's.

A strip of width W, thickness b, Young's modulus E, Poisson ratio nu, plate stiffness
D = E b^3 / (12 (1 - nu^2)), has centreline strains per unit length eps (stretch), kappa (normal
curvature, the rod's kappa_n), tau (twist) and kappa_g (in-plane curvature). Across the width,
y in [-W/2, W/2], the even part of its deflection w(x, y) is written in n modes,

    w_yy = sum_j c_j y^(2j - 2),  w = sum_j c_j (B_j(y) - <B_j>),  B_j = y^(2j) / ((2j - 1) 2j),

c_1 the transverse curvature at mid-width (1/m), <.> the mean over the width (the centroid
convention, int w dy = 0). The free-edged Foppl-von Karman strip (F) integrates over the width to
the rod's energy plus this module's density (J/m)

    f = E b [eps m . v + v . S v / 2] + (D / 2) [c . P c + 2 nu kappa p . c + nu^2 W kappa^2]
        + D (1 - nu) c' . Q c' + E b [kappa_g tau c' . a + tau^2 c' . Psi c' / 2],              (X)

with v = (tau^2, -kappa c_1, ..., -kappa c_n), c' = dc/dx and m, S, P, p, a, Psi, Q integrals over
the width (CrossSectionModes); plus the modes' bending along the strip,
(D / 2) [c'' . R c'' + 2 nu c'' . N c] with c' = 0 at a clamp (X'), and the torsion-warping of the
cross-section's rotation, E Gamma tau'^2 / 2 with E Gamma = D W^3 / 12 and tau = 0 at a clamp (V).
Its limits are exact: c = 0 is the trapeze ribbon (ddg.energies.trapeze); tau = 0, nu = 0 the rod
and the elastica; uniform strains with c eliminated the Audoly-Neukirch density
E b W^5 Psi(k^4) (nu kappa^2 + tau^2)^2 / 8, k^4 = 3 (1 - nu^2) kappa^2 W^4 / b^2 (`psi`,
`foundation_share`; `local_optimum` gives the modes' approximation of it).

Discretely c^e lives on the edges (after each twist angle, ddg.models.wide_ribbons), zero on the two
clamped edges. Per interior node i with Voronoi length l, from the rod's integrated strains and the
Voronoi mean stretch (ddg.energies.stencil_coupling):

    E_i = l f(eps_i, kappa_i / l, tau_i / l, (c^{i-1} + c^i) / 2),  c' = (c^i - c^{i-1}) / l,  kappa_g -> kappa_g_i / l.

`field_density` returns E_i and its exact first and second partials (f is a polynomial); Eq. X' is a
constant quadratic form in the modes (`modes_curvature_form`); Eq. V couples neighbouring stencils'
twists (`torsion_warping`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

__all__ = ["CrossSectionModes", "field_density", "modes_curvature_form", "torsion_warping", "torsion_warping_stiffness",
           "local_optimum",
           "psi", "foundation_share", "SERIES_BELOW"]


def _width_integral(power: np.ndarray | int, width: float):
    """int_{-W/2}^{W/2} y^power dy for even powers."""
    power = np.asarray(power)
    return 2.0 * (0.5 * width) ** (power + 1) / (power + 1)


@dataclass(frozen=True)
class CrossSectionModes:
    """The width integrals of (X) for n modes of a strip's cross-section, and its stiffnesses."""

    width: float
    thickness: float
    young_modulus: float
    poisson_ratio: float
    modes: int

    def __post_init__(self):
        if not (isinstance(self.modes, (int, np.integer)) and 1 <= self.modes <= 4):
            raise ValueError(f"modes = {self.modes!r} outside the allowed range 1 .. 4")
        w, n = self.width, self.modes
        j = np.arange(1, n + 1)
        # phi = (B_1, B_1 .. B_n): powers and denominators of y^(2j) / ((2j - 1) 2j)
        powers = np.r_[2, 2 * j]
        denominators = np.r_[2.0, (2 * j - 1) * 2.0 * j]
        raw_m = _width_integral(powers, w) / denominators
        raw_s = _width_integral(powers[:, None] + powers[None, :], w) / (denominators[:, None] * denominators[None, :])
        # the modes about their means (the centroid convention): phi_a - <phi_a> for a >= 1
        shift = np.r_[0.0, raw_m[1:] / w]
        m = raw_m - w * shift
        s = raw_s - np.outer(raw_m, shift) - np.outer(shift, raw_m) + w * np.outer(shift, shift)
        p = _width_integral(2 * j - 2, w)
        big_p = _width_integral((2 * j - 2)[:, None] + (2 * j - 2)[None, :], w)
        odd = 2 * j - 1
        q = _width_integral(odd[:, None] + odd[None, :], w) / (odd[:, None] * odd[None, :])
        object.__setattr__(self, "m", m)
        object.__setattr__(self, "S", s)
        object.__setattr__(self, "p", p)
        object.__setattr__(self, "P", big_p)
        object.__setattr__(self, "Q", q)
        # the odd strain of a changing cross-section, psi_j = 2 y^(2j + 1) / ((2j - 1) 2j (2j + 1))
        d = (2 * j - 1) * 2.0 * j * (2 * j + 1)
        object.__setattr__(self, "a", 2.0 * _width_integral(2 * j + 2, w) / d)
        object.__setattr__(self, "Psi", 4.0 * _width_integral((2 * j + 1)[:, None] + (2 * j + 1)[None, :], w)
                           / (d[:, None] * d[None, :]))

    @property
    def constant_hessian(self) -> np.ndarray:
        """The Hessian of G = E b [eps m . v + v . S v / 2] in (eps, v) (Eq. X), (n + 2, n + 2)."""
        n = self.modes
        h_g = np.zeros((n + 2, n + 2))
        h_g[0, 1:] = h_g[1:, 0] = self.membrane * self.m
        h_g[1:, 1:] = self.membrane * self.S
        return h_g

    @property
    def membrane(self) -> float:
        """E b: the membrane stiffness per unit width."""
        return self.young_modulus * self.thickness

    @property
    def plate(self) -> float:
        """D = E b^3 / (12 (1 - nu^2))."""
        nu = self.poisson_ratio
        return self.young_modulus * self.thickness**3 / (12.0 * (1.0 - nu * nu))


@njit(cache=True)
def _point_terms(eps, k, t, c, m, s, big_p, p, eb, d, nu, width, jac, h_g, g_w, f_z, f_zz):
    """f of (X) without its c' terms at one point z = (eps, kappa, tau, c_1 .. c_n): returns f and
    fills its partials f_z (3 + n) and second partials f_zz (3 + n, 3 + n); jac (n + 2, 3 + n),
    h_g (n + 2, n + 2) and g_w (n + 2) are work arrays (h_g holds the constant Hessian of G)."""
    n = c.shape[0]
    size = 3 + n
    # G(eps, v) = E b [eps m . v + v . S v / 2], v = (tau^2, -kappa c_1, .., -kappa c_n)
    mv = m[0] * t * t
    for j in range(n):
        mv -= m[1 + j] * k * c[j]
    vsv = 0.0
    for a in range(n + 1):
        va = t * t if a == 0 else -k * c[a - 1]
        sva = s[a, 0] * t * t
        for b in range(n):
            sva -= s[a, 1 + b] * k * c[b]
        vsv += va * sva
        g_w[1 + a] = eb * (eps * m[a] + sva)
    g_w[0] = eb * mv
    value = eb * (eps * mv + 0.5 * vsv)
    # w = (eps, v) as functions of z: its Jacobian, then f_z = J^T g_w, f_zz = J^T h_G J + sum g_w w''
    for a in range(n + 2):
        for b in range(size):
            jac[a, b] = 0.0
    jac[0, 0] = 1.0
    jac[1, 2] = 2.0 * t
    for j in range(n):
        jac[2 + j, 1] = -c[j]
        jac[2 + j, 3 + j] = -k
    for b in range(size):
        acc = 0.0
        for a in range(n + 2):
            acc += jac[a, b] * g_w[a]
        f_z[b] = acc
    for b in range(size):
        for e in range(b, size):
            acc = 0.0
            for a in range(n + 2):
                if jac[a, b] != 0.0:
                    for r in range(n + 2):
                        acc += jac[a, b] * h_g[a, r] * jac[r, e]
            f_zz[b, e] = acc
            f_zz[e, b] = acc
    f_zz[2, 2] += 2.0 * g_w[1]                    # d2 (tau^2) / dtau2
    for j in range(n):                            # d2 (-kappa c_j) / dkappa dc_j
        f_zz[1, 3 + j] -= g_w[2 + j]
        f_zz[3 + j, 1] -= g_w[2 + j]
    # the plate's bending beyond the rod's: (D / 2) [c . P c + 2 nu kappa p . c + nu^2 W kappa^2]
    pc_c = 0.0
    p_c = 0.0
    for i in range(n):
        pci = 0.0
        for j in range(n):
            pci += big_p[i, j] * c[j]
            f_zz[3 + i, 3 + j] += d * big_p[i, j]
        pc_c += c[i] * pci
        p_c += p[i] * c[i]
        f_z[3 + i] += d * (pci + nu * k * p[i])
        f_zz[1, 3 + i] += d * nu * p[i]
        f_zz[3 + i, 1] += d * nu * p[i]
    value += 0.5 * d * (pc_c + 2.0 * nu * k * p_c + nu * nu * width * k * k)
    f_z[1] += d * (nu * p_c + nu * nu * width * k)
    f_zz[1, 1] += d * nu * nu * width
    return value


@njit(cache=True)
def _point_kernel(eps, k, t, c, m, s, big_p, p, eb, d, nu, width, h_g, value, first, second):
    n = c.shape[1]
    jac = np.empty((n + 2, 3 + n))
    g_w = np.empty(n + 2)
    for i in range(len(eps)):
        value[i] = _point_terms(eps[i], k[i], t[i], c[i], m, s, big_p, p, eb, d, nu, width, jac, h_g, g_w,
                                first[i], second[i])


def _point_density(eps, k, t, c, modes: CrossSectionModes):
    """f of (X) without its c' term at points (eps, k, t, c (N, n)): values (N,), partials (N, 3 + n)
    and second partials (N, 3 + n, 3 + n) in z = (eps, kappa, tau, c_1 .. c_n)."""
    eps, k, t = (np.ascontiguousarray(a, dtype=float) for a in (eps, k, t))
    c = np.ascontiguousarray(c, dtype=float)
    count, n = c.shape
    value, first, second = np.empty(count), np.empty((count, 3 + n)), np.empty((count, 3 + n, 3 + n))
    _point_kernel(eps, k, t, c, modes.m, modes.S, modes.P, modes.p, modes.membrane, modes.plate,
                  modes.poisson_ratio, modes.width, modes.constant_hessian, value, first, second)
    return value, first, second


@njit(cache=True)
def field_kernel(eps, kappa, kappa_g, tau, c_before, c_after, ell, m, s, big_p, p, q, a, big_psi, eb, d, nu,
                  width, h_g, energy, first, second):
    count, n = c_before.shape
    size = 4 + 2 * n
    jac = np.empty((n + 2, 3 + n))
    g_w = np.empty(n + 2)
    f_z = np.empty(3 + n)
    f_zz = np.empty((3 + n, 3 + n))
    c_mean = np.empty(n)
    dc = np.empty(n)
    qdc = np.empty(n)
    pdc = np.empty(n)
    z_of_u = np.empty(size, np.int64)   # u = (eps, kappa, kappa_g, tau, c^{i-1}, c^i) -> z (-1: kappa_g)
    z_of_u[0], z_of_u[1], z_of_u[2], z_of_u[3] = 0, 1, -1, 2
    for j in range(n):
        z_of_u[4 + j] = 3 + j
        z_of_u[4 + n + j] = 3 + j
    scale = np.empty(size)
    g = d * (1.0 - nu)
    for i in range(count):
        length = ell[i]
        for j in range(n):
            c_mean[j] = 0.5 * (c_before[i, j] + c_after[i, j])
        f = _point_terms(eps[i], kappa[i] / length, tau[i] / length, c_mean, m, s, big_p, p, eb, d, nu, width,
                         jac, h_g, g_w, f_z, f_zz)
        # u -> z = (eps, kappa / length, tau / length, (c^{i-1} + c^i) / 2): E_i = length f
        scale[0], scale[1], scale[2], scale[3] = length, 1.0, 0.0, 1.0
        for j in range(2 * n):
            scale[4 + j] = 0.5 * length
        fi = first[i]
        se = second[i]
        for r in range(size):
            zr = z_of_u[r]
            fi[r] = scale[r] * f_z[zr] if zr >= 0 else 0.0
            for col in range(size):
                zc = z_of_u[col]
                se[r, col] = f_zz[zr, zc] * scale[r] * scale[col] / length if zr >= 0 and zc >= 0 else 0.0
        # terms of dc = c^i - c^{i-1}: the twisting of a changing cross-section, D (1 - nu) dc . Q dc / length,
        # and the odd strain -tau c' . psi(y): E b [kappa_g tau dc . a / length^2 + tau^2 dc . Psi dc / (2 length^3)]
        for j in range(n):
            dc[j] = c_after[i, j] - c_before[i, j]
        qq = 0.0
        adc = 0.0
        dpd = 0.0
        for j in range(n):
            qj = 0.0
            pj = 0.0
            for r in range(n):
                qj += q[j, r] * dc[r]
                pj += big_psi[j, r] * dc[r]
            qdc[j], pdc[j] = qj, pj
            qq += dc[j] * qj
            adc += a[j] * dc[j]
            dpd += dc[j] * pj
        kg, t = kappa_g[i], tau[i]
        l2, l3 = length * length, length * length * length
        energy[i] = length * f + g * qq / length + eb * (kg * t * adc / l2 + 0.5 * t * t * dpd / l3)
        fi[2] += eb * t * adc / l2
        fi[3] += eb * (kg * adc / l2 + t * dpd / l3)
        se[2, 3] += eb * adc / l2
        se[3, 2] += eb * adc / l2
        se[3, 3] += eb * dpd / l3
        for j in range(n):
            d_dc = 2.0 * g * qdc[j] / length + eb * (kg * t / l2 * a[j] + t * t / l3 * pdc[j])
            g_dc = eb * t / l2 * a[j]                                   # d2 / dkappa_g d(dc)
            t_dc = eb * (kg / l2 * a[j] + 2.0 * t / l3 * pdc[j])        # d2 / dtau d(dc)
            for block, sign in ((4, -1.0), (4 + n, 1.0)):
                fi[block + j] += sign * d_dc
                se[2, block + j] += sign * g_dc
                se[block + j, 2] += sign * g_dc
                se[3, block + j] += sign * t_dc
                se[block + j, 3] += sign * t_dc
            for r in range(n):
                dcdc = 2.0 * g * q[j, r] / length + eb * t * t / l3 * big_psi[j, r]
                se[4 + j, 4 + r] += dcdc
                se[4 + n + j, 4 + n + r] += dcdc
                se[4 + j, 4 + n + r] -= dcdc
                se[4 + n + j, 4 + r] -= dcdc


def field_density(eps, kappa, kappa_g, tau, c_before, c_after, voronoi_lengths, modes: CrossSectionModes):
    """E_i per stencil (N,) and its partials (N, 4 + 2n) and second partials (N, 4 + 2n, 4 + 2n) in
    the stencil's strains u = (eps_i, kappa_i, kappa_g_i, tau_i, c^{i-1}_1..n, c^i_1..n): kappa,
    kappa_g, tau the rod's integrated strains (Eqs. 3-5), eps the Voronoi mean stretch,
    c_before/c_after (N, n) the cross-section modes of the stencil's two edges. Compiled
    (`field_kernel`, one pass over the stencils)."""
    arrays = [np.ascontiguousarray(x, dtype=float) for x in (eps, kappa, kappa_g, tau, c_before, c_after,
                                                              voronoi_lengths)]
    count, n = arrays[4].shape
    size = 4 + 2 * n
    energy, first, second = np.empty(count), np.empty((count, size)), np.empty((count, size, size))
    field_kernel(*arrays, modes.m, modes.S, modes.P, modes.p, modes.Q, modes.a, modes.Psi, modes.membrane,
                  modes.plate, modes.poisson_ratio, modes.width, modes.constant_hessian, energy, first, second)
    return energy, first, second


def torsion_warping_stiffness(modes: CrossSectionModes) -> float:
    """E Gamma = D W^3 / 12: the bending of the fibres of a cross-section whose rotation theta(x)
    changes at a changing rate (w = theta y, w_xx = tau' y), Eq. V."""
    return modes.plate * modes.width**3 / 12.0


def torsion_warping(tau, voronoi_lengths, pair_lengths, stiffness: float):
    """Eq. V discretely: E Gamma / 2 int tau'^2, tau' between neighbouring nodes i, i + 1 as
    (tau_{i+1} / l_{i+1} - tau_i / l_i) / d_i (d_i their distance, the rest length of the edge
    between them), and at each clamp, where tau = 0, over the half edge between the clamp point and
    the first interior node: E Gamma (tau_0 / l_0)^2 / h_0 and likewise at the end.

    Returns the pairs' energies (n - 1,), partials (n - 1, 2) and second partials (n - 1, 2, 2) in
    (tau_i, tau_{i+1}) (integrated twists, Eq. 5), then the two clamp terms' energies (2,),
    partials (2,) and second partials (2,) in tau_0 and tau_{n-1}."""
    return torsion_warping_terms(np.ascontiguousarray(tau, dtype=float),
                                 np.ascontiguousarray(voronoi_lengths, dtype=float),
                                 np.ascontiguousarray(pair_lengths, dtype=float), float(stiffness))


@njit(cache=True)
def torsion_warping_terms(tau, ell, pair_lengths, stiffness):
    """torsion_warping on float arrays (compiled; the one-call assembly calls it)."""
    n = tau.shape[0]
    energy = np.empty(n - 1)
    first = np.empty((n - 1, 2))
    second = np.empty((n - 1, 2, 2))
    for i in range(n - 1):
        a, b = 1.0 / ell[i], 1.0 / ell[i + 1]
        jump = tau[i + 1] / ell[i + 1] - tau[i] / ell[i]
        k = stiffness / pair_lengths[i]
        energy[i] = 0.5 * k * jump * jump
        first[i, 0] = -k * jump * a
        first[i, 1] = k * jump * b
        second[i, 0, 0] = k * a * a
        second[i, 1, 1] = k * b * b
        second[i, 0, 1] = -k * a * b
        second[i, 1, 0] = -k * a * b
    # the clamps: tau = 0 at s = 0 and L; the clamp point is the clamped edge's midpoint, so the
    # first node is half an edge, l_0 / 2 on the uniform centreline, from it
    end_energy = np.empty(2)
    end_first = np.empty(2)
    end_second = np.empty(2)
    for k, end in enumerate((0, n - 1)):
        c = stiffness / (0.5 * ell[end]) / ell[end] ** 2
        end_energy[k] = 0.5 * c * tau[end] ** 2
        end_first[k] = c * tau[end]
        end_second[k] = c
    return energy, first, second, end_energy, end_first, end_second


@njit(cache=True)
def add_pair_partials(f_u, f_uu, pair_first, pair_second, index):
    """A pair energy's per-stencil partials (torsion_warping_terms' pairs, in the strain at
    u[index] of neighbouring stencils) added into the stencils' f_u (n, k) and f_uu (n, k, k); the
    mixed partials pair_second[:, 0, 1] couple two stencils (rod_curvature.add_pair_cross_terms)."""
    for i in range(f_u.shape[0] - 1):
        f_u[i, index] += pair_first[i, 0]
        f_u[i + 1, index] += pair_first[i, 1]
        f_uu[i, index, index] += pair_second[i, 0, 0]
        f_uu[i + 1, index, index] += pair_second[i, 1, 1]


@njit(cache=True)
def add_torsion_warping_partials(f_u, f_uu, pair_first, pair_second, end_first, end_second):
    """Eq. V's partials per twist (torsion_warping's pairs and clamp terms) added into the
    stencils' partials f_u (n, k) and f_uu (n, k, k) in u = (eps, kappa_n, kappa_g, tau, ...), the
    twist at u[3]. The mixed partials of neighbouring twists (pair_second[:, 0, 1]) couple two
    stencils: rod_curvature.add_pair_cross_terms adds them."""
    count = f_u.shape[0]
    add_pair_partials(f_u, f_uu, pair_first, pair_second, 3)
    f_u[0, 3] += end_first[0]
    f_u[count - 1, 3] += end_first[1]
    f_uu[0, 3, 3] += end_second[0]
    f_uu[count - 1, 3, 3] += end_second[1]


@njit(cache=True)
def modes_bending_terms(rows, cols, values, q, n_dof, want_gradient, want_hessian, grad, band):
    """Eq. X' as the constant quadratic form 1/2 q . K q of modes_curvature_form (K's lower triangle
    rows >= cols, values): returns the energy, adds K q to grad and K's entries to the flattened
    lower band (entry (r, c) at band[(r - c) n_dof + c])."""
    force = np.zeros(n_dof)
    for k in range(rows.shape[0]):
        r, c, v = rows[k], cols[k], values[k]
        force[r] += v * q[c]
        if r != c:
            force[c] += v * q[r]
    if want_gradient:
        grad += force
        if want_hessian:
            for k in range(rows.shape[0]):
                band[(rows[k] - cols[k]) * n_dof + cols[k]] += values[k]
    return 0.5 * np.dot(q, force)


def modes_curvature_form(field_dofs: np.ndarray, spacing: float, modes: CrossSectionModes):
    """Eq. X': the modes' bending along the strip, (D / 2) int [c'' . R c'' + 2 nu c'' . N c] dx,
    R_ij = int (B_i - <B_i>)(B_j - <B_j>) dy, N_ij = int (B_i - <B_i>) y^(2j - 2) dy, with c'' the
    second difference of the edges' modes, (c^{e+1} - 2 c^e + c^{e-1}) / h^2 over each interior edge
    (weight h), and c' = 0 at the clamp points, the clamped edges' midpoints (ghost c^{-1} = c^1,
    weight h / 2), since a clamp holds w_x = 0 across its width. A constant quadratic form in the
    DOFs: returns its lower triangle (rows, cols, values), rows >= cols, on a uniform centreline of
    spacing h; field_dofs (M - 1, n) the modes' DOFs per edge."""
    n = modes.modes
    r = np.asarray(modes.S)[1:1 + n, 1:1 + n] * modes.plate
    j = np.arange(1, n + 1)
    w = modes.width
    centred = np.r_[2 * j]  # B_j - <B_j> against y^(2k - 2): int B_j y^(2k-2) - <B_j> int y^(2k-2)
    raw = _width_integral(centred[:, None] + (2 * j - 2)[None, :], w) / ((2 * j - 1) * 2.0 * j)[:, None]
    mean = (_width_integral(2 * j, w) / ((2 * j - 1) * 2.0 * j) / w)[:, None] * _width_integral(2 * j - 2, w)[None, :]
    coupling = modes.plate * modes.poisson_ratio * (raw - mean)
    h = float(spacing)
    edges = field_dofs.shape[0]
    entries = {}

    def add(second, weight, own=None):
        """second: [(edge, coefficient)] of c'' at one edge; own: that edge (for the nu term)."""
        for e1, a1 in second:
            for e2, a2 in second:
                block = weight * a1 * a2 * r
                for i in range(n):
                    for k in range(n):
                        key = (field_dofs[e1, i], field_dofs[e2, k])
                        entries[key] = entries.get(key, 0.0) + block[i, k]
            if own is not None and modes.poisson_ratio != 0.0:
                block = weight * a1 * coupling
                for i in range(n):
                    for k in range(n):
                        for key in ((field_dofs[e1, i], field_dofs[own, k]), (field_dofs[own, k], field_dofs[e1, i])):
                            entries[key] = entries.get(key, 0.0) + block[i, k]

    for e in range(1, edges - 1):
        add([(e - 1, 1.0 / h**2), (e, -2.0 / h**2), (e + 1, 1.0 / h**2)], h, own=e)
    add([(0, -2.0 / h**2), (1, 2.0 / h**2)], 0.5 * h)
    add([(edges - 1, -2.0 / h**2), (edges - 2, 2.0 / h**2)], 0.5 * h)
    lower = [(row, col, value) for (row, col), value in entries.items() if row >= col]
    rows, cols, values = (np.array(x) for x in zip(*lower))
    return rows.astype(np.int64), cols.astype(np.int64), values.astype(float)


def local_optimum(kappa, tau, modes: CrossSectionModes):
    """The least energy of the cross-section at uniform strains (kappa, tau per unit length, c' = 0),
    with the mid-fibre stretch eps relaxed too: min over (eps, c) of E b W eps^2 / 2 + f (Eq. X),
    a quadratic, so one linear solve each. Returns (eps, c (N, n), energy (N,)): the energy beyond
    the rod's bending and twisting that the Audoly-Neukirch density gives exactly as
    E b W^5 Psi(k^4) (nu kappa^2 + tau^2)^2 / 8 (`psi`)."""
    kappa, tau = (np.atleast_1d(np.asarray(a, dtype=float)) for a in (kappa, tau))
    n = modes.modes
    zero = np.zeros(len(kappa))
    value, first, second = _point_density(zero, kappa, tau, np.zeros((len(kappa), n)), modes)
    unknowns = np.r_[0, 3 + np.arange(n)]  # eps and the modes
    hessian = second[:, unknowns][:, :, unknowns]
    hessian[:, 0, 0] += modes.membrane * modes.width
    solution = -np.linalg.solve(hessian, first[:, unknowns][..., None])[..., 0]
    eps, c = solution[:, 0], solution[:, 1:]
    energy = _point_density(eps, kappa, tau, c, modes)[0] + 0.5 * modes.membrane * modes.width * eps**2
    return eps, c, energy


#: Taylor coefficients of Psi(s) = sum_n a_n s^n (exact rationals from the series of Phi(k) / k^4,
#: tests/ddg/energies/test_cross_section.py re-derives the first ones); the radius of convergence is about
#: s = 125, so at s < SERIES_BELOW = 4 the 14 terms leave a relative error below 1e-20.
_SERIES = np.array([
    1 / 180, -1 / 22680, 2879 / 8172964800, -3911 / 1389404016000,
    74070881 / 3292970882160960000, -226894807 / 1262305504828368000000,
    1.4363508775581876e-15, -1.1477862247352584e-17, 9.171945645653379e-20,
    -7.329290517165085e-22, 5.8568270637827055e-24, -4.68018332398229e-26,
    3.739928754518298e-28, -2.98857248116756e-30])
SERIES_BELOW = 4.0


def foundation_share(k):
    """Phi(k) = 1 - (2 / k) (cosh k - cos k) / (sinh k + sin k) (k > 0) and its first two
    derivatives in k, each scaled by e^-k so that no term overflows."""
    k = np.asarray(k, dtype=float)
    e = np.exp(-k)
    sh, ch = 0.5 * (1.0 - e * e), 0.5 * (1.0 + e * e)  # e^-k sinh k, e^-k cosh k
    sn, co = e * np.sin(k), e * np.cos(k)
    den = sh + sn
    r = (ch - co) / den
    r1 = 2.0 * sh * sn / den**2
    r2 = 2.0 * e * (ch * np.sin(k) + sh * np.cos(k)) / den**2 - 4.0 * sh * sn * (ch + co) / den**3
    phi = 1.0 - 2.0 * r / k
    phi1 = 2.0 * r / k**2 - 2.0 * r1 / k
    phi2 = -4.0 * r / k**3 + 4.0 * r1 / k**2 - 2.0 * r2 / k
    return phi, phi1, phi2


def psi(s):
    """Psi(s) = Phi(s^(1/4)) / s (s >= 0) and its first and second derivatives in s (arrays)."""
    s = np.asarray(s, dtype=float)
    value, first, second = np.empty_like(s), np.empty_like(s), np.empty_like(s)
    small = s < SERIES_BELOW
    if np.any(small):
        x = s[small]
        n = np.arange(len(_SERIES))
        powers = x[:, None] ** n[None, :]
        value[small] = powers @ _SERIES
        first[small] = (powers[:, :-1] * n[None, 1:]) @ _SERIES[1:]
        second[small] = (powers[:, :-2] * (n[2:] * (n[2:] - 1))[None, :]) @ _SERIES[2:]
    large = ~small
    if np.any(large):
        x = s[large]
        k = x**0.25
        phi, phi1, phi2 = foundation_share(k)
        k1 = 0.25 / k**3          # dk/ds
        k2 = -3.0 / (16.0 * k**7)  # d2k/ds2
        value[large] = phi / x
        first[large] = phi1 * k1 / x - phi / x**2
        second[large] = (phi2 * k1**2 + phi1 * k2) / x - 2.0 * phi1 * k1 / x**2 + 2.0 * phi / x**3
    return value, first, second


