"""Newton's method, MUMPS factorisations, inertia and the lowest eigenpair for NaghdiStrip.

Linear algebra: the tangent K (symmetric, indefinite past an instability) is factorised by
MUMPS as L D L^T (PETSc PCCHOLESKY with MUMPS, sym = 2); with ICNTL(13) = 1 (no ScaLAPACK root
node) and ICNTL(24) = 1 (null-pivot detection) PETSc's MatGetInertia returns the exact inertia
of D, hence the number of negative eigenvalues of the constrained tangent (Sylvester). Measured
on PETSc 3.18.5: the count agrees with SLEPc's eigenvalues (tests/test_fem_reference.py).
Dirichlet rows and columns are replaced by the identity (diagonal 1), which adds only positive
eigenvalues, and by 0 on the metric M, which sends them to infinity in K v = lambda M v.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from dolfinx import fem
from petsc4py import PETSc

from .shell import NaghdiStrip


DEBUG = False


class NewtonFailure(RuntimeError):
    pass


@dataclass
class NewtonOptions:
    """Converged when |R| <= atol or |R| <= rtol |R_0| (R in units of D/L: nodal forces of the
    scaled problem) or when a correction was below dx_tol in max norm (units of L: with Newton's
    quadratic convergence the state is then exact to ~dx_tol^2). The residual itself stalls at
    a round-off floor of 1e-8 to 1e-7 (membrane stiffness / bending stiffness ~ (L/b)^2,
    measured), hence the correction criterion."""

    atol: float = 1e-8
    rtol: float = 1e-11
    dx_tol: float = 1e-10
    max_iterations: int = 25
    divergence_factor: float = 1e4


def _cholesky_ksp(comm, prefix: str, inertia: bool = False) -> PETSc.KSP:
    ksp = PETSc.KSP().create(comm)
    ksp.setOptionsPrefix(prefix)
    ksp.setType("preonly")
    pc = ksp.getPC()
    pc.setType("cholesky")
    pc.setFactorSolverType("mumps")
    opts = PETSc.Options()
    if inertia:
        # exact inertia: no ScaLAPACK root node (ICNTL 13), null pivots detected (ICNTL 24,
        # default threshold); the Newton solves use neither (null-pivot fixing makes them inexact)
        opts[f"{prefix}mat_mumps_icntl_13"] = 1
        opts[f"{prefix}mat_mumps_icntl_24"] = 1
    ksp.setFromOptions()
    return ksp


class Solver:
    """Newton, inertia and eigenvalues of one NaghdiStrip."""

    def __init__(self, model: NaghdiStrip, options: NewtonOptions | None = None):
        self.model = model
        self.options = options or NewtonOptions()
        comm = model.mesh.comm
        self.A = fem.petsc.create_matrix(model.tangent_form)
        self.b = fem.petsc.create_vector(model.residual_form)
        self.dx = self.b.duplicate()
        self.ksp = _cholesky_ksp(comm, "fem_newton_")
        self.inertia_ksp = _cholesky_ksp(comm, "fem_inertia_", inertia=True)
        self.M = fem.petsc.assemble_matrix(model.mass_form, bcs=model.bcs, diagonal=0.0)
        self.M.assemble()
        self.total_iterations = 0

    # --- assembly ----------------------------------------------------------------------
    def assemble_tangent(self) -> PETSc.Mat:
        self.A.zeroEntries()
        fem.petsc.assemble_matrix(self.A, self.model.tangent_form, bcs=self.model.bcs, diagonal=1.0)
        self.A.assemble()
        return self.A

    def assemble_residual(self) -> PETSc.Vec:
        """R(q) with the lifting of the clamp values: the bc rows hold q - g."""
        m, b, x = self.model, self.b, self.model.q.vector
        with b.localForm() as loc:
            loc.set(0.0)
        fem.petsc.assemble_vector(b, m.residual_form)
        fem.petsc.apply_lifting(b, [m.tangent_form], bcs=[m.bcs], x0=[x], scale=-1.0)
        b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        fem.petsc.set_bc(b, m.bcs, x, -1.0)
        return b

    # --- Newton --------------------------------------------------------------------------
    def newton(self) -> int:
        """Solve R(q) = 0 from the current q with the current clamp values; returns iterations.
        Raises NewtonFailure (q is then left at the last iterate)."""
        opts, m = self.options, self.model
        x = m.q.vector
        r0 = None
        for it in range(opts.max_iterations + 1):
            b = self.assemble_residual()
            r = b.norm()
            if DEBUG:
                print("newton", it, r, self.dx.norm(PETSc.NormType.NORM_INFINITY) if it else 0.0)
            if not np.isfinite(r):
                raise NewtonFailure(f"residual not finite at iteration {it}")
            if r0 is None:
                r0 = r
            if r <= max(opts.atol, opts.rtol * r0):
                self.total_iterations += it
                return it
            if it > 0 and (r > opts.divergence_factor * max(r0, opts.atol)):
                self.total_iterations += it
                raise NewtonFailure(f"residual grew from {r0:.3e} to {r:.3e}")
            if it == opts.max_iterations:
                break
            self.assemble_tangent()
            self.ksp.setOperators(self.A)
            try:
                self.ksp.solve(b, self.dx)
            except PETSc.Error as exc:  # factorisation failure
                self.total_iterations += it
                raise NewtonFailure(f"factorisation failed: {exc}") from None
            if self.ksp.getConvergedReason() < 0:
                self.total_iterations += it
                raise NewtonFailure(f"linear solve failed ({self.ksp.getConvergedReason()})")
            x.axpy(-1.0, self.dx)
            x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
            step = self.dx.norm(PETSc.NormType.NORM_INFINITY)
            if not np.isfinite(step):
                raise NewtonFailure("correction not finite")
            if step < opts.dx_tol:
                self.total_iterations += it + 1
                return it + 1
        self.total_iterations += opts.max_iterations
        raise NewtonFailure(f"no convergence in {opts.max_iterations} iterations (|R| = {r:.3e}, |R0| = {r0:.3e})")

    def newton_bordered(self, c: PETSc.Vec, q_ref: np.ndarray, amplitude: float, mu: float = 0.0):
        """Solve R(q) + mu c = 0 with c . (q - q_ref) = amplitude for (q, mu) from the current q:
        the state held at a given amplitude along the mode c = M phi by a force mu c (the
        bordered system is regular at the pitchfork, where K alone is singular).
        Returns (iterations, mu); raises NewtonFailure."""
        opts, m = self.options, self.model
        x = m.q.vector
        ref = x.duplicate()
        ref.setArray(q_ref)
        kc = self.b.duplicate()
        diff = self.b.duplicate()
        r0 = None
        try:
            for it in range(opts.max_iterations + 1):
                b = self.assemble_residual()
                b.axpy(mu, c)
                x.copy(diff)
                diff.axpy(-1.0, ref)
                r2 = c.dot(diff) - amplitude
                r = math.hypot(b.norm(), r2)
                if DEBUG:
                    print("bordered", it, b.norm(), r2, mu, self.dx.norm(PETSc.NormType.NORM_INFINITY) if it else 0.0)
                if not np.isfinite(r):
                    raise NewtonFailure("bordered residual not finite")
                r0 = r if r0 is None else r0
                if r <= max(opts.atol, opts.rtol * r0) and it > 0:
                    self.total_iterations += it
                    return it, mu
                if it == opts.max_iterations:
                    break
                self.assemble_tangent()
                self.ksp.setOperators(self.A)
                self.ksp.solve(b, self.dx)
                self.ksp.solve(c, kc)
                if self.ksp.getConvergedReason() < 0:
                    raise NewtonFailure("linear solve failed in the bordered Newton")
                dmu = (r2 - c.dot(self.dx)) / c.dot(kc)
                # dq = -(K^-1 r1 + dmu K^-1 c); the lifted residual already holds q - g on bc rows
                x.axpy(-1.0, self.dx)
                x.axpy(-dmu, kc)
                x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
                mu += dmu
                self.dx.axpy(dmu, kc)
                if self.dx.norm(PETSc.NormType.NORM_INFINITY) < opts.dx_tol:
                    self.total_iterations += it + 1
                    return it + 1, mu
        finally:
            ref.destroy()
            kc.destroy()
            diff.destroy()
        self.total_iterations += opts.max_iterations
        raise NewtonFailure(f"bordered Newton: no convergence in {opts.max_iterations} iterations")

    def descend(self, max_steps: int = 200, sigma: float = 1e-2) -> int:
        """Snap to a stable equilibrium at the current clamp values: Levenberg-Marquardt steps
        (K + sigma diag K) dq = -R, sigma raised until that matrix has no negative eigenvalue
        (inertia) and the energy falls, lowered after each success; plain Newton is tried once
        sigma is small. Used past a fold, where Newton from the last state cannot converge.
        Returns iterations; raises NewtonFailure."""
        m = self.model
        x = m.q.vector
        fem.petsc.set_bc(x, m.bcs)  # impose the clamp values exactly (the load step is tiny)
        x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        energy = m.energy()
        its = 0
        for _ in range(max_steps):
            base = m.get_state()
            b = self.assemble_residual()
            K = self.assemble_tangent()
            diag = K.getDiagonal()
            while True:
                A = K.copy()
                shifted = diag.copy()
                shifted.scale(1.0 + sigma)
                A.setDiagonal(shifted)
                self.inertia_ksp.setOperators(A)
                self.inertia_ksp.setUp()
                nneg, nzero, _ = self.inertia_ksp.getPC().getFactorMatrix().getInertia()
                ok = nneg + nzero == 0
                if ok:
                    self.inertia_ksp.solve(b, self.dx)
                    x.axpy(-1.0, self.dx)
                    x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
                    new_energy = m.energy()
                    ok = np.isfinite(new_energy) and new_energy < energy
                A.destroy()
                shifted.destroy()
                if ok:
                    energy = new_energy
                    sigma = max(sigma / 3.0, 1e-8)
                    break
                m.set_state(base)
                sigma *= 10.0
                if sigma > 1e8:
                    diag.destroy()
                    raise NewtonFailure("descent: no energy decrease")
            diag.destroy()
            its += 1
            if sigma < 1e-4:
                state = m.get_state()
                saved = self.options.max_iterations
                self.options.max_iterations = 8
                try:
                    its += self.newton()
                    if self.negative_eigenvalues() == 0:
                        self.total_iterations += its
                        return its
                except NewtonFailure:
                    pass
                finally:
                    self.options.max_iterations = saved
                m.set_state(state)
        self.total_iterations += its
        raise NewtonFailure(f"descent: no stable equilibrium in {max_steps} steps")

    # --- stability -------------------------------------------------------------------------
    def negative_eigenvalues(self) -> int:
        """Number of negative eigenvalues of the constrained tangent at the current q
        (inertia of MUMPS's L D L^T factorisation)."""
        A = self.assemble_tangent()
        self.inertia_ksp.setOperators(A)
        self.inertia_ksp.setUp()
        factor = self.inertia_ksp.getPC().getFactorMatrix()
        nneg, nzero, _npos = factor.getInertia()
        return int(nneg + nzero)

    def lowest_modes(self, count: int = 1, target: float = 0.0):
        """The `count` eigenpairs of K v = lambda M v nearest `target` (shift-invert, SLEPc),
        sorted by eigenvalue; lambda is already lambda_min L^4 / EI2 (shell.eigen_normalisation).
        Returns (eigenvalues, list of mixed-space vectors as numpy arrays)."""
        from slepc4py import SLEPc

        A = self.assemble_tangent()
        K = A.copy()
        eps = SLEPc.EPS().create(self.model.mesh.comm)
        eps.setOperators(K, self.M)
        eps.setProblemType(SLEPc.EPS.ProblemType.GHEP)
        eps.setDimensions(count, max(2 * count + 8, 12))
        eps.setTarget(target)
        eps.setWhichEigenpairs(SLEPc.EPS.Which.TARGET_REAL)
        st = eps.getST()
        st.setType(SLEPc.ST.Type.SINVERT)
        st.setShift(target)
        ksp = st.getKSP()
        ksp.setType("preonly")
        pc = ksp.getPC()
        pc.setType("cholesky")
        pc.setFactorSolverType("mumps")
        eps.setTolerances(1e-10, 200)
        eps.solve()
        nconv = eps.getConverged()
        values, vectors = [], []
        vr = K.createVecRight()
        for i in range(nconv):
            lam = eps.getEigenpair(i, vr)
            values.append(lam.real)
            vectors.append(vr.getArray().copy())
        eps.destroy()
        K.destroy()
        order = np.argsort(values)
        return np.array(values)[order][:count], [vectors[i] for i in order[:count]]
