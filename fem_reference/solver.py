"""Newton's method, MUMPS factorisations, inertia and the lowest eigenpair for NaghdiStrip.

Linear algebra: the tangent K (symmetric, indefinite past an instability) is factorised by
MUMPS as L D L^T (PETSc PCCHOLESKY with MUMPS, sym = 2); with ICNTL(13) = 1 (no ScaLAPACK root
node) and ICNTL(24) = 1 (null-pivot detection) PETSc's MatGetInertia returns the exact inertia
of D, hence the number of negative eigenvalues of the constrained tangent (Sylvester). Measured
on PETSc 3.18.5: the count agrees with SLEPc's eigenvalues (tests/fem_reference/test_fem_reference.py).
Dirichlet rows and columns are replaced by the identity (diagonal 1), which adds only positive
eigenvalues, and by 0 on the metric M, which sends them to infinity in K v = lambda M v.

Counters (cheap: integer sums and time.perf_counter differences, read through public attributes):
Solver.iterations_by_phase (Newton iterations per ITERATION_PHASES, the phase set by
Solver.counting), Solver.failed_solves, and Solver.clock (a PhaseClock: wall time of assembly,
factorisations, triangular solves and eigenvalue/inertia work, and of the sections the
continuation opens: threshold location, branch switching, I/O).
"""
from __future__ import annotations

import math
import time
from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np
from dolfinx import fem
from petsc4py import PETSc

from .shell import NaghdiStrip


DEBUG = False

#: Where the Newton iterations of a run go (Solver.iterations_by_phase; summary.json
#: "newton_iterations_by_phase", with the same names as ddg.solve.continuation.PHASES where the
#: meaning is the same): solves of load steps that converged ("accepted steps") and that failed
#: ("rejected steps": the substep was then retried without the secant predictor or halved),
#: leaving the unstable U state at the pitchfork ("branch switching": the bordered amplitude
#: continuation and the final Newton), Newton from the inextensible guess at the first compression
#: step ("compression start"), Levenberg-Marquardt descent past a fold with its closing Newton
#: ("fold snaps"), the bisections of the thresholds ("threshold dW1" on U, "threshold dW2" from
#: US: every solve in them, converged or not), and solves made outside any of these ("other": a
#: caller that set no phase, e.g. a test calling Solver.newton directly). Unlike the DDG models,
#: the FEM's newton_iterations counts every phase, thresholds included: the entries sum to it.
ITERATION_PHASES = ("accepted steps", "rejected steps", "branch switching", "compression start", "fold snaps",
                    "threshold dW1", "threshold dW2", "other")

#: Sections of PhaseClock (summary.json "wall_time_by_phase_s", a partition of the run's wall
#: time): "build" (mesh, forms, solver set-up), "assembly" (residual and tangent, dolfinx),
#: "factorisation" (MUMPS L D L^T of the Newton tangent), "linear solves" (its triangular
#: solves), "eigenvalues and inertia" (the inertia factorisation of the stability test and
#: SLEPc's shift-invert eigensolve, each with its own MUMPS factorisation), "threshold location"
#: and "branch switching" (all of their time, whatever it is spent on; the split inside them is
#: in "wall_time_within_phases_s"), "I/O" (XDMF fields, path.csv rows, summary checkpoints), and
#: "other" (the rest: observables, centerlines, copies of states, Python bookkeeping).
TIME_PHASES = ("build", "assembly", "factorisation", "linear solves", "eigenvalues and inertia",
               "threshold location", "branch switching", "I/O", "other")
#: Sections that keep all of their time (the sections opened inside them are split separately).
OPAQUE_SECTIONS = ("threshold location", "branch switching")


class PhaseClock:
    """Wall time per section, exclusive: `with clock.section(name):` adds to seconds[name] the
    time spent in the block minus the time of the sections opened inside it, so the sections
    never count a second twice. Inside an opaque section (OPAQUE_SECTIONS) the inner sections
    add to within[opaque name][inner name] instead, and the opaque section keeps its whole time
    (its own remainder is within[...]["other"]). Cost: two perf_counter calls per section."""

    def __init__(self, opaque=OPAQUE_SECTIONS):
        self.opaque = tuple(opaque)
        self.seconds: dict[str, float] = {}
        self.within: dict[str, dict[str, float]] = {}
        self._stack: list[list] = []  # [name, start, seconds of the sections opened inside]

    @contextmanager
    def section(self, name: str):
        frame = [name, time.perf_counter(), 0.0]
        self._stack.append(frame)
        try:
            yield
        finally:
            total = time.perf_counter() - frame[1]
            self._stack.pop()
            if self._stack:
                self._stack[-1][2] += total
            owner = next((f[0] for f in reversed(self._stack) if f[0] in self.opaque), None)
            if name in self.opaque and owner is None:
                self.seconds[name] = self.seconds.get(name, 0.0) + total
                inner = self.within.setdefault(name, {})
                inner["other"] = inner.get("other", 0.0) + total - frame[2]
            elif owner is None:
                self.seconds[name] = self.seconds.get(name, 0.0) + total - frame[2]
            else:
                inner = self.within.setdefault(owner, {})
                inner[name] = inner.get(name, 0.0) + total - frame[2]

    def breakdown(self, total: float, outside: dict | None = None, phases=TIME_PHASES) -> dict[str, float]:
        """Seconds of every phase (0 where none was spent): `outside` (phases timed before the
        clock ran, e.g. {"build": s}) as given, the clock's sections, and "other" = total (the
        wall time the clock covered) minus its sections; the values sum to total + outside."""
        outside = dict(outside or {})
        measured = {k: v for k, v in self.seconds.items() if k != "other" and k not in outside}
        out = {name: outside.get(name, measured.get(name, 0.0)) for name in phases if name != "other"}
        out.update({k: v for k, v in {**outside, **measured}.items() if k not in out})
        out["other"] = total - sum(measured.values())
        return out


class NewtonFailure(RuntimeError):
    pass


#: Converged to round-off (Solver.newton and Solver.arclength_correct): once the smallest residual
#: has not halved for ROUNDOFF_STALL_ITERATIONS iterations, a residual below Solver.residual_floor
#: is round-off and the state an equilibrium to within it. Needed on very thin strips next to a
#: singular tangent: at L/b = 4000 (96 x 12 elements) near the junction of US+ with S, Newton's
#: residual stalls at 3.7e-6 while its corrections along the soft mode stay 1e-9 to 1e-8 L, above
#: dx_tol, so it failed (measured at dW/L 0.4609; the path stopped at 0.4608).
ROUNDOFF_STALL_ITERATIONS = 3


@dataclass
class NewtonOptions:
    """Converged when |R| <= atol or |R| <= rtol |R_0| (R in units of D/L: nodal forces of the
    scaled problem) or when a correction was below dx_tol in max norm (units of L: with Newton's
    quadratic convergence the state is then exact to ~dx_tol^2). The residual itself stalls at
    a round-off floor of 1e-8 to 1e-7 (membrane stiffness / bending stiffness ~ (L/b)^2,
    measured), hence the correction criterion. Next to a singular tangent on very thin strips
    the corrections along the soft mode stay above dx_tol too; a residual stalled within
    Solver.residual_floor is then accepted as round-off (ROUNDOFF_STALL_ITERATIONS).

    chord_below > 0: after a full Newton iteration whose correction was below chord_below (units of
    L), the next correction reuses that iteration's factorisation (a chord step: one residual
    assembly and two triangular solves instead of a tangent assembly and a factorisation). In
    the quadratic regime that correction is the one that confirms convergence (below dx_tol);
    the convergence test is unchanged (a correction below dx_tol), and a chord correction that
    is not below it is kept and followed by full Newton iterations. Chord steps count as
    iterations (Solver.chord_steps says how many there were).

    stall_window > 0: give up (NewtonFailure) when the smallest residual so far has not halved in
    the last stall_window iterations. Off (0) on the path; the dW2 bisection uses it: past the
    fold of US Newton from the US side oscillates between two residual levels until
    max_iterations (measured: 25 iterations per failed solve, 429 of the bisection's 458)."""

    atol: float = 1e-8
    rtol: float = 1e-11
    dx_tol: float = 1e-10
    max_iterations: int = 25
    divergence_factor: float = 1e4
    stall_window: int = 0
    chord_below: float = 1e-5


def _without_zeros(M: PETSc.Mat) -> PETSc.Mat:
    """The assembled matrix M with its stored zeros dropped: the metric M has values only in the
    displacement block (129093 of the mixed pattern's 930825 entries at 60 x 10 elements), so a
    product with it costs 0.15 ms instead of 1.1 ms; SLEPc's shift-invert makes ~20 per
    eigensolve."""
    import scipy.sparse

    M.assemble()
    indptr, indices, values = M.getValuesCSR()
    csr = scipy.sparse.csr_matrix((values, indices, indptr), shape=M.getSize())
    csr.eliminate_zeros()
    out = PETSc.Mat().createAIJ(size=M.getSizes(), comm=M.getComm(),
                                csr=(csr.indptr.astype(PETSc.IntType), csr.indices.astype(PETSc.IntType), csr.data))
    out.assemble()
    M.destroy()
    return out


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
        self.M = _without_zeros(fem.petsc.assemble_matrix(model.mass_form, bcs=model.bcs, diagonal=0.0))
        self.total_iterations = 0
        #: Newton iterations per phase (ITERATION_PHASES); they sum to total_iterations
        self.iterations_by_phase: dict[str, int] = dict.fromkeys(ITERATION_PHASES, 0)
        #: Newton solves (newton, newton_bordered, descend) that raised NewtonFailure
        self.failed_solves = 0
        #: iterations of the last solve, converged or not
        self.last_iterations = 0
        #: Newton iterations made as chord steps (NewtonOptions.chord_below; counted in the phases)
        self.chord_steps = 0
        #: wall time per section (assembly, factorisation, linear solves, eigenvalues and inertia,
        #: and those the continuation opens)
        self.clock = PhaseClock()
        self._phase = ("other", "other")
        #: solves (newton, arclength_correct) accepted as converged to round-off
        self.roundoff_convergences = 0
        params = model.params
        membrane = params.young_modulus * params.thickness / (1.0 - params.membrane_poisson_ratio**2)
        #: |R| (units of D/L) that round-off alone leaves: machine epsilon times the membrane
        #: stiffness E t / (1 - nu^2) per free DOF, in quadrature: 7.5e-6 at L/b = 4000 on 96 x 12
        #: elements, where the residual stalls at 3.7e-6 (measured). No safety factor on top: next
        #: to the singular tangent a residual r leaves the state off by r / lambda along the soft
        #: mode (with ten times the estimate, Newton at dW/L 0.4612 stopped 1.3e-4 L off S).
        self.residual_floor = np.finfo(float).eps * membrane * math.sqrt(float(np.count_nonzero(model.free)))

    # --- counters ----------------------------------------------------------------------
    @contextmanager
    def counting(self, phase: str, failed: str | None = None):
        """Newton iterations of the solves in the block count as `phase` when the solve
        converges and as `failed` (default: phase) when it raises NewtonFailure."""
        for name in (phase, failed):
            if name is not None and name not in self.iterations_by_phase:
                raise ValueError(f"unknown phase {name!r}; one of {ITERATION_PHASES}")
        saved = self._phase
        self._phase = (phase, failed or phase)
        try:
            yield
        finally:
            self._phase = saved

    def _spent(self, iterations: int, converged: bool) -> None:
        self.total_iterations += iterations
        self.last_iterations = iterations
        self.iterations_by_phase[self._phase[0 if converged else 1]] += iterations
        if not converged:
            self.failed_solves += 1

    def _at_roundoff(self, best: list[float], residual: float) -> bool:
        """Converged to round-off: `residual` within the floor and the smallest residual so far
        (best, one entry per iteration) not halved over the last ROUNDOFF_STALL_ITERATIONS."""
        k = ROUNDOFF_STALL_ITERATIONS
        return residual <= self.residual_floor and len(best) > k and best[-1] > 0.5 * best[-1 - k]

    def _fail(self, iterations: int, message: str) -> NewtonFailure:
        self._spent(iterations, False)
        return NewtonFailure(message)

    def _factor_and_solve(self, ksp: PETSc.KSP, rhs: PETSc.Vec, out: PETSc.Vec) -> None:
        """Factorise ksp's operator if it changed (timed as "factorisation"), then the
        triangular solves ("linear solves")."""
        with self.clock.section("factorisation"):
            ksp.setUp()
        with self.clock.section("linear solves"):
            ksp.solve(rhs, out)

    # --- assembly ----------------------------------------------------------------------
    def assemble_tangent(self) -> PETSc.Mat:
        with self.clock.section("assembly"):
            self.A.zeroEntries()
            fem.petsc.assemble_matrix(self.A, self.model.tangent_form, bcs=self.model.bcs, diagonal=1.0)
            self.A.assemble()
        return self.A

    def assemble_residual(self) -> PETSc.Vec:
        """R(q) with the lifting of the clamp values: the bc rows hold q - g."""
        m, b, x = self.model, self.b, self.model.q.vector
        with self.clock.section("assembly"):
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
        Raises NewtonFailure (q is then left at the last iterate). The iterations count in the
        phase of Solver.counting (its failed phase when NewtonFailure is raised)."""
        opts, m = self.options, self.model
        x = m.q.vector
        r0 = None
        best: list[float] = []  # smallest residual up to each iteration
        chord = False  # this iteration reuses the last factorisation
        for it in range(opts.max_iterations + 1):
            b = self.assemble_residual()
            r = b.norm()
            if DEBUG:
                print("newton", it, r, self.dx.norm(PETSc.NormType.NORM_INFINITY) if it else 0.0)
            if not np.isfinite(r):
                raise self._fail(it, f"residual not finite at iteration {it}")
            if r0 is None:
                r0 = r
            if r <= max(opts.atol, opts.rtol * r0):
                self._spent(it, True)
                return it
            if it > 0 and (r > opts.divergence_factor * max(r0, opts.atol)):
                raise self._fail(it, f"residual grew from {r0:.3e} to {r:.3e}")
            best.append(min(r, best[-1]) if best else r)
            if self._at_roundoff(best, r):
                self.roundoff_convergences += 1
                self._spent(it, True)
                return it
            window = opts.stall_window
            if window > 0 and it >= window and best[-1] > 0.5 * best[-1 - window]:
                raise self._fail(it, f"residual stalled at {best[-1]:.3e} for {window} iterations")
            if it == opts.max_iterations:
                break
            try:
                if chord:  # the factorisation of the last iteration (self.A is unchanged since)
                    self.chord_steps += 1
                    with self.clock.section("linear solves"):
                        self.ksp.solve(b, self.dx)
                else:
                    self.assemble_tangent()
                    self.ksp.setOperators(self.A)
                    self._factor_and_solve(self.ksp, b, self.dx)
            except PETSc.Error as exc:  # factorisation failure
                raise self._fail(it, f"factorisation failed: {exc}") from None
            if self.ksp.getConvergedReason() < 0:
                raise self._fail(it, f"linear solve failed ({self.ksp.getConvergedReason()})")
            x.axpy(-1.0, self.dx)
            x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
            step = self.dx.norm(PETSc.NormType.NORM_INFINITY)
            if not np.isfinite(step):
                raise self._fail(it + 1, "correction not finite")
            if step < opts.dx_tol:
                self._spent(it + 1, True)
                return it + 1
            chord = not chord and step < opts.chord_below
        raise self._fail(opts.max_iterations,
                         f"no convergence in {opts.max_iterations} iterations (|R| = {r:.3e}, |R0| = {r0:.3e})")

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
        it = 0
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
                    raise self._fail(it, "bordered residual not finite")
                r0 = r if r0 is None else r0
                if r <= max(opts.atol, opts.rtol * r0) and it > 0:
                    self._spent(it, True)
                    return it, mu
                if it == opts.max_iterations:
                    break
                self.assemble_tangent()
                self.ksp.setOperators(self.A)
                try:
                    self._factor_and_solve(self.ksp, b, self.dx)
                    with self.clock.section("linear solves"):
                        self.ksp.solve(c, kc)
                except PETSc.Error as exc:
                    raise self._fail(it, f"factorisation failed in the bordered Newton: {exc}") from None
                if self.ksp.getConvergedReason() < 0:
                    raise self._fail(it, "linear solve failed in the bordered Newton")
                dmu = (r2 - c.dot(self.dx)) / c.dot(kc)
                # dq = -(K^-1 r1 + dmu K^-1 c); the lifted residual already holds q - g on bc rows
                x.axpy(-1.0, self.dx)
                x.axpy(-dmu, kc)
                x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
                mu += dmu
                self.dx.axpy(dmu, kc)
                if self.dx.norm(PETSc.NormType.NORM_INFINITY) < opts.dx_tol:
                    self._spent(it + 1, True)
                    return it + 1, mu
        finally:
            ref.destroy()
            kc.destroy()
            diff.destroy()
        raise self._fail(opts.max_iterations, f"bordered Newton: no convergence in {opts.max_iterations} iterations")

    # --- pseudo-arclength in the shear ----------------------------------------------------
    def _shear_derivative(self, compression: float, shear: float) -> tuple[np.ndarray, np.ndarray]:
        """(R, dR/dW) at the current q: the lifted residual (bc rows q - g) and its derivative in
        the clamp shear W, exact as the difference over a unit W (R is linear in the clamp values
        g for a fixed q: the lifting adds K(q) (g - q) on the free rows)."""
        m = self.model
        r = self.assemble_residual().getArray().copy()
        m.set_clamp(compression, shear + 1.0)
        r_w = self.assemble_residual().getArray().copy() - r
        m.set_clamp(compression, shear)
        return r, r_w

    def _solve_two(self, first: np.ndarray, second: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """K^-1 first and K^-1 second with one factorisation of the tangent at the current q."""
        self.assemble_tangent()
        self.ksp.setOperators(self.A)
        rhs, out = self.b.duplicate(), self.b.duplicate()
        try:
            rhs.setArray(first)
            self._factor_and_solve(self.ksp, rhs, out)
            a = out.getArray().copy()
            rhs.setArray(second)
            with self.clock.section("linear solves"):
                self.ksp.solve(rhs, out)
            b = out.getArray().copy()
        finally:
            rhs.destroy()
            out.destroy()
        if self.ksp.getConvergedReason() < 0:
            raise NewtonFailure("linear solve failed in the pseudo-arclength corrector")
        return a, b

    def shear_tangent(self, compression: float, shear: float, weight: float) -> tuple[np.ndarray, float]:
        """Unit tangent (dq, dW) of the branch of equilibria through the current q (dq = -K^-1
        dR/dW dW) in the norm weight |dq|^2 + dW^2, oriented with dW > 0."""
        r, r_w = self._shear_derivative(compression, shear)
        _, dq = self._solve_two(r, r_w)
        dq = -dq
        norm = math.sqrt(weight * float(np.dot(dq, dq)) + 1.0)
        return dq / norm, 1.0 / norm

    def arclength_correct(self, compression: float, shear: float, anchor: np.ndarray, anchor_shear: float,
                          tangent: tuple[np.ndarray, float], ds: float, weight: float,
                          max_iterations: int = 12) -> tuple[int, float]:
        """Bordered Newton for (q, W) from the current q at clamp shear `shear` (Keller's
        pseudo-arclength, as ddg.solve.arclength): R(q, W) = 0 and weight <q - anchor, t_q> +
        (W - anchor_shear) t_W = ds. Converged when the correction is below dx_tol (max norm, units
        of L), |R| <= atol or R is round-off (Solver._at_roundoff), with the arclength condition
        met to 1e-8 ds. Returns (iterations,
        W); raises NewtonFailure (q is then the last iterate)."""
        opts, m = self.options, self.model
        t_q, t_w = tangent
        m.set_clamp(compression, shear)
        step = math.inf
        best: list[float] = []
        for it in range(max_iterations + 1):
            r, r_w = self._shear_derivative(compression, shear)
            x = m.get_state()
            arc = weight * float(np.dot(x - anchor, t_q)) + (shear - anchor_shear) * t_w - ds
            residual = float(np.linalg.norm(r))
            if not np.isfinite(residual):
                raise self._fail(it, "pseudo-arclength: residual not finite")
            best.append(min(residual, best[-1]) if best else residual)
            usual = residual <= opts.atol or step < opts.dx_tol
            if (usual or self._at_roundoff(best, residual)) and abs(arc) <= 1e-8 * ds:
                if not usual:
                    self.roundoff_convergences += 1
                self._spent(it, True)
                return it, shear
            if it == max_iterations:
                break
            try:
                a, b = self._solve_two(r, r_w)
            except PETSc.Error as exc:
                raise self._fail(it, f"factorisation failed in the pseudo-arclength corrector: {exc}") from None
            d_w = (weight * float(np.dot(a, t_q)) - arc) / (t_w - weight * float(np.dot(b, t_q)))
            dq = -a - d_w * b
            step = max(float(np.max(np.abs(dq))), abs(d_w))
            if not np.isfinite(step):
                raise self._fail(it + 1, "pseudo-arclength: correction not finite")
            shear += d_w
            m.set_state(x + dq)
            m.set_clamp(compression, shear)
        raise self._fail(max_iterations, f"pseudo-arclength: no convergence in {max_iterations} iterations")

    def descend(self, max_steps: int = 200, sigma: float = 1e-2) -> int:
        """Snap to a stable equilibrium at the current clamp values: Levenberg-Marquardt steps
        (K + sigma diag K) dq = -R, sigma raised until that matrix has no negative eigenvalue
        (inertia) and the energy falls, lowered after each success; plain Newton is tried once
        sigma is small. Used past a fold, where Newton from the last state cannot converge.
        Returns iterations (accepted Levenberg-Marquardt steps plus the closing Newton's); raises
        NewtonFailure. Each iteration counts once in Solver.iterations_by_phase (the closing
        Newton counts its own; the Levenberg-Marquardt steps are counted here)."""
        m = self.model
        x = m.q.vector
        fem.petsc.set_bc(x, m.bcs)  # impose the clamp values exactly (the load step is tiny)
        x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        energy = m.energy()
        its = 0  # returned: LM steps and the closing Newton's iterations
        steps = 0  # LM steps not yet counted
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
                with self.clock.section("factorisation"):
                    self.inertia_ksp.setUp()
                    nneg, nzero, _ = self.inertia_ksp.getPC().getFactorMatrix().getInertia()
                ok = nneg + nzero == 0
                if ok:
                    with self.clock.section("linear solves"):
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
                    raise self._fail(steps, "descent: no energy decrease")
            diag.destroy()
            its += 1
            steps += 1
            if sigma < 1e-4:
                state = m.get_state()
                saved = self.options.max_iterations
                self.options.max_iterations = 8
                try:
                    newton_its = self.newton()
                    its += newton_its
                    if self.negative_eigenvalues() == 0:
                        self._spent(steps, True)
                        self.last_iterations = its
                        return its
                except NewtonFailure:
                    pass
                finally:
                    self.options.max_iterations = saved
                m.set_state(state)
        raise self._fail(steps, f"descent: no stable equilibrium in {max_steps} steps")

    # --- stability -------------------------------------------------------------------------
    def negative_eigenvalues(self) -> int:
        """Number of negative eigenvalues of the constrained tangent at the current q
        (inertia of MUMPS's L D L^T factorisation)."""
        A = self.assemble_tangent()
        with self.clock.section("eigenvalues and inertia"):
            self.inertia_ksp.setOperators(A)
            self.inertia_ksp.setUp()
            factor = self.inertia_ksp.getPC().getFactorMatrix()
            nneg, nzero, _npos = factor.getInertia()
        return int(nneg + nzero)

    def stability(self, modes: int = 1):
        """(negative, eigenvalues, vectors) at the current q from one tangent assembly and one
        MUMPS factorisation: the number of negative eigenvalues of the constrained tangent from
        the inertia of its L D L^T (as negative_eigenvalues), then the `modes` eigenpairs of
        K v = lambda M v nearest 0 (as lowest_modes) by SLEPc's shift-invert at 0 on that same
        factorisation (ST in place: K - 0 M is K itself) instead of a copy factorised again.
        modes = 0: the inertia only."""
        A = self.assemble_tangent()
        with self.clock.section("eigenvalues and inertia"):
            self.inertia_ksp.setOperators(A)
            self.inertia_ksp.setUp()
            nneg, nzero, _npos = self.inertia_ksp.getPC().getFactorMatrix().getInertia()
            if modes <= 0:
                return int(nneg + nzero), np.array([]), []
            from slepc4py import SLEPc

            values, vectors = self._lowest_modes(A, modes, 0.0, SLEPc, factored=self.inertia_ksp,
                                                 ncv=max(2 * modes + 4, 6))
        return int(nneg + nzero), values, vectors

    def lowest_modes(self, count: int = 1, target: float = 0.0):
        """The `count` eigenpairs of K v = lambda M v nearest `target` (shift-invert, SLEPc),
        sorted by eigenvalue; lambda is already lambda_min L^4 / EI2 (shell.eigen_normalisation).
        Returns (eigenvalues, list of mixed-space vectors as numpy arrays)."""
        from slepc4py import SLEPc

        A = self.assemble_tangent()
        with self.clock.section("eigenvalues and inertia"):
            return self._lowest_modes(A, count, target, SLEPc)

    def _lowest_modes(self, A, count, target, SLEPc, factored: PETSc.KSP | None = None, ncv: int | None = None):
        """SLEPc shift-invert about target; `factored`: a KSP already holding the factorisation
        of A (target 0 only), used in place (SLEPc resets it afterwards); ncv: the Krylov
        subspace (default max(2 count + 8, 12); stability() takes 6 for one mode: the same
        eigenvalue to 1e-15 relative in half the solves, measured at 60 x 10 elements)."""
        K = A if factored is not None else A.copy()
        eps = SLEPc.EPS().create(self.model.mesh.comm)
        eps.setOperators(K, self.M)
        eps.setProblemType(SLEPc.EPS.ProblemType.GHEP)
        eps.setDimensions(count, ncv or max(2 * count + 8, 12))
        eps.setTarget(target)
        eps.setWhichEigenpairs(SLEPc.EPS.Which.TARGET_REAL)
        st = eps.getST()
        st.setType(SLEPc.ST.Type.SINVERT)
        st.setShift(target)
        if factored is not None:
            if target != 0.0:
                raise ValueError("a factorisation of K is reused for the shift 0 only")
            st.setMatMode(SLEPc.ST.MatMode.INPLACE)
            st.setKSP(factored)
        else:
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
        if factored is None:
            K.destroy()
        order = np.argsort(values)
        return np.array(values)[order][:count], [vectors[i] for i in order[:count]]
