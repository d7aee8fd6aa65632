"""The mid-edge plate's Newton linear algebra: banded Cholesky against MUMPS's sparse LDL^T with
inertia (issue 50 item 1: "chosen by a measured crossover against the band").

    .venv/bin/python -m benchmarks.plate_mumps [--rows 8 12 18 28] [--width 1/6] [--repeat 5]
        [--out benchmarks/results]

For each row count R it compresses the mid-edge plate on ghost_clamp_mesh(L, W, rows=R) (W/L = --width,
dL/L = 1/2, 10 compression steps, no shear) and takes the free-DOF Hessian of the buckled U (positive
definite), K = model.free_matrix(final_state.evaluation.hessian), then times (median of --repeat calls
after one untimed call, OpenBLAS threads as inherited):

- banded Cholesky as the project calls it (scipy.linalg.cholesky_banded, lower band) and one
  cho_solve_banded;
- MUMPS through petsc4py (Debian's PETSc, as dolfinx uses it; one MPI process), LDL^T of the symmetric
  matrix (PC "cholesky" without the SPD flag: MUMPS SYM = 2), ICNTL(13) = 1: the analysis with the
  numerical factorisation once, then the numerical factorisation alone with the analysis reused (the
  Hessian keeps its pattern through a path), and one solve;
- the inertia: the count of negative pivots MUMPS reports (INFOG(12)) on K - sigma I, with sigma = 1.5
  times K's lowest eigenvalue (scipy eigsh, shift-invert at 0), against the band LDL^T's count
  (SymmetricBanded.inertia, ddg.solve.band_ldlt).

Each solve's relative residual |K x - b| / |b| is recorded. Writes OUT/plate_mumps.json and .md; the
conclusion line is computed from the table. Not part of the test run; nothing asserts on timings.
"""
from __future__ import annotations

import argparse
import statistics
import sys
import time
from fractions import Fraction
from pathlib import Path

import numpy as np

from benchmarks.common import Provenance, machine_section, markdown_table, warn_if_changed, write_report
from benchmarks.plate_linear_algebra import band_to_csc

COMPRESSION_RATIO = 0.5
COMPRESSION_STEPS = 10
#: K - SHIFT_FACTOR lambda_1 I has at least one negative eigenvalue: the inertia check's matrix
SHIFT_FACTOR = 1.5


def timed(fn, repeat: int) -> tuple[float, object]:
    """Median wall time (ms) of `repeat` calls after one untimed call, and the last result."""
    out = fn()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(1e3 * (time.perf_counter() - t0))
    return statistics.median(times), out


def hessian(rows: int, width: float):
    """(K, triangles) of the compressed mid-edge plate on `rows` rows."""
    import ddg
    from ddg.geometry.plate_mesh import ghost_clamp_mesh

    strip = ddg.Strip.from_ratios(width, COMPRESSION_RATIO)
    res = ddg.simulate(strip, ddg.LoadingProtocol(COMPRESSION_RATIO, 0.0, compression_steps=COMPRESSION_STEPS),
                       model="plate-midedge", mesh=ghost_clamp_mesh(strip.length, strip.width, rows=rows),
                       branches=False)
    if res.final_state is None:
        raise RuntimeError(f"rows = {rows}: no compressed state ({res.summary.get('message')})")
    model = res.model
    return model.free_matrix(res.final_state.evaluation.hessian), int(model.mesh.triangle_count)


class Mumps:
    """MUMPS LDL^T of a fixed pattern through petsc4py: factor() refactorises with the analysis kept."""

    def __init__(self, csr):
        from petsc4py import PETSc

        self.PETSc = PETSc
        self.matrix = PETSc.Mat().createAIJ(size=csr.shape, csr=(csr.indptr, csr.indices, csr.data))
        self.matrix.setOption(PETSc.Mat.Option.SYMMETRIC, True)
        self.matrix.assemble()
        self.ksp = PETSc.KSP().create()
        self.ksp.setOperators(self.matrix)
        self.ksp.setType("preonly")
        pc = self.ksp.getPC()
        pc.setType("cholesky")
        pc.setFactorSolverType("mumps")
        pc.setFactorSetUpSolverType()
        self.factor_matrix = pc.getFactorMatrix()
        self.factor_matrix.setMumpsIcntl(13, 1)  # the root factorised sequentially: exact inertia
        self.ksp.setUp()  # analysis and the first numerical factorisation

    def set_values(self, csr) -> None:
        self.matrix.setValuesCSR(csr.indptr, csr.indices, csr.data)
        self.matrix.assemble()

    def factor(self) -> None:
        """The numerical factorisation alone (the matrix's values changed, its pattern not)."""
        self.matrix.assemble()  # a new state of the operator: PETSc refactorises numerically
        self.ksp.setOperators(self.matrix)
        self.ksp.setUp()

    def negative_pivots(self) -> int:
        return int(self.factor_matrix.getMumpsInfog(12))

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        b = self.matrix.createVecRight()
        b.setArray(rhs)
        x = self.matrix.createVecLeft()
        self.ksp.solve(b, x)
        return x.getArray().copy()


def measure(rows: int, width: float, repeat: int) -> dict:
    import scipy.linalg as sla
    import scipy.sparse.linalg as spla

    from ddg.solve.banded import SymmetricBanded

    t0 = time.perf_counter()
    K, triangles = hessian(rows, width)
    build_s = time.perf_counter() - t0
    band = np.ascontiguousarray(K.band)
    n = band.shape[1]
    csc = band_to_csc(band)
    rng = np.random.default_rng(0)
    b = rng.standard_normal(n)

    def residual(x):
        return float(np.linalg.norm(csc @ x - b) / np.linalg.norm(b))

    chol_f, factor = timed(lambda: sla.cholesky_banded(band, lower=True, check_finite=False), repeat)
    chol_s, x_band = timed(lambda: sla.cho_solve_banded((factor, True), b, check_finite=False), repeat)

    t0 = time.perf_counter()
    mumps = Mumps(csc.tocsr())
    first_ms = 1e3 * (time.perf_counter() - t0)
    mumps_f, _ = timed(mumps.factor, repeat)
    mumps_s, x_mumps = timed(lambda: mumps.solve(b), repeat)

    lowest = float(spla.eigsh(csc, k=1, sigma=0.0, which="LM", return_eigenvectors=False)[0])
    sigma = SHIFT_FACTOR * lowest
    shifted = band.copy()
    shifted[0] -= sigma
    from ddg.solve.band_ldlt import UnreliablePivot

    try:
        band_negative, band_note = int(SymmetricBanded(shifted).inertia()[0]), ""
    except UnreliablePivot as exc:  # no pivoting: a pivot singular to rounding gives no count
        band_negative, band_note = None, str(exc)
    mumps.set_values(band_to_csc(shifted, pattern=band).tocsr())
    mumps.factor()
    mumps_negative = mumps.negative_pivots()
    return {
        "rows": rows, "width_ratio": width, "triangles": triangles, "n": n, "bandwidth": band.shape[0] - 1,
        "nnz": int(csc.nnz), "build_s": build_s,
        "band_cholesky_factor_ms": chol_f, "band_cholesky_solve_ms": chol_s,
        "band_cholesky_ms": chol_f + chol_s, "band_residual": residual(x_band),
        "mumps_analysis_and_factor_ms": first_ms, "mumps_factor_ms": mumps_f, "mumps_solve_ms": mumps_s,
        "mumps_ms": mumps_f + mumps_s, "mumps_residual": residual(x_mumps),
        "lowest_eigenvalue": lowest, "negative_pivots_band_ldlt": band_negative, "band_ldlt_note": band_note,
        "negative_pivots_mumps": mumps_negative,
    }


def markdown(report: dict) -> str:
    rows = report["results"]
    header = ["rows", "triangles", "n", "bandwidth", "nnz", "band Cholesky f", "f+s", "MUMPS analysis+f",
              "MUMPS f", "f+s", "band / MUMPS (f+s)", "residual band", "residual MUMPS", "negative: band LDL^T",
              "MUMPS"]
    table = [[str(r["rows"]), str(r["triangles"]), str(r["n"]), str(r["bandwidth"]), str(r["nnz"]),
              f"{r['band_cholesky_factor_ms']:.1f}",
              f"{r['band_cholesky_ms']:.1f}", f"{r['mumps_analysis_and_factor_ms']:.1f}",
              f"{r['mumps_factor_ms']:.1f}", f"{r['mumps_ms']:.1f}", f"{r['band_cholesky_ms'] / r['mumps_ms']:.2f}",
              f"{r['band_residual']:.1e}", f"{r['mumps_residual']:.1e}",
              "unreliable pivot" if r["negative_pivots_band_ldlt"] is None else str(r["negative_pivots_band_ldlt"]),
              str(r["negative_pivots_mumps"])] for r in rows]
    faster = [r for r in rows if r["mumps_ms"] < r["band_cholesky_ms"]]
    counted = [r for r in rows if r["negative_pivots_band_ldlt"] is not None]
    agree = sum(r["negative_pivots_band_ldlt"] == r["negative_pivots_mumps"] for r in counted)
    unreliable = [r for r in rows if r["negative_pivots_band_ldlt"] is None]
    missed = ""
    if unreliable:
        where = ", ".join(f"{r['rows']} rows" for r in unreliable)
        counts = ", ".join(str(r["negative_pivots_mumps"]) for r in unreliable)
        missed = (f"; it could not (a pivot singular to rounding, no pivoting) at {where}, where MUMPS (with "
                  f"pivoting) counted {counts}")
    if faster:
        first = min(faster, key=lambda r: r["rows"])
        crossover = (f"MUMPS's refactorisation + solve is faster than the banded Cholesky from {first['rows']} rows "
                     f"(n = {first['n']}: {first['mumps_ms']:.1f} against {first['band_cholesky_ms']:.1f} ms) in "
                     f"{len(faster)} of {len(rows)} meshes")
    else:
        crossover = f"the banded Cholesky is faster than MUMPS's refactorisation + solve on all {len(rows)} meshes"
    lines = [
        "# Mid-edge plate linear algebra: banded Cholesky against MUMPS LDL^T (benchmarks/plate_mumps.py)", "",
        f"Compressed mid-edge plate (W/L = {report['config']['width']}, dL/L = 1/2, {COMPRESSION_STEPS} compression "
        "steps) on ghost_clamp_mesh rows; the free-DOF Hessian of the buckled U. Times in ms, median of "
        f"{report['config']['repeat']} calls after one untimed call; f = factor, s = one solve; MUMPS through "
        "petsc4py (one process, LDL^T, the analysis reused after the first call). Negative eigenvalue counts of "
        f"K - {SHIFT_FACTOR} lambda_1 I.", "",
        f"- {crossover}.",
        f"- Negative pivots: MUMPS and the band LDL^T agree on {agree} of the {len(counted)} shifted matrices the "
        f"band LDL^T could count{missed}.", "",
        *markdown_table(header, table).splitlines(),
        *machine_section(report, extra=f" Load average at start and end: {report['load_average']}."),
    ]
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rows", type=int, nargs="+", default=[8, 12, 18, 28])
    parser.add_argument("--width", default="1/6")
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--out", default="benchmarks/results")
    args = parser.parse_args(argv)
    try:
        width = float(Fraction(args.width))
    except (ValueError, ZeroDivisionError):
        parser.exit(2, f"--width {args.width!r}: give a number or fraction in (0, 1]\n")
    if not 0.0 < width <= 1.0 or args.repeat < 1 or any(r < 2 or r > 60 for r in args.rows):
        parser.exit(2, f"--width {args.width} must lie in (0, 1], --repeat {args.repeat} >= 1, --rows "
                       f"{args.rows} within 2..60\n")
    out = Path(args.out)
    provenance = Provenance()
    results = []
    for rows in args.rows:
        results.append(measure(rows, width, args.repeat))
        r = results[-1]
        print(f"rows {rows}: n = {r['n']}, band {r['band_cholesky_ms']:.1f} ms, MUMPS {r['mumps_ms']:.1f} ms "
              f"(analysis + factor {r['mumps_analysis_and_factor_ms']:.1f}), negative pivots "
              f"{r['negative_pivots_band_ldlt']} / {r['negative_pivots_mumps']}", flush=True)
    report = {"benchmark": "plate_mumps", "config": {"rows": args.rows, "width": args.width, "repeat": args.repeat},
              "results": results, **provenance.report(results)}
    warn_if_changed(report)
    print(write_report(out, "plate_mumps", report, markdown(report)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
