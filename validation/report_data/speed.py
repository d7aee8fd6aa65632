"""Speed against accuracy on the speed scene: each model and resolution's wall time and error against
the FEM's converged values (or, lacking them, the FEM gold run or the finest run), with the shell's
stored meshes and the entries of benchmarks/speed_accuracy.py."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ddg.output.io import read_json_object

from .. import claims as C
from ..estimates import load_study
from ..reference import FEM_FINE, FEM_GOLD, ROOT, GoldCurve, gold_name
from ..studies import SPEED_SCENE


#: The speed-accuracy benchmark of the three plate models (benchmarks/speed_accuracy.py): its entries
#: join the chart, labelled "(benchmark)", with their idle-machine wall times.
SPEED_BENCHMARK = ROOT / "benchmarks" / "results" / "speed_accuracy.json"


def _speed_row(model, resolution, summary: dict, curve_error, dw1_error) -> dict:
    return {"model": model, "resolution": resolution, "wall_time_s": summary.get("wall_time_s"),
            "curve_error": curve_error, "dW1_error": dw1_error, "converged": summary.get("converged")}


def speed_accuracy(results, study_specs, golds, benchmark: Path = SPEED_BENCHMARK) -> tuple[list[dict], str]:
    """Wall time and error of each model and resolution on SPEED_SCENE; the FEM shell's stored meshes
    (its gold study and data/fem_fine) and the speed-accuracy benchmark's entries too. Returns
    (rows, reference).

    With the FEM's mesh study of the scene (not a single run), the reference is its
    converged values: the dW1 error is the distance to the converged dW1, the curve error the
    largest distance to the converged H_mid/L curve 0.02 away from the converged thresholds
    (Study.curve_error, without its bar: the reference text states the bars). A benchmark entry's
    curve is that of the study run on its mesh (its dW1 reproduced within the bisection bracket).
    Without the study, the FEM gold's run is the reference (both thresholds' bands excluded); without
    FEM data, the finest run of the report."""
    gold = golds.get(SPEED_SCENE)
    runs = [(s, results[s]) for s in study_specs if s in results]
    converged = load_study("fem", *SPEED_SCENE) if gold is not None else None
    if converged is not None and (converged.dW1 is None or converged.curve is None):
        converged = None
    if converged is not None:
        reference = None
        bars = float(np.max(converged.curve.error_bar))
        ref_name = (f"the FEM's converged values ({converged.describe()}): dW1/L {converged.dW1.value:.4f} +- "
                    f"{converged.dW1.error_bar:.4f}; H_mid/L curve bars up to {bars:.1e}")
    elif gold is not None:
        reference = gold
        ref_name = f"the FEM gold ({gold.summary['scene']['resolution']} elements along L; no converged study)"
    else:
        if not runs:
            return [], "none"
        plates = [(s, r) for s, r in runs if s.model == "plate"] or runs
        spec, reference = max(plates, key=lambda t: t[0].resolution)
        ref_name = f"the finest {spec.model} run (resolution {spec.resolution}; no FEM gold data for this scene)"

    def errors(run, summary: dict) -> tuple:
        if converged is None:
            return C.curve_difference_away_from_thresholds(run, reference), C.threshold_difference(run, reference)
        value = summary.get("dW1_over_L")
        return (None if run is None else converged.curve_error(run, with_bar=False),
                None if value is None else abs(value - converged.dW1.value))

    data = [_speed_row(spec.model, spec.resolution, run.summary, *errors(run, run.summary))
            for spec, run in runs if run is not reference]
    if gold is not None:  # the shell itself on its stored meshes (its study's and data/fem_fine's)
        folders = [p.parent for p in sorted((FEM_GOLD / gold_name(*SPEED_SCENE)).glob("N*/summary.json"))]
        folders += [d for d in sorted(FEM_FINE.glob("dL0.5_W0.1667_N*")) if (d / "summary.json").exists()]
        for directory in folders:
            if reference is not None and directory.resolve() == Path(reference.directory).resolve():
                continue
            fem = GoldCurve(directory)
            mesh = fem.summary.get("mesh") or {}
            label = (f"{mesh['elements_along_L']}x{mesh['elements_across_W']}" if "elements_across_W" in mesh
                     else fem.summary["scene"]["resolution"])
            data.append(_speed_row("fem", label, fem.summary, *errors(fem, fem.summary)))
    stored = read_json_object(benchmark) if converged is not None and Path(benchmark).exists() else None
    for name in (stored or {}).get("entry_order", []):
        entry = stored["entries"].get(name) or {}
        if entry.get("status") != "ok":
            continue
        study_run = ROOT / entry["study_run"] if entry.get("study_run") else None
        run = GoldCurve(study_run) if study_run is not None and (study_run / "path.csv").exists() else None
        data.append(_speed_row(f"{entry['model']} (benchmark)", entry["mesh_label"], entry, *errors(run, entry)))
    return data, ref_name

