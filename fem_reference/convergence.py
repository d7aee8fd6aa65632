"""Mesh convergence of the FEM reference: `python -m fem_reference convergence ...`.

Runs the full protocol on 3-4 meshes (elements along L; across W near-isotropic), then

* H_mid/L(dW) of each mesh on a common dW grid (the recorded shear steps; the path switched to
  US+ where it exists), Richardson-extrapolated from the three finest meshes with the observed
  order p = log(|f2 - f1| / |f3 - f2|) / log(r) (r the refinement ratio; P2 elements give p ~ 2,
  clipped to [0.5, 4]), and each mesh's estimated error |f_h - f_extrapolated|;
* dW1/L of each mesh and its Richardson extrapolation;
* wall time per recorded load step and per path of each mesh.

Writes OUT/convergence.csv (one row per mesh and dW), OUT/thresholds.csv (one row per mesh) and
OUT/convergence.md (the table), plus each run's path.csv and summary.json under OUT/N<res>/.
"""
from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from ddg.output.io import atomic_write_text, write_table_csv


def observed_order(f1, f2, f3, ratio):
    """Order p from three solutions on meshes h, h/r, h/r^2 (f3 finest); nan if not monotone."""
    d1, d2 = f2 - f1, f3 - f2
    with np.errstate(divide="ignore", invalid="ignore"):
        p = np.log(np.abs(d1 / d2)) / math.log(ratio)
    return np.where(d1 * d2 > 0, p, np.nan)


def richardson(f2, f3, ratio, p):
    """Extrapolated value from the two finest meshes with order p."""
    return f3 + (f3 - f2) / (ratio**p - 1.0)


def extrapolate(values: np.ndarray, resolutions, default_order=2.0):
    """values[mesh, point] on meshes `resolutions` (increasing): (extrapolated, order) per point,
    the order observed on the three finest meshes where monotone (clipped to [0.5, 4]), else
    default_order (P2)."""
    res = np.asarray(resolutions, float)
    r = res[-1] / res[-2]
    if len(res) >= 3:
        p = observed_order(values[-3], values[-2], values[-1], res[-2] / res[-3])
        p = np.where(np.isfinite(p), np.clip(p, 0.5, 4.0), default_order)
    else:
        p = np.full(values.shape[1:], default_order)
    return richardson(values[-2], values[-1], r, p), p


#: Observed orders accepted as asymptotic by `estimate` (P2 elements: about 2 for displacements;
#: a threshold, the zero of an eigenvalue, may converge at up to twice that).
ASYMPTOTIC_ORDERS = (1.0, 4.0)
#: Roache's safety factor of the grid convergence index for a three-mesh study whose observed
#: order is at least LOW_ORDER (Roache 1998: 1.25 where three meshes confirm the order)...
GCI_SAFETY = 1.25
#: ... and below it: a low observed order is not a confirmed one (extrapolating at order 0.75
#: adds three times the finest difference), so Roache's factor for an unconfirmed order, 3.
LOW_ORDER = 1.5
GCI_SAFETY_LOW_ORDER = 3.0
#: A sequence that is not asymptotic (differences of opposite sign, not shrinking, an order
#: outside ASYMPTOTIC_ORDERS, or only two meshes) gets this many times the largest difference of
#: its finest three meshes as its error bar (issue 28: at W/L = 1/6, dL/L = 1/2 the gold's 0.0010
#: from |d2| alone was 3.5 times smaller than the distance to an independent mesh series).
NON_ASYMPTOTIC_FACTOR = 3.0
#: The slowest order the rule extrapolates at: a sequence shrinking slower has not begun to
#: converge (at order 0.1 its limit would lie 24 |d2| away, at 0 infinitely far); its distance to
#: the limit is taken at this order.
SLOWEST_ORDER = 0.5
#: The rule's version, stored with every estimate (richardson.json "rule"): 1 the spread of the
#: finest two and GCI 1.25 at any order (before issue 28), 2 the rule above.
ERROR_BAR_RULE = 2


def order_from_ratios(d1: float, d2: float, coarse_ratio: float, fine_ratio: float) -> float | None:
    """The observed order p of three meshes refined by `coarse_ratio` then `fine_ratio` (sizes
    h1 = coarse_ratio h2, h2 = fine_ratio h3), from their differences d1 = f2 - f1, d2 = f3 - f2
    under the error model f = f* + C h^p: the root of

        |d1 / d2| = r_f^p (r_c^p - 1) / (r_f^p - 1)

    (Celik et al. 2008, J. Fluids Eng. 130, 078001, Eqs. 4-5; with equal ratios p = ln|d1/d2|/ln r).
    None when the differences change sign, or are too small a ratio for any p > 0 (not
    shrinking as a converging sequence would)."""
    if not d1 * d2 > 0:
        return None
    target, rc, rf = abs(d1 / d2), float(coarse_ratio), float(fine_ratio)
    if abs(rc - rf) < 1e-12 * rf:
        p = math.log(target) / math.log(rf)
        return p if p > 0 else None

    def ratio(p):  # increasing in p, from ln(rc)/ln(rf) at p -> 0
        return rf**p * math.expm1(p * math.log(rc)) / math.expm1(p * math.log(rf))

    if target <= math.log(rc) / math.log(rf):
        return None
    lo, hi = 1e-9, 1.0
    while ratio(hi) < target:
        hi *= 2.0
        if hi > 200.0:
            return hi
    for _ in range(200):  # bisection: ratio() is monotone
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if ratio(mid) < target else (lo, mid)
    return 0.5 * (lo + hi)


def estimate(values, resolutions, tolerance: float = 0.0, sizes=None) -> dict | None:
    """The converged value of one quantity from its values on meshes `resolutions` (elements
    along L, increasing; None or nan where a mesh did not give it), with an error bar that holds
    (the rule of data/fem_gold/README.md, ERROR_BAR_RULE = 2). `sizes` are the meshes' linear
    resolutions for the refinement ratios (default `resolutions`; the gold passes
    sqrt(along x across), Celik's N^(1/2), since its fourth mesh refines across by 28/18).

    Of the finest three meshes with a value, d1 = f2 - f1 and d2 = f3 - f2:
    * asymptotic: d1, d2 of one sign and the observed order p (order_from_ratios) in
      ASYMPTOTIC_ORDERS: the Richardson extrapolation f3 + d2/(r^p - 1), error bar
      Fs |d2|/(r^p - 1) (Roache's grid convergence index of the finest mesh), Fs = GCI_SAFETY
      for p >= LOW_ORDER and GCI_SAFETY_LOW_ORDER below;
    * otherwise (differences of opposite sign, not shrinking, p outside the window): the finest
      value, error bar NON_ASYMPTOTIC_FACTOR x max(|d1|, |d2|), and at least the distance
      |d2|/(r^p - 1) to the limit at the observed order where p < 1 and both differences exceed
      the bisection bracket (p counted as at least SLOWEST_ORDER), asymptotic False;
    * two meshes: the finest value, NON_ASYMPTOTIC_FACTOR x their difference; one: no error bar.
    `tolerance` (the bisection bracket of a threshold) is added to the error bar. None without any
    value."""
    sizes = resolutions if sizes is None else sizes
    triples = [(int(n), float(h), float(v)) for n, h, v in zip(resolutions, sizes, values)
               if v is not None and np.isfinite(v)]
    if not triples:
        return None
    ns, hs, fs = [t[0] for t in triples], [t[1] for t in triples], [t[2] for t in triples]
    out = {"value": fs[-1], "error_bar": None, "order": None, "asymptotic": False, "finest": fs[-1],
           "meshes": ns, "basis": "one mesh: no error bar", "rule": ERROR_BAR_RULE}
    if len(fs) == 2:
        out.update(error_bar=NON_ASYMPTOTIC_FACTOR * abs(fs[1] - fs[0]) + tolerance,
                   basis=f"two meshes: the finest value, {NON_ASYMPTOTIC_FACTOR:g} times their difference")
    if len(fs) >= 3:
        (h1, h2, h3), (f1, f2, f3) = hs[-3:], fs[-3:]
        d1, d2 = f2 - f1, f3 - f2
        r = h3 / h2
        p = order_from_ratios(d1, d2, h2 / h1, r)
        if p is not None and ASYMPTOTIC_ORDERS[0] <= p <= ASYMPTOTIC_ORDERS[1]:
            safety = GCI_SAFETY if p >= LOW_ORDER else GCI_SAFETY_LOW_ORDER
            out.update(value=f3 + d2 / (r**p - 1.0), error_bar=safety * abs(d2) / (r**p - 1.0) + tolerance,
                       order=p, asymptotic=True,
                       basis=f"Richardson, observed order, grid convergence index (safety factor {safety:g})")
        else:
            why = ("differences of one sign, order outside [1, 4]" if p is not None
                   else "differences change sign" if d1 * d2 <= 0 and abs(d2) < abs(d1)
                   else "differences do not shrink")
            spread = NON_ASYMPTOTIC_FACTOR * max(abs(d1), abs(d2))
            # one sign, shrinking slower than order 1, differences resolved (beyond the bisection
            # bracket): the limit at the observed order may lie further than the spread (order 0.5:
            # |d2|/(r^p - 1) = 4.4 |d2|); the bar reaches it, orders below SLOWEST_ORDER counted as it
            resolved = min(abs(d1), abs(d2)) > tolerance
            slow = p is not None and p < ASYMPTOTIC_ORDERS[0] and resolved
            reach = abs(d2) / (r**max(p, SLOWEST_ORDER) - 1.0) if slow else 0.0
            out.update(error_bar=max(spread, reach) + tolerance, order=p,
                       basis=f"not asymptotic ({why}): the finest value, {NON_ASYMPTOTIC_FACTOR:g} times the "
                             "largest difference of the finest three meshes"
                             + (", or the distance to the limit at the observed order" if reach > spread else ""))
    return out


def study_estimates(runs, resolutions, band: float = 0.02, default_tolerances: dict | None = None,
                    sizes=None) -> dict:
    """estimate() of dW1, dW2 (with the runs' bisection tolerances: summary.json's
    threshold_tolerances_over_L, else `default_tolerances` for runs stored before that key), H_mid
    after compression and H_mid(dW) on the common recorded grid of the runs that reached the shear
    stage; the curve's largest error bar away from the thresholds (|dW - dW_i| > band). `sizes`:
    the meshes' linear resolutions for the refinement ratios (estimate; default `resolutions`)."""
    def tolerance(key):
        return max(float((r.summary.get("threshold_tolerances_over_L") or default_tolerances or {}).get(key) or 0.0)
                   for r in runs)

    sizes = list(resolutions) if sizes is None else list(sizes)
    dw1 = estimate([r.summary["dW1_over_L"] for r in runs], resolutions, 0.5 * tolerance("dW1"), sizes)
    dw2 = estimate([r.summary["dW2_over_L"] for r in runs], resolutions, tolerance("dW2"), sizes)
    out = {"dW1": dw1, "dW2": dw2,
           "H_mid_compressed": estimate([r.summary["H_mid_over_L_compressed"] for r in runs], resolutions,
                                        sizes=sizes)}
    sheared = [(n, h, r) for n, h, r in zip(resolutions, sizes, runs) if any(row["stage"] == "shear" for row in r.rows)]
    if len(sheared) >= 2:
        resolutions, sizes, runs = [n for n, _, _ in sheared], [h for _, h, _ in sheared], [r for _, _, r in sheared]
        rows, _ = summarise(runs, resolutions)
        thresholds = [e["value"] if e else None for e in (dw1, dw2)]
        out["H_mid_curve"], out["H_mid_curve_away"] = _curve_estimates(rows, resolutions, sizes, "H_mid_over_L",
                                                                       thresholds, band)
        if all("F_shear_norm" in row for row in rows):
            force, away = _curve_estimates(rows, resolutions, sizes, "F_shear_norm", thresholds, band)
            if force:
                out["F_shear_curve"], out["F_shear_curve_away"] = force, away
    return out


def _curve_estimates(rows, resolutions, sizes, column: str, thresholds, band: float) -> tuple[list[dict], dict]:
    """estimate() of `column` (summarise's rows) at every dW of the grid, from the meshes that
    reached it, and the figures of its points more than `band` from the thresholds (points,
    asymptotic points, largest error bar). A point that only one mesh reached has no error bar
    and is left out: the curve ends where fewer than two meshes go on."""
    values = {(row["resolution"], row["dW_over_L"]): row[column] for row in rows}
    curve = []
    for x in sorted({row["dW_over_L"] for row in rows}):
        e = estimate([values[(n, x)] for n in resolutions], resolutions, sizes=sizes)
        if e is None or e["error_bar"] is None:   # fewer than two meshes recorded it there (nan)
            continue
        curve.append({"dW_over_L": x, **{k: e[k] for k in ("value", "error_bar", "order", "asymptotic")}})
    away = [c for c in curve if _away(np.array([c["dW_over_L"]]), *thresholds, margin=band)[0]]
    return curve, {"band_over_L": band, "points": len(away), "asymptotic_points": sum(c["asymptotic"] for c in away),
                   "max_error_bar": max((c["error_bar"] for c in away), default=None)}


#: Meshes of one convergence study: at least 2 (Richardson extrapolation needs two; one mesh
#: would report zero errors), at most 6 (each is a whole path, 5-20 minutes at 60-120 elements).
MIN_MESHES, MAX_MESHES = 2, 6


def check_resolutions(resolutions, width_ratio: float, name: str = "--resolutions") -> list[int]:
    """Distinct element counts along L (after rounding up to even), each within the mesh bounds
    and the machine's memory (mesh.checked_spec); sorted. One-line InputError otherwise."""
    from ddg.geometry.strip import InputError

    from .mesh import checked_spec

    values = list(resolutions)
    if not MIN_MESHES <= len(values) <= MAX_MESHES:
        raise InputError(f"{name} = {values} has {len(values)} meshes; give {MIN_MESHES} to {MAX_MESHES} "
                         "(Richardson extrapolation needs two; each is a whole path)")
    specs = {}
    for value in values:
        spec = checked_spec(value, width_ratio, None, name)
        if spec.nx in specs:
            raise InputError(f"{name} = {values}: {specs[spec.nx]} and {value} give the same mesh "
                             f"({spec.nx} elements along L: odd counts are rounded up to even); give distinct meshes")
        specs[spec.nx] = value
    return sorted(int(v) for v in values)


def run_convergence(args) -> int:
    from ddg.output.io import check_output_directory

    from .api import check_inputs, simulate
    from .scene import scene_from_args

    strip, protocol = scene_from_args(args)
    resolutions = check_resolutions(args.resolutions, strip.width_ratio)
    out = check_output_directory(args.out, "--out")
    for n in resolutions:  # every run's inputs and folder checked before the first is computed
        check_inputs(strip, protocol, n, out=out / f"N{n}", names={"resolution": "--resolutions", "out": "--out"})
    runs = []
    for n in resolutions:
        result = simulate(strip, protocol, n, out=out / f"N{n}", fields=False, progress=not args.quiet)
        runs.append(result)
        if not args.quiet:
            print(f"N = {n}: dW1/L = {result.summary['dW1_over_L']}, dW2/L = {result.summary['dW2_over_L']}, "
                  f"{result.summary['wall_time_s']:.1f} s, converged {result.converged}", flush=True)
    rows, table = summarise(runs, resolutions)
    write_outputs(out, rows, table, runs, resolutions, strip, protocol)
    return 0 if all(r.converged for r in runs) else 3


def load_runs(folders, name: str = "--runs") -> list:
    """The stored runs of `convergence-table --runs`, each a finished run folder with a
    compressed state and shear steps; one-line InputError naming the folder otherwise."""
    import json

    from ddg.geometry.strip import InputError
    from ddg.output.io import STATUS_RUNNING, StoredRun

    folders = list(folders)
    if len(folders) < MIN_MESHES:
        raise InputError(f"{name} = {folders} has {len(folders)} folder(s); give the runs of one scene on "
                         f"{MIN_MESHES} or more meshes")
    runs = []
    for folder in folders:
        text = str(folder)
        if text.strip() == "" or not os.path.isdir(text):
            raise InputError(f"{name}: {text!r} is not a directory")
        for file in ("summary.json", "path.csv"):
            if not os.path.isfile(os.path.join(text, file)):
                raise InputError(f"{name}: {text!r} has no {file}; give the output folder of a run")
        try:
            run = StoredRun(text)
            scene = run.summary["scene"]
            key = (float(scene["width_ratio"]), float(scene["compression_ratio"]), float(scene["slenderness"]))
            resolution = int(scene["resolution"])
            for needed in ("mesh", "n_dof", "recorded_steps", "dW1_over_L", "dW2_over_L", "wall_time_s",
                           "newton_iterations", "converged"):
                run.summary[needed]
            shear = [r for r in run.rows if r["stage"] == "shear"]
            for row in run.rows:
                float(row["dW_over_L"]), float(row["H_mid_over_L"]), row["phase"]
        except (OSError, UnicodeDecodeError) as exc:
            raise InputError(f"{name}: {text!r} cannot be read: {exc}") from None
        except (ValueError, KeyError, TypeError, AttributeError) as exc:  # json.JSONDecodeError is a ValueError
            what = f"missing {exc}" if isinstance(exc, KeyError) else f"{type(exc).__name__}: {exc}"
            raise InputError(f"{name}: {text!r} is not a run folder of fem_reference ({what})") from None
        if run.summary.get("status") == STATUS_RUNNING:
            raise InputError(f"{name}: {text!r} holds a run still in progress or killed (summary.json status "
                             "'running'); rerun it")
        if run.summary.get("H_mid_over_L_compressed") is None or not shear:
            raise InputError(f"{name}: {text!r} has no shear steps (the run stopped before the shear stage)")
        if run.summary.get("model") not in (None, "fem"):
            raise InputError(f"{name}: {text!r} is a run of model {json.dumps(run.summary.get('model'))}, "
                             "not of fem_reference")
        runs.append((key, resolution, run))
    return runs


def table_from_runs(args) -> int:
    """`convergence-table --runs DIR ...`: the convergence table of finished runs of one scene."""
    from ddg.geometry.strip import InputError, LoadingProtocol, Strip
    from ddg.output.io import check_output_directory

    loaded = load_runs(args.runs)
    scenes = {key for key, _, _ in loaded}
    if len(scenes) != 1:
        raise InputError(f"the runs are of different scenes {sorted(scenes)}; give runs of one scene")
    loaded.sort(key=lambda item: item[1])
    resolutions = [resolution for _, resolution, _ in loaded]
    if len(set(resolutions)) != len(resolutions):
        raise InputError(f"resolutions {resolutions} repeat; give one run per mesh")
    out = check_output_directory(args.out, "--out")
    runs = [run for _, _, run in loaded]
    width, compression, slenderness = scenes.pop()
    strip = Strip.from_ratios(width, compression, slenderness)
    rows, table = summarise(runs, resolutions)
    write_outputs(out, rows, table, runs, resolutions, strip, LoadingProtocol(compression))
    return 0


def summarise(runs, resolutions):
    """Per-mesh H_mid(dW) on the recorded dW grid of the coarsest of the runs that went furthest
    (each run interpolated onto it, nan beyond the largest dW it reached: a run that stopped short
    leaves the others' points in place), extrapolated values and estimated errors."""
    shear = [[r for r in run.rows if r["stage"] == "shear"] for run in runs]
    curves, forces = [], []
    for s in shear:
        dw_i = np.array([row["dW_over_L"] for row in s])
        order = np.argsort(dw_i)
        curves.append((dw_i[order], np.array([row["H_mid_over_L"] for row in s])[order]))
        force = [row.get("F_shear_norm") for row in s]
        forces.append(None if any(f is None or f == "" for f in force) else np.array(force, float)[order])
    reach = [c[0][-1] for c in curves]
    furthest = next(i for i, x in enumerate(reach) if x >= max(reach) - 1e-12)
    grid = shear[furthest]
    n_common = len(grid)
    dw = np.array([row["dW_over_L"] for row in grid])

    def on_grid(x, y, end):
        return np.where(dw <= end + 1e-12, np.interp(dw, x, y), np.nan)

    H = np.array([on_grid(*c, end) for c, end in zip(curves, reach)])
    # the clamp's shear force on the same grid (paper Fig. E.18), where every run recorded it
    F = None if any(f is None for f in forces) else \
        np.array([on_grid(c[0], f, end) for c, f, end in zip(curves, forces, reach)])

    def phase_nearest(rows, x, end):
        if x > end + 1e-12:
            return ""
        return rows[int(np.argmin(np.abs(np.array([r["dW_over_L"] for r in rows]) - x)))]["phase"]

    phases = [[phase_nearest(s, x, end) for x in dw] for s, end in zip(shear, reach)]
    compressed = np.array([[run.summary["H_mid_over_L_compressed"]] for run in runs])
    H_ext, p = extrapolate(H, resolutions) if len(runs) >= 2 else (H[-1], np.full(n_common, np.nan))
    Hc_ext, pc = extrapolate(compressed, resolutions) if len(runs) >= 2 else (compressed[-1], [np.nan])
    rows = []
    for i, run in enumerate(runs):
        for j in range(n_common):
            rows.append({"resolution": resolutions[i], "dW_over_L": dw[j], "H_mid_over_L": H[i, j],
                         "phase": phases[i][j], "H_extrapolated": H_ext[j], "order": p[j],
                         "error_estimate": abs(H[i, j] - H_ext[j]),
                         **({} if F is None else {"F_shear_norm": F[i, j]})})
    dw1 = np.array([np.nan if run.summary["dW1_over_L"] is None else run.summary["dW1_over_L"] for run in runs])
    dw2 = np.array([np.nan if run.summary["dW2_over_L"] is None else run.summary["dW2_over_L"] for run in runs])
    dw1_ext, p1 = extrapolate(dw1[:, None], resolutions) if len(runs) >= 2 else (dw1[-1:], [np.nan])
    dw2_ext, p2 = extrapolate(dw2[:, None], resolutions) if len(runs) >= 2 else (dw2[-1:], [np.nan])
    table = []
    for i, run in enumerate(runs):
        s = run.summary
        steps = s["recorded_steps"] - 1
        table.append({
            "resolution": resolutions[i],
            "triangles": (s.get("mesh") or {}).get("triangles"),
            "n_dof": s["n_dof"],
            "H_compressed": s["H_mid_over_L_compressed"],
            "H_compressed_error": abs(s["H_mid_over_L_compressed"] - float(Hc_ext[0])),
            "dW1_over_L": dw1[i],
            "dW1_error": abs(dw1[i] - float(dw1_ext[0])),
            "dW2_over_L": dw2[i],
            "dW2_error": abs(dw2[i] - float(dw2_ext[0])),
            "H_max_error": float(np.nanmax(np.abs(H[i] - H_ext))),
            "H_max_error_away": float(np.nanmax(np.where(_away(dw, dw1_ext[0], dw2[-1]), np.abs(H[i] - H_ext),
                                                         np.nan))),
            "dW_reached_over_L": float(curves[i][0][-1]),
            "wall_time_path_s": s["wall_time_s"],
            "wall_time_per_step_s": s["wall_time_s"] / max(steps, 1),
            "newton_iterations": s["newton_iterations"],
            "converged": s["converged"],
        })
    table.append({"resolution": "extrapolated", "H_compressed": float(Hc_ext[0]), "dW1_over_L": float(dw1_ext[0]),
                  "dW2_over_L": float(dw2_ext[0]), "order_H_compressed": float(np.asarray(pc).ravel()[0]),
                  "order_dW1": float(np.asarray(p1).ravel()[0]), "order_dW2": float(np.asarray(p2).ravel()[0])})
    return rows, table


def _away(dw, dw1, dw2, margin=0.02):
    """dW values at least `margin` from both thresholds (where H_mid is smooth in the mesh)."""
    mask = np.ones_like(dw, dtype=bool)
    for t in (dw1, dw2):
        if t is not None and np.isfinite(t):
            mask &= np.abs(np.abs(dw) - t) > margin
    return mask


def write_outputs(out: Path, rows, table, runs, resolutions, strip, protocol) -> None:
    out.mkdir(parents=True, exist_ok=True)
    write_table_csv(out / "convergence.csv", rows)
    keys = list(dict.fromkeys(k for t in table for k in t))   # first appearance: the same order on every run
    write_table_csv(out / "thresholds.csv", table, keys)

    def f(v, fmt="{:.5f}"):
        return "-" if v is None or (isinstance(v, float) and not np.isfinite(v)) else fmt.format(v)

    lines = [f"# FEM mesh convergence: W/L = {strip.width_ratio:.4g}, dL/L = {protocol.compression_ratio:g}, "
             f"L/b = {strip.slenderness:.0f}", "",
             "Richardson extrapolation from the finest meshes with the observed order (clipped to [0.5, 4]); "
             "errors are |value - extrapolated|. H errors over the recorded dW grid, each mesh up to where it "
             "reached; 'away' excludes "
             "dW within 0.02 L of dW1 and dW2.", "",
             "| N along L | triangles | unknowns | H_mid/L compressed | error | dW1/L | error | dW2/L | error | "
             "dW/L reached | max H error | max H error away | s / step | s / path | Newton its |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for t in table[:-1]:
        lines.append(f"| {t['resolution']} | {t['triangles']} | {t['n_dof']} | {f(t['H_compressed'], '{:.6f}')} | "
                     f"{f(t['H_compressed_error'], '{:.1e}')} | {f(t['dW1_over_L'], '{:.4f}')} | "
                     f"{f(t['dW1_error'], '{:.1e}')} | {f(t['dW2_over_L'], '{:.4f}')} | {f(t['dW2_error'], '{:.1e}')} "
                     f"| "
                     f"{f(t['dW_reached_over_L'], '{:.3f}')} | {f(t['H_max_error'], '{:.1e}')} | "
                     f"{f(t['H_max_error_away'], '{:.1e}')} | {f(t['wall_time_per_step_s'], '{:.2f}')} | "
                     f"{f(t['wall_time_path_s'], '{:.0f}')} | {t['newton_iterations']} |")
    e = table[-1]
    lines += ["", f"Extrapolated: H_mid/L compressed = {f(e['H_compressed'], '{:.6f}')} (order "
              f"{f(e['order_H_compressed'], '{:.2f}')}), dW1/L = {f(e['dW1_over_L'], '{:.4f}')} "
              f"(order {f(e['order_dW1'], '{:.2f}')}), dW2/L = {f(e['dW2_over_L'], '{:.4f}')} "
              f"(order {f(e['order_dW2'], '{:.2f}')}).", ""]
    atomic_write_text(out / "convergence.md", "\n".join(lines) + "\n")
