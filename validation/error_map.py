"""The error map (issue 17 item 3): the error of every model at every resolution on every scene
with a converged FEM reference, and its wall time:
`python -m validation.error_map --out data/error_map [--only SCENE ...] [--models MODEL ...]
[--workers N | --scheduler ADDRESS] [--retries 2]`.

Scenes: the ten of the benchmark (dL/L in {1/2, 1/4} x W/L in {1/20, 1/12, 1/6, 1/3, 1/2}, the
paper's strip: L/b = 1181 at dL/L = 1/2, 787 at 1/4), each referenced by the FEM shell's mesh study
in data/fem_gold (validation.estimates.load_study: Richardson extrapolation with the observed order
and Roache's grid convergence index where asymptotic, else the finest value with the spread), and
the narrow strip W/L = 1/20, dL/L = 1/2 at L/b = 300 and 100 (data/narrow_limit: the FEM on 64 x 8
and 96 x 12 elements, read as a two-mesh study by validation.estimates.study_from_runs: the finer
value, the spread as error bar).

Rows, one per (model, resolution, scene): the rod at M = 50/100/200 and every other model of the
rod's family registered in ddg.api.DEFAULT_RESOLUTION at run time (the ribbons) at M = 51/101/201,
run here through ddg.api.run_candidate (the default path of docs/guide/run_a_scene.rst: 40
compression and 120 shear steps to dW_max, thresholds from stability, no branch tracing; nothing
written to disk); the plate at each
mesh of its study (data/plate_gold/<scene>/R*, data/narrow_limit/Lb*/plate_R*), the mid-edge plate
where data/midedge_gold has it and the FEM at each mesh of its study (data/fem_gold/<scene>/N*x*,
data/narrow_limit/Lb*/fem_N*), read, not rerun. Per row, for q in dW1/L, dW2/L: |q - reference|
(q_error), the reference's error bar (q_ref_error_bar) and their sum (q_bound); for H_mid/L, on
the reference curve's dW grid inside the run's range and more than THRESHOLD_BAND = 0.02 from the
reference's dW1 and dW2 and from the run's own (validation.claims; a small shift of a threshold is
a large H_mid difference there, and the thresholds' own errors are the dW1 and dW2 columns), the
largest |H_mid - reference| (H_mid_error), the largest reference error bar (H_mid_ref_error_bar)
and the largest pointwise sum (H_mid_bound, as validation.estimates.Study.mesh_error); the wall
time of the run (summary.json wall_time_s: path and thresholds) and a reason where a value is
missing. A bound is left empty where the run did not complete its path (its comparison would cover
part of the path only). ddg.advise reads the q_bound columns.

Resumable: a row is written to OUT/error_map.csv (atomically, the whole table) as soon as it is
computed; a rerun keeps a row whose model, resolution and scene match with the same source hash
(the ddg sources, validation.runs.code_version, for the runs made here; the run's summary.json for
the stored ones) and the same reference hash (the reference study's files), and recomputes any
other. Then OUT/README.md (the tables below it is computed from) and two figures (matplotlib,
extra `plot`): OUT/speed_accuracy.png and OUT/enough_map.png.

The runs made here are Dask tasks, as `python -m ddg sweep`'s (ddg.sweep.cluster): by default on a
LocalCluster of one single-threaded worker process per core (--workers N), with --scheduler on an
existing cluster (its workers need the same ddg sources: the rows carry the client's source hash).
Each worker returns its row, the client writes it to the table as the run ends; the stored runs'
rows are made by the client. A worker killed mid-run costs that run, which is retried (--retries);
--timeout is checked at each Newton solve. Ctrl-C keeps every row written (exit 130).

A failed run is not a measurement, so the map never holds one: a run that ends in an error (it
raised, or ran past --timeout: status "error"), or whose task failed, is reported on stderr with
its reason and not written; the table keeps what it had for that key (an older row, not current, so
the next run retries it), a row of status "error" read from an older table is dropped at the next
write (its run retried too), and the command exits 1 after the README and the figures. So neither a
bad --timeout nor a broken model can put failures into the committed map (the default --out,
data/error_map). Every option is checked before any folder is made or any run starts (exit 2, one
line): --only against the map's scenes, --models against the models the map has (the registry
ddg.api.DEFAULT_RESOLUTION and the FEM), --timeout in [1, MAX_TIMEOUT] s, the cluster options, and
a --scheduler connected to first.
"""
from __future__ import annotations

import csv
import hashlib
import json
import math
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ddg.advise import (NOT_RUN, QUANTITIES, RULE_V1_MARGIN, at_scene, basis_scenes, choose, compared_at,
                        cross_validated_margin, fitting, map_scenes, measured_error, parse_rows, scene_name)
from ddg.cli_parser import OneLineParser
from ddg.output.io import (StoredRun, atomic_write_text, finished_run_summary, finite_float, save_figure,
                          write_table_csv)
from ddg.solve.probe import Probe

from .claims import THRESHOLD_BAND
from .benchmark import fraction_label
from .estimates import (MIDEDGE_GOLD, PLATE_GOLD, Study, difference_away_from_thresholds, load_study,
                        study_from_runs)
from .reference import FEM_GOLD, ROOT, gold_name

try:   # the error map's reference scenes beyond the paper's ten (fem_reference.gold; no dolfinx needed)
    from fem_reference.gold import HELD_OUT_SCENES, MAP_SCENES, NEW_MAP_SCENES
    from fem_reference.gold import scene_name as fem_scene_name
except ImportError:   # an older fem_reference: the paper's ten and data/narrow_limit only
    MAP_SCENES, NEW_MAP_SCENES, HELD_OUT_SCENES, fem_scene_name = (), (), (), None
from .studies import COMPRESSIONS, WIDTHS_GOLD

NARROW = ROOT / "data" / "narrow_limit"
#: L/b of the narrow-strip folders with a FEM reference (data/narrow_limit/Lb<L/b>), W/L = 1/20, dL/L = 1/2.
NARROW_SLENDERNESS = (300.0, 100.0)
ROD_RESOLUTIONS = (50, 100, 200)
#: The ribbons' node counts: not multiples of 4 (ddg.models.ribbon: at M = 0 mod 4 the inflection
#: points fall on nodes).
RIBBON_RESOLUTIONS = (51, 101, 201)
PLATE_MODELS = ("plate", "plate-midedge")
CSV_NAME = "error_map.csv"
#: Seconds one run made here may take before it is stopped as failed (a model that stalls).
RUN_TIMEOUT = 120
#: Most seconds --timeout may give a run (a day: no run of the map's scenes needs a tenth of it).
MAX_TIMEOUT = 86400
#: The row status of a run that raised or ran out of time: never written to the table (module docstring).
FAILED = "error"
#: Tolerances of the README's tables and of the held-out check (units of L).
TOLERANCES = (0.01, 0.02, 0.05)
#: A reference curve that ends more than this short of dW_max/L gives no H_mid bound (units of L):
#: the recorded shear steps are dW_max/120 ~ 0.007 L apart, so a complete path ends within one.
REFERENCE_PATH_SLACK = 0.02
#: The held-out scenes in two sets. The first was checked with rule v1 of ddg.advise (no margin)
#: and failed there (45 of 56 on the map of then); rule v2 (the cross-validated margin) was then fixed on the fitting
#: scenes alone, and the second set's FEM references were computed after that, so that only the
#: second set is a check of rule v2 on scenes never seen while designing it.
HELD_OUT_FIRST = ("dL0.5_W0.125_Lb1181", "dL0.25_W0.125_Lb787", "dL0.5_W0.25_Lb1181")
HELD_OUT_SECOND = ("dL0.25_W0.25_Lb787", "dL0.5_W0.1_Lb1181", "dL0.25_W0.1_Lb787")

COLUMNS = ("scene", "role", "compression_ratio", "width_ratio", "slenderness", "width_squared_over_thickness_length",
           "model", "resolution", "resolution_label", "n_dof", "status",
           "dW1", "ref_dW1", "dW1_error", "dW1_ref_error_bar", "dW1_bound",
           "dW2", "ref_dW2", "dW2_error", "dW2_ref_error_bar", "dW2_bound",
           "H_mid_error", "H_mid_ref_error_bar", "H_mid_bound", "H_mid_points",
           "wall_time_s", "reason", "reference", "run_source", "source_hash", "reference_hash", "rules_version")
#: The version of the rules that turn a run and its reference into a row (row_errors: the
#: quantities, the excluded band, REFERENCE_PATH_SLACK, the reasons). A row of another version is
#: recomputed (`current`), so that a rule change reaches every row, not only the rows rerun for
#: another cause. Bump it with any change of those rules. 2: H_mid bounds left out where the
#: reference stops short (issue 17); rows without the column are from before it. 3: the H_mid
#: band left out about the run's own thresholds too, not only the reference's (issue 32).
RULES_VERSION = "3"


def _hash(*paths: Path) -> str:
    digest = hashlib.sha256()
    for p in paths:
        digest.update(Path(p).read_bytes())
    return digest.hexdigest()[:16]


#: Keys of a FEM study (richardson.json) the map does not read: left out of its reference hash, so
#: that adding them (the clamp force's curve, issue 18) leaves the map's rows current.
UNREAD_STUDY_KEYS = ("F_shear_curve", "F_shear_curve_away")


def _study_hash(path: Path) -> str:
    """_hash of a FEM study as written without UNREAD_STUDY_KEYS (the same bytes as a study
    written before those keys existed)."""
    study = json.loads(Path(path).read_text())
    text = json.dumps({k: v for k, v in study.items() if k not in UNREAD_STUDY_KEYS}, indent=2) + "\n"
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _relative(path: Path) -> str:
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
        """"held-out" for a scene of fem_reference.gold.HELD_OUT_SCENES (issue 32, named under
        ddg.advise's rule v3 before their references existed): never used by the prediction, only
        to check it; else "fit" (the held-out sets of rules v1 and v2, HELD_OUT_FIRST and
        HELD_OUT_SECOND, were checked then and fit from rule v3 on)."""
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
    """Every scene with a FEM reference in the repository (module docstring)."""
    out = []
    for c in COMPRESSIONS:
        for w in sorted(WIDTHS_GOLD):
            name = gold_name(c, w)
            study_file = FEM_GOLD / name / "richardson.json"
            study = load_study("fem", c, w)
            stored = _stored_plates("plate", PLATE_GOLD / name) + _stored_plates("plate-midedge", MIDEDGE_GOLD / name)
            stored += _stored_fem(FEM_GOLD / name)
            out.append(ReferenceScene(c, w, None, study, _relative(study_file),
                                      _study_hash(study_file) if study_file.exists() else "", stored))
    gold_map = {}
    for c, w, lb in MAP_SCENES + NEW_MAP_SCENES + HELD_OUT_SCENES:
        name = fem_scene_name(c, w, lb)
        study_file = FEM_GOLD / name / "richardson.json"
        study = load_study("fem", c, w, name=name) if study_file.exists() else None
        if study is None or len(study.meshes) < 2:   # one mesh: no error bar, no reference yet
            continue
        stored = _stored_plates("plate", PLATE_GOLD / name) + _stored_plates("plate-midedge", MIDEDGE_GOLD / name)
        stored += _stored_fem(FEM_GOLD / name)
        gold_map[(c, w, lb)] = ReferenceScene(c, w, lb, study, _relative(study_file),
                                              _study_hash(study_file), stored, name)
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
                                  " + ".join(_relative(p) for _, p in fem) + " (two-mesh study)",
                                  _hash(*ref_files) if fem else "", stored))
    return out


# ------------------------------------------------------------------------------------ errors
def _threshold_reason(summary: dict, key: str) -> str:
    unresolved = (summary.get("unresolved_thresholds") or {}).get(f"{key}_over_L")
    if unresolved:
        return f"{key} null: located at {unresolved.get('value'):.4f} but unresolved ({unresolved.get('reason')})"
    if summary.get("status") not in ("complete", None):
        return f"{key} null: the run {summary.get('status')} ({summary.get('message')})"
    if key == "dW1":
        return "dW1 null: not located (lambda_min of the U branch never changes sign on the path)"
    return "dW2 null: not located (the stable path never reaches S)"


def row_errors(reference: Study | None, summary: dict, rows: list[dict]) -> dict:
    """The error columns of one run against the reference study (module docstring)."""
    out: dict = {}
    reasons = []
    complete = summary.get("status") == "complete" and bool(summary.get("path_complete", True))
    for key in ("dW1", "dW2"):
        ours = summary.get(f"{key}_over_L")
        ref = reference.threshold(key) if reference is not None else None
        out[key] = ours
        out[f"ref_{key}"] = None if ref is None else ref.value
        out[f"{key}_ref_error_bar"] = None if ref is None else ref.error_bar
        if ours is None:
            reasons.append(_threshold_reason(summary, key))
        elif ref is None or ref.error_bar is None:
            reasons.append(f"{key}: the reference has no value with an error bar")
        else:
            out[f"{key}_error"] = abs(ours - ref.value)
            out[f"{key}_bound"] = out[f"{key}_error"] + ref.error_bar
    shear = [r for r in rows if r.get("stage") == "shear"]
    curve = reference.curve if reference is not None else None
    if curve is None:
        reasons.append("H_mid: the reference has no curve with error bars")
    elif len(shear) < 2:
        reasons.append("H_mid: the run has fewer than two shear states")
    else:
        dw = np.array([float(r["dW_over_L"]) for r in shear])
        h = np.array([float(r["H_mid_over_L"]) for r in shear])
        order = np.argsort(dw)
        dw, h = dw[order], h[order]
        # away from both curves' thresholds: the reference's and the run's own (rules version 3). Near
        # either, H_mid jumps (US -> S) or turns (U -> US), and a threshold error shows as an H_mid
        # error of order the jump; the thresholds are measured by their own quantities
        own = [summary.get(f"{k}_over_L") for k in ("dW1", "dW2")]
        keep, signed = difference_away_from_thresholds(curve, list(reference.thresholds()) + own, dw, h,
                                                       THRESHOLD_BAND)
        if not np.any(keep):
            reasons.append("H_mid: no reference point inside the run's range away from the thresholds")
        else:
            diff = np.abs(signed)
            bar = curve.error_bar[keep]
            out["H_mid_error"] = float(diff.max())
            out["H_mid_ref_error_bar"] = float(bar.max())
            out["H_mid_bound"] = float((diff + bar).max())
            out["H_mid_points"] = int(keep.sum())
            if dw[-1] < curve.dw[-1] - 1e-9:
                reasons.append(f"H_mid compared up to dW/L = {dw[-1]:.4f} only (the reference goes to "
                               f"{curve.dw[-1]:.4f})")
            limit = summary.get("dW_max_over_L")
            if limit is not None and curve.dw[-1] < float(limit) - REFERENCE_PATH_SLACK:
                # a bound over part of the path is another quantity than over all of it (it leaves out
                # US -> S, where the errors are largest): not one ddg.advise may compare or interpolate
                out.pop("H_mid_bound", None)
                reasons.append(f"H_mid: the reference stops at dW/L = {curve.dw[-1]:.4f} of dW_max/L = "
                               f"{float(limit):.4f} (its runs stopped), so no bound over the path")
    if not complete:
        reasons.append(f"run not complete ({summary.get('status')}: {summary.get('message')}): no bounds")
        for q in QUANTITIES:
            out.pop(f"{q}_bound", None)
    out["reason"] = "; ".join(reasons)
    return out


# ------------------------------------------------------------------------------------ the table
def read_table(path: Path) -> list[dict]:
    """The CSV's rows as strings (empty cells ''), [] if it does not exist."""
    if not Path(path).exists():
        return []
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def _key(row: dict) -> tuple:
    return row["model"], str(row["resolution_label"]), row["scene"]


def _cell(value):
    if value is None:
        return ""
    if isinstance(value, float):
        return "" if not math.isfinite(value) else repr(value)
    return value


class Table:
    """OUT/error_map.csv, rewritten atomically after every row (rows of other keys kept). Failed runs
    (status FAILED) are never written: put refuses them, and those of an older table are dropped."""

    def __init__(self, path: Path):
        self.path = Path(path)
        self.rows = [r for r in read_table(self.path) if r.get("status") != FAILED]

    def current(self, key: tuple, source_hash: str, reference_hash: str) -> bool:
        """A row of `key` made from this source, against this reference, under RULES_VERSION."""
        return any(_key(r) == key and r.get("source_hash") == source_hash and r.get("reference_hash") == reference_hash
                   and r.get("rules_version") == RULES_VERSION for r in self.rows)

    def set_role(self, scene: str, role: str) -> None:
        """The role column of a scene's rows (rows written before the column existed have none)."""
        if any(r["scene"] == scene and r.get("role") != role for r in self.rows):
            for r in self.rows:
                if r["scene"] == scene:
                    r["role"] = role
            write_table_csv(self.path, [{c: r.get(c, "") for c in COLUMNS} for r in self.rows], list(COLUMNS))

    def put(self, row: dict) -> bool:
        """Write `row` in place of the row of its key; False, and nothing written, for a failed run
        (status FAILED): the table keeps what it had for that key."""
        if row.get("status") == FAILED:
            return False
        row = {c: _cell(row.get(c)) for c in COLUMNS} | {"rules_version": RULES_VERSION}
        self.rows = [r for r in self.rows if _key(r) != _key(row)] + [row]
        write_table_csv(self.path, self.rows, list(COLUMNS))
        return True


def _base(scene: ReferenceScene, model: str, resolution: int, label: str) -> dict:
    s = scene.actual_slenderness
    return {"scene": scene.name, "role": scene.role, "compression_ratio": scene.compression_ratio,
            "width_ratio": scene.width_ratio, "slenderness": s,
            "width_squared_over_thickness_length": scene.width_ratio**2 * s, "model": model,
            "resolution": resolution, "resolution_label": label, "reference": scene.reference_source,
            "reference_hash": scene.reference_hash}


def _with_summary(row: dict, scene: ReferenceScene, summary: dict, path_rows: list[dict]) -> dict:
    row.update(row_errors(scene.reference, summary, path_rows))
    row.update(n_dof=summary.get("n_dof"), status=summary.get("status"), wall_time_s=summary.get("wall_time_s"))
    return row


def rod_family() -> list[tuple[str, tuple[int, ...]]]:
    """(model, node counts) of the rod's family registered in ddg.api.DEFAULT_RESOLUTION now."""
    from ddg.api import DEFAULT_RESOLUTION

    return [(m, ROD_RESOLUTIONS if m == "rod" else RIBBON_RESOLUTIONS) for m in DEFAULT_RESOLUTION
            if m not in PLATE_MODELS]


class _Timeout(Exception):
    pass


class _Deadline(Probe):
    """A run's time limit, checked at each Newton solve and recorded step (in any thread: a Dask
    worker runs its tasks outside the main thread, where SIGALRM cannot be used)."""

    def __init__(self, seconds: float):
        self.seconds, self.end = seconds, time.monotonic() + seconds

    def solve(self, phase: str, iterations: int, converged: bool) -> None:
        self._check()

    def step(self, stage: str, row: dict, wall_s: float) -> None:
        self._check()

    def _check(self) -> None:
        if time.monotonic() > self.end:
            raise _Timeout(f"the run took more than {self.seconds:g} s")


def run_row(scene: ReferenceScene, model: str, resolution: int, timeout: int = RUN_TIMEOUT) -> dict:
    """One run made here or in a Dask worker (ddg.api.run_candidate, nothing written) and its row;
    stopped after `timeout` s (0: no limit)."""
    import ddg
    from ddg.api import run_candidate

    strip = ddg.Strip.from_ratios(scene.width_ratio, scene.compression_ratio, scene.slenderness)
    row = _base(scene, model, resolution, f"M{resolution}")
    row["run_source"] = "ddg.api.run_candidate"
    t0 = time.perf_counter()
    try:
        result = run_candidate(strip, ddg.LoadingProtocol(scene.compression_ratio), model, resolution,
                               probe=_Deadline(timeout) if timeout else None)
    except Exception as exc:  # noqa: BLE001  (a failing model, or one out of time, is a row with its reason)
        result = getattr(exc, "result", None)
        if result is None:
            row.update(status="error", wall_time_s=time.perf_counter() - t0,
                       reason=f"run failed: {type(exc).__name__}: {' '.join(str(exc).split())[:200]}")
            return row
    return _with_summary(row, scene, result.summary, result.rows)


def stored_row(scene: ReferenceScene, mesh: StoredMesh) -> dict:
    """A stored study's run and its row."""
    run = StoredRun(mesh.folder)
    row = _base(scene, mesh.model, mesh.resolution, mesh.label)
    row["run_source"] = _relative(mesh.folder)
    return _with_summary(row, scene, run.summary, run.rows)


def build(out: Path, only=None, models=None, quiet: bool = False, timeout: int = RUN_TIMEOUT, *,
          scheduler: str | None = None, workers: int | None = None, retries: int = 2,
          failures: list | None = None) -> list[dict]:
    """Every row (module docstring) into OUT/error_map.csv, skipping current ones; the table's rows.
    The stored runs' rows are made here; the runs made here are Dask tasks (run_row on a worker,
    ddg.sweep.cluster.run_all: `scheduler`, else a LocalCluster of `workers` processes), each row
    written as its run ends. A failed run is not written: one line on stderr, and its
    "scene model label: reason" appended to `failures`. Ctrl-C: the rows written are kept, the
    interrupt is raised with a `run_message`."""
    from ddg.output.interrupts import signal_name_of
    from ddg.sweep.cluster import Task, run_all

    from .runs import code_version

    table = Table(Path(out) / CSV_NAME)
    code = code_version()

    def failed(what: str, why: str) -> None:
        print(f"error: {what}: {why}; not written to the map (a rerun retries it)", file=sys.stderr, flush=True)
        if failures is not None:
            failures.append(f"{what}: {why}")

    family = rod_family()
    tasks = []
    for scene in reference_scenes():
        if only and scene.name not in only and (scene.folder_name or gold_name(scene.compression_ratio,
                                                                               scene.width_ratio)) not in only:
            continue
        if scene.reference is None:
            print(f"{scene.name}: no FEM reference study, skipped", file=sys.stderr, flush=True)
            continue
        table.set_role(scene.name, scene.role)
        for mesh in scene.stored:
            if models and mesh.model not in models:
                continue
            source = _hash(mesh.folder / "summary.json")
            if table.current((mesh.model, mesh.label, scene.name), source, scene.reference_hash):
                continue
            row = stored_row(scene, mesh)
            row["source_hash"] = source
            if not table.put(row):
                failed(f"{scene.name} {mesh.model} {mesh.label}", row.get("reason") or "the run failed")
        for model, resolutions in family:
            if models and model not in models:
                continue
            for m in resolutions:
                if not table.current((model, f"M{m}", scene.name), code, scene.reference_hash):
                    tasks.append(Task(f"error-map-{scene.name}-{model}-M{m}-{scene.reference_hash}-{code}", run_row,
                                      (scene, model, m, timeout), m))

    def finished(task, row, error):
        scene, model, m, _ = task.args
        if error is not None:  # the task itself failed (its worker died at every attempt): no row, rerun next time
            failed(f"{scene.name} {model} M{m}", error)
            return
        row["source_hash"] = code
        if not table.put(row):   # the run raised or ran out of time: not a measurement
            failed(f"{scene.name} {model} M{m}", row.get("reason") or "the run failed")
            return
        if not quiet:
            print(f"{scene.name} {model} M{m}: {row.get('status')}, {row.get('wall_time_s') or 0:.1f} s, "
                  f"dW1 err {row.get('dW1_error')}, dW2 err {row.get('dW2_error')}, H_mid err "
                  f"{row.get('H_mid_error')} {row.get('reason') or ''}", file=sys.stderr, flush=True)

    ran = run_all(tasks, finished, scheduler=scheduler, workers=workers, retries=retries, code=code)
    if ran.interrupted is not None:
        done = sum(table.current((t.args[1], f"M{t.args[2]}", t.args[0].name), code, t.args[0].reference_hash)
                   for t in tasks)
        ran.interrupted.run_message = (f"interrupted by {signal_name_of(ran.interrupted)}: {done} of {len(tasks)} "
                                       f"runs finished and written to {table.path}; a rerun computes only the "
                                       f"other {len(tasks) - done}")
        raise ran.interrupted
    return table.rows


# ------------------------------------------------------------------------------------ analysis
_f = finite_float


def within(row: dict, tolerance: float, quantities=QUANTITIES) -> bool:
    """The row's error plus reference error bar is at most `tolerance` on every quantity."""
    return all(_f(row.get(f"{q}_bound")) is not None and _f(row[f"{q}_bound"]) <= tolerance for q in quantities)


def cheapest_within(rows: list[dict], tolerance: float, quantities=QUANTITIES, runnable_only: bool = False):
    """The row of least wall time within `tolerance` on `quantities` (None if none is)."""
    ok = [r for r in rows if within(r, tolerance, quantities) and _f(r.get("wall_time_s")) is not None
          and not (runnable_only and r["model"] == "fem")]
    return min(ok, key=lambda r: _f(r["wall_time_s"]), default=None)


def combined_error(row: dict) -> float | None:
    """The largest error + reference error bar over the three quantities (None if one is missing)."""
    values = [_f(row.get(f"{q}_bound")) for q in QUANTITIES]
    return None if any(v is None for v in values) else max(values)


def held_out_check(rows: list[dict], tolerance: float = 0.01, quantities=QUANTITIES, rule: str = "v3") -> list[dict]:
    """Check of ddg.advise's prediction on scenes it did not use: each held-out scene (role
    "held-out": never in the fitting set) and, leave-one-out, each fitting scene S with S removed
    from the fitting set. If the fitting scenes bracket it, every candidate predicted there (the
    plates at the rows measured at S too) is compared on each of `quantities` with its measured error
    |q - reference| at S (ddg.advise.measured_error; it holds where measured <= predicted), and
    advise's choice at
    `tolerance` is recorded: its verdict, predicted error and cost, and, where S has a row of it, its
    measured error and wall time. One dict per scene; scenes not bracketed without themselves say
    so. `rule` "v3": the cross-validated margin measured on the fitting scenes that remain (for a
    fitting scene S, nested: without S); "v1": margin 1."""
    parsed = load_rows(rows)
    fit = fitting(parsed)
    runnable = {r["model"] for r in parsed if r["model"] not in NOT_RUN}
    out = []
    for scene in map_scenes(parsed):
        same = [r for r in parsed if at_scene(r, scene)]
        role = "held-out" if same and same[0].get("role") == "held-out" else "fit"
        reduced = [r for r in fit if not at_scene(r, scene)]
        basis, why = basis_scenes(reduced, scene)
        entry = {"scene": scene.name, "role": role, "held_out": bool(basis), "why": why,
                 "basis": [s.name for s in basis], "compared": 0, "held": 0, "violations": [], "choice": None,
                 "choice_within": None, "choice_predicted": None, "choice_predicted_wall": None,
                 "choice_measured": None, "choice_measured_wall": None, "choice_holds": None}
        if not basis:
            out.append(entry)
            continue
        margin = RULE_V1_MARGIN if rule == "v1" else cross_validated_margin(reduced, runnable)
        entry["margin"] = margin.value
        for p, q, predicted, measured in compared_at(reduced + same, scene, basis, runnable, margin.value,
                                                     quantities):
            entry["compared"] += 1
            if measured <= predicted + 1e-12:
                entry["held"] += 1
            else:
                entry["violations"].append(f"{p.model} {p.label} {q}: measured {measured:.4f} > predicted "
                                           f"{predicted:.4f}")
        choice = choose(scene.width_ratio, scene.compression_ratio, scene.slenderness, tolerance, quantities,
                        rows=reduced, runnable=runnable, margin=margin)
        judged = [q for q in quantities if q not in choice.unknown]
        entry.update(choice=f"{choice.model} {choice.label}", choice_within=choice.within,
                     choice_predicted=choice.worst(), choice_predicted_wall=choice.wall_time_s,
                     choice_unknown=sorted(choice.unknown))
        mine = [r for r in same if r["model"] == choice.model and r["resolution_label"] == choice.label]
        if mine:
            entry["choice_measured_wall"] = mine[-1].get("wall_time_s")
            measured = [measured_error(mine[-1], q) for q in judged]
            if judged and None not in measured:
                entry["choice_measured"] = max(measured)
                entry["choice_holds"] = bool(max(measured) <= tolerance) if choice.within else None
        out.append(entry)
    return out


def held_out_targets(entries: list[dict], tolerance: float) -> dict:
    """Issue 32's targets on the held-out scenes of one tolerance's held_out_check: scenes inside
    the map, those with a choice predicted within the tolerance, the median wall time of those
    choices (measured where the scene has the chosen run, else predicted), and the (candidate,
    quantity) predictions that hold."""
    inside = [e for e in entries if e["role"] == "held-out" and e["held_out"]]
    within = [e for e in inside if e["choice_within"]]
    walls = sorted(e["choice_measured_wall"] if e["choice_measured_wall"] is not None else e["choice_predicted_wall"]
                   for e in within if (e["choice_measured_wall"] or e["choice_predicted_wall"]) is not None)
    median = None if not walls else (walls[len(walls) // 2] if len(walls) % 2 else
                                     0.5 * (walls[len(walls) // 2 - 1] + walls[len(walls) // 2]))
    return {"tolerance": tolerance, "held_out": sum(e["role"] == "held-out" for e in entries),
            "inside": len(inside), "within": len(within), "median_wall_s": median,
            "held": sum(e["held"] for e in inside), "compared": sum(e["compared"] for e in inside),
            "choices_measured": sum(e["choice_holds"] is not None for e in within),
            "choices_holding": sum(bool(e["choice_holds"]) for e in within)}


def load_rows(rows: list[dict]) -> list[dict]:
    """Rows of the CSV (strings) parsed as ddg.advise.load_map parses the file."""
    return parse_rows(rows)


# ------------------------------------------------------------------------------------ README, figures
def _num(value, spec="{:.4f}") -> str:
    v = _f(value)
    return "–" if v is None else spec.format(v)


def _scene_order(rows):
    names = []
    for r in rows:
        if r["scene"] not in names:
            names.append(r["scene"])
    first = {n: next(r for r in rows if r["scene"] == n) for n in names}
    return sorted(names, key=lambda n: (-float(first[n]["compression_ratio"]), float(first[n]["width_ratio"]),
                                        -float(first[n]["slenderness"]))), first


def _choice_cell(row) -> str:
    if row is None:
        return "none"
    errs = "/".join(_num(row.get(f"{q}_bound"), "{:.4f}") for q in QUANTITIES)
    return f"{row['model']} {row['resolution_label']} ({_num(row['wall_time_s'], '{:.3g}')} s; {errs})"


def readme(rows: list[dict], held: dict, figures: list[str], missing: list[str]) -> str:
    """OUT/README.md: the command, the scenes, per scene the cheapest model within each
    tolerance on dW1 and on all three quantities, the held-out check; every number from the rows."""
    names, first = _scene_order(rows)
    lines = ["# Error map: every model against the converged FEM reference (issue 17 item 3)", "",
             "Generated by `.venv/bin/python -m validation.error_map --out data/error_map` (validation/error_map.py; "
             "its docstring defines every column). error_map.csv has one row per (model, resolution, scene): for "
             "dW1/L, dW2/L and H_mid/L the error against the FEM study's extrapolated value, the reference's error "
             "bar and their sum (`*_bound`, what `python -m ddg advise` reads), the wall time and a reason where a "
             "value is missing. H_mid is compared 0.02 L away from the reference's thresholds and from the run's "
             "own (rules version 3).", "",
             f"{len(rows)} rows on {len(names)} scenes. Models: "
             + ", ".join(f"{m} ({sum(r['model'] == m for r in rows)} rows)"
                         for m in dict.fromkeys(r["model"] for r in rows)) + ".", ""]
    for tol in TOLERANCES[:1]:
        lines += [f"## Cheapest model within {tol:g} L (error + reference error bar), per scene", "",
                  "Measured on the scene itself. A cell gives the model, its resolution, its wall time and its "
                  "dW1/dW2/H_mid bounds. `runnable` leaves out the FEM (ddg does not run it). A dash is a missing "
                  "value; its reason is in the CSV.", "",
                  "| dL/L | W/L | L/b | W²/(bL) | on dW1 (runnable) | on all three (runnable) | on all three (any, FEM "
                  "included) |", "|---:|---:|---:|---:|---|---|---|"]
        for n in names:
            mine = [r for r in rows if r["scene"] == n]
            f = first[n]
            lines.append(f"| {fraction_label(f['compression_ratio'])} | {fraction_label(f['width_ratio'])} | "
                         f"{float(f['slenderness']):.0f} | {float(f['width_squared_over_thickness_length']):.2f} | "
                         f"{_choice_cell(cheapest_within(mine, tol, ('dW1',), True))} | "
                         f"{_choice_cell(cheapest_within(mine, tol, QUANTITIES, True))} | "
                         f"{_choice_cell(cheapest_within(mine, tol, QUANTITIES, False))} |")
        lines.append("")
    lines += ["## Per model and resolution: the largest bound over the scenes where it has a value", "",
              "| model | resolution | scenes | max dW1 bound | max dW2 bound | max H_mid bound | rows with a "
              "missing value |", "|---|---|---:|---:|---:|---:|---:|"]
    for model in dict.fromkeys(r["model"] for r in rows):
        for label in dict.fromkeys(r["resolution_label"] for r in rows if r["model"] == model):
            mine = [r for r in rows if r["model"] == model and r["resolution_label"] == label]
            cells = []
            for q in QUANTITIES:
                values = [_f(r.get(f"{q}_bound")) for r in mine if _f(r.get(f"{q}_bound")) is not None]
                cells.append(_num(max(values)) if values else "–")
            missing_rows = sum(combined_error(r) is None for r in mine)
            lines.append(f"| {model} | {label} | {len(mine)} | {' | '.join(cells)} | {missing_rows} |")
    lines += ["", "## Held-out check of the prediction (ddg.advise)", ""]
    lines += held_out_section(rows, held)
    lines += ["## What is missing", ""] + [f"- {m}" for m in missing] + [""]
    if figures:
        lines += ["## Figures", ""] + [f"![{f}]({f})" for f in figures] + [""]
    return "\n".join(lines)


def held_out_section(rows: list[dict], held: dict) -> list[str]:
    """The README's held-out check under rule v3: the rule, issue 32's targets on the held-out
    scenes per tolerance, leave-one-out on the fitting set, a table per scene; `held` is
    {tolerance: held_out_check(rows, tolerance)}."""
    first = held[min(held)]
    margin = cross_validated_margin(parse_rows(rows), {r["model"] for r in rows if r["model"] not in NOT_RUN})
    lines = ["Rule v3 (ddg/advise.py, its docstring): a candidate's predicted error on each quantity is the largest "
             "error + reference error bar over the map scenes at the corners of the box about the scene (dL/L, W/L, "
             "and L/b relative to the paper's at that dL/L), the plates keyed by element size (the larger bound of "
             "the two measured meshes bracketing it), times the cross-validated margin: the largest ratio "
             "measured/predicted under leave-one-out on the fitting scenes (held-out scenes never enter it). On "
             f"this map: {margin.text()}.", "",
             "Held-out scenes (fem_reference.gold.HELD_OUT_SCENES): named and committed with rule v3 before their "
             "references were computed. Issue 32's targets, at tolerances 0.01 and 0.02: a model predicted within "
             "the tolerance at >= 80 % of scenes, its median wall time <= 30 s, measured <= predicted in >= 95 % of "
             "(scene, candidate, quantity) predictions.", "",
             "| tolerance | held-out scenes | inside the map | a choice predicted within | median wall of those "
             "(s) | predictions that hold | chosen runs measured within |", "|---:|---:|---:|---:|---:|---:|---:|"]
    for tol, entries in held.items():
        t = held_out_targets(entries, tol)
        share = "–" if not t["inside"] else f"{100 * t['within'] / t['inside']:.0f} %"
        holds = ("–" if not t["compared"] else
                 f"{t['held']} of {t['compared']} ({100 * t['held'] / t['compared']:.1f} %)")
        lines.append(f"| {tol:g} | {t['held_out']} | {t['inside']} | {t['within']} ({share}) | "
                     f"{_num(t['median_wall_s'], '{:.3g}')} | {holds} | {t['choices_holding']} of "
                     f"{t['choices_measured']} |")
    fit = [e for e in first if e["role"] == "fit"]
    inside = [e for e in fit if e["held_out"]]
    lines += ["", f"Leave-one-out on the fitting set: each fitting scene is removed in turn and predicted from the "
              f"others, its margin measured without it (nested); {len(inside)} of {len(fit)} are bracketed by the "
              f"others (the rest lie at an edge of the map). {sum(e['held'] for e in inside)} of "
              f"{sum(e['compared'] for e in inside)} predictions hold.", "",
              "Earlier rules, on their own held-out sets (now fitting scenes): rule v1 (no margin) held on 54 of 72 "
              "and 66 of 72 predictions of its two sets, rule v2 (the margin) on 72 of 72 and 72 of 72; both fell "
              "back to a plate mesh pair at 37 of 60 map (scene, tolerance) cases (issue 32).", "",
              "| scene | role | basis | margin | held | " + " | ".join(f"choice at {t:g}: predicted (measured)"
                                                                    for t in held) + " |",
              "|---|---|---|---:|---:|" + "---|" * len(held)]
    by_scene = {tol: {e["scene"]: e for e in es} for tol, es in held.items()}
    shown = sorted([e for e in first if e["held_out"]], key=lambda e: e["role"] != "held-out")
    for e in shown:
        cells = []
        for tol in held:
            c = by_scene[tol][e["scene"]]
            verdict = "within" if c["choice_within"] else "NOT within"
            unknown = f", {'/'.join(c['choice_unknown'])} unknown" if c.get("choice_unknown") else ""
            cells.append(f"{c['choice']} {verdict}: {_num(c['choice_predicted'])} "
                         f"({_num(c['choice_measured'])}){unknown}")
        lines.append(f"| {e['scene']} | {e['role']} | {', '.join(e['basis'])} | {e['margin']:.3f} | "
                     f"{e['held']}/{e['compared']} | {' | '.join(cells)} |")
    failing = [f"{e['scene']}: {v}" for e in shown for v in e["violations"]]
    if failing:
        lines += ["", f"Predictions that do not hold ({len(failing)}): " + "; ".join(failing[:40])
                  + (" ..." if len(failing) > 40 else "")]
    lines.append("")
    return lines


def _paper(row: dict) -> bool:
    """The row is on the paper's strip (b = 0.127 mm: L/b 1181 at dL/L = 1/2, 787 at 1/4)."""
    import ddg

    default = ddg.Strip.from_ratios(float(row["width_ratio"]), float(row["compression_ratio"])).slenderness
    return abs(float(row["slenderness"]) - default) < 1e-6 * default


FAMILY_MARKERS = {"rod": "o", "plate": "^", "plate-midedge": "v", "fem": "D"}


def _marker(model: str) -> str:
    return FAMILY_MARKERS.get(model, "s")   # the ribbons: squares


def figures(rows: list[dict], out: Path, tolerance: float = 0.01) -> list[str]:
    """OUT/speed_accuracy.png (per width: wall time against the combined error, `tolerance`
    dashed) and OUT/enough_map.png (per dL/L and per tolerance of TOLERANCES, the cheapest model
    within it on all three quantities at each map scene over W/L and L/b, held-out scenes open);
    [] with one line naming the extra if matplotlib is missing."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("figures skipped: matplotlib is missing (pip install 'ddg-strips[plot]')", file=sys.stderr)
        return []
    widths = sorted({round(float(r["width_ratio"]), 6) for r in rows})
    models = list(dict.fromkeys(r["model"] for r in rows))
    colours = {m: f"C{k}" for k, m in enumerate(models)}
    fig, axes = plt.subplots(1, len(widths), figsize=(3.0 * len(widths), 3.2), sharey=True, squeeze=False)
    for ax, w in zip(axes[0], widths):
        for r in rows:
            if abs(float(r["width_ratio"]) - w) > 1e-6 or _f(r.get("wall_time_s")) is None or not _paper(r):
                continue
            e = combined_error(r)
            filled = float(r["compression_ratio"]) > 0.4
            ax.scatter(_f(r["wall_time_s"]), e if e is not None else 1.0, marker=_marker(r["model"]), s=18,
                       facecolors=colours[r["model"]] if filled else "none", edgecolors=colours[r["model"]],
                       alpha=0.85 if e is not None else 0.3)
        ax.axhline(tolerance, color="0.5", lw=0.6, ls="--")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_title(f"W/L = {fraction_label(w)}", fontsize=9)
        ax.set_xlabel("wall time (s)", fontsize=8)
        ax.tick_params(labelsize=7)
    axes[0, 0].set_ylabel("max over dW1, dW2, H_mid of\nerror + reference error bar (/L)", fontsize=8)
    handles = [plt.Line2D([], [], ls="", marker=_marker(m), color=colours[m], label=m) for m in models]
    fig.legend(handles=handles, loc="upper center", ncol=len(models), fontsize=7, frameon=False)
    fig.text(0.01, 0.01, "the paper's L/b only; filled: dL/L = 1/2, open: smaller; faint at 1: a quantity missing; "
             f"dashed: {tolerance:g}", fontsize=6)
    fig.tight_layout(rect=(0, 0.03, 1, 0.9))
    save_figure(fig, out / "speed_accuracy.png", dpi=90)
    plt.close(fig)

    names, first = _scene_order(rows)
    compressions = sorted({float(r["compression_ratio"]) for r in rows}, reverse=True)
    fig, axes = plt.subplots(len(compressions), len(TOLERANCES), figsize=(4.2 * len(TOLERANCES),
                                                                          3.2 * len(compressions)), squeeze=False)
    for i, c in enumerate(compressions):
        for j, tol in enumerate(TOLERANCES):
            ax = axes[i, j]
            for n in names:
                f = first[n]
                if abs(float(f["compression_ratio"]) - c) > 1e-9:
                    continue
                mine = [r for r in rows if r["scene"] == n]   # a DDG model if one is enough, else the FEM
                best = cheapest_within(mine, tol, QUANTITIES, runnable_only=True) or cheapest_within(mine, tol)
                x, y = float(f["width_ratio"]), float(f["slenderness"])
                label = "none" if best is None else f"{best['model']}\n{best['resolution_label']}"
                colour = "0.6" if best is None else colours[best["model"]]
                marker = "x" if best is None else _marker(best["model"])
                ax.scatter(x, y, marker=marker, color=colour, s=40,
                           facecolors="none" if f.get("role") == "held-out" else colour)
                ax.annotate(label, (x, y), textcoords="offset points", xytext=(4, 4), fontsize=6)
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_xlabel("W/L", fontsize=8)
            ax.set_ylabel("L/b", fontsize=8)
            ax.set_title(f"dL/L = {fraction_label(c)}: cheapest DDG model (else FEM mesh)\nwithin {tol:g} on dW1, "
                         "dW2 and H_mid (measured there)", fontsize=7)
            ax.tick_params(labelsize=7)
    fig.tight_layout()
    save_figure(fig, out / "enough_map.png", dpi=90)
    plt.close(fig)
    return ["speed_accuracy.png", "enough_map.png"]


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


def main(argv=None) -> int:
    from ddg.geometry.strip import InputError
    from ddg.limits import check_integer
    from ddg.output.interrupts import exit_code_of, terminate_as_interrupt
    from ddg.output.io import check_output_directory
    from ddg.solve.blas_threads import requested_threads
    from ddg.sweep import cluster

    parser = OneLineParser(prog="python -m validation.error_map", description=__doc__.split("\n")[0])
    parser.add_argument("--out", default="data/error_map", help="output directory (default data/error_map)")
    parser.add_argument("--only", nargs="+", default=None,
                        help="scenes to (re)compute, e.g. dL0.5_W0.05 or dL0.5_W0.05_Lb300 (default all)")
    parser.add_argument("--models", nargs="+", default=None, help="models to (re)compute (default all)")
    parser.add_argument("--timeout", type=int, default=RUN_TIMEOUT,
                        help=f"seconds per run made here, 1..{MAX_TIMEOUT} (default {RUN_TIMEOUT}); a run past it "
                             "fails and is not written")
    parser.add_argument("--report-only", action="store_true", help="no runs: README and figures from the CSV")
    cluster.add_options(parser)  # --workers, --scheduler, --retries: the runs are Dask tasks, as the sweep's
    args = parser.parse_args(argv)
    terminate_as_interrupt()  # SIGTERM too keeps the rows written
    scenes = reference_scenes()
    try:   # every option before any folder or run (module docstring); the scheduler connected to last
        check_selection(args.only, args.models, scenes)
        check_integer("--timeout", args.timeout, 1, MAX_TIMEOUT, "seconds one run made here may take")
        scheduler, workers, retries = cluster.checked_options(args.scheduler, args.workers, args.retries)
        if not args.report_only:
            requested_threads()   # a bad DDG_BLAS_THREADS would fail every run on its worker
            scheduler = cluster.ready(scheduler, workers)
        out = check_output_directory(args.out, "--out")
    except InputError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    failures: list[str] = []
    try:
        rows = read_table(out / CSV_NAME) if args.report_only else build(
            out, args.only, args.models, timeout=args.timeout, scheduler=scheduler, workers=workers, retries=retries,
            failures=failures)
    except InputError as exc:  # the scheduler at --scheduler went away after it was checked
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as exc:
        print(f"error: {getattr(exc, 'run_message', 'interrupted')}", file=sys.stderr)
        return exit_code_of(exc)
    if not rows:
        print("error: the map has no rows" + (f" ({len(failures)} runs failed)" if failures else ""), file=sys.stderr)
        return 1 if failures else 3
    held = {tol: held_out_check(rows, tol) for tol in TOLERANCES}
    names = figures(rows, out)
    atomic_write_text(out / "README.md", readme(rows, held, names, missing_scenes(scenes)))
    print(f"wrote {out / CSV_NAME} ({len(rows)} rows), {out / 'README.md'}"
          + "".join(f", {out / n}" for n in names))
    if failures:
        print(f"error: {len(failures)} run(s) failed and are not in the map (first: {failures[0]}); a rerun "
              "retries them", file=sys.stderr)
        return 1
    return 0


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


if __name__ == "__main__":
    raise SystemExit(main())
