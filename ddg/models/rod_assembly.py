"""The DAR's energy, gradient and banded Hessian in one compiled call (paper section 3.1, Eq. 6),
and with the quartic twist term of Eq. (A.5) for the Sadowsky ribbon.

The same pieces as the model's Python composition (ddg.models.rod.RodModel.evaluate): frames
transported in time (ddg.geometry.frames.rod_frames), the material curvatures (Eq. 4) and the
twist (Eq. 5), the densities of bending (Eq. 6b), twisting (Eq. 6c) and, where zeta > 0, the
Sadowsky term (ddg.energies.sadowsky), the stretching of the edges (Eq. 6a) and the stencils'
chain rule (ddg.energies.rod_curvature.add_stencil_terms); no physics is written here. One call
instead of a dozen spares the interpreter's dispatches (docs/findings/measured.md), and it is what
the compiled Newton loop (ddg.solve.compiled_newton) calls.

The ribbons with width add their terms in the same call, chosen by the kind in `args`'s last entry
(the width terms, `width_terms`; kind ROD adds nothing) and compiled apart per kind (ENERGIES, by
ddg.assembly.specialise: a model compiles only its own terms): the trapeze term's stretch-twist coupling
(ddg.energies.trapeze) on the stencils' chain rule with the stretch (rod_curvature.
add_stretched_stencil_terms), Wunderlich's pairs of stencils (ddg.energies.wunderlich, their cross
terms by rod_curvature.add_pair_cross_terms), and the cross-section as a field (ddg.energies.
cross_section: Eq. X's density, Eq. V's torsion-warping and Eq. X's constant bending form). The
models' piecewise composition (RodModel.evaluate_piecewise, ddg.models.wide_ribbons) is the
reference this is tested against (tests/ddg/solve/test_compiled_newton.py).

`rod_energy(q, state, args, want_gradient, want_hessian, grad, band)`: state = the committed
(tangents, d1, m_ref); args = the model's constants (RodModel.assembly_args); grad (n,) and the
flattened lower band ((bandwidth + 1) n) are zeroed by the caller and added into. Returns the
energy by part (PARTS, zero where the model has no such part) and the frames of q (tangents, d1,
m_ref).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..energies.cross_section import (add_pair_partials, add_torsion_warping_partials, field_kernel,
                                      modes_bending_terms, torsion_warping_terms)
from ..energies.rod_bending import bending_density
from ..energies.rod_curvature import (STENCIL_SIZE, add_pair_cross_terms, add_stencil_terms,
                                      add_stretched_stencil_terms, curvature_rows)
from ..energies.rod_twist import discrete_twist, twisting_density
from ..energies.sadowsky import sadowsky_terms
from ..energies.stencil_coupling import stencil_stretch_values
from ..energies.stretch import add_edge_terms
from ..energies.trapeze import trapeze_density
from ..energies.wunderlich import wunderlich_pair_density
from ..geometry.frames import rod_frames
from ..assembly.specialise import specialise
from ..solve.compiled_newton import CompiledLoops, compile_loops

#: The parts rod_energy returns, in its order (zero where the model has no such term).
PARTS = ("stretching", "bending", "twisting", "sadowsky", "trapeze", "wunderlich", "cross_section",
         "torsion_warping", "cross_section_bending", "curvature_gradient")

#: The kinds of width terms (the first entry of `width_terms`).
ROD, TRAPEZE, WUNDERLICH, CROSS_SECTION = range(4)

#: How many vectors, matrices and index arrays the width terms carry (one layout for every kind:
#: the same argument types for every kind's compiled energy and loops).
_VECTORS, _MATRICES, _INDICES = 5, 5, 3


def width_terms(kind: int = ROD, reals=(), vectors=(), matrices=(), indices=(), table=None):
    """The last entry of RodModel.assembly_args: (kind, reals (k,), 5 float vectors, 5 float
    matrices, 3 int vectors, an int table), unused places empty. Per kind:

    - TRAPEZE: reals (C3, C5) of ddg.energies.trapeze;
    - WUNDERLICH: reals (W,), vectors (pair lengths, regularisation dl / zeta per stencil);
    - CROSS_SECTION: reals (E b, D, nu, W, E Gamma, B_k: the curvature gradient's stiffness),
      vectors (pair lengths, m, p, a, the bending form's values), matrices (S, P, Q, Psi, the
      constant Hessian) of CrossSectionModes, indices (the modes' places in a stencil's block, the
      bending form's rows and columns), table the modes' DOFs (edges, modes)."""
    def padded(items, count, make):
        items = [np.ascontiguousarray(a) for a in items]
        return tuple(items + [make() for _ in range(count - len(items))])

    return (int(kind), np.asarray(reals, dtype=float),
            padded([np.asarray(v, dtype=float) for v in vectors], _VECTORS, lambda: np.zeros(0)),
            padded([np.asarray(m, dtype=float) for m in matrices], _MATRICES, lambda: np.zeros((0, 0))),
            padded([np.asarray(i, dtype=np.int64) for i in indices], _INDICES, lambda: np.zeros(0, np.int64)),
            np.ascontiguousarray(np.zeros((0, 0), np.int64) if table is None else table, dtype=np.int64))


@njit(cache=True)
def _with_stretch(first, second):
    """The rod's per-stencil partials (n, 3) and (n, 3, 3) in (kappa_n, kappa_g, tau) placed in the
    (eps, kappa_n, kappa_g, tau) order of add_stretched_stencil_terms."""
    n = first.shape[0]
    f = np.zeros((n, 4))
    s = np.zeros((n, 4, 4))
    for i in range(n):
        for a in range(3):
            f[i, 1 + a] = first[i, a]
            for b in range(3):
                s[i, 1 + a, 1 + b] = second[i, a, b]
    return f, s


@njit(cache=True)
def _trapeze(x, tau, first, second, rest_lengths, voronoi, reals, node_stride, n_dof, want_gradient,
             want_hessian, grad, band, m1, m2, parts):
    eps = stencil_stretch_values(x, rest_lengths)
    energy, f_t, s_t = trapeze_density(eps, tau, voronoi, reals[0], reals[1])
    parts[4] = energy.sum()
    if want_gradient:
        f, s = _with_stretch(first, second)
        for i in range(f.shape[0]):   # (eps, tau) sit at (0, 3) of (eps, kappa_n, kappa_g, tau)
            for a in range(2):
                f[i, 3 * a] += f_t[i, a]
                for b in range(2):
                    s[i, 3 * a, 3 * b] += s_t[i, a, b]
        add_stretched_stencil_terms(x, m1, m2, rest_lengths, f, s, node_stride, np.zeros(0, np.int64), n_dof, grad,
                                    band, want_hessian, np.empty((0, 4, STENCIL_SIZE)))


@njit(cache=True)
def _wunderlich(x, kappa_n, tau, first, second, rest_lengths, voronoi, ei2, gj, reals, vectors, node_stride,
                n_dof, want_gradient, want_hessian, grad, band, m1, m2, parts):
    energy, f_w, s_w, _ = wunderlich_pair_density(kappa_n, tau, voronoi, vectors[0], reals[0], ei2, gj, vectors[1])
    total = energy.sum()
    parts[5] = total if math.isfinite(total) else math.inf
    if not want_gradient:
        return
    f, s = _with_stretch(first, second)
    if not math.isfinite(total):   # past the pole: the rod's terms in the band, a gradient of nan
        add_stretched_stencil_terms(x, m1, m2, rest_lengths, f, s, node_stride, np.zeros(0, np.int64), n_dof, grad,
                                    band, want_hessian, np.empty((0, 4, STENCIL_SIZE)))
        grad[:] = np.nan
        return
    # the pair's strains (kappa_n, tau) of stencils i and i + 1 sit at (1, 3) of each stencil's u
    pairs = energy.shape[0]
    cross = np.empty((pairs, 2, 2))
    for p in range(pairs):
        for a in range(2):
            f[p, 1 + 2 * a] += f_w[p, a]
            f[p + 1, 1 + 2 * a] += f_w[p, 2 + a]
            for b in range(2):
                s[p, 1 + 2 * a, 1 + 2 * b] += s_w[p, a, b]
                s[p + 1, 1 + 2 * a, 1 + 2 * b] += s_w[p, 2 + a, 2 + b]
                cross[p, a, b] = s_w[p, a, 2 + b]
    gradients = np.empty((kappa_n.shape[0] if want_hessian else 0, 4, STENCIL_SIZE))
    add_stretched_stencil_terms(x, m1, m2, rest_lengths, f, s, node_stride, np.zeros(0, np.int64), n_dof, grad, band,
                                want_hessian, gradients)
    if want_hessian:
        add_pair_cross_terms(gradients, cross, np.array([1, 3]), node_stride, n_dof, band)


@njit(cache=True)
def _cross_section(q, x, kappa_n, kappa_g, tau, first, second, rest_lengths, voronoi, reals, vectors, matrices,
                   indices, table, node_stride, n_dof, want_gradient, want_hessian, grad, band, m1, m2, parts):
    edges, modes = table.shape
    c = np.empty((edges, modes))
    for e in range(edges):
        for j in range(modes):
            c[e, j] = q[table[e, j]]
    count = tau.shape[0]
    size = 4 + 2 * modes
    eps = stencil_stretch_values(x, rest_lengths)
    energy, f_u, f_uu = np.empty(count), np.empty((count, size)), np.empty((count, size, size))
    pair_lengths, m, p, a, form = vectors
    big_s, big_p, big_q, big_psi, h_g = matrices
    unit_place, rows, cols = indices
    field_kernel(eps, kappa_n, kappa_g, tau, c[:-1], c[1:], voronoi, m, big_s, big_p, p, big_q, a, big_psi,
                  reals[0], reals[1], reals[2], reals[3], h_g, energy, f_u, f_uu)
    pairs, pf, ps, ends, ef, es = torsion_warping_terms(tau, voronoi, pair_lengths, reals[4])
    curvature_gradient = reals[5] > 0.0
    if curvature_gradient:  # B_k / 2 int kappa_n'^2 (CrossSectionRibbon's curvature_gradient; zero by default)
        gradient_pairs, kf, ks, _, _, _ = torsion_warping_terms(kappa_n, voronoi, pair_lengths, reals[5])
        parts[9] = gradient_pairs.sum()
    parts[6] = energy.sum()
    parts[7] = pairs.sum() + ends.sum()
    parts[8] = modes_bending_terms(rows, cols, form, q, n_dof, want_gradient, want_hessian, grad, band)
    if not want_gradient:
        return
    # u = (eps, kappa_n, kappa_g, tau, modes): the rod's own partials and Eq. V's per-twist parts join Eq. X's
    for i in range(count):
        for a in range(3):
            f_u[i, 1 + a] += first[i, a]
            for b in range(3):
                f_uu[i, 1 + a, 1 + b] += second[i, a, b]
    add_torsion_warping_partials(f_u, f_uu, pf, ps, ef, es)
    if curvature_gradient:
        add_pair_partials(f_u, f_uu, kf, ks, 1)
    gradients = np.empty((count if want_hessian else 0, 4, STENCIL_SIZE))
    add_stretched_stencil_terms(x, m1, m2, rest_lengths, f_u, f_uu, node_stride, unit_place, n_dof, grad, band,
                                want_hessian, gradients)
    if want_hessian:
        if curvature_gradient:
            cross = np.zeros((count - 1, 2, 2))
            for i in range(count - 1):
                cross[i, 0, 0] = ks[i, 0, 1]
                cross[i, 1, 1] = ps[i, 0, 1]
            add_pair_cross_terms(gradients, cross, np.array([1, 3]), node_stride, n_dof, band)
        else:
            add_pair_cross_terms(gradients, ps[:, 0:1, 1:2].copy(), np.array([3]), node_stride, n_dof, band)


#: The kind of width terms a specialisation of the energy adds (bound per specialisation by
#: ddg.assembly.specialise: numba compiles only the branch it selects).
KIND = ROD


def _rod_energy(q, state, args, want_gradient, want_hessian, grad, band):
    old_t, old_d1, old_m_ref = state
    node_stride, edge_nodes, rest_lengths, stretch_k, voronoi, ei2, ei1, gj, zeta, width = args
    _, reals, vectors, matrices, indices, table = width
    nodes = old_t.shape[0] + 1
    n_dof = q.shape[0]
    x = np.empty((nodes, 3))
    theta = np.empty(nodes - 1)
    for j in range(nodes):
        for k in range(3):
            x[j, k] = q[node_stride * j + k]
        if j < nodes - 1:
            theta[j] = q[node_stride * j + 3]
    t, d1, m1, m2, m_ref = rod_frames(x, old_t, old_d1, theta, old_m_ref)
    kappa = curvature_rows(x, m1, m2)
    kappa_n = kappa[:, 0].copy()
    kappa_g = kappa[:, 1].copy()
    tau = discrete_twist(theta, m_ref)
    e_b, first, second = bending_density(kappa_n, kappa_g, voronoi, ei2, ei1)
    e_t, f_t, s_t = twisting_density(tau, voronoi, gj)
    first += f_t
    second += s_t
    parts = np.zeros(len(PARTS))
    if zeta > 0.0:
        e_q, f_q, s_q = sadowsky_terms(kappa_n, tau, voronoi, ei2, zeta)
        first += f_q
        second += s_q
        parts[3] = e_q.sum()
    parts[0] = add_edge_terms(x, edge_nodes, rest_lengths, stretch_k, node_stride, n_dof, grad, band,
                              want_gradient, want_hessian)
    parts[1] = e_b.sum()
    parts[2] = e_t.sum()
    if KIND == TRAPEZE:
        _trapeze(x, tau, first, second, rest_lengths, voronoi, reals, node_stride, n_dof, want_gradient,
                 want_hessian, grad, band, m1, m2, parts)
    elif KIND == WUNDERLICH:
        _wunderlich(x, kappa_n, tau, first, second, rest_lengths, voronoi, ei2, gj, reals, vectors, node_stride,
                    n_dof, want_gradient, want_hessian, grad, band, m1, m2, parts)
    elif KIND == CROSS_SECTION:
        _cross_section(q, x, kappa_n, kappa_g, tau, first, second, rest_lengths, voronoi, reals, vectors, matrices,
                       indices, table, node_stride, n_dof, want_gradient, want_hessian, grad, band, m1, m2, parts)
    elif want_gradient:
        add_stencil_terms(x, m1, m2, first, second, node_stride, n_dof, grad, band, want_hessian)
    return parts, (t, d1, m_ref)


#: The compiled energy per kind of width terms: one implementation (_rod_energy), compiled apart for
#: each kind, so that a model compiles its own terms only.
KIND_NAMES = {ROD: "plain", TRAPEZE: "trapeze", WUNDERLICH: "wunderlich", CROSS_SECTION: "cross_section"}
ENERGIES = {kind: specialise(_rod_energy, name, KIND=kind) for kind, name in KIND_NAMES.items()}


#: The compiled Newton step and pseudo-arclength corrector per kind, each bound to that kind's energy.
LOOPS = {kind: compile_loops(name, ENERGIES[kind]) for kind, name in KIND_NAMES.items()}


def loops_of(args) -> CompiledLoops:
    """The compiled solver loops of a model's constants (RodModel.assembly_args)."""
    return LOOPS[kind_of(args)]


def kind_of(args) -> int:
    """The kind of width terms of a model's constants (RodModel.assembly_args)."""
    return args[-1][0]


def rod_energy(q, state, args, want_gradient, want_hessian, grad, band):
    """The energy by part and the frames of q, its gradient added to grad and (want_hessian) its
    Hessian to the flattened lower band, by the compiled energy of args' kind (see the module)."""
    return ENERGIES[kind_of(args)](q, state, args, want_gradient, want_hessian, grad, band)
