"""The report's runs read back: a scene's run of a model, a path's column on a stage, the FEM gold
curves of the report's scenes."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..reference import load_gold
from ..studies import WIDE_RIBBONS

MODELS = ("rod", "plate", "ribbon") + WIDE_RIBBONS


def shear_values(run, key):
    """`key` of a run's shear states, in order."""
    return np.array([float(r[key]) for r in run.rows if r["stage"] == "shear"])


def compression_values(run, key):
    """`key` of a run's compression states, in order."""
    return np.array([float(r[key]) for r in run.rows if r["stage"] == "compression"])


def find_run(results, model, compression, width, resolution=None, poisson=0.0):
    """The run of `results` ({RunSpec: run}) on a scene, or None."""
    for spec, run in results.items():
        if (spec.model == model and abs(spec.compression_ratio - compression) < 1e-9
                and abs(spec.width_ratio - width) < 1e-9 and spec.poisson_ratio == poisson
                and (resolution is None or spec.resolution == resolution)):
            return run
    return None


def load_golds(scenes, gold_root: Path | None = None) -> dict:
    """(dL/L, W/L) -> FEM gold curve, for the scenes that have one."""
    golds = {}
    for c, w in scenes:
        gold = load_gold(c, w) if gold_root is None else load_gold(c, w, gold_root)
        if gold is not None:
            golds[(c, w)] = gold
    return golds

