"""Linear algebra of one plate Newton iteration: banded Cholesky against sparse LDL^T, inertia, BLAS threads.

    .venv/bin/python -m benchmarks.plate_linear_algebra [--cases 1/6:2000,6000,20000 1/20:2000,6000 1/2:2000,6000]
        [--repeat 10] [--budget 10] [--compression-steps 10] [--dense-max 4000] [--threads default 1]
        [--out benchmarks/results] [--cache out/plate_linear_algebra_cache] [--timeout 3600] [--fresh] [--rebuild]
        [--report-only]

For each W/L and target triangle count N (`--cases W/L:N,N,...`; `--triangles` with `--width-ratios`
gives the full grid instead) it builds three free-DOF Hessians of the plate,

    res = ddg.simulate(ddg.Strip.from_ratios(W/L, 0.5),
                       ddg.LoadingProtocol(0.5, 0.0, compression_steps=10), model="plate", resolution=N)
    K = res.model.free_matrix(res.final_state.evaluation.hessian)   # "compressed": buckled U, positive definite

and, on the same mesh, the flat strip compressed in its plane (clamps moved by dL, free nodes at the
in-plane equilibrium: x interpolated linearly between the clamps, then Newton steps, which stay flat):
"flat 1%" at dL/L = 0.01 (thousands of Euler strains: most out-of-plane modes unstable) and "flat 3 eps_E"
at dL/L = 3 eps_E, eps_E = 4 pi^2 (8/9) b^2 / (12 L^2) the clamped narrow plate's Euler strain (a few
unstable modes, as Newton meets just past a bifurcation). Both are indefinite. Where n <= --dense-max the
eigenvalues of each matrix are counted densely (numpy.linalg.eigvalsh).

The matrices are built once per case in a child process with one BLAS thread and cached in --cache
(npz; a rerun reuses them, --rebuild recomputes). Then, per case and per BLAS thread setting
(--threads: "default" = the environment as inherited, 2 threads on the 2-core machine; "1" = a child
started with OPENBLAS_NUM_THREADS=OMP_NUM_THREADS=1; threadpoolctl is not installed), a fresh child
times (median and minimum over up to --repeat calls after one untimed warm-up; a call slower than
--budget seconds is timed once, and the repeats stop at about --budget seconds):

- banded Cholesky as the project calls it (scipy.linalg.cholesky_banded(band, lower=True,
  check_finite=False); on an indefinite matrix the time to its failure), and with one cho_solve_banded;
- the band LDL^T without pivoting of ddg.solve.band_ldlt (numba; factor, one solve, inertia);
- CHOLMOD through scikit-sparse (sksparse.cholmod), for the orderings nesdis (CHOLMOD's nested
  dissection), amd and metis: the symbolic analysis alone, simplicial LDL^T with the analysis reused
  (analyze once, then Factor.cholesky_inplace per factorisation: the pattern of a Newton Hessian does not
  change) and one solve, the same including the analysis (cholmod.cholesky), and supernodal LL^T with
  the analysis reused (positive definite matrices only: CHOLMOD's supernodal factor is LL^T); the
  inertia from the signs of Factor.D() of the LDL^T; fill nnz(L);
- banded LU (scipy.linalg.solve_banded: LAPACK gbsv, factor and one solve) with the conversion to its
  storage;
- default threads only, on the compressed matrix: SuperLU (splu with COLAMD, MMD_AT_PLUS_A, MMD_AT_PLUS_A
  in symmetric mode, natural order), the lowest eigenvalue (eigsh sigma=0 and the project's
  SymmetricBanded.lowest_eigenpairs), and the element work (PlateModel.evaluate full / energy+gradient /
  energy only, BandAssembler.assemble, the free-DOF restriction) on the model rebuilt from the cached
  state.

The CSC matrix is built from the band (band[d, j] = A[j + d, j]; exact zeros dropped, except that the flat
matrices are stored on the compressed matrix's pattern, as a Newton Hessian keeps its pattern). Each solve's
relative residual |A x - b| / |b| is recorded. Writes OUT/plate_linear_algebra.json and .md atomically;
the conclusion is computed from the tables. Timings of each (case, threads) child are also cached
(keyed by this script's and ddg/solve/band_ldlt.py's sources and the timing options; --fresh retimes),
so an interrupted run resumes; --report-only rewrites the report from the cached timings without measuring
(whatever version of the code produced them: each record keeps its fingerprint). Not part of the test
run. Smoke run (~1 min):
--cases 1/6:500 --repeat 3 --out /tmp/plate_la_smoke --cache /tmp/plate_la_smoke/cache.
"""
from __future__ import annotations

import argparse
import contextlib
import gc
import hashlib
import json
import math
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np

from benchmarks.common import (Provenance, load_average, machine_section, ratio, run_in_child, section,
                               source_fingerprint, table_section, text_table, write_report)

DEFAULT_CASES = ["1/6:2000,6000,20000", "1/20:2000,6000", "1/2:2000,6000"]
COMPRESSION_RATIO = 0.5
COMPRESSION_STEPS = 10
FLAT_RATIO = 0.01          # dL/L of the strongly indefinite flat matrix
MILD_EULER_MULTIPLE = 3.0  # dL/L = this times the Euler strain for the mildly indefinite one
ORDERINGS = ("nesdis", "amd", "metis")
THREAD_VARS = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "BLIS_NUM_THREADS")
MATRICES = ("compressed", "flat 1%", "flat 3 eps_E")

SUPERLU_VARIANTS = {
    "SuperLU COLAMD": {},
    "SuperLU MMD_AT_PLUS_A": {"permc_spec": "MMD_AT_PLUS_A"},
    "SuperLU MMD_AT_PLUS_A symmetric mode": {"permc_spec": "MMD_AT_PLUS_A", "diag_pivot_thresh": 0.0,
                                             "options": {"SymmetricMode": True}},
    "SuperLU NATURAL": {"permc_spec": "NATURAL"},
}
# SuperLU MMD_AT_PLUS_A without symmetric mode fills in badly (10 s and 11.5e6 nonzeros at n = 6333 in the
# previous run of this benchmark): above this n it is not run (the report says so)
SUPERLU_MMD_MAX_N = 12000


def cholmod_module():
    """sksparse.cholmod if importable, else (None, reason)."""
    try:
        from sksparse import cholmod
        return cholmod, None
    except Exception as exc:  # ImportError, or a binary built against another numpy
        return None, f"scikit-sparse not importable ({type(exc).__name__}: {exc}); CHOLMOD skipped"


def cholmod_version() -> str:
    try:
        from importlib.metadata import version
        return f"scikit-sparse {version('scikit-sparse')}"
    except Exception:
        return "scikit-sparse (version unknown)"


# ---------------------------------------------------------------------------- timing
@contextlib.contextmanager
def _gc_paused():
    gc_was = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if gc_was:
            gc.enable()


def _stats(times: list[float], single: bool = False) -> dict:
    out = {"median_ms": 1e3 * statistics.median(times), "min_ms": 1e3 * min(times), "repeats": len(times)}
    if single:
        out["single_call"] = True  # the warm-up itself, slower than the budget
    return out


def _count(first: float, repeat: int, budget: float) -> int:
    return max(1, min(repeat, int(budget / max(first, 1e-9))))


def timed(fn, repeat: int, budget: float, setup=None) -> tuple[dict, object]:
    """Median/min wall time of fn(setup()) after one warm-up; setup is untimed. A warm-up slower than
    `budget` seconds is the only sample; otherwise up to `repeat` calls, about `budget` seconds."""
    arg = setup() if setup else None
    t0 = time.perf_counter()
    out = fn(arg)
    first = time.perf_counter() - t0
    if first > budget:
        return _stats([first], single=True), out
    times = []
    with _gc_paused():
        for _ in range(_count(first, repeat, budget)):
            arg = setup() if setup else None
            t0 = time.perf_counter()
            out = fn(arg)
            times.append(time.perf_counter() - t0)
    return _stats(times), out


def timed_pair(factor, solve, repeat: int, budget: float):
    """factor() then solve(factor) per repeat (see timed); stats of both, of their sum, the last results."""
    t0 = time.perf_counter()
    f = factor()
    t1 = time.perf_counter()
    x = solve(f)
    first = (t1 - t0, time.perf_counter() - t1)
    if sum(first) > budget:
        return _stats([first[0]], True), _stats([first[1]], True), _stats([sum(first)], True), (f, x)
    tf, ts = [], []
    with _gc_paused():
        for _ in range(_count(sum(first), repeat, budget)):
            t0 = time.perf_counter()
            f = factor()
            t1 = time.perf_counter()
            x = solve(f)
            t2 = time.perf_counter()
            tf.append(t1 - t0)
            ts.append(t2 - t1)
    return _stats(tf), _stats(ts), _stats([a + b for a, b in zip(tf, ts)]), (f, x)


# ---------------------------------------------------------------------------- matrices
def band_to_csc(band: np.ndarray, pattern: np.ndarray | None = None):
    """The symmetric matrix of lower band storage band[d, j] = A[j + d, j] as CSC (both triangles), exact
    zeros dropped except where `pattern` (a band of the same shape) is nonzero: those are stored."""
    import scipy.sparse as sp

    n = band.shape[1]
    rows, cols, vals = [], [], []
    for d in range(band.shape[0]):
        j = np.arange(n - d)
        v = band[d, : n - d]
        keep = v != 0.0
        if pattern is not None:
            keep |= pattern[d, : n - d] != 0.0
        j, v = j[keep], v[keep]
        rows.append(j + d)
        cols.append(j)
        vals.append(v)
        if d:
            rows.append(j)
            cols.append(j + d)
            vals.append(v)
    rows, cols, vals = np.concatenate(rows), np.concatenate(cols), np.concatenate(vals)
    out = sp.csc_matrix((vals, (rows, cols)), shape=(n, n))
    out.sort_indices()
    return out


def general_band(band: np.ndarray) -> np.ndarray:
    """Symmetric lower band -> the (2u+1, n) general band form of solve_banded (as SymmetricBanded.solve)."""
    u, n = band.shape[0] - 1, band.shape[1]
    full = np.zeros((2 * u + 1, n))
    full[u:] = band
    for d in range(1, u + 1):
        full[u - d, d:] = band[d, : n - d]
    return full


def effective_bandwidth(band: np.ndarray) -> int:
    nz = [d for d in range(band.shape[0]) if np.any(band[d] != 0.0)]
    return max(nz) if nz else 0


def euler_strain(strip) -> float:
    """Clamped-clamped Euler strain of the narrow plate: P_E / (E b W) with P_E = 4 pi^2 (8/9) EI / L^2
    (the plate bends with 8/9 of the rod's EI, ddg.models.plate)."""
    return 4.0 * math.pi ** 2 * (8.0 / 9.0) * strip.thickness ** 2 / (12.0 * strip.length ** 2)


def flat_equilibrium(model, compression: float, max_steps: int = 8) -> tuple[np.ndarray, list[float]]:
    """The flat strip with the clamps moved by `compression` and the free nodes at their in-plane
    equilibrium: x interpolated linearly between the clamp columns, then Newton steps with the banded
    solve (LU when indefinite; in-plane and out-of-plane decouple at z = 0, so the steps stay flat)."""
    q = model.apply_clamps(model.rest_state(), compression, 0.0)
    x = model.mesh.nodes[:, 0]
    x0, x1 = x[model.left_nodes].max(), x[model.right_nodes].min()
    s = np.clip((x - x0) / (x1 - x0), 0.0, 1.0)
    free_nodes = np.ones(model.mesh.node_count, dtype=bool)
    free_nodes[model.left_nodes] = free_nodes[model.right_nodes] = False
    q[model.node_dofs[free_nodes, 0]] = (x - compression * s)[free_nodes]
    history = []
    for _ in range(max_steps):
        ev = model.evaluate(q)
        g = ev.gradient[model.free]
        history.append(float(np.linalg.norm(g)))
        if len(history) > 1 and (history[-1] <= 1e-12 * history[0] or history[-1] > 0.5 * history[-2]):
            break
        q[model.free] += model.free_matrix(ev.hessian).solve(-g)
    return q, history


def dense_inertia(band: np.ndarray) -> dict:
    from ddg.solve.banded import SymmetricBanded

    t0 = time.perf_counter()
    a = SymmetricBanded(band).to_dense()
    w = np.linalg.eigvalsh(a)
    tol = band.shape[1] * np.finfo(float).eps * float(np.max(np.abs(w)))
    return {"negative": int(np.sum(w < -tol)), "zero": int(np.sum(np.abs(w) <= tol)), "positive": int(np.sum(w > tol)),
            "lambda_min": float(w[0]), "lambda_max": float(w[-1]), "min_abs_lambda": float(np.min(np.abs(w))),
            "zero_tolerance": tol, "time_s": time.perf_counter() - t0}


# ---------------------------------------------------------------------------- child: build the matrices
def build_case(width_ratio: float, width_label: str, triangles: int, compression_steps: int, dense_max: int,
               path: str) -> dict:
    """Compressed state and the two flat states of one case; bands and metadata into `path` (npz)."""
    import ddg

    t0 = time.perf_counter()
    strip = ddg.Strip.from_ratios(width_ratio, COMPRESSION_RATIO)
    res = ddg.simulate(strip, ddg.LoadingProtocol(COMPRESSION_RATIO, 0.0, compression_steps=compression_steps),
                       model="plate", resolution=triangles)
    state_time = time.perf_counter() - t0
    model = res.model
    meta = {
        "width_ratio": width_ratio, "width_label": width_label, "triangles_target": triangles,
        "compression_steps": compression_steps,
        "triangles": int(model.mesh.triangle_count), "nodes": int(model.mesh.node_count), "n_dof": int(model.n_dof),
        "state": {"converged": bool(res.summary["converged"]), "message": res.summary.get("message", ""),
                  "dL_over_L": float(res.rows[-1]["dL_over_L"]) if res.rows else None,
                  "H_mid_over_L": float(res.rows[-1]["H_mid_over_L"]) if res.rows else None,
                  "newton_iterations": res.summary.get("newton_iterations"), "time_s": state_time},
        "ddg_source_sha256": source_fingerprint(),
        "built": time.strftime("%Y-%m-%dT%H:%M:%S"),
        "matrices": {},
    }
    if res.final_state is None:
        raise RuntimeError(f"no equilibrium to take the Hessian of: {res.summary.get('message')}")
    arrays = {"q_compressed": res.final_state.q}
    bands = {"compressed": np.ascontiguousarray(model.free_matrix(res.final_state.evaluation.hessian).band)}
    eps_e = euler_strain(strip)
    for name, ratio_ in (("flat 1%", FLAT_RATIO), ("flat 3 eps_E", MILD_EULER_MULTIPLE * eps_e)):
        t1 = time.perf_counter()
        q, hist = flat_equilibrium(model, ratio_ * strip.length)
        bands[name] = np.ascontiguousarray(model.free_matrix(model.evaluate(q).hessian).band)
        meta["matrices"][name] = {"dL_over_L": ratio_, "euler_strain": eps_e, "newton_gradient_norms": hist,
                                  "max_abs_z": float(np.max(np.abs(q[model.node_dofs[:, 2]]))),
                                  "time_s": time.perf_counter() - t1}
    meta["matrices"]["compressed"] = {"dL_over_L": COMPRESSION_RATIO}
    for name, band in bands.items():
        arrays["band " + name] = band
        m = meta["matrices"][name]
        m["n"] = int(band.shape[1])
        m["bandwidth"] = effective_bandwidth(band)
        m["max_abs_diagonal"] = float(np.max(np.abs(band[0])))
        if band.shape[1] <= dense_max:
            m["dense"] = dense_inertia(band)
    tmp = Path(path).with_suffix(".tmp.npz")
    np.savez(tmp, meta=np.array(json.dumps(meta)), **arrays)
    os.replace(tmp, path)
    return {"path": path, "time_s": time.perf_counter() - t0, "triangles": meta["triangles"]}


def load_case(path: str) -> tuple[dict, dict]:
    with np.load(path, allow_pickle=False) as z:
        meta = json.loads(str(z["meta"]))
        arrays = {k: z[k] for k in z.files if k != "meta"}
    return meta, arrays


# ---------------------------------------------------------------------------- child: time one case
def blas_threads() -> int | None:
    """openblas_get_num_threads() of the OpenBLAS this process loaded, if any."""
    import ctypes

    import scipy.linalg  # noqa: F401  (loads LAPACK/BLAS)
    for name in ("libopenblas.so.0", "libopenblasp-r0.3.21.so", "libopenblas.so"):
        try:
            return int(ctypes.CDLL(name).openblas_get_num_threads())
        except (OSError, AttributeError):
            continue
    return None


def _inertia_of(d: np.ndarray, tol: float) -> dict:
    return {"negative": int(np.sum(d < -tol)), "zero": int(np.sum(np.abs(d) <= tol)), "positive": int(np.sum(d > tol)),
            "min_abs_pivot": float(np.min(np.abs(d)))}


def time_matrix(band: np.ndarray, repeat: int, budget: float, full: bool,
                pattern: np.ndarray | None = None) -> tuple[dict, dict, dict, int]:
    """Times of every method on one matrix (CSC on its nonzeros and those of `pattern`);
    (times, inertia, notes, nnz of the CSC matrix)."""
    import scipy.linalg as sla
    import scipy.sparse.linalg as spla

    from ddg.solve.band_ldlt import band_ldlt

    band = np.ascontiguousarray(band)
    n, u = band.shape[1], band.shape[0] - 1
    A = band_to_csc(band, pattern)
    rhs = np.random.default_rng(0).standard_normal(n)
    rnorm = float(np.linalg.norm(rhs))
    def resid(x):
        return float(np.linalg.norm(A @ x - rhs) / rnorm)
    t, inertia, notes = {}, {}, {}
    tol = n * np.finfo(float).eps * float(np.max(np.abs(band[0])))

    # banded Cholesky, as ddg.solve.banded.SymmetricBanded.cholesky / .solve
    def chol_factor():
        try:
            return sla.cholesky_banded(band, lower=True, check_finite=False)
        except sla.LinAlgError:
            return None

    pd = chol_factor() is not None
    inertia["banded Cholesky succeeds"] = pd
    if pd:
        f, s, fs, (_, x) = timed_pair(chol_factor, lambda c: sla.cho_solve_banded((c, True), rhs, check_finite=False),
                                      repeat, budget)
        t["banded Cholesky"] = {"factor": f, "solve": s, "factor+solve": fs, "residual": resid(x)}
    else:
        f, _ = timed(lambda _: chol_factor(), repeat, budget)
        t["banded Cholesky"] = {"factor": f, "failed": True,
                                "note": "not positive definite: time to LAPACK's failure"}

    # band LDL^T without pivoting (ddg.solve.band_ldlt, numba)
    try:
        f, s, fs, (F, x) = timed_pair(lambda: band_ldlt(band), lambda F: F.solve(rhs) if F.reliable else None,
                                      repeat, budget)
        entry = {"factor": f, "factor+solve": fs}
        if F.reliable:
            entry.update({"solve": s, "residual": resid(x)})
        t["band LDL^T"] = entry
        inertia["band LDL^T"] = {**F.inertia(strict=False)._asdict(), "reliable": F.reliable,
                                 "min_abs_pivot": float(np.nanmin(np.abs(F.d))), "tolerance": F.tolerance}
    except Exception as exc:
        notes["band LDL^T"] = f"{type(exc).__name__}: {exc}"

    # banded LU (gbsv: factor + solve in one call) and the conversion to its storage
    conv, full_band = timed(lambda _: general_band(band), repeat, budget)
    fs, x = timed(lambda _: sla.solve_banded((u, u), full_band, rhs, check_finite=False), repeat, budget)
    t["banded LU"] = {"factor+solve": fs, "conversion": conv, "residual": resid(x)}

    # CHOLMOD
    cholmod, why = cholmod_module()
    if cholmod is None:
        notes["CHOLMOD"] = why
    else:
        for o in ORDERINGS:
            name = f"CHOLMOD LDL^T {o}"
            try:
                an, F = timed(lambda _: cholmod.analyze(A, mode="simplicial", ordering_method=o), repeat, budget)
                t[f"CHOLMOD analysis {o}"] = {"factor": an}

                def refactor(F=F):
                    F.cholesky_inplace(A)
                    return F

                f, s, fs, (F, x) = timed_pair(refactor, lambda F: F(rhs), repeat, budget)
                d = F.D()
                t[name] = {"factor": f, "solve": s, "factor+solve": fs, "residual": resid(x),
                           "nnz_L": int(F.LD().nnz)}
                inertia[name] = _inertia_of(d, tol)
                f, _ = timed(lambda _: cholmod.cholesky(A, mode="simplicial", ordering_method=o), repeat, budget)
                t[f"CHOLMOD LDL^T {o} with analysis"] = {"factor": f}
            except Exception as exc:
                notes[name] = f"{type(exc).__name__}: {exc}"
            name = f"CHOLMOD LL^T supernodal {o}"
            if not pd:
                continue  # supernodal CHOLMOD is LL^T: it fails on an indefinite matrix
            try:
                F = cholmod.analyze(A, mode="supernodal", ordering_method=o)

                def refactor(F=F):
                    F.cholesky_inplace(A)
                    return F

                f, s, fs, (F, x) = timed_pair(refactor, lambda F: F(rhs), repeat, budget)
                t[name] = {"factor": f, "solve": s, "factor+solve": fs, "residual": resid(x), "nnz_L": int(F.L().nnz)}
            except Exception as exc:
                notes[name] = f"{type(exc).__name__}: {exc}"

    if full:
        for name, kw in SUPERLU_VARIANTS.items():
            if name == "SuperLU MMD_AT_PLUS_A" and n > SUPERLU_MMD_MAX_N:
                notes[name] = f"not run: n = {n} > {SUPERLU_MMD_MAX_N} (fill grows too fast)"
                continue
            try:
                f, s, fs, (lu, x) = timed_pair(lambda: spla.splu(A, **kw), lambda lu: lu.solve(rhs), repeat, budget)
                t[name] = {"factor": f, "solve": s, "factor+solve": fs, "residual": resid(x),
                           "fill_nnz": int(lu.L.nnz + lu.U.nnz)}
            except Exception as exc:  # e.g. a singular matrix
                notes[name] = f"{type(exc).__name__}: {exc}"
    return t, inertia, notes, int(A.nnz)


def time_case(path: str, threads: str, repeat: int, budget: float) -> dict:
    """Every measurement of one cached case in this process (its BLAS threads set by the parent)."""
    meta, arrays = load_case(path)
    full = threads == "default"
    out = {"threads": threads, "blas_threads": blas_threads(), "matrices": {},
           "thread_env": {k: os.environ.get(k) for k in THREAD_VARS}, "load_average_start": load_average()}
    for name in MATRICES:
        # the flat matrices on the compressed one's pattern: a Newton Hessian's pattern does not change (at z = 0
        # the in-plane and out-of-plane blocks decouple; dropping those exact zeros would favour the sparse solvers)
        times, inertia, notes, nnz = time_matrix(arrays["band " + name], repeat, budget,
                                                 full=full and name == "compressed",
                                                 pattern=None if name == "compressed" else arrays["band compressed"])
        out["matrices"][name] = {"factorisations": times, "inertia": inertia, "notes": notes, "nnz": nnz}
    if full:
        band = np.ascontiguousarray(arrays["band compressed"])
        out["eigen"] = time_eigen(band, repeat, budget)
        out["element"], note = time_element(meta, arrays["q_compressed"], repeat, budget)
        if note:
            out["matrices"]["compressed"]["notes"]["element"] = note
    out["load_average_end"] = load_average()
    return out


def time_eigen(band: np.ndarray, repeat: int, budget: float) -> dict:
    import scipy.sparse.linalg as spla

    from ddg.solve.banded import SymmetricBanded

    A = band_to_csc(band)
    n = band.shape[1]
    eig = {}
    st, w = timed(lambda _: spla.eigsh(A, k=1, sigma=0.0, which="LM", tol=1e-12, v0=np.ones(n),
                                       return_eigenvectors=False), repeat, budget)
    eig["eigsh sigma=0"] = {**st, "lambda": float(np.min(w))}
    st, w = timed(lambda M: M.lowest_eigenpairs(1), repeat, budget, setup=lambda: SymmetricBanded(band.copy()))
    eig["lowest_eigenpairs"] = {**st, "lambda": float(np.atleast_1d(w)[0])}

    def prefactored():
        M = SymmetricBanded(band.copy())
        M.cholesky()
        return M

    st, w = timed(lambda M: M.lowest_eigenpairs(1), repeat, budget, setup=prefactored)
    eig["lowest_eigenpairs, factor reused"] = {**st, "lambda": float(np.atleast_1d(w)[0])}
    return eig


def time_element(meta: dict, q: np.ndarray, repeat: int, budget: float) -> tuple[dict, str | None]:
    """Element work of PlateModel on the cached compressed state (the model rebuilt from the strip and N)."""
    import ddg
    from ddg.models.plate import PlateModel

    strip = ddg.Strip.from_ratios(meta["width_ratio"], COMPRESSION_RATIO)
    model = PlateModel(strip, meta["triangles_target"])
    if model.mesh.triangle_count != meta["triangles"] or model.n_dof != len(q):
        return {}, "the rebuilt model's mesh differs from the cached one: element work not timed"
    el = {}
    st, _ = timed(lambda _: model.evaluate(q), repeat, budget)
    el["evaluate, full (energy, gradient, Hessian + assembly)"] = st
    st, _ = timed(lambda _: model.evaluate(q, gradient=True, hessian=False), repeat, budget)
    el["evaluate, energy + gradient"] = st
    st, _ = timed(lambda _: model.evaluate(q, gradient=False, hessian=False), repeat, budget)
    el["evaluate, energy only"] = st
    assembler = getattr(model, "_assembler", None)
    note = None
    H = model.evaluate(q).hessian
    if assembler is not None and hasattr(assembler, "assemble"):
        captured = {}
        original = assembler.assemble

        def capture(blocks, *a, **k):
            captured["args"] = (blocks, a, k)
            return original(blocks, *a, **k)

        assembler.assemble = capture  # on this instance only, removed below
        try:
            H = model.evaluate(q).hessian
        finally:
            del assembler.assemble
        if "args" in captured:
            blocks, a, k = captured["args"]
            st, _ = timed(lambda _: assembler.assemble(blocks, *a, **k), repeat, budget)
            el["band assembly alone (BandAssembler.assemble)"] = st
        else:
            note = "evaluate does not call BandAssembler.assemble (kernels assemble straight into the band)"
    else:
        note = "model has no _assembler: assembly not timed separately"
    st, _ = timed(lambda _: H.restrict(model.free.start, model.free.stop), repeat, budget)
    el["restriction to the free DOFs (SymmetricBanded.restrict)"] = st
    return el, note


# ---------------------------------------------------------------------------- parent: orchestration
@contextlib.contextmanager
def thread_env(threads: str):
    """os.environ for a child with `threads` BLAS threads ("default": unchanged), restored afterwards."""
    saved = {k: os.environ.get(k) for k in THREAD_VARS}
    try:
        if threads != "default":
            for k in THREAD_VARS:
                os.environ[k] = threads
        yield
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


def case_key(label: str, triangles: int, steps: int) -> str:
    return f"plate_la_W{label.replace('/', 'o')}_N{triangles}_s{steps}"


def timing_fingerprint(repeat: int, budget: float) -> str:
    h = hashlib.sha256()
    here = Path(__file__).resolve()
    for p in (here, here.parent.parent / "ddg" / "solve" / "band_ldlt.py"):
        h.update(p.read_bytes())
    h.update(f"{repeat} {budget}".encode())
    return h.hexdigest()


def parse_cases(args) -> list[tuple[float, str, int]]:
    if args.triangles or args.width_ratios:
        widths = args.width_ratios or ["1/20", "1/6", "1/2"]
        tris = args.triangles or [500, 1000, 2000, 4000]
        return [(ratio(w), w, n) for w in widths for n in tris]
    out = []
    for spec in args.cases:
        label, _, ns = spec.partition(":")
        if not ns:
            raise argparse.ArgumentTypeError(f"case {spec!r} must be W/L:N[,N...]")
        out += [(ratio(label), label, int(n)) for n in ns.split(",")]
    return out


def run_all(args, cases) -> list[dict]:
    cache = Path(args.cache)
    cache.mkdir(parents=True, exist_ok=True)
    fp = timing_fingerprint(args.repeat, args.budget)
    records = []
    for w, label, n in cases:
        key = case_key(label, n, args.compression_steps)
        path = cache / f"{key}.npz"
        rec = {"width_ratio": w, "width_label": label, "triangles_target": n, "cache": str(path), "timings": {}}
        records.append(rec)
        if args.report_only and not path.exists():
            rec["error"] = "no cached matrices (--report-only)"
            continue
        if args.rebuild or not path.exists():
            with thread_env("1"):
                status, payload, elapsed = run_in_child(build_case, (w, label, n, args.compression_steps,
                                                                     args.dense_max, str(path)), args.timeout or None)
            print(f"W/L = {label}, N = {n}: matrices {status} in {elapsed:.1f} s", file=sys.stderr)
            if status != "ok":
                rec["error"] = f"building the matrices: {status}: {payload}"
                print(rec["error"], file=sys.stderr)
                continue
        rec["meta"], _ = load_case(str(path))
        for threads in args.threads:
            tpath = cache / f"{key}.time-{threads}.json"
            if not args.fresh and tpath.exists():
                saved = json.loads(tpath.read_text())
                same = saved.get("fingerprint") == fp and saved.get("matrices_built") == rec["meta"]["built"]
                if same or args.report_only:
                    rec["timings"][threads] = saved["result"]
                    rec.setdefault("timing_fingerprints", {})[threads] = saved.get("fingerprint")
                    print(f"W/L = {label}, N = {n}, threads {threads}: cached timings", file=sys.stderr)
                    continue
            if args.report_only:
                rec.setdefault("errors", {})[threads] = "no cached timings (--report-only)"
                continue
            with thread_env(threads):
                status, payload, elapsed = run_in_child(time_case, (str(path), threads, args.repeat, args.budget),
                                                        args.timeout or None)
            print(f"W/L = {label}, N = {n}, threads {threads}: {status} in {elapsed:.1f} s", file=sys.stderr)
            if status != "ok":
                rec.setdefault("errors", {})[threads] = f"{status}: {payload}"
                print(payload, file=sys.stderr)
                continue
            rec["timings"][threads] = payload
            tmp = tpath.with_suffix(".tmp")
            tmp.write_text(json.dumps({"fingerprint": fp, "matrices_built": rec["meta"]["built"], "result": payload},
                                      default=_json_default))
            os.replace(tmp, tpath)
    return records


def _json_default(x):
    if isinstance(x, (np.integer,)):
        return int(x)
    if isinstance(x, (np.floating, float)):
        return float(x) if math.isfinite(x) else None
    if isinstance(x, np.bool_):
        return bool(x)
    raise TypeError(type(x))


# ---------------------------------------------------------------------------- analysis
def ms(rec: dict, threads: str, matrix: str, method: str, key: str) -> float | None:
    try:
        e = rec["timings"][threads]["matrices"][matrix]["factorisations"][method]
        return e[key]["median_ms"]
    except (KeyError, TypeError):
        return None


def best(rec: dict, matrix: str, method: str, key: str) -> tuple[float | None, str | None]:
    """The lower median over the thread settings, and which setting."""
    vals = [(ms(rec, th, matrix, method, key), th) for th in rec["timings"]]
    vals = [v for v in vals if v[0] is not None]
    return min(vals) if vals else (None, None)


def best_cholmod(rec: dict, matrix: str, kind: str, key: str) -> tuple[float | None, str | None, str | None]:
    """The fastest CHOLMOD ordering of `kind` ("LDL^T" or "LL^T supernodal"): (ms, ordering, threads)."""
    vals = []
    for o in ORDERINGS:
        v, th = best(rec, matrix, f"CHOLMOD {kind} {o}", key)
        if v is not None:
            vals.append((v, o, th))
    return min(vals) if vals else (None, None, None)


def ok_records(records):
    return [r for r in records if r.get("timings")]


def summarise(records: list[dict]) -> list[dict]:
    """Per case, the numbers the conclusion and the tables use."""
    out = []
    for r in ok_records(records):
        m = r["meta"]
        s = {"label": r["width_label"], "triangles": m["triangles"], "n": m["matrices"]["compressed"]["n"],
             "bandwidth": m["matrices"]["compressed"]["bandwidth"]}
        for key in ("factor", "factor+solve"):
            cands = {}
            for meth in ("banded Cholesky", "band LDL^T"):
                v, th = best(r, "compressed", meth, key)
                if v is not None:
                    cands[meth] = (v, th)
            for kind in ("LDL^T", "LL^T supernodal"):
                v, o, th = best_cholmod(r, "compressed", kind, key)
                if v is not None:
                    cands[f"CHOLMOD {kind} {o}"] = (v, th)
            ranked = sorted(cands.items(), key=lambda kv: kv[1][0])
            s[f"ranked {key}"] = [(k, v, th) for k, (v, th) in ranked]
        for mat in ("flat 1%", "flat 3 eps_E"):
            cands = {}
            v, th = best(r, mat, "band LDL^T", "factor")
            if v is not None:
                cands["band LDL^T"] = (v, th)
            v, o, th = best_cholmod(r, mat, "LDL^T", "factor")
            if v is not None:
                cands[f"CHOLMOD LDL^T {o}"] = (v, th)
            s[f"ranked inertia {mat}"] = sorted(((k, v, th) for k, (v, th) in cands.items()), key=lambda x: x[1])
        out.append(s)
    return out


def inertia_rows(records) -> list[dict]:
    """One row per (case, matrix): dense counts, LDL^T counts, banded Cholesky success."""
    rows = []
    for r in ok_records(records):
        th = "default" if "default" in r["timings"] else next(iter(r["timings"]))
        for mat in MATRICES:
            inert = r["timings"][th]["matrices"][mat]["inertia"]
            dense = r["meta"]["matrices"][mat].get("dense")
            rows.append({"label": r["width_label"], "triangles": r["meta"]["triangles"], "matrix": mat,
                         "n": r["meta"]["matrices"][mat]["n"], "dense": dense,
                         "nnz": r["timings"][th]["matrices"][mat].get("nnz"),
                         "chol": inert.get("banded Cholesky succeeds"),
                         "ldlt": inert.get("band LDL^T"),
                         "cholmod": {o: inert.get(f"CHOLMOD LDL^T {o}") for o in ORDERINGS}})
    return rows


def conclusion(records: list[dict]) -> list[str]:
    summ = summarise(records)
    if not summ:
        return ["no case completed"]
    lines = []
    # 0. overall: which method wins factor + one solve on the positive definite Hessians, by how much
    wins, over_ldl, over_any = {}, [], []
    for s in summ:
        ranked = s["ranked factor+solve"]
        if not ranked:
            continue
        wins.setdefault(ranked[0][0], []).append(s)
        ldl = next((x for x in ranked if x[0].startswith("CHOLMOD LDL^T")), None)
        if ranked[0][0] == "banded Cholesky":
            if ldl:
                over_ldl.append(ldl[1] / ranked[0][1])
            if len(ranked) > 1:
                over_any.append(ranked[1][1] / ranked[0][1])
    if wins:
        text = "Fastest factor + one solve on the positive definite Hessians: " + "; ".join(
            f"{name} in {len(v)}/{len(summ)} cases" for name, v in sorted(wins.items(), key=lambda kv: -len(kv[1])))
        if over_ldl:
            text += (f"; where banded Cholesky wins, the fastest CHOLMOD LDL^T takes {min(over_ldl):.2f}x to "
                     f"{max(over_ldl):.2f}x its time and the next fastest method {min(over_any):.2f}x to "
                     f"{max(over_any):.2f}x")
        lines.append(text + ".")
    # 1. per size: banded Cholesky against the fastest sparse LDL^T / LL^T, factor + one solve
    for s in summ:
        ranked = s["ranked factor+solve"]
        if not ranked:
            continue
        name, v, th = ranked[0]
        chol = next((x for x in ranked if x[0] == "banded Cholesky"), None)
        ldl = next((x for x in ranked if x[0].startswith("CHOLMOD LDL^T")), None)
        text = (f"W/L = {s['label']}, {s['triangles']} triangles (n = {s['n']}, bandwidth {s['bandwidth']}), "
                f"compressed "
                f"(positive definite) Hessian, factor + one solve: fastest {name} at {v:.2f} ms ({th_label(th)})")
        if len(ranked) > 1:
            text += f", {ranked[1][1] / v:.2f}x faster than the next ({ranked[1][0]}, {ranked[1][1]:.2f} ms)"
        if chol and ldl:
            if chol[1] <= ldl[1]:
                text += (f"; banded Cholesky ({chol[1]:.2f} ms) is {ldl[1] / chol[1]:.2f}x faster than the fastest "
                         f"CHOLMOD LDL^T ({ldl[0].split()[-1]}, {ldl[1]:.2f} ms): use the banded Cholesky at this size")
            else:
                text += (f"; the fastest CHOLMOD LDL^T ({ldl[0].split()[-1]}, {ldl[1]:.2f} ms) is "
                         f"{chol[1] / ldl[1]:.2f}x "
                         f"faster than banded Cholesky ({chol[1]:.2f} ms): use CHOLMOD LDL^T at this size")
        lines.append(text + ".")
    # 2. inertia on the indefinite matrices: the fastest way to the count of negative eigenvalues
    for s in summ:
        parts = []
        for mat in ("flat 1%", "flat 3 eps_E"):
            ranked = s[f"ranked inertia {mat}"]
            if len(ranked) >= 1:
                name, v, th = ranked[0]
                p = f"{mat}: {name} {v:.2f} ms"
                if len(ranked) > 1:
                    p += f", {ranked[1][1] / v:.2f}x faster than {ranked[1][0]} ({ranked[1][1]:.2f} ms)"
                parts.append(p)
        if parts:
            lines.append(f"Inertia (LDL^T factorisation) at W/L = {s['label']}, {s['triangles']} triangles: "
                         + "; ".join(parts) + ".")
    # 2b. a Newton step on an indefinite Hessian: the project's path (banded Cholesky to its failure, conversion,
    # banded LU) against an LDL^T factor + one solve, which also gives the inertia
    for r in ok_records(records):
        parts = []
        for mat in ("flat 1%", "flat 3 eps_E"):
            path = []
            for th in r["timings"]:
                a, b = ms(r, th, mat, "banded Cholesky", "factor"), ms(r, th, mat, "banded LU", "factor+solve")
                try:
                    c = r["timings"][th]["matrices"][mat]["factorisations"]["banded LU"]["conversion"]["median_ms"]
                except KeyError:
                    c = None
                if a is not None and b is not None and c is not None:
                    path.append((a + b + c, th))
            ldl = best(r, mat, "band LDL^T", "factor+solve")
            v, o, th = best_cholmod(r, mat, "LDL^T", "factor+solve")
            if path and ldl[0] is not None:
                p0 = min(path)
                p = (f"{mat}: Cholesky to failure + conversion + banded LU {p0[0]:.2f} ms, band LDL^T factor + solve "
                     f"{ldl[0]:.2f} ms ({p0[0] / ldl[0]:.2f}x)")
                if v is not None:
                    p += f", CHOLMOD LDL^T {o} factor + solve {v:.2f} ms ({p0[0] / v:.2f}x)"
                parts.append(p)
        if parts:
            lines.append(f"Newton step on the indefinite Hessians at W/L = {r['width_label']}, "
                         f"{r['meta']['triangles']} triangles (the project's path / the LDL^T, which also gives "
                         "the inertia): " + "; ".join(parts) + ".")
    # 3. inertia agreement
    rows = inertia_rows(records)
    dense_rows = [x for x in rows if x["dense"] and x["ldlt"]]
    agree_dense = [x for x in dense_rows if x["ldlt"]["reliable"] and x["ldlt"]["negative"] == x["dense"]["negative"]
                   and all(c is None or c["negative"] == x["dense"]["negative"] for c in x["cholmod"].values())]
    all_counts = [x for x in rows if x["ldlt"]]
    agree_all = [x for x in all_counts if all(c is not None and c["negative"] == x["ldlt"]["negative"]
                                              for c in x["cholmod"].values())]
    pd_match = [x for x in all_counts if bool(x["chol"]) == (x["ldlt"]["negative"] == 0 and x["ldlt"]["zero"] == 0)]
    unreliable = [x for x in all_counts if not x["ldlt"]["reliable"]]
    negs = sorted({x["ldlt"]["negative"] for x in all_counts if x["matrix"] != "compressed"})
    lines.append(
        f"Inertia: the negative-pivot counts of the band LDL^T and of CHOLMOD's LDL^T ({', '.join(ORDERINGS)}) equal "
        f"the "
        f"dense eigenvalue count in {len(agree_dense)}/{len(dense_rows)} matrices with n <= the dense limit; band "
        f"LDL^T "
        f"and the three CHOLMOD orderings agree in {len(agree_all)}/{len(all_counts)} matrices; the banded Cholesky "
        f"succeeded exactly when the LDL^T had no negative or zero pivot in {len(pd_match)}/{len(all_counts)} "
        f"(negative counts of the indefinite matrices: {', '.join(map(str, negs)) or 'none'}); band LDL^T pivots "
        f"within n eps max|A_jj| of zero in {len(unreliable)}/{len(all_counts)} matrices.")
    # residuals of the solves
    res = {}
    for r in ok_records(records):
        for tr in r["timings"].values():
            for mm in tr["matrices"].values():
                for meth, e in mm["factorisations"].items():
                    if e.get("residual") is not None:
                        key = "CHOLMOD" if meth.startswith("CHOLMOD") else meth
                        res[key] = max(res.get(key, 0.0), e["residual"])
    if res:
        lines.append("Largest relative residual |A x - b| / |b| of one solve over all matrices: "
                     + ", ".join(f"{k} {v:.1e}" for k, v in sorted(res.items(), key=lambda kv: kv[0])) + ".")
    # 4. threads
    thr = []
    for r in ok_records(records):
        if {"default", "1"} <= set(r["timings"]):
            a, b = ms(r, "default", "compressed", "banded Cholesky", "factor"), ms(r, "1", "compressed",
                                                                                 "banded Cholesky", "factor")
            if a and b:
                thr.append((r, a / b))
    if thr:
        faster = [x for x in thr if x[1] > 1.0]
        lines.append(
            f"BLAS threads, banded Cholesky factor on the compressed Hessian: default-threads time / 1-thread time = "
            f"{min(x[1] for x in thr):.2f} to {max(x[1] for x in thr):.2f}; one thread is faster in {len(faster)}/"
            f"{len(thr)} cases" + (" (" + ", ".join(f"W/L = {x[0]['width_label']} at {x[0]['meta']['triangles']}"
                                                    for x in faster) + ")" if faster else "") + ".")
    # 5. the band LDL^T kernel against banded Cholesky
    ratios = []
    for r in ok_records(records):
        for th in r["timings"]:
            a, b = ms(r, th, "compressed", "band LDL^T", "factor"), ms(r, th, "compressed", "banded Cholesky", "factor")
            if a and b:
                ratios.append(a / b)
    if ratios:
        lines.append(f"Band LDL^T kernel (ddg.solve.band_ldlt) / banded Cholesky factor time on the compressed "
                     f"Hessians: "
                     f"{min(ratios):.2f} to {max(ratios):.2f} (median {statistics.median(ratios):.2f}) over "
                     f"{len(ratios)} (case, threads) pairs.")
    # 6. element work against the factorisation
    ev = []
    for r in ok_records(records):
        el = r["timings"].get("default", {}).get("element", {})
        full = el.get("evaluate, full (energy, gradient, Hessian + assembly)", {}).get("median_ms")
        chol = ms(r, "default", "compressed", "banded Cholesky", "factor")
        if full and chol:
            ev.append(full / chol)
    if ev:
        lines.append(f"Element evaluation + assembly (PlateModel.evaluate, full) costs {min(ev):.2f}x to "
                     f"{max(ev):.2f}x "
                     f"the banded Cholesky factor (default threads); no more than it in {sum(x <= 1 for x in ev)}/"
                     f"{len(ev)} cases.")
    return lines


# ---------------------------------------------------------------------------- reporting
def th_label(th: str) -> str:
    return "default BLAS threads" if th == "default" else f"{th} BLAS thread{'s' if th != '1' else ''}"


def _f(x, spec=".2f"):
    return "" if x is None else format(x, spec)


def _bt(v_th, mark=True):
    v, th = v_th
    if v is None:
        return ""
    return _f(v) + (" (1t)" if mark and th == "1" else "")


MAIN_HEADER = ("W/L", "triangles", "n", "band", "nnz", "chol f", "chol f+s", "band LDL^T f", "band LDL^T f+s",
               "CHOLMOD LDL^T nesdis f", "f+s", "CHOLMOD LDL^T amd f", "f+s", "CHOLMOD LDL^T metis f", "f+s",
               "CHOLMOD LL^T sn (best ordering) f", "f+s", "fastest f+s", "x next")


def main_rows(records) -> list[tuple]:
    rows = []
    summ = {(s["label"], s["triangles"]): s for s in summarise(records)}
    for r in records:
        if not r.get("timings"):
            rows.append((r["width_label"], str(r["triangles_target"]), r.get("error", "failed")[:80])
                        + ("",) * (len(MAIN_HEADER) - 3))
            continue
        m = r["meta"]
        mc = m["matrices"]["compressed"]
        th0 = next(iter(r["timings"]))
        cells = [_bt(best(r, "compressed", "banded Cholesky", "factor")),
                 _bt(best(r, "compressed", "banded Cholesky", "factor+solve")),
                 _bt(best(r, "compressed", "band LDL^T", "factor")), _bt(best(r, "compressed", "band LDL^T",
                                                                              "factor+solve"))]
        for o in ORDERINGS:
            cells += [_bt(best(r, "compressed", f"CHOLMOD LDL^T {o}", "factor")),
                      _bt(best(r, "compressed", f"CHOLMOD LDL^T {o}", "factor+solve"))]
        v, o, th = best_cholmod(r, "compressed", "LL^T supernodal", "factor")
        cells.append(_bt((v, th)) + (f" {o}" if o else ""))
        v, o, th = best_cholmod(r, "compressed", "LL^T supernodal", "factor+solve")
        cells.append(_bt((v, th)) + (f" {o}" if o else ""))
        s = summ.get((r["width_label"], m["triangles"]))
        ranked = s["ranked factor+solve"] if s else []
        rows.append((r["width_label"], str(m["triangles"]), str(mc["n"]), str(mc["bandwidth"]),
                     str(r["timings"][th0]["matrices"]["compressed"].get("nnz", "")), *cells,
                     ranked[0][0] if ranked else "", _f(ranked[1][1] / ranked[0][1]) if len(ranked) > 1 else ""))
    return rows


THREAD_METHODS = [("banded Cholesky", "factor"), ("band LDL^T", "factor"), ("CHOLMOD LDL^T nesdis", "factor"),
                  ("CHOLMOD LL^T supernodal nesdis", "factor"), ("banded LU", "factor+solve")]
THREAD_HEADER = ("W/L", "triangles", "BLAS threads (default child)",
                 *[f"{m} {k} {th}" for m, k in THREAD_METHODS for th in ("default", "1")])


def thread_rows(records) -> list[tuple]:
    rows = []
    for r in ok_records(records):
        cells = []
        for m, k in THREAD_METHODS:
            for th in ("default", "1"):
                cells.append(_f(ms(r, th, "compressed", m, k)))
        rows.append((r["width_label"], str(r["meta"]["triangles"]),
                     str(r["timings"].get("default", {}).get("blas_threads", "")), *cells))
    return rows


INERTIA_HEADER = ("W/L", "triangles", "matrix", "dL/L", "n", "nnz", "dense neg/zero/pos", "band LDL^T neg/zero/pos",
                  "reliable", "min|d| / tol", "CHOLMOD nesdis neg", "amd neg", "metis neg", "chol succeeds",
                  "chol (to failure) f", "band LDL^T f", "CHOLMOD LDL^T nesdis f", "amd f", "metis f", "LU f+s")


def inertia_table_rows(records) -> list[tuple]:
    rows = []
    by = {(x["label"], x["triangles"], x["matrix"]): x for x in inertia_rows(records)}
    for r in ok_records(records):
        for mat in MATRICES:
            x = by[(r["width_label"], r["meta"]["triangles"], mat)]
            d, ld = x["dense"], x["ldlt"]
            cm = [str(c["negative"]) if c else "" for c in x["cholmod"].values()]
            times = [_bt(best(r, mat, "banded Cholesky", "factor")), _bt(best(r, mat, "band LDL^T", "factor"))]
            times += [_bt(best(r, mat, f"CHOLMOD LDL^T {o}", "factor")) for o in ORDERINGS]
            times.append(_bt(best(r, mat, "banded LU", "factor+solve")))
            rows.append((x["label"], str(x["triangles"]), mat, _f(r["meta"]["matrices"][mat]["dL_over_L"], ".3g"),
                         str(x["n"]), str(x["nnz"]), f"{d['negative']}/{d['zero']}/{d['positive']}" if d else "",
                         f"{ld['negative']}/{ld['zero']}/{ld['positive']}" if ld else "",
                         ("yes" if ld["reliable"] else "NO") if ld else "",
                         _f(ld["min_abs_pivot"] / ld["tolerance"], ".2e") if ld and ld["tolerance"] else "",
                         *cm, "yes" if x["chol"] else "no", *times))
    return rows


OTHER_HEADER = ("W/L", "triangles", "LU f+s", "LU conversion", "SuperLU COLAMD f", "SuperLU MMD f", "SuperLU MMD sym f",
                "SuperLU natural f", "CHOLMOD analysis nesdis", "amd", "metis", "CHOLMOD LDL^T nesdis incl. analysis",
                "amd", "metis", "nnz(L) band", "nnz(L) LDL^T nesdis", "amd", "metis", "nnz(L) LL^T sn nesdis")


def other_rows(records) -> list[tuple]:
    rows = []
    for r in ok_records(records):
        th = "default" if "default" in r["timings"] else next(iter(r["timings"]))
        fac = r["timings"][th]["matrices"]["compressed"]["factorisations"]
        def g(m, k="factor"):
            return _f(ms(r, th, "compressed", m, k))
        def nnz(m):
            return str(fac.get(m, {}).get("nnz_L", ""))
        mc = r["meta"]["matrices"]["compressed"]
        band_nnz = sum(mc["n"] - d for d in range(mc["bandwidth"] + 1))
        lu = fac.get("banded LU", {})
        rows.append((r["width_label"], str(r["meta"]["triangles"]), g("banded LU", "factor+solve"),
                     _f(lu.get("conversion", {}).get("median_ms")),
                     *[g(k) for k in SUPERLU_VARIANTS], *[g(f"CHOLMOD analysis {o}") for o in ORDERINGS],
                     *[g(f"CHOLMOD LDL^T {o} with analysis") for o in ORDERINGS], str(band_nnz),
                     *[nnz(f"CHOLMOD LDL^T {o}") for o in ORDERINGS], nnz("CHOLMOD LL^T supernodal nesdis")))
    return rows


ELEMENT_HEADER = ("W/L", "triangles", "evaluate full", "energy+grad", "energy only", "assembly", "restrict",
                  "eigsh sigma=0", "lowest_eigenpairs", "lowest_eigenpairs (factor reused)", "eval/chol")


def element_rows(records) -> list[tuple]:
    rows = []
    for r in ok_records(records):
        d = r["timings"].get("default", {})
        el, eig = d.get("element", {}), d.get("eigen", {})
        def g(dd, prefix):
            return next((v["median_ms"] for k, v in dd.items() if k.startswith(prefix)), None)
        full = g(el, "evaluate, full")
        chol = ms(r, "default", "compressed", "banded Cholesky", "factor")
        rows.append((r["width_label"], str(r["meta"]["triangles"]), _f(full), _f(g(el, "evaluate, energy +")),
                     _f(g(el, "evaluate, energy only")), _f(g(el, "band assembly")), _f(g(el, "restriction")),
                     _f(eig.get("eigsh sigma=0", {}).get("median_ms")), _f(eig.get("lowest_eigenpairs",
                                                                                   {}).get("median_ms")),
                     _f(eig.get("lowest_eigenpairs, factor reused", {}).get("median_ms")),
                     _f(full / chol if full and chol else None)))
    return rows


def markdown_report(report: dict) -> str:
    records = report["cases"]
    lines = [
        "# Plate linear algebra: banded Cholesky against sparse LDL^T (CHOLMOD), inertia, BLAS threads",
        "",
        "Matrices (free-DOF plate Hessians, `python -m benchmarks.plate_linear_algebra`): **compressed** = "
        "`res.model.free_matrix(res.final_state.evaluation.hessian)` after `ddg.simulate(strip, "
        f"LoadingProtocol(0.5, 0.0, compression_steps={report['compression_steps']}), model='plate', resolution=N)` "
        "(the buckled U at dL/L = 0.5: positive definite); **flat 1%** and **flat 3 eps_E** = the Hessian of the flat "
        "strip at its in-plane equilibrium with the clamps moved by dL/L = 0.01 and by 3 Euler strains (indefinite). "
        "CSC for the sparse solvers built from the band (band[d, j] = A[j + d, j]). Times in ms: median of up to "
        f"{report['repeat']} calls after one warm-up, about {report['budget']:g} s per measurement at most (a call "
        f"slower than that timed once). Each value is the faster of the two BLAS thread settings (a child process "
        "with the default threads, one with OPENBLAS_NUM_THREADS=1); `(1t)` marks the one-thread value. "
        f"CHOLMOD: {report['cholmod']}.",
    ]
    lines += section("Conclusion", report["conclusion"])
    lines += table_section(
        "Compressed (positive definite) Hessian: factor and factor + one solve (ms)", MAIN_HEADER, main_rows(records),
        "n = free DOFs; band = bandwidth; nnz = nonzeros of the CSC matrix. chol = `scipy.linalg.cholesky_banded(band, "
        "lower=True, check_finite=False)` (as SymmetricBanded.cholesky), f+s adds one `cho_solve_banded`; band LDL^T = "
        "`ddg.solve.band_ldlt.band_ldlt` (numba, no pivoting) and `.solve`; CHOLMOD LDL^T = scikit-sparse simplicial "
        "LDL^T with the symbolic analysis reused (`analyze(A, mode='simplicial', ordering_method=o)` once, "
        "`Factor.cholesky_inplace(A)` timed) and one solve `Factor(b)`; CHOLMOD LL^T sn = supernodal LL^T, analysis "
        "reused, the fastest of nesdis/amd/metis (named). fastest f+s / x next: the fastest factor + one solve among "
        "these and the next one's time over it.")
    lines += table_section(
        "Inertia and the indefinite Hessians (ms)", INERTIA_HEADER, inertia_table_rows(records),
        "dense = eigenvalues by `numpy.linalg.eigvalsh` (n <= the dense limit; zero = |lambda| <= n eps max|lambda|); "
        "nnz = stored entries of the CSC matrix: the flat matrices are stored on the compressed matrix's pattern (at z "
        "= 0 "
        "the in-plane and out-of-plane DOFs decouple and a third of the entries are exact zeros; a Newton Hessian "
        "keeps "
        "its pattern, and the reused CHOLMOD analysis needs it); "
        "band LDL^T = signs of the pivots of `ddg.solve.band_ldlt` (zero = |d| <= n eps max|A_jj|, then reliable = "
        "no); "
        "min|d| / tol = the smallest pivot magnitude over that tolerance; CHOLMOD neg = negative entries of "
        "`Factor.D()` of the simplicial LDL^T per ordering; chol succeeds = the banded Cholesky factors the matrix "
        "(positive definite). Times: chol = to success or to LAPACK's failure; band LDL^T and CHOLMOD LDL^T factor "
        "(analysis reused); LU f+s = `scipy.linalg.solve_banded`.")
    lines += table_section(
        "BLAS threads: default against one (ms, compressed Hessian)", THREAD_HEADER, thread_rows(records),
        "Each pair: the same measurement in the child with the inherited environment (default) and in one started "
        "with OPENBLAS_NUM_THREADS=OMP_NUM_THREADS=1. BLAS threads = `openblas_get_num_threads()` in the default "
        "child.")
    lines += table_section(
        "Other factorisations, analysis and fill (ms, default threads, compressed Hessian)", OTHER_HEADER,
        other_rows(records),
        "LU f+s = `scipy.linalg.solve_banded` (LAPACK gbsv) and the conversion to its storage; SuperLU = `splu` factor "
        "(COLAMD default; MMD = permc_spec='MMD_AT_PLUS_A'; MMD sym = the same with diag_pivot_thresh=0 and "
        f"SymmetricMode; natural = the band order; MMD not run above n = {SUPERLU_MMD_MAX_N}); CHOLMOD analysis = "
        "`analyze` alone; incl. analysis = `cholmod.cholesky(A, mode='simplicial', ordering_method=o)`; nnz(L): the "
        "band "
        "factor's stored entries, `Factor.LD()` (LDL^T, with D) and `Factor.L()` (supernodal).")
    lines += table_section(
        "Element work and eigen-solve (ms, default threads, compressed state)", ELEMENT_HEADER, element_rows(records),
        "evaluate full = `PlateModel.evaluate(q)`; energy+grad = `evaluate(q, hessian=False)`; energy only = "
        "`evaluate(q, gradient=False, hessian=False)`; assembly = `BandAssembler.assemble` alone (empty when evaluate "
        "does not call it); restrict = `SymmetricBanded.restrict` to the free DOFs; eigsh sigma=0 = "
        "`scipy.sparse.linalg.eigsh(A, k=1, sigma=0, tol=1e-12)`; lowest_eigenpairs = "
        "`SymmetricBanded.lowest_eigenpairs(1)`"
        " fresh and with its Cholesky already computed; eval/chol = evaluate full over the banded Cholesky factor.")
    lines += section("Notes")
    for r in records:
        if not r.get("timings"):
            lines.append(f"- W/L = {r['width_label']}, N = {r['triangles_target']}: {r.get('error', 'no timings')}.")
            continue
        m = r["meta"]
        st = m["state"]
        flat = "; ".join(f"{k}: dL/L = {v['dL_over_L']:.3g}, in-plane Newton |g| {v['newton_gradient_norms'][0]:.2e} "
                         f"-> "
                         f"{v['newton_gradient_norms'][-1]:.2e}, max|z| {v['max_abs_z']:.1e}"
                         for k, v in m["matrices"].items() if "newton_gradient_norms" in v)
        notes = []
        for th, tr in r["timings"].items():
            for mat, mm in tr["matrices"].items():
                for k, v in mm["notes"].items():
                    notes.append(f"{mat}, threads {th}: {k}: {v}")
        eig = r["timings"].get("default", {}).get("eigen", {})
        resid = max((v.get("residual", 0.0) for tr in r["timings"].values() for mm in tr["matrices"].values()
                     for v in mm["factorisations"].values()), default=None)
        lines.append(
            f"- W/L = {r['width_label']}, N = {r['triangles_target']} ({m['triangles']} triangles): compressed state "
            f"{st['message']!r} at dL/L = {_f(st['dL_over_L'], '.4f')} (H_mid/L {_f(st['H_mid_over_L'], '.4f')}, "
            f"{st['newton_iterations']} Newton its, {st['time_s']:.1f} s); {flat}; lowest eigenvalue of the compressed "
            f"Hessian: " + ", ".join(f"{k} {v['lambda']:.6g}" for k, v in eig.items())
            + (f"; largest solve residual {resid:.1e}" if resid is not None else "")
            + f"; matrices built {m['built']} at ddg sources `{m['ddg_source_sha256'][:16]}`"
            + "; load average (1 min) at the start / end of the timing children: "
            + ", ".join(f"{th_label(th)} {tr.get('load_average_start')} / {tr.get('load_average_end')}"
                        for th, tr in r["timings"].items())
            + "".join(f"; {th_label(th)} timings measured by an earlier version of the benchmark code (fingerprint "
                      f"`{fp[:12]}`, now `{report['timing_fingerprint'][:12]}`)"
                      for th, fp in r.get("timing_fingerprints", {}).items() if fp != report["timing_fingerprint"])
            + ("; " + "; ".join(notes) if notes else "") + ".")
    lines += [f"- scikit-sparse install: {report['cholmod_install']}"]
    lines += machine_section(report, extra=f" Load average (1 min) before / after: {report['load_average'][0]} / "
                                           f"{report['load_average'][1]}.", changed_note=" (CHANGED during the run)")
    return "\n".join(lines)


CHOLMOD_INSTALL = (
    "`.venv/bin/python -m pip install -c .venv/constraints.txt scikit-sparse` (with build isolation) built and "
    "installed "
    "scikit-sparse 0.4.16 from its sdist against the system SuiteSparse 5.12 (libsuitesparse-dev: libcholmod.so.3, "
    "linked to METIS 5 and OpenBLAS); pip first tried 0.5.0, whose metadata requires numpy > 2.0 and scipy >= 1.14, "
    "which the constraints (numpy 1.24.2, scipy 1.10.1) exclude. No --no-build-isolation or Cython install was needed.")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.plate_linear_algebra",
                                     description=__doc__.split("\n")[0])
    parser.add_argument("--cases", nargs="+", default=DEFAULT_CASES, help="W/L:N[,N...] per width ratio")
    parser.add_argument("--triangles", type=int, nargs="+", help="target triangle counts (grid with --width-ratios)")
    parser.add_argument("--width-ratios", nargs="+", help="W/L values (grid with --triangles)")
    parser.add_argument("--repeat", type=int, default=10, help="timed calls per measurement at most (median reported)")
    parser.add_argument("--budget", type=float, default=10.0, help="seconds per measurement, about")
    parser.add_argument("--compression-steps", type=int, default=COMPRESSION_STEPS)
    parser.add_argument("--dense-max", type=int, default=4000, help="largest n for the dense eigenvalue count")
    parser.add_argument("--threads", nargs="+", default=["default", "1"], help="BLAS thread settings: default and/or N")
    parser.add_argument("--timeout", type=float, default=3600.0, help="seconds per child process (0: none)")
    parser.add_argument("--cache", default="out/plate_linear_algebra_cache", help="matrices and per-child timings")
    parser.add_argument("--fresh", action="store_true", help="retime even where cached timings exist")
    parser.add_argument("--rebuild", action="store_true", help="recompute the cached matrices")
    parser.add_argument("--report-only", action="store_true",
                        help="no measurement: the report from the cached timings, whatever code produced them")
    parser.add_argument("--out", default="benchmarks/results",
                        help="directory for plate_linear_algebra.json and plate_linear_algebra.md")
    args = parser.parse_args(argv)
    try:
        cases = parse_cases(args)
    except (argparse.ArgumentTypeError, ValueError) as exc:
        parser.error(str(exc))
    if args.repeat < 1 or args.compression_steps < 1 or any(n < 16 for _, _, n in cases) or args.budget <= 0:
        parser.error("--repeat, --compression-steps and --budget must be positive and every N >= 16")
    if any(th != "default" and not th.isdigit() for th in args.threads):
        parser.error("--threads takes 'default' and/or positive integers")

    provenance = Provenance()
    records = run_all(args, cases)
    report = {
        "benchmark": "plate_linear_algebra",
        "compression_ratio": COMPRESSION_RATIO,
        "compression_steps": args.compression_steps,
        "repeat": args.repeat,
        "budget": args.budget,
        "threads": args.threads,
        "cases": records,
        "conclusion": conclusion(records),
        "cholmod": (cholmod_module()[1] or f"available ({cholmod_version()}, sksparse.cholmod)"),
        "cholmod_install": CHOLMOD_INSTALL,
        "timing_fingerprint": timing_fingerprint(args.repeat, args.budget),
        "report_only": args.report_only,
        **provenance.report(blas=True),
    }
    wrote = write_report(args.out, "plate_linear_algebra", report, markdown_report(report), json_default=_json_default)
    print(text_table(MAIN_HEADER, main_rows(records)))
    print()
    print(text_table(INERTIA_HEADER, inertia_table_rows(records)))
    print()
    for line in report["conclusion"]:
        print(line)
    print(wrote)
    return 0


if __name__ == "__main__":
    sys.exit(main())
