"""Studies of the curvature profiles along paths (Figs. A.12-A.14): the states at requested shears
(compression, then shear through each requested dW/L on the stable path), the plate's twist at its
inflection points against L/b, and the curvatures.csv writer. They run paths; the profiles
themselves are ddg.analysis.curvatures."""
from __future__ import annotations

import csv
import io
from pathlib import Path

import numpy as np

from ..analysis.curvatures import CURVATURE_COLUMNS, inflection_jumps, plate_curvatures
from ..api import make_model
from ..geometry.strip import Strip
from ..limits import InputError
from ..models.names import PLATE, RIBBON, ROD
from ..models.ribbon import RIBBON_INITS, RibbonModel
from ..models.rod import RodModel
from ..output.io import atomic_write_text
from ..protocol.driver import Loading, Run, follow
from ..protocol.steppers import StaticStepper
from ..solve.continuation import ContinuationFailure, ContinuationOptions, relax_from
from ..solve.state import Snapshot


def write_curvatures_csv(path, records: list[dict]) -> None:
    """curvatures.csv: one row per station of each record (a dict with model, step, dL_over_L,
    dW_over_L and a profile from centerline_curvatures)."""
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(CURVATURE_COLUMNS)
    for rec in records:
        p = rec["profile"]
        for k in range(len(p["s_over_L"])):
            writer.writerow([rec["model"], rec["step"], repr(float(rec["dL_over_L"])), repr(float(rec["dW_over_L"])),
                             *(repr(float(p[c][k])) for c in ("s_over_L", "k1_L", "k2_L", "tau_L"))])
    atomic_write_text(Path(path), buf.getvalue())


# ---------------------------------------------------------------------- states at requested shears
def states_at_shears(model_name: str, strip, compression_ratio: float, shear_ratios, resolution=None, *,
                     ribbon_init: str = "direct", zeta=None, max_step: float = 0.02, options=None, mesh=None):
    """Run compression, then shear through the requested dW/L in increasing order (recorded steps
    of at most max_step L, quasi-static, through the protocol's one driver, ddg.protocol.driver),
    yielding (model, state) at each requested dW/L, the model's reference frames those of the state.
    A path that stops raises ContinuationFailure with the stepper's message.

    model_name: rod, plate, ribbon; for the ribbon ribbon_init="rod" follows the rod and relaxes
    each requested state under the ribbon energy (ddg.solve.continuation.relax_from)."""
    shear_ratios = sorted(float(r) for r in np.atleast_1d(shear_ratios))
    if not shear_ratios or shear_ratios[0] < 0:
        raise InputError(f"shear ratios = {shear_ratios!r} must be a non-empty list of dW/L >= 0")
    limit = strip.shear_limit(compression_ratio * strip.length) / strip.length
    if shear_ratios[-1] > limit:
        raise InputError(f"dW/L = {shear_ratios[-1]:g} beyond the shear limit {limit:.6g} (Eq. B.1); allowed [0, "
                         f"{limit:.6g}]")
    options = options or ContinuationOptions()
    L = strip.length
    relax = None
    if model_name == RIBBON:
        if ribbon_init not in RIBBON_INITS:
            raise InputError(f"ribbon init = {ribbon_init!r} is not available; choose one of {list(RIBBON_INITS)}")
        ribbon = RibbonModel(strip, 101 if resolution is None else resolution, zeta=zeta)
        driver = RodModel(strip, ribbon.nodes) if ribbon_init == ROD else ribbon
        if ribbon_init == ROD:
            relax = lambda state: relax_from(ribbon, driver, state, options)  # noqa: E731
    else:
        driver = make_model(model_name, strip, resolution, mesh)
        ribbon = None
    # the recorded loads: compression in steps of at most max_step L, then shear through each
    # requested dW/L in steps of at most max_step L; row[i] is the recorded row a request reads
    # (the last compression row where it asks for no shear beyond the previous one)
    dL = compression_ratio * L
    steps = max(1, int(np.ceil(compression_ratio / max_step)))
    shears, wanted, current = [], [], 0.0
    for ratio in shear_ratios:
        n = int(np.ceil((ratio - current) / max_step - 1e-9))
        shears += [L * (current + (ratio - current) * k / n) for k in range(1, n + 1)]
        wanted.append(steps + len(shears))  # rows: the rest, `steps` compressions, the shears so far
        current = ratio
    loading = Loading(tuple(dL * k / steps for k in range(1, steps + 1)), tuple(shears), dL)
    kept: dict[int, Snapshot] = {}

    def keep(stage, state, row, rows=[0]):  # noqa: B006  (the count of rows recorded so far)
        if rows[0] in wanted:
            kept[rows[0]] = Snapshot.take(driver, state)
        rows[0] += 1

    def observe(stage, state):  # no row is written: the driver reads H_mid after compression only
        return {"H_mid_over_L": None}

    outcome = follow(Run(StaticStepper(driver, options, folds=False), loading, observe=observe, summary={},
                         listeners=(keep,)))
    if outcome.interrupted is not None:
        raise outcome.interrupted
    if outcome.error is not None:
        raise outcome.error
    if outcome.stopped is not None:
        raise ContinuationFailure(outcome.stopped)
    for row in wanted:
        snapshot = kept[row]
        driver.restore_frames(snapshot.frames)
        if relax is not None:
            yield ribbon, relax(snapshot.state)
        else:
            yield driver, snapshot.state


# ---------------------------------------------------------------------- thickness study (Figs. A.13-A.14)
def inflection_twist_study(width_ratios=(1 / 20, 1 / 6), slendernesses=(300.0, 600.0, 1200.0), shear_ratio: float = 0.3,
                           compression_ratio: float = 0.5, triangles: int = 800, max_step: float = 0.05,
                           options=None) -> list[dict]:
    """The plate's centerline twist at its inflection points (k2 = 0, away from the clamps)
    against L/b, at dW/L = shear_ratio on the stable path: per width and L/b, tau L at the
    inflection (mean of |tau L| over the inflection points), the largest |tau L| along the
    centerline, their ratio, and the k2 and tau jump ratios (inflection_jumps). As the plate
    thins, stretching costs more against bending and the surface becomes developable, which
    forces the twist at the inflection towards zero (Sadowsky's limit, Figs. A.13-A.14)."""
    rows = []
    for ratio in width_ratios:
        for slenderness in slendernesses:
            strip = Strip.from_ratios(ratio, compression_ratio, slenderness)
            ((model, state),) = list(states_at_shears(PLATE, strip, compression_ratio, [shear_ratio], triangles,
                                                      max_step=max_step, options=options))
            profile = plate_curvatures(model, state.q)
            jumps = inflection_jumps(profile)
            tau_infl = float(np.mean([abs(j["tau_at_inflection_L"]) for j in jumps])) if jumps else float("nan")
            tau_max = float(np.max(np.abs(profile["tau_L"])))
            rows.append({"W_over_L": ratio, "L_over_b": slenderness, "dW_over_L": shear_ratio,
                         "inflections": len(jumps), "tau_inflection_L": tau_infl, "tau_max_L": tau_max,
                         "tau_inflection_over_max": tau_infl / tau_max,
                         "k2_jump_ratio": _mean_of(jumps, "k2_jump_ratio"),
                         "tau_jump_ratio": _mean_of(jumps, "tau_jump_ratio"),
                         "triangles": model.mesh.triangle_count})
    return rows


def _mean_of(rows: list[dict], key: str) -> float:
    """Mean of rows[...][key]; NaN for no rows."""
    return float(np.mean([r[key] for r in rows])) if rows else float("nan")
