"""Every claim of validation/claims.py evaluated on the report's runs and the stored studies, the plate's
clamp force against the FEM's, and the check whether the plate/FEM gap is the plate's material."""
from __future__ import annotations

import dataclasses
import math

import numpy as np

from .. import claims as C
from ..estimates import Study, load_study, single_run_study, study_from_runs
from ..reference import FEM_FINE, GoldCurve, load_dep_material
from ..studies import SPEED_SCENE
from ..verdicts import MaterialCheck, MeshTrend
from .runs import find_run

CLAIM_COLUMNS = ["claim", "statement", "bound", "measured", "holds", "outcome", "reason", "difference",
                 "combined_error_bar", "in_error_bars", "needs"]


FORCE_COLUMNS = ["reference", "compression_ratio", "width_ratio", "range", "points", "F_scale", "difference",
                 "combined_error_bar", "excess", "worst_at_dW_over_L"]


def force_table(dep6=None, load=None) -> list[dict]:
    """The plate study's clamp force against the FEM's on the scenes of claim plate_vs_fem_force
    (and against the shell with the plate's material, `dep6`, at W/L = 1/6), split by range: the
    whole compared path (0.02 from the thresholds, as the claim) and the U branch (up to 0.02 below
    the smaller dW1); figures relative to the FEM's largest |F| on the compared points. A scene
    without both studies is left out."""
    load = load or load_study
    pairs = [("FEM study", c, w, load("plate", c, w), load("fem", c, w))
             for c, w in [SPEED_SCENE, *C.NARROW_SCENES]]
    if dep6 is not None:
        pairs.append(("FEM, plate's material (90 el.)", *SPEED_SCENE, load("plate", *SPEED_SCENE), dep6))
    out = []
    for reference, c, w, plate, fem in pairs:
        if plate is None or fem is None or plate.force is None or fem.force is None:
            continue
        dw1 = min(x.value for x in (plate.dW1, fem.dW1) if x is not None) if plate.dW1 or fem.dW1 else None
        ranges = [("path, 0.02 from the thresholds", C.curve_agreement(plate, fem, quantity="force"))]
        if dw1 is not None:
            ranges.append(("U branch", C.curve_agreement(plate, fem, band=0.0, upto=dw1 - C.THRESHOLD_BAND,
                                                         quantity="force")))
        for name, a in ranges:
            if a is not None:
                out.append({"reference": reference, "compression_ratio": c, "width_ratio": w, "range": name,
                            "points": a.points, "F_scale": a.scale, "difference": a.difference,
                            "combined_error_bar": a.combined_error_bar, "excess": a.excess,
                            "worst_at_dW_over_L": a.at})
    return out


def material_check(results, golds) -> MaterialCheck | None:
    """Is the plate/FEM gap at SPEED_SCENE the plate's material (the DEP's nu = 1/3 membrane and
    nu_b = -1/3 bending, against the shell's nu = 0)? The material's effect (the FEM shell run with
    the DEP's material, data/fem_dep, against the nu = 0 shell on the same mesh, data/fem_fine) is
    set against the gap (the plate's converged values, data/plate_gold, against the FEM gold's,
    largest difference) and the plate against the shell with its own material; with the plate's
    dW1 on each mesh of its study."""
    iso_dir = FEM_FINE / "dL0.5_W0.1667_N90"
    plate, fem = load_study("plate", *SPEED_SCENE), load_study("fem", *SPEED_SCENE)
    dep = load_dep_material()
    if dep is None or plate is None or fem is None or not (iso_dir / "summary.json").exists():
        return None
    iso = GoldCurve(iso_dir)
    dep_study = dep_material_study(fem)

    def gap(a, b, key):
        agreement = C.threshold_agreement(a, b, key) if key != "curve" else C.curve_agreement(a, b)
        return None if agreement is None else agreement.difference

    plate_dw1_study = plate.dW1.value if plate.dW1 is not None else None
    numbers = {"fem_dep_vs_nu0_dW1": C.threshold_difference(dep, iso),
               "fem_dep_vs_nu0_curve": C.curve_difference_away_from_thresholds(dep, iso),
               "plate_vs_fem_gold_dW1": gap(plate, fem, "dW1"),
               "plate_vs_fem_gold_curve": gap(plate, fem, "curve"),
               "plate_vs_fem_dep_dW1": (abs(plate_dw1_study - dep.summary["dW1_over_L"])
                                        if plate_dw1_study is not None and dep.summary.get("dW1_over_L") else None),
               "plate_vs_fem_dep_curve": gap(plate, dep_study, "curve") if dep_study is not None else None,
               "fem_dep_resolution": dep.summary["scene"]["resolution"],
               "plate_triangles": plate.finest.size}
    if any(v is None or not math.isfinite(v) for v in numbers.values()):
        return None
    points = [(m.size, m.dW1) for m in plate.meshes if m.dW1 is not None]
    trend = MeshTrend(points, fem.dW1.value) if fem.dW1 is not None and points else None
    return MaterialCheck(**numbers, mesh_trend=trend)


def _missing(**inputs) -> str:
    """What a claim lacks: the names of the inputs that are None, joined ('' if none is)."""
    return ", ".join(f"no {name}" for name, value in inputs.items() if value is None)


def rod_study(results, profile) -> Study | None:
    """The rod's study at W/L = 1/20, dL/L = 1/2 from the profile's convergence runs."""
    resolutions = [n for n in profile.convergence.get("rod", ()) if find_run(results, "rod", 0.5, 1 / 20, n)]
    return study_from_runs("rod", [find_run(results, "rod", 0.5, 1 / 20, n) for n in resolutions], resolutions)


def dep_material_study(fem) -> Study | None:
    """The FEM shell with the plate's material (data/fem_dep, one mesh) as a study whose error bars
    (H_mid and the clamp force) are the measured errors of the nu = 0 shell on the same mesh
    (data/fem_fine against the FEM gold study's converged curves), up to where the gold study's
    curves reach; None where any is missing."""
    dep, iso_dir = load_dep_material(), FEM_FINE / "dL0.5_W0.1667_N90"
    if dep is None or fem is None or fem.curve is None or not (iso_dir / "summary.json").exists():
        return None
    zero = lambda dw: np.zeros_like(dw)  # noqa: E731
    iso = single_run_study("fem", GoldCurve(iso_dir), zero, zero)

    def error_of(dw):
        return np.abs(np.interp(dw, iso.curve.dw, iso.curve.value) - np.interp(dw, fem.curve.dw, fem.curve.value))

    def force_error_of(dw):  # the same for the clamp force, where the gold study has its force curve
        return np.abs(np.interp(dw, iso.force.dw, iso.force.value) - np.interp(dw, fem.force.dw, fem.force.value))

    study = single_run_study("fem", dep, error_of, force_error_of if fem.force is not None else None)
    # the borrowed error bars are measured only where the gold study has its curves (up to the
    # smallest dW all its meshes reached): the study ends there
    return dataclasses.replace(study, curve=study.curve.upto(fem.curve.dw[-1]),
                               force=None if study.force is None else study.force.upto(fem.force.dw[-1]))


def evaluate_claims(results, profile, golds) -> list[dict]:
    """Every claim of validation/claims.py: the single-model claims on this report's runs, the
    cross-model claims on converged values (the stored FEM and plate studies, the rod study of this
    report's convergence runs). A claim whose runs or reference data are not there does not hold
    (reason "no data: ..." naming what is missing)."""
    get = lambda m, c, w: find_run(results, m, c, w, profile.models.get(m))  # noqa: E731
    res = lambda m: "" if profile.models.get(m) is None else f", resolution {profile.models[m]}"  # noqa: E731
    out = []
    rod = find_run(results, "rod", 0.5, 1 / 20, 100)  # the claims are stated for M = 100
    rod_quarter = find_run(results, "rod", 0.25, 1 / 20, 100)
    plate6 = get("plate", 0.5, 1 / 6)
    gold6 = golds.get((0.5, 1 / 6))
    ribbon = get("ribbon", 0.5, 1 / 20)
    rods = rod_study(results, profile)
    dep6 = dep_material_study(load_study("fem", *SPEED_SCENE))
    names = {
        "rod": "rod run (M = 100, W/L = 1/20, dL/L = 1/2)",
        "rod_quarter": "rod run (M = 100, W/L = 1/20, dL/L = 1/4)",
        "plate6": f"plate run (W/L = 1/6, dL/L = 1/2{res('plate')})",
        "ribbon": f"ribbon run (W/L = 1/20, dL/L = 1/2{res('ribbon')})",
        "gold6": "FEM gold data (data/fem_gold/dL0.5_W0.1667)",
    }

    def lacking(**inputs) -> str:
        return _missing(**{names[k]: v for k, v in inputs.items()})

    out.append(C.evaluate("rod_elastica", C.elastica_error(rod) if rod else None, lacking(rod=rod)))
    out.append(C.evaluate("plate_elastica", C.elastica_error(plate6) if plate6 else None, lacking(plate6=plate6)))
    out.append(C.evaluate("ribbon_elastica", C.elastica_error(ribbon) if ribbon else None, lacking(ribbon=ribbon)))
    out.append(C.evaluate("fem_elastica", C.elastica_error(gold6) if gold6 else None, lacking(gold6=gold6)))
    out += C.cross_model_verdicts(rods, dep6)
    rods_paper = [r for r in (rod, rod_quarter) if r is not None]
    errors = [C.paper_threshold_error(r) for r in rods_paper]
    out.append(C.evaluate("rod_thresholds_paper", max(errors) if len(errors) == 2 and None not in errors else None,
                          lacking(rod=rod, rod_quarter=rod_quarter) or "a threshold the paper quotes was not located"))
    dw1_sixth = plate6.summary.get("dW1_over_L") if plate6 else None
    out.append(C.evaluate("plate_dW1_paper_sixth", abs(dw1_sixth - 0.27) if dw1_sixth is not None else None,
                          lacking(plate6=plate6) or "dW1 not located in the plate run"))
    return out

