"""The error map's scenes: every scene with a converged FEM reference in the repository, the stored
runs of the other models on it, the models the map has rows of, and what the map lacks.

A scene is referenced by the FEM shell's mesh study in data/fem_gold (validation.estimates.load_study),
or, for the narrow strip at L/b = 300 and 100 without such a study, by its two FEM meshes in
data/narrow_limit read as a two-mesh study (validation.estimates.study_from_runs). A scene's
reference hash is that of the study's files, so that a changed reference makes its rows stale.
"""
from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass, field
from pathlib import Path

from ddg.advise import scene_name
from ddg.output.io import StoredRun, finished_run_summary

from ..estimates import MIDEDGE_GOLD, PLATE_GOLD, Study, load_study, study_from_runs
from ..reference import FEM_GOLD, ROOT, gold_name
from ..studies import COMPRESSIONS, WIDTHS_GOLD

try:   # the error map's reference scenes beyond the paper's ten (fem_reference.gold; no dolfinx needed)
    from fem_reference.gold import HELD_OUT_SCENES, MAP_SCENES, NEW_MAP_SCENES
    from fem_reference.gold import scene_name as fem_scene_name
except ImportError:   # an older fem_reference: the paper's ten and data/narrow_limit only
    MAP_SCENES, NEW_MAP_SCENES, HELD_OUT_SCENES, fem_scene_name = (), (), (), None

NARROW = ROOT / "data" / "narrow_limit"
#: L/b of the narrow-strip folders with a FEM reference (data/narrow_limit/Lb<L/b>), W/L = 1/20, dL/L = 1/2.
NARROW_SLENDERNESS = (300.0, 100.0)
ROD_RESOLUTIONS = (50, 100, 200)
#: The ribbons' node counts: not multiples of 4 (ddg.models.ribbon: at M = 0 mod 4 the inflection
#: points fall on nodes).
RIBBON_RESOLUTIONS = (51, 101, 201)
PLATE_MODELS = ("plate", "plate-midedge")
#: Keys of a FEM study (richardson.json) the map does not read (the clamp force's curve): left out of
#: its reference hash, so that adding them leaves the map's rows current.
UNREAD_STUDY_KEYS = ("F_shear_curve", "F_shear_curve_away")


def file_hash(*paths: Path) -> str:
    """The first 16 hex digits of the SHA-256 of the files' bytes, in order."""
    digest = hashlib.sha256()
    for p in paths:
        digest.update(Path(p).read_bytes())
    return digest.hexdigest()[:16]


def study_hash(path: Path) -> str:
    """file_hash of a FEM study as written without UNREAD_STUDY_KEYS (the same bytes as a study
    written before those keys existed)."""
    study = json.loads(Path(path).read_text())
    text = json.dumps({k: v for k, v in study.items() if k not in UNREAD_STUDY_KEYS}, indent=2) + "\n"
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def relative_path(path: Path) -> str:
    """`path` relative to the checkout where it is inside it, else as given."""
    path = Path(path)
    return str(path.relative_to(ROOT)) if path.is_relative_to(ROOT) else str(path)


@dataclass
class StoredMesh:
    """A finished run of a stored study: model, resolution (rows or elements along L), label, folder."""
    model: str
    resolution: int
    label: str
    folder: Path


@dataclass
class ReferenceScene:
    """A scene of the map: its ratios, the FEM reference study, where that came from, and the
    stored runs of the other models on it."""
    compression_ratio: float
    width_ratio: float
    slenderness: float | None          # None: the paper's thickness
    reference: Study | None
    reference_source: str
    reference_hash: str
    stored: list[StoredMesh] = field(default_factory=list)
    folder_name: str = ""

    @property
    def role(self) -> str:
        """"held-out" for a scene of fem_reference.gold.HELD_OUT_SCENES (named under ddg.advise's rule
        v3 before their references existed): never used by the prediction, only to check it; else
        "fit" (the held-out sets of rules v1 and v2, validation.error_map.held_out.HELD_OUT_FIRST and
        HELD_OUT_SECOND, fit from rule v3 on)."""
        held = any(abs(self.compression_ratio - c) < 1e-9 and abs(self.width_ratio - w) < 1e-9
                   and self.slenderness == lb for c, w, lb in HELD_OUT_SCENES)
        return "held-out" if held else "fit"

    @property
    def actual_slenderness(self) -> float:
        import ddg

        return ddg.Strip.from_ratios(self.width_ratio, self.compression_ratio, self.slenderness).slenderness

    @property
    def name(self) -> str:
        return scene_name(self.compression_ratio, self.width_ratio, self.actual_slenderness)


def _stored_plates(model: str, folder: Path) -> list[StoredMesh]:
    out = []
    for run in sorted(folder.glob("R*")) if folder.is_dir() else []:
        if run.name[1:].isdigit() and finished_run_summary(run) is not None:
            out.append(StoredMesh(model, int(run.name[1:]), run.name, run))
    return sorted(out, key=lambda m: m.resolution)


def _stored_fem(folder: Path) -> list[StoredMesh]:
    from fem_reference.gold import scene_runs

    return [StoredMesh("fem", along, f"N{along}x{across}", path) for along, across, path in scene_runs(folder)]


def reference_scenes() -> list[ReferenceScene]:
    """Every scene with a FEM reference in the repository (module docstring): the paper's ten, the
    map's scenes of fem_reference.gold with a study on two meshes or more, and the narrow strip of
    data/narrow_limit where no such study replaces it."""
    out = []
    for c in COMPRESSIONS:
        for w in sorted(WIDTHS_GOLD):
            name = gold_name(c, w)
            study_file = FEM_GOLD / name / "richardson.json"
            study = load_study("fem", c, w)
            stored = _stored_plates("plate", PLATE_GOLD / name) + _stored_plates("plate-midedge", MIDEDGE_GOLD / name)
            stored += _stored_fem(FEM_GOLD / name)
            out.append(ReferenceScene(c, w, None, study, relative_path(study_file),
                                      study_hash(study_file) if study_file.exists() else "", stored))
    gold_map = {}
    for c, w, lb in MAP_SCENES + NEW_MAP_SCENES + HELD_OUT_SCENES:
        name = fem_scene_name(c, w, lb)
        study_file = FEM_GOLD / name / "richardson.json"
        study = load_study("fem", c, w, name=name) if study_file.exists() else None
        if study is None or len(study.meshes) < 2:   # one mesh: no error bar, no reference yet
            continue
        stored = _stored_plates("plate", PLATE_GOLD / name) + _stored_plates("plate-midedge", MIDEDGE_GOLD / name)
        stored += _stored_fem(FEM_GOLD / name)
        gold_map[(c, w, lb)] = ReferenceScene(c, w, lb, study, relative_path(study_file),
                                              study_hash(study_file), stored, name)
    out += list(gold_map.values())
    for lb in NARROW_SLENDERNESS:
        if (0.5, 1 / 20, lb) in gold_map:   # a three-mesh gold study of the same scene replaces the two meshes
            continue
        folder = NARROW / f"Lb{lb:.0f}"
        fem = [(int(p.name.split("_N")[1].split("x")[0]), p) for p in sorted(folder.glob("fem_N*x*"))
               if finished_run_summary(p) is not None]
        fem.sort()
        study = None
        if len(fem) >= 2:
            study = study_from_runs("fem", [StoredRun(p) for _, p in fem], [n for n, _ in fem],
                                    unit="elements along L")
        stored = [StoredMesh("plate", int(p.name.split("_R")[1]), f"R{p.name.split('_R')[1]}", p)
                  for p in sorted(folder.glob("plate_R*")) if finished_run_summary(p) is not None]
        stored += [StoredMesh("fem", n, p.name.split("_", 1)[1], p) for n, p in fem]
        ref_files = [p / "summary.json" for _, p in fem] + [p / "path.csv" for _, p in fem]
        out.append(ReferenceScene(0.5, 1 / 20, lb, study,
                                  " + ".join(relative_path(p) for _, p in fem) + " (two-mesh study)",
                                  file_hash(*ref_files) if fem else "", stored))
    return out


def missing_scenes(scenes: list[ReferenceScene]) -> list[str]:
    """What the map lacks, in words, from the scenes found."""
    out = []
    for c, w, lb in MAP_SCENES + NEW_MAP_SCENES + HELD_OUT_SCENES:
        name = fem_scene_name(c, w, lb)
        study = load_study("fem", c, w, name=name) if (FEM_GOLD / name / "richardson.json").exists() else None
        if study is None or len(study.meshes) < 2:
            role = "held-out" if (c, w, lb) in HELD_OUT_SCENES else "fit"
            done = 0 if study is None else len(study.meshes)
            out.append(f"{name} ({role}): {done} FEM mesh(es) finished, a reference needs two or more "
                       f"(python -m fem_reference gold --only {name})")
    for s in scenes:
        if s.reference is None:
            out.append(f"{s.name}: no FEM reference study (its FEM runs are missing or unfinished)")
        elif not any(m.model == "plate" for m in s.stored):
            out.append(f"{s.name}: no stored plate study")
    lbs = sorted({round(s.actual_slenderness) for s in scenes if s.reference is not None})
    out.append(f"L/b: FEM references exist at L/b = {', '.join(str(v) for v in lbs)}; L/b other than the paper's "
               "at W/L > 1/20 has none")
    thin = [s for s in scenes if s.reference is not None and s.actual_slenderness > 2000]
    for s in thin:
        stops = {}
        for m in s.stored:
            summary = finished_run_summary(m.folder) or {}
            if summary.get("status") == "stopped":
                shear = [r for r in StoredRun(m.folder).rows if r["stage"] == "shear"]
                stops.setdefault(m.model, []).append(f"{m.label} at dW/L = {shear[-1]['dW_over_L']:.4f}"
                                                     if shear else m.label)
        if stops:
            missing = [q for q in ("dW1", "dW2") if s.reference.threshold(q) is None]
            out.append(f"{s.name}: stopped runs: " + "; ".join(f"{model} {', '.join(v)}" for model, v in stops.items())
                       + (f". The reference there has no {' and no '.join(missing)}" if missing else
                          ". The reference there has dW1 and dW2"))
    midedge = sorted({s.name for s in scenes for m in s.stored if m.model == "plate-midedge"})
    out.append(f"the mid-edge plate has stored runs on {len(midedge)} scenes only ({', '.join(midedge) or 'none'})")
    out.append("data/fem_fine and data/fem_convergence are other meshes of dL0.5_W0.1667 and data/fem_dep another "
               "material: none is a held-out scene")
    return out


def rod_family() -> list[tuple[str, tuple[int, ...]]]:
    """(model, node counts) of the rod's family registered in ddg.api.DEFAULT_RESOLUTION now."""
    from ddg.api import DEFAULT_RESOLUTION

    return [(m, ROD_RESOLUTIONS if m == "rod" else RIBBON_RESOLUTIONS) for m in DEFAULT_RESOLUTION
            if m not in PLATE_MODELS]


def map_models() -> list[str]:
    """The models the map has rows of: the rod's family in the registry (rod_family), the plates and
    the FEM (their stored studies)."""
    return list(dict.fromkeys([m for m, _ in rod_family()] + list(PLATE_MODELS) + ["fem"]))


def check_selection(only, models, scenes: list[ReferenceScene]) -> None:
    """--only names scenes of the map (each scene's name, e.g. dL0.5_W0.05_Lb1181, or its data folder's,
    e.g. dL0.5_W0.05) and --models models it has (map_models); a one-line InputError naming the first
    unknown value and the allowed ones otherwise."""
    from ddg.geometry.strip import InputError

    known = list(dict.fromkeys(n for s in scenes for n in (s.name, s.folder_name or gold_name(s.compression_ratio,
                                                                                                 s.width_ratio))))
    unknown = [n for n in (only or []) if n not in known]
    if unknown:
        raise InputError(f"--only {unknown[0]!r} is not a scene of the map; choose from {', '.join(known)}")
    allowed = map_models()
    unknown = [m for m in (models or []) if m not in allowed]
    if unknown:
        raise InputError(f"--models {unknown[0]!r} is not a model of the map; choose from {', '.join(allowed)}")
