"""Linear algebra of one plate Newton iteration: factorisations, eigen-solve, element evaluation.

    .venv/bin/python -m benchmarks.plate_linear_algebra [--triangles 500 1000 2000 4000]
        [--width-ratios 1/20 1/6 1/2] [--repeat 10] [--compression-steps 10] [--out benchmarks/results]

For each W/L and target triangle count N it computes the compressed plate state,

    res = ddg.simulate(ddg.Strip.from_ratios(W/L, 0.5),
                       ddg.LoadingProtocol(0.5, 0.0, compression_steps=10), model="plate", resolution=N)
    K = res.model.free_matrix(res.final_state.evaluation.hessian)   # SymmetricBanded, free DOFs

and times, on that matrix (median and minimum over --repeat calls, after one untimed warm-up):

- banded Cholesky, as the project does it: scipy.linalg.cholesky_banded(band, lower=True,
  check_finite=False), and one solve with its factor (cho_solve_banded);
- banded LU: scipy.linalg.solve_banded((u, u), ab, rhs) (LAPACK gbsv: factor and one solve in
  one call; the project's SymmetricBanded.solve uses it on indefinite matrices), plus the
  conversion from symmetric lower band storage to the general band form it needs;
- SuperLU: scipy.sparse.linalg.splu on the CSC matrix with the default COLAMD ordering, with
  permc_spec="MMD_AT_PLUS_A", with MMD_AT_PLUS_A in SuperLU's symmetric mode
  (diag_pivot_thresh=0, SymmetricMode=True: the setting SuperLU recommends for SPD matrices)
  and with the natural (band) order; factor, then one solve with the factor; fill nnz(L)+nnz(U);
- CHOLMOD (sksparse.cholmod.cholesky, full and with the symbolic analysis reused) if scikit-sparse
  is importable; otherwise reported as unavailable;
- the lowest eigenvalue: scipy.sparse.linalg.eigsh(A, k=1, sigma=0) (shift-invert, SuperLU inside)
  and the project's SymmetricBanded.lowest_eigenpairs(1) (Lanczos on the banded-Cholesky
  inverse), on a fresh matrix (its own factorisation included) and with the factor reused;
- the element work: PlateModel.evaluate(q) (energy, gradient, Hessian with band assembly),
  evaluate(q, hessian=False), evaluate(q, gradient=False, hessian=False) (energy only), the band
  assembly BandAssembler.assemble alone (on the element blocks of that state) and the restriction
  to the free DOFs (SymmetricBanded.restrict).

The CSC matrix is built from the band (band[d, j] = A[j + d, j]), not from to_dense. Each solve's
relative residual |A x - b| / |b| is recorded as a check. Writes OUT/plate_linear_algebra.json
and OUT/plate_linear_algebra.md atomically. Not part of the test run.
"""
from __future__ import annotations

import argparse
import contextlib
import gc
import math
import statistics
import sys
import time
import traceback

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from benchmarks.common import (Provenance, machine_section, ratio, section, table_section, text_table,
                               write_report)

TRIANGLES = [500, 1000, 2000, 4000]
WIDTH_RATIOS = ["1/20", "1/6", "1/2"]
COMPRESSION_RATIO = 0.5
COMPRESSION_STEPS = 10

SUPERLU_VARIANTS = {
    "SuperLU COLAMD": {},
    "SuperLU MMD_AT_PLUS_A": {"permc_spec": "MMD_AT_PLUS_A"},
    "SuperLU MMD_AT_PLUS_A symmetric mode": {"permc_spec": "MMD_AT_PLUS_A", "diag_pivot_thresh": 0.0,
                                             "options": {"SymmetricMode": True}},
    "SuperLU NATURAL": {"permc_spec": "NATURAL"},
}


def cholmod_module():
    """sksparse.cholmod if importable, else (None, reason)."""
    try:
        from sksparse import cholmod
        return cholmod, None
    except Exception as exc:  # ImportError, or a binary built against another numpy
        return None, (f"scikit-sparse not importable ({type(exc).__name__}: {exc}); Debian 12 has no "
                      "python3-sksparse / python3-scikit-sparse package and the configured pip index has no "
                      "scikit-sparse wheel (building it would compile against numpy), so CHOLMOD is skipped "
                      "(the C library libcholmod3 is installed, without a Python binding)")


# ---------------------------------------------------------------------------- timing
@contextlib.contextmanager
def _gc_paused():
    """The garbage collector off (and back on if it was) around the timed calls."""
    gc_was = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if gc_was:
            gc.enable()


def _stats(times: list[float], repeat: int) -> dict:
    return {"median_ms": 1e3 * statistics.median(times), "min_ms": 1e3 * min(times), "repeats": repeat}


def timed(fn, repeat: int, setup=None) -> tuple[dict, object]:
    """Median/min wall time of fn(setup()) over `repeat` calls after one warm-up; setup is untimed."""
    out = fn(setup() if setup else None)  # warm-up (imports, caches, page faults)
    times = []
    with _gc_paused():
        for _ in range(repeat):
            arg = setup() if setup else None
            t0 = time.perf_counter()
            out = fn(arg)
            times.append(time.perf_counter() - t0)
    return _stats(times, repeat), out


def timed_pair(factor, solve, repeat: int) -> tuple[dict, dict, object, object]:
    """Time factor() and then solve(factor) on that factor, per repeat; returns stats of both and
    of their sum, and the last factor and solution."""
    f = factor()
    x = solve(f)  # warm-up
    tf, ts = [], []
    with _gc_paused():
        for _ in range(repeat):
            t0 = time.perf_counter()
            f = factor()
            t1 = time.perf_counter()
            x = solve(f)
            t2 = time.perf_counter()
            tf.append(t1 - t0)
            ts.append(t2 - t1)
    both = [a + b for a, b in zip(tf, ts)]
    return _stats(tf, repeat), _stats(ts, repeat), _stats(both, repeat), (f, x)


# ---------------------------------------------------------------------------- matrices
def band_to_csc(band: np.ndarray) -> sp.csc_matrix:
    """The symmetric matrix of lower band storage band[d, j] = A[j + d, j] as CSC (both triangles)."""
    n = band.shape[1]
    rows, cols, vals = [], [], []
    for d in range(band.shape[0]):
        j = np.arange(n - d)
        v = band[d, : n - d]
        keep = v != 0.0
        j, v = j[keep], v[keep]
        rows.append(j + d)
        cols.append(j)
        vals.append(v)
        if d:
            rows.append(j)
            cols.append(j + d)
            vals.append(v)
    rows, cols, vals = np.concatenate(rows), np.concatenate(cols), np.concatenate(vals)
    return sp.csc_matrix((vals, (rows, cols)), shape=(n, n))


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


# ---------------------------------------------------------------------------- one case
def run_case(width_ratio: float, width_label: str, triangles: int, repeat: int, compression_steps: int) -> dict:
    import ddg
    from ddg.solve.banded import SymmetricBanded

    t0 = time.perf_counter()
    strip = ddg.Strip.from_ratios(width_ratio, COMPRESSION_RATIO)
    res = ddg.simulate(strip, ddg.LoadingProtocol(COMPRESSION_RATIO, 0.0, compression_steps=compression_steps),
                       model="plate", resolution=triangles)
    state_time = time.perf_counter() - t0
    model = res.model
    case = {
        "width_ratio": width_ratio, "width_label": width_label, "triangles_target": triangles,
        "triangles": int(model.mesh.triangle_count), "nodes": int(model.mesh.node_count),
        "state": {"converged": bool(res.summary["converged"]), "message": res.summary.get("message", ""),
                  "dL_over_L": float(res.rows[-1]["dL_over_L"]) if res.rows else None,
                  "H_mid_over_L": float(res.rows[-1]["H_mid_over_L"]) if res.rows else None,
                  "newton_iterations": res.summary.get("newton_iterations"), "time_s": state_time},
    }
    if res.final_state is None:
        case["error"] = "no equilibrium to take the Hessian of"
        return case
    q = res.final_state.q
    K = model.free_matrix(res.final_state.evaluation.hessian)
    band = np.ascontiguousarray(K.band)
    n, u = band.shape[1], band.shape[0] - 1
    A = band_to_csc(band)
    rng = np.random.default_rng(0)
    rhs = rng.standard_normal(n)
    rnorm = float(np.linalg.norm(rhs))
    resid = lambda x: float(np.linalg.norm(A @ x - rhs) / rnorm)
    case.update({"n": n, "bandwidth_storage": u, "bandwidth": effective_bandwidth(band), "nnz": int(A.nnz),
                 "band_entries": int((u + 1) * n)})
    t = {}        # method -> {"factor": stats, "solve": stats, "factor+solve": stats, ...}
    notes = {}

    # banded Cholesky, as ddg.solve.banded.SymmetricBanded.cholesky / .solve
    def chol_factor():
        try:
            return sla.cholesky_banded(band, lower=True, check_finite=False)
        except sla.LinAlgError:
            return None

    fac = chol_factor()
    case["positive_definite"] = fac is not None
    if fac is not None:
        f, s, fs, (fac, x) = timed_pair(chol_factor, lambda c: sla.cho_solve_banded((c, True), rhs, check_finite=False),
                                        repeat)
        t["banded Cholesky"] = {"factor": f, "solve": s, "factor+solve": fs, "residual": resid(x)}
    else:
        f, _ = timed(lambda _: chol_factor(), repeat)
        t["banded Cholesky"] = {"factor": f, "note": "not positive definite (time to the failure)"}

    # banded LU (gbsv: factor + solve in one call), and the storage conversion the project does per solve
    conv, full = timed(lambda _: general_band(band), repeat)
    fs, x = timed(lambda _: sla.solve_banded((u, u), full, rhs, check_finite=False), repeat)
    t["banded LU"] = {"factor+solve": fs, "conversion": conv, "residual": resid(x)}

    # SuperLU variants
    for name, kw in SUPERLU_VARIANTS.items():
        try:
            f, s, fs, (lu, x) = timed_pair(lambda: spla.splu(A, **kw), lambda lu: lu.solve(rhs), repeat)
            t[name] = {"factor": f, "solve": s, "factor+solve": fs, "residual": resid(x),
                       "fill_nnz": int(lu.L.nnz + lu.U.nnz)}
        except Exception as exc:  # e.g. a singular matrix
            notes[name] = f"{type(exc).__name__}: {exc}"

    # CHOLMOD
    cholmod, why = cholmod_module()
    if cholmod is not None:
        try:
            f, s, fs, (F, x) = timed_pair(lambda: cholmod.cholesky(A), lambda F: F(rhs), repeat)
            t["CHOLMOD"] = {"factor": f, "solve": s, "factor+solve": fs, "residual": resid(x)}
            symbolic = cholmod.analyze(A)
            f, s, fs, (F, x) = timed_pair(lambda: symbolic.cholesky(A), lambda F: F(rhs), repeat)
            t["CHOLMOD, analysis reused"] = {"factor": f, "solve": s, "factor+solve": fs, "residual": resid(x)}
        except Exception as exc:
            notes["CHOLMOD"] = f"{type(exc).__name__}: {exc}"
    else:
        notes["CHOLMOD"] = why

    # lowest eigenvalue
    eig = {}
    st, w = timed(lambda _: spla.eigsh(A, k=1, sigma=0.0, which="LM", tol=1e-12, v0=np.ones(n),
                                       return_eigenvectors=False), repeat)
    eig["eigsh sigma=0"] = {**st, "lambda": float(np.min(w)), "what": "scipy.sparse.linalg.eigsh(A, k=1, sigma=0, tol=1e-12) (its own SuperLU factorisation)"}
    st, w = timed(lambda M: M.lowest_eigenpairs(1), repeat, setup=lambda: SymmetricBanded(band.copy()))
    eig["lowest_eigenpairs"] = {**st, "lambda": float(np.atleast_1d(w)[0]),
                            "what": "SymmetricBanded.lowest_eigenpairs(1) on a fresh matrix (its banded Cholesky included)"}

    def prefactored():
        M = SymmetricBanded(band.copy())
        M.cholesky()
        return M

    st, w = timed(lambda M: M.lowest_eigenpairs(1), repeat, setup=prefactored)
    eig["lowest_eigenpairs, factor reused"] = {**st, "lambda": float(np.atleast_1d(w)[0]),
                                           "what": "SymmetricBanded.lowest_eigenpairs(1), banded Cholesky already computed"}

    # element evaluation and assembly
    el = {}
    st, _ = timed(lambda _: model.evaluate(q), repeat)
    el["evaluate, full (energy, gradient, Hessian + assembly)"] = st
    st, _ = timed(lambda _: model.evaluate(q, gradient=True, hessian=False), repeat)
    el["evaluate, energy + gradient"] = st
    st, _ = timed(lambda _: model.evaluate(q, gradient=False, hessian=False), repeat)
    el["evaluate, energy only"] = st
    assembler = getattr(model, "_assembler", None)
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
            st, _ = timed(lambda _: assembler.assemble(blocks, *a, **k), repeat)
            el["band assembly alone (BandAssembler.assemble)"] = st
        st, _ = timed(lambda _: H.restrict(model.free.start, model.free.stop), repeat)
        el["restriction to the free DOFs (SymmetricBanded.restrict)"] = st
    else:
        notes["assembly"] = "model has no _assembler; assembly not timed separately"

    case.update({"factorisations": t, "eigen": eig, "element": el, "notes": notes})
    case["summary"] = summarise_case(case)
    return case


def _ms(entry: dict | None, key: str) -> float | None:
    if not entry or key not in entry:
        return None
    return entry[key]["median_ms"]


def summarise_case(case: dict) -> dict:
    t = case["factorisations"]
    factor = {k: _ms(v, "factor") for k, v in t.items() if _ms(v, "factor") is not None and "note" not in v}
    both = {k: _ms(v, "factor+solve") for k, v in t.items() if _ms(v, "factor+solve") is not None}
    out = {}
    for label, d in (("factor", factor), ("factor+solve", both)):
        ranked = sorted(d.items(), key=lambda kv: kv[1])
        if ranked:
            out[f"fastest_{label}"] = ranked[0][0]
            out[f"fastest_{label}_ms"] = ranked[0][1]
            if len(ranked) > 1:
                out[f"runner_up_{label}"] = ranked[1][0]
                out[f"runner_up_{label}_ratio"] = ranked[1][1] / ranked[0][1]
    chol = factor.get("banded Cholesky")
    el = case["element"]
    full = el.get("evaluate, full (energy, gradient, Hessian + assembly)", {}).get("median_ms")
    asm = el.get("band assembly alone (BandAssembler.assemble)", {}).get("median_ms")
    if chol:
        out["evaluate_full_over_banded_cholesky"] = full / chol if full else None
        out["assembly_over_banded_cholesky"] = asm / chol if asm else None
    return out


# ---------------------------------------------------------------------------- reporting
FACTOR_COLUMNS = [("banded Cholesky", "factor"), ("banded Cholesky", "factor+solve"), ("banded LU", "factor+solve"),
                  ("SuperLU COLAMD", "factor"), ("SuperLU MMD_AT_PLUS_A", "factor"),
                  ("SuperLU MMD_AT_PLUS_A symmetric mode", "factor"), ("SuperLU NATURAL", "factor"),
                  ("CHOLMOD", "factor"), ("CHOLMOD, analysis reused", "factor")]
FACTOR_HEADER = ("W/L", "triangles", "n", "band", "nnz", "PD", "chol", "chol+solve", "LU f+s", "SuperLU COLAMD",
                 "SuperLU MMD", "SuperLU MMD sym", "SuperLU natural", "CHOLMOD", "CHOLMOD reused", "fastest factor",
                 "x next")
ELEMENT_HEADER = ("W/L", "triangles", "evaluate full", "energy+grad", "energy only", "assembly", "restrict",
                  "eigsh sigma=0", "lowest_eigenpairs", "lowest_eigenpairs (factor reused)", "eval/chol",
                  "assembly/chol")


def _f(x, spec=".2f"):
    return "" if x is None else format(x, spec)


def factor_rows(cases: list[dict]) -> list[tuple]:
    rows = []
    for c in cases:
        if "factorisations" not in c:
            rows.append((c["width_label"], str(c["triangles_target"]), "", "", "", "", c.get("error", "failed"))
                        + ("",) * (len(FACTOR_HEADER) - 7))
            continue
        t, s = c["factorisations"], c["summary"]
        cells = [_f(_ms(t.get(m), k)) for m, k in FACTOR_COLUMNS]
        rows.append((c["width_label"], str(c["triangles"]), str(c["n"]), str(c["bandwidth"]), str(c["nnz"]),
                     "yes" if c["positive_definite"] else "NO", *cells, s.get("fastest_factor", ""),
                     _f(s.get("runner_up_factor_ratio"))))
    return rows


def _get(d: dict, key: str) -> float | None:
    return d[key]["median_ms"] if key in d else None


def element_rows(cases: list[dict]) -> list[tuple]:
    rows = []
    for c in cases:
        if "element" not in c:
            continue
        el, eig, s = c["element"], c["eigen"], c["summary"]
        g = lambda d, prefix: next((v["median_ms"] for k, v in d.items() if k.startswith(prefix)), None)
        rows.append((c["width_label"], str(c["triangles"]), _f(g(el, "evaluate, full")), _f(g(el, "evaluate, energy +")),
                     _f(g(el, "evaluate, energy only")), _f(g(el, "band assembly")), _f(g(el, "restriction")),
                     _f(_get(eig, "eigsh sigma=0")), _f(_get(eig, "lowest_eigenpairs")),
                     _f(_get(eig, "lowest_eigenpairs, factor reused")),
                     _f(s.get("evaluate_full_over_banded_cholesky")), _f(s.get("assembly_over_banded_cholesky"))))
    return rows


def conclusion(cases: list[dict]) -> list[str]:
    ok = [c for c in cases if "summary" in c and c["summary"].get("fastest_factor")]
    if not ok:
        return ["no case completed"]
    lines = []
    for label in ("factor", "factor+solve"):
        wins = {}
        for c in ok:
            wins.setdefault(c["summary"][f"fastest_{label}"], []).append(c)
        parts = []
        for name, cs in sorted(wins.items(), key=lambda kv: -len(kv[1])):
            ratios = [c["summary"].get(f"runner_up_{label}_ratio") for c in cs if c["summary"].get(f"runner_up_{label}_ratio")]
            runners = sorted({c["summary"].get(f"runner_up_{label}") for c in cs if c["summary"].get(f"runner_up_{label}")})
            parts.append(f"{name} in {len(cs)}/{len(ok)} cases"
                         + (f", by {min(ratios):.1f}x to {max(ratios):.1f}x over the next fastest ({', '.join(runners)})"
                            if ratios else ""))
        lines.append(f"Fastest {'factorisation' if label == 'factor' else 'factorisation + one solve'}: " + "; ".join(parts) + ".")
    ev = [c["summary"].get("evaluate_full_over_banded_cholesky") for c in ok]
    asm = [c["summary"].get("assembly_over_banded_cholesky") for c in ok]
    ev = [x for x in ev if x is not None]
    asm = [x for x in asm if x is not None]
    if ev:
        lines.append(
            f"Element evaluation + assembly (PlateModel.evaluate, full) costs {min(ev):.1f}x to {max(ev):.1f}x the banded "
            f"Cholesky: it costs no more than the factorisation in {sum(x <= 1.0 for x in ev)}/{len(ev)} cases"
            + (f"; the band assembly alone costs {min(asm):.2f}x to {max(asm):.2f}x the Cholesky "
               f"(no more than it in {sum(x <= 1.0 for x in asm)}/{len(asm)} cases)." if asm else "."))
    return lines


def markdown_report(report: dict) -> str:
    cases = report["cases"]
    lines = [
        "# Plate linear algebra: factorisations, eigen-solve and element work on one Hessian",
        "",
        f"Matrix: the free-DOF Hessian `res.model.free_matrix(res.final_state.evaluation.hessian)` of the plate "
        f"compressed to dL/L = {COMPRESSION_RATIO} in {report['compression_steps']} steps (`LoadingProtocol(0.5, 0.0, "
        f"compression_steps={report['compression_steps']})`, structured mesh of about N triangles), converted from "
        "the band (band[d, j] = A[j + d, j]) to CSC for the sparse solvers "
        "(`python -m benchmarks.plate_linear_algebra`). Times in ms, median of "
        f"{report['repeat']} calls after one warm-up.",
    ]
    lines += section("Conclusion", report["conclusion"])
    lines += table_section(
        "Factorisations (ms)", FACTOR_HEADER, factor_rows(cases),
        "n = free DOFs; band = bandwidth (largest d with a nonzero band[d]); nnz = nonzeros of the full symmetric "
        "matrix; PD = the banded Cholesky succeeds. chol = `scipy.linalg.cholesky_banded(band, lower=True, "
        "check_finite=False)` (as SymmetricBanded.cholesky); chol+solve adds one `cho_solve_banded`; LU f+s = "
        "`scipy.linalg.solve_banded` (LAPACK gbsv, factor and one solve in one call; the conversion to its storage is "
        "timed separately in the JSON); SuperLU columns = `splu` factor only (COLAMD = default; MMD = "
        "permc_spec='MMD_AT_PLUS_A'; MMD sym = the same with diag_pivot_thresh=0 and SymmetricMode; natural = "
        "permc_spec='NATURAL', the band order). fastest factor / x next: the fastest factor-only method "
        "(banded LU excluded, it has no factor-only time) and the next one's time over it.")
    lines += table_section(
        "Element work and eigen-solve (ms)", ELEMENT_HEADER, element_rows(cases),
        "evaluate full = `PlateModel.evaluate(q)` (energy, gradient, Hessian kernels and band assembly); energy+grad "
        "= `evaluate(q, hessian=False)`; energy only = `evaluate(q, gradient=False, hessian=False)`; assembly = "
        "`BandAssembler.assemble` alone on that state's element blocks; restrict = the free-DOF block "
        "(`SymmetricBanded.restrict`). eigsh sigma=0 = `scipy.sparse.linalg.eigsh(A, k=1, sigma=0, tol=1e-12)` "
        "(shift-invert with its own SuperLU factorisation); lowest_eigenpairs = the project's "
        "`SymmetricBanded.lowest_eigenpairs(1)` on a fresh matrix (its banded Cholesky included) and with the factor "
        "already computed. eval/chol and assembly/chol: their time over the banded Cholesky factorisation.")
    lines += section("Notes")
    for c in cases:
        st = c["state"]
        extra = "; ".join(f"{k}: {v}" for k, v in c.get("notes", {}).items() if k != "CHOLMOD")
        lam = {k: v["lambda"] for k, v in c.get("eigen", {}).items()}
        res_max = max((v.get("residual", 0.0) for v in c.get("factorisations", {}).values()), default=None)
        lines.append(
            f"- W/L = {c['width_label']}, N = {c['triangles_target']}: state {st['message']!r} at dL/L = "
            f"{_f(st['dL_over_L'], '.4f')} (H_mid/L {_f(st['H_mid_over_L'], '.4f')}, {st['newton_iterations']} Newton "
            f"its, {st['time_s']:.1f} s)"
            + ("; lowest eigenvalue (raw Hessian units): " + ", ".join(f"{k} {v:.6g}" for k, v in lam.items()) if lam else "")
            + (f"; largest solve residual {res_max:.1e}" if res_max is not None else "")
            + ("; fill nnz(L)+nnz(U): " + ", ".join(f"{k} {v['fill_nnz']}" for k, v in c["factorisations"].items()
                                                  if "fill_nnz" in v)
               + f" (banded Cholesky stores {c['band_entries']})" if c.get("factorisations") else "")
            + (f"; {extra}" if extra else "") + (f"; {c['error']}" if c.get("error") else "") + ".")
    lines += [f"- CHOLMOD: {report['cholmod']}"]
    lines += machine_section(report, extra=f" Load average (1 min) before / after: {report['load_average'][0]} / "
                                           f"{report['load_average'][1]}.", changed_note=" (CHANGED during the run)")
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.plate_linear_algebra",
                                     description=__doc__.split("\n")[0])
    parser.add_argument("--triangles", type=int, nargs="+", default=TRIANGLES, help="target triangle counts N")
    parser.add_argument("--width-ratios", nargs="+", default=WIDTH_RATIOS, help="W/L values (decimals or fractions)")
    parser.add_argument("--repeat", type=int, default=10, help="timed calls per measurement (median reported)")
    parser.add_argument("--compression-steps", type=int, default=COMPRESSION_STEPS)
    parser.add_argument("--out", default="benchmarks/results",
                        help="directory for plate_linear_algebra.json and plate_linear_algebra.md")
    args = parser.parse_args(argv)
    try:
        widths = [(ratio(w), w) for w in args.width_ratios]
    except argparse.ArgumentTypeError as exc:
        parser.error(str(exc))
    if args.repeat < 1 or any(t < 16 for t in args.triangles) or args.compression_steps < 1:
        parser.error("--repeat and --compression-steps must be >= 1 and every N >= 16")

    provenance = Provenance()
    cases = []
    for w, label in widths:
        for n in args.triangles:
            t0 = time.perf_counter()
            try:
                case = run_case(w, label, n, args.repeat, args.compression_steps)
            except Exception:
                case = {"width_ratio": w, "width_label": label, "triangles_target": n, "error": traceback.format_exc()}
                print(case["error"], file=sys.stderr)
            cases.append(case)
            s = case.get("summary", {})
            print(f"W/L = {label}, N = {n}: {time.perf_counter() - t0:.1f} s; fastest factor "
                  f"{s.get('fastest_factor')} {_f(s.get('fastest_factor_ms'))} ms", file=sys.stderr)

    report = {
        "benchmark": "plate_linear_algebra",
        "compression_ratio": COMPRESSION_RATIO,
        "compression_steps": args.compression_steps,
        "repeat": args.repeat,
        "cases": cases,
        "conclusion": conclusion(cases),
        "cholmod": cholmod_module()[1] or "available (sksparse.cholmod)",
        **provenance.report(blas=True),
    }
    wrote = write_report(args.out, "plate_linear_algebra", report, markdown_report(report),
                         json_default=lambda x: None if isinstance(x, float) and not math.isfinite(x) else float(x))
    print(text_table(FACTOR_HEADER, factor_rows(cases)))
    print()
    print(text_table(ELEMENT_HEADER, element_rows(cases)))
    print()
    for line in report["conclusion"]:
        print(line)
    print(wrote)
    return 0


if __name__ == "__main__":
    sys.exit(main())
