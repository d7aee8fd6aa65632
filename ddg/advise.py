"""Which model is enough for a scene: the error map read back, a conservative prediction of each
model's error on a scene, and the cheapest model and resolution predicted within a tolerance
(issue 17 item 4: `python -m ddg advise`, `ddg.simulate(..., model="auto", tolerance=...)`).

The error map (data/error_map/error_map.csv, written by `python -m validation.error_map`) has one
row per (model, resolution, scene): for each quantity q of dW1/L, dW2/L and H_mid/L its error
against the converged FEM reference of that scene and the reference's own error bar, and their sum
`q_bound` (for H_mid the largest pointwise sum over the shear path, 0.02 L away from the
reference's thresholds), with the run's wall time. Rows of held-out scenes (column role =
"held-out") are never used to predict: they exist to check the prediction.

Prediction rule (conservative, never an extrapolation). A scene is (dL/L, W/L, L/b). Its basis is
the map scenes of the same dL/L that bracket it: in W/L the nearest map width at or below it and
the nearest at or above it (one width where it equals a map width); at each of those widths, in
L/b the nearest map L/b at or below and at or above (one where it equals one, to 0.1 %). A scene
whose dL/L is not in the map, or whose W/L or L/b lies outside the map's range at a bracketing
width, has no basis: it is outside the map. The predicted error of a candidate on quantity q is the
largest q_bound over the basis scenes (error plus reference error bar: the worst of the bracketing
scenes), times the map's cross-validated margin (below); a candidate missing at one basis scene, or whose
q is missing there (e.g. dW2 null), has no prediction for q and is not chosen. Its predicted cost
is its largest wall time over the basis scenes. The choice is the candidate of least predicted
cost whose predicted errors on the requested quantities are all at most the tolerance.

Cross-validated margin (rule v2). Errors are not monotone in W/L: the plate on 8 rows is worse at
W/L = 1/8 than at 1/12 and at 1/6, so the largest bound of the bracketing scenes (rule v1, margin 1)
can understate an interior scene's error. The margin is measured on the fitting scenes alone,
leave-one-out: each fitting scene bracketed by the others is predicted from them by rule v1, and the
margin is the largest ratio measured bound / predicted bound over every (candidate, quantity) there,
and at least 1 (cross_validated_margin). It is recomputed from whatever map is read, never from the
held-out scenes; it was introduced after rule v1 had been checked on the first three held-out scenes
(data/error_map/README.md gives both rules' figures on every held-out scene). On a scene of the map
itself (one basis scene: nothing interpolated) the bound measured there is the prediction, margin 1.

Safe choice: outside the map, or when no candidate is predicted within the tolerance, the paper's
plate (Eq. 11) on a convergence pair, two exactly equilateral meshes refined by 1.5 (12 and 18
rows of triangles across W for W/L <= 1/4, 24 and 36 above: the finer two meshes of the plate
studies in data/plate_gold), whose difference measures the discretisation error of the finer one;
the reason says which of the two cases it is. The FEM rows of the map are information only: the
shell is not run by ddg.
"""
from __future__ import annotations

import csv
import math
import os
from dataclasses import asdict, dataclass, field
from pathlib import Path

from .geometry.strip import InputError, Strip

ROOT = Path(__file__).resolve().parent.parent
#: The committed error map (python -m validation.error_map --out data/error_map).
DEFAULT_MAP = ROOT / "data" / "error_map" / "error_map.csv"
#: Environment variable naming another error map file (tests, other machines).
MAP_ENV = "DDG_ERROR_MAP"
#: The quantities of the map, in its column prefixes.
QUANTITIES = ("dW1", "dW2", "H_mid")
#: Tolerances accepted, in units of L: positive and at most 1 (a dW/L or H_mid/L error of L is
#: no statement).
TOLERANCE_RANGE = (0.0, 1.0)
#: Relative difference under which two W/L or L/b values are the same scene.
SAME = 1e-3
#: Models the map holds that ddg does not run (information only).
NOT_RUN = ("fem",)
#: Plate of the safe choice: rows of triangles across W on the coarsest mesh of the plate studies
#: (validation/plate_gold.py BASE_ROWS), by W/L; the pair is 1.5 and 2.25 times it.
SAFE_MODEL = "plate"
SAFE_BASE_ROWS = ((0.25, 8), (1.0, 16))
REFINEMENT = 1.5


# ------------------------------------------------------------------------------------ input checks
def check_tolerance(value) -> float:
    """The tolerance as a float in (0, 1] (units of L); InputError naming the value otherwise."""
    low, high = TOLERANCE_RANGE
    if isinstance(value, bool) or value is None:
        raise InputError(f"tolerance = {value!r} is not a number; allowed ({low:g}, {high:g}] (units of L)")
    try:
        number = float(value)
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"tolerance = {value!r} is not a number; allowed ({low:g}, {high:g}] (units of L)") from None
    if not (math.isfinite(number) and low < number <= high):
        raise InputError(f"tolerance = {value!r} outside the allowed range ({low:g}, {high:g}] (units of L)")
    return number


def check_quantities(value) -> tuple[str, ...]:
    """The quantities asked for: a comma-separated string or a sequence of names of QUANTITIES
    (default all three); InputError naming an unknown one."""
    if value is None:
        return QUANTITIES
    items = [v.strip() for v in value.split(",")] if isinstance(value, str) else list(value)
    if not items or any(not isinstance(v, str) for v in items):
        raise InputError(f"quantities = {value!r} must name some of {', '.join(QUANTITIES)}")
    for v in items:
        if v not in QUANTITIES:
            raise InputError(f"quantity {v!r} is not in the error map; allowed {', '.join(QUANTITIES)}")
    return tuple(dict.fromkeys(items))


def map_file(path=None) -> tuple[Path, bool]:
    """(the error map's path, whether it was named explicitly): `path`, else $DDG_ERROR_MAP, else
    DEFAULT_MAP. A named file that does not exist is an InputError; the default one may be missing
    (then every scene is outside the map)."""
    named = path if path is not None else os.environ.get(MAP_ENV) or None
    if named is None:
        return DEFAULT_MAP, False
    if not isinstance(named, (str, os.PathLike)) or isinstance(named, bool):
        raise InputError(f"error map = {named!r} must be a file path")
    p = Path(named)
    if not p.is_file():
        raise InputError(f"error map {str(p)!r} is not a readable file (the CSV of python -m validation.error_map)")
    return p, True


# ------------------------------------------------------------------------------------ the map
def _number(text):
    if text is None or text == "":
        return None
    try:
        value = float(text)
    except ValueError:
        return text
    return value if math.isfinite(value) else None


NUMERIC = ("compression_ratio", "width_ratio", "slenderness", "resolution", "wall_time_s",
           *(f"{q}_{k}" for q in QUANTITIES for k in ("error", "ref_error_bar", "bound")))


def load_map(path) -> list[dict]:
    """The rows of an error map CSV, numeric columns parsed (None where empty); [] if the file
    is missing; InputError if it lacks the columns the prediction reads."""
    path = Path(path)
    if not path.is_file():
        return []
    with open(path, newline="") as fh:
        reader = csv.DictReader(fh)
        needed = {"model", "resolution_label", "scene", *NUMERIC}
        missing = needed - set(reader.fieldnames or ())
        if missing:
            raise InputError(f"error map {str(path)!r} lacks the columns {', '.join(sorted(missing))}")
        return parse_rows(reader)


def fitting(rows) -> list[dict]:
    """The rows the prediction uses: all but those of held-out scenes (column role = "held-out":
    scenes kept out of the fitting set to check the prediction, validation/error_map.py)."""
    return [r for r in rows if r.get("role") != "held-out"]


def parse_rows(raw_rows) -> list[dict]:
    """Rows of the map as read by csv.DictReader (strings), numeric columns parsed."""
    rows = []
    for raw in raw_rows:
        row = dict(raw)
        for key in NUMERIC:
            row[key] = _number(raw.get(key))
        rows.append(row)
    return rows


@dataclass(frozen=True)
class Scene:
    """A scene of the map: dL/L, W/L, L/b."""
    compression_ratio: float
    width_ratio: float
    slenderness: float

    @property
    def name(self) -> str:
        return scene_name(self.compression_ratio, self.width_ratio, self.slenderness)


def scene_name(compression_ratio: float, width_ratio: float, slenderness: float) -> str:
    """dL<dL/L>_W<W/L>_Lb<L/b>, e.g. dL0.5_W0.05_Lb1181 (the map's scene column)."""
    return f"dL{compression_ratio:.4g}_W{width_ratio:.4g}_Lb{slenderness:.0f}"


def _same(a: float, b: float) -> bool:
    return abs(a - b) <= SAME * max(abs(a), abs(b))


def map_scenes(rows) -> list[Scene]:
    """The distinct scenes of the map's rows."""
    found: list[Scene] = []
    for r in rows:
        s = Scene(float(r["compression_ratio"]), float(r["width_ratio"]), float(r["slenderness"]))
        if not any(_same(s.compression_ratio, t.compression_ratio) and _same(s.width_ratio, t.width_ratio)
                   and _same(s.slenderness, t.slenderness) for t in found):
            found.append(s)
    return found


def _bracket(values: list[float], x: float) -> list[float] | None:
    """The values equal to x (one), else the nearest below and above x (two); None outside."""
    values = sorted(set(values))
    equal = [v for v in values if _same(v, x)]
    if equal:
        return equal[:1]
    below, above = [v for v in values if v < x], [v for v in values if v > x]
    if not below or not above:
        return None
    return [below[-1], above[0]]


def basis_scenes(rows, scene: Scene) -> tuple[list[Scene], str]:
    """The map scenes bracketing `scene` (module docstring), and "" ; or [] and why it is outside."""
    scenes = [s for s in map_scenes(rows) if _same(s.compression_ratio, scene.compression_ratio)]
    if not scenes:
        have = sorted({f"{s.compression_ratio:g}" for s in map_scenes(rows)})
        return [], (f"dL/L = {scene.compression_ratio:g} is not in the map (it has dL/L = {', '.join(have) or 'none'})")
    widths = _bracket([s.width_ratio for s in scenes], scene.width_ratio)
    if widths is None:
        lo, hi = min(s.width_ratio for s in scenes), max(s.width_ratio for s in scenes)
        return [], f"W/L = {scene.width_ratio:.4g} is outside the map's range [{lo:.4g}, {hi:.4g}] at dL/L = " \
                   f"{scene.compression_ratio:g}"
    basis = []
    for w in widths:
        at = [s for s in scenes if _same(s.width_ratio, w)]
        lbs = _bracket([s.slenderness for s in at], scene.slenderness)
        if lbs is None:
            have = ", ".join(f"{s.slenderness:.0f}" for s in sorted(at, key=lambda s: s.slenderness))
            return [], (f"L/b = {scene.slenderness:.4g} is outside the map's L/b at W/L = {w:.4g}, dL/L = "
                        f"{scene.compression_ratio:g} (it has L/b = {have})")
        basis += [s for s in at if any(_same(s.slenderness, b) for b in lbs)]
    return basis, ""


# ------------------------------------------------------------------------------------ prediction
def at_scene(row, s: Scene) -> bool:
    """The map row is of scene s (dL/L, W/L and L/b the same to SAME)."""
    return (_same(float(row["compression_ratio"]), s.compression_ratio)
            and _same(float(row["width_ratio"]), s.width_ratio) and _same(float(row["slenderness"]), s.slenderness))


@dataclass
class Prediction:
    """A candidate (model, resolution) on a scene: predicted error per quantity (None: no
    prediction, see why), predicted wall time (s), the basis scenes."""
    model: str
    resolution: int
    label: str
    errors: dict
    wall_time_s: float | None
    basis: list[str]
    why: dict = field(default_factory=dict)

    def within(self, tolerance: float, quantities) -> bool:
        return all(self.errors.get(q) is not None and self.errors[q] <= tolerance for q in quantities)

    def worst(self, quantities) -> float:
        values = [self.errors.get(q) for q in quantities]
        return math.inf if any(v is None for v in values) else max(values)


def predictions(rows, basis: list[Scene], runnable=None, margin: float = 1.0) -> list[Prediction]:
    """Each candidate of the map (not NOT_RUN; among `runnable` model names if given) predicted
    on the basis scenes, by the rule of the module docstring: the largest bound of the basis
    scenes times `margin` (1: rule v1)."""
    candidates = {}
    for r in rows:
        if r["model"] in NOT_RUN or (runnable is not None and r["model"] not in runnable):
            continue
        if r.get("resolution") is None:
            continue
        candidates.setdefault((r["model"], int(r["resolution"]), r["resolution_label"]), []).append(r)
    out = []
    for (model, resolution, label), mine in candidates.items():
        errors, why, times = {}, {}, []
        per_scene = [[r for r in mine if at_scene(r, s)] for s in basis]
        for q in QUANTITIES:
            values = []
            for s, found in zip(basis, per_scene):
                bound = found[-1].get(f"{q}_bound") if found else None
                if bound is None:
                    why[q] = (f"no row at {s.name}" if not found
                              else f"{q} missing at {s.name}: {found[-1].get('reason') or 'no value'}")
                    break
                values.append(bound)
            errors[q] = max(values) * margin if q not in why else None
        for found in per_scene:
            if found and found[-1].get("wall_time_s") is not None:
                times.append(found[-1]["wall_time_s"])
        wall = max(times) if len(times) == len(basis) else None
        out.append(Prediction(model, resolution, label, errors, wall, [s.name for s in basis], why))
    out.sort(key=lambda p: (math.inf if p.wall_time_s is None else p.wall_time_s, p.model, p.resolution))
    return out


@dataclass(frozen=True)
class Margin:
    """The cross-validated margin (module docstring): its value, the (candidate, quantity)
    comparisons it was measured on, and the one that set it."""
    value: float
    compared: int
    scenes: int
    worst: str

    def text(self) -> str:
        if self.worst.startswith("rule v1"):
            return "margin 1 (rule v1)"
        if self.worst.startswith("on a map scene"):
            return "margin 1 (a scene of the map: its own measured bound)"
        if not self.compared:
            return "margin 1 (no fitting scene is bracketed by the others: nothing to cross-validate)"
        return (f"margin {self.value:.3f}: the largest measured/predicted ratio of leave-one-out on {self.scenes} "
                f"fitting scenes ({self.compared} comparisons; worst {self.worst})")


#: Rule v1: the largest bound of the bracketing scenes as it is (no margin).
RULE_V1_MARGIN = Margin(1.0, 0, 0, "rule v1: no margin")
#: A scene of the map itself (its W/L and L/b both in the map): the bound measured there, no margin
#: (nothing is interpolated).
ON_A_MAP_SCENE = Margin(1.0, 0, 0, "on a map scene: measured there")


def compared_at(rows, scene: Scene, basis: list[Scene], runnable=None, margin: float = 1.0,
                quantities=QUANTITIES) -> list[tuple[Prediction, str, float, float]]:
    """Leave one out: `scene`'s own rows are set aside, the other `rows` predict each candidate on
    `basis` (times `margin`), and each prediction meets the candidate's measured bound at `scene`:
    (prediction, quantity, predicted, measured) wherever both exist."""
    mine = {(r["model"], r["resolution_label"]): r for r in rows if at_scene(r, scene)}
    others = [r for r in rows if not at_scene(r, scene)]
    out = []
    for p in predictions(others, basis, runnable, margin):
        row = mine.get((p.model, p.label))
        if row is None:
            continue
        for q in quantities:
            predicted, measured = p.errors.get(q), row.get(f"{q}_bound")
            if predicted is not None and measured is not None:
                out.append((p, q, predicted, measured))
    return out


def cross_validated_margin(rows, runnable=None) -> Margin:
    """Leave-one-out on the fitting rows (held-out rows are dropped first): each scene bracketed
    by the others is predicted from them with margin 1; the margin is the largest ratio measured
    bound / predicted bound over every (candidate, quantity) compared, and at least 1."""
    rows = fitting(rows)
    worst, where, compared, scenes = 1.0, "none above 1", 0, 0
    for scene in map_scenes(rows):
        basis, _ = basis_scenes([r for r in rows if not at_scene(r, scene)], scene)
        if not basis:
            continue
        scenes += 1
        for p, q, predicted, measured in compared_at(rows, scene, basis, runnable):
            if not predicted > 0:
                continue
            compared += 1
            if measured / predicted > worst:
                worst = measured / predicted
                where = f"{p.model} {p.label} {q} at {scene.name}: {measured:.4f} against {predicted:.4f}"
    return Margin(worst, compared, scenes, where)


@dataclass
class Choice:
    """What `advise` recommends for a scene (auto_block() is what summary.json stores)."""
    model: str
    resolution: int | list
    label: str
    reason: str
    predicted_errors: dict
    basis_scenes: list
    map_file: str
    tolerance: float
    quantities: tuple
    scene: Scene
    inside_map: bool
    safe: bool
    wall_time_s: float | None = None
    cost_basis: str = ""
    candidates: list = field(default_factory=list, repr=False)
    margin: Margin | None = None

    def auto_block(self) -> dict:
        return {"chosen_model": self.model, "resolution": self.resolution, "resolution_label": self.label,
                "reason": self.reason, "predicted_errors": dict(self.predicted_errors),
                "basis_scenes": list(self.basis_scenes), "map_file": self.map_file, "tolerance": self.tolerance,
                "quantities": list(self.quantities), "inside_map": self.inside_map, "safe_choice": self.safe,
                "predicted_wall_time_s": self.wall_time_s, "cost_basis": self.cost_basis,
                "margin": None if self.margin is None else self.margin.value,
                "margin_basis": None if self.margin is None else self.margin.text(),
                "scene": asdict(self.scene) | {"name": self.scene.name}}


def safe_rows(width_ratio: float) -> tuple[int, int]:
    """The plate's convergence pair (rows of triangles across W) of the safe choice."""
    base = next(rows for limit, rows in SAFE_BASE_ROWS if width_ratio <= limit)
    return int(round(base * REFINEMENT)), int(round(base * REFINEMENT**2))


def _fmt(value) -> str:
    return "none" if value is None else f"{value:.4f}"


def choose(width_ratio, compression_ratio, slenderness=None, tolerance=None, quantities=None, rows=None,
           path=None, runnable=None, margin: Margin | None = None) -> Choice:
    """The cheapest candidate predicted within `tolerance` on `quantities` at the scene (W/L,
    dL/L, L/b; L/b None: the paper's thickness), from the map `rows` (default: read from `path`,
    $DDG_ERROR_MAP or DEFAULT_MAP), else the safe choice with the reason. `margin` None: the map's
    cross-validated margin (RULE_V1_MARGIN: rule v1). Inputs are checked first (InputError)."""
    tolerance = check_tolerance(tolerance)
    quantities = check_quantities(quantities)
    strip = Strip.from_ratios(width_ratio, compression_ratio, slenderness)
    scene = Scene(float(compression_ratio), float(width_ratio), float(strip.slenderness))
    if rows is None:
        file, _ = map_file(path)
        rows = load_map(file)
        where = str(file.relative_to(ROOT)) if file.is_relative_to(ROOT) else str(file)
    else:
        where = str(path) if path is not None else "(rows given)"
    rows = fitting(rows)
    names = "/".join(quantities)
    basis, outside = basis_scenes(rows, scene) if rows else ([], f"the error map {where} has no rows")
    if not basis:
        return _safe(scene, tolerance, quantities, where, rows, inside=False,
                     reason=f"outside the error map: {outside}; nothing is extrapolated, so the safe choice")
    if margin is None:
        margin = ON_A_MAP_SCENE if len(basis) == 1 else cross_validated_margin(rows, runnable)
    found = predictions(rows, basis, runnable, margin.value)
    eligible = [p for p in found if p.within(tolerance, quantities) and p.wall_time_s is not None]
    if eligible:
        p = eligible[0]
        errors = ", ".join(f"{q} {_fmt(p.errors[q])}" for q in quantities)
        reason = (f"the cheapest of {len(eligible)} candidates predicted within {tolerance:g} on {names} "
                  f"(predicted error + reference error bar: {errors}; the largest over the bracketing map scenes "
                  f"{', '.join(p.basis)}, times the {margin.text()})")
        return Choice(p.model, p.resolution, p.label, reason, {q: p.errors[q] for q in QUANTITIES},
                      [s.name for s in basis], where, tolerance, quantities, scene, True, False, p.wall_time_s,
                      f"largest wall time of {p.model} {p.label} on the basis scenes", found, margin)
    best = min(found, key=lambda p: p.worst(quantities), default=None)
    best_text = (f"; the closest is {best.model} {best.label} at {_fmt(best.worst(quantities))}"
                 if best is not None and math.isfinite(best.worst(quantities)) else "")
    return _safe(scene, tolerance, quantities, where, rows, inside=True, basis=basis, candidates=found, margin=margin,
                 reason=(f"no candidate of the map is predicted within {tolerance:g} on {names} at the bracketing "
                         f"scenes {', '.join(s.name for s in basis)} (their largest bound times the "
                         f"{margin.text()}){best_text}: the safe choice"))


def _safe(scene, tolerance, quantities, where, rows, inside, reason, basis=(), candidates=(), margin=None) -> Choice:
    pair = list(safe_rows(scene.width_ratio))
    label = f"R{pair[0]}+R{pair[1]}"
    # cost: the plate's finer mesh on the map's scenes of the same dL/L (not this scene's), if any
    times = [r["wall_time_s"] for r in rows if r["model"] == SAFE_MODEL and r.get("resolution") == pair[1]
             and r.get("wall_time_s") is not None and _same(float(r["compression_ratio"]), scene.compression_ratio)]
    coarse = [r["wall_time_s"] for r in rows if r["model"] == SAFE_MODEL and r.get("resolution") == pair[0]
              and r.get("wall_time_s") is not None and _same(float(r["compression_ratio"]), scene.compression_ratio)]
    wall = max(times) + max(coarse) if times and coarse else None
    cost = (f"largest wall times of the plate R{pair[0]} and R{pair[1]} on the map's scenes at dL/L = "
            f"{scene.compression_ratio:g} (not this scene), summed" if wall is not None
            else f"the map has no plate run on R{pair[0]} and R{pair[1]} at dL/L = {scene.compression_ratio:g}")
    errors = {q: None for q in QUANTITIES}
    return Choice(SAFE_MODEL, pair, label, reason + f" (the plate on the convergence pair {pair[0]}/{pair[1]} rows; "
                  "the difference of the two measures the finer one's discretisation error)", errors,
                  [s.name for s in basis], where, tolerance, quantities, scene, inside, True, wall, cost,
                  list(candidates), margin)


def study_mesh(model: str, strip: Strip, rows: int):
    """The study mesh of a plate model with `rows` rows of triangles across W, as the mesh studies
    build it (validation/plate_gold.py): exactly equilateral for the plate, ghost-clamp for the
    mid-edge plate."""
    from .geometry.plate_mesh import equilateral_mesh, ghost_clamp_mesh

    if model == "plate-midedge":
        return ghost_clamp_mesh(strip.length, strip.width, rows=rows)
    return equilateral_mesh(strip.length, strip.width, rows)


# ------------------------------------------------------------------------------------ printing
def format_choice(choice: Choice) -> str:
    """The choice in words: model, resolution, predicted errors with their basis, cost."""
    s = choice.scene
    lines = [f"scene: W/L = {s.width_ratio:.4g}, dL/L = {s.compression_ratio:g}, L/b = {s.slenderness:.4g} "
             f"(W^2/(bL) = {s.width_ratio**2 * s.slenderness:.3g}); tolerance {choice.tolerance:g} on "
             f"{', '.join(choice.quantities)}; map {choice.map_file}"]
    if choice.safe:
        lines.append(f"choice: SAFE CHOICE, {choice.model} on two meshes, rows {choice.resolution[0]} and "
                     f"{choice.resolution[1]}")
    else:
        lines.append(f"choice: {choice.model} {choice.label} (resolution {choice.resolution})")
    lines.append(f"reason: {choice.reason}")
    if not choice.safe:
        for q in QUANTITIES:
            mark = "" if q in choice.quantities else " (not asked)"
            lines.append(f"  predicted |{q} error| + reference error bar <= {_fmt(choice.predicted_errors[q])}{mark}")
        lines.append(f"  basis: {', '.join(choice.basis_scenes)}")
    if choice.margin is not None:
        lines.append(f"  {choice.margin.text()}")
    cost = "unknown" if choice.wall_time_s is None else f"about {choice.wall_time_s:.3g} s"
    lines.append(f"cost: {cost} ({choice.cost_basis})")
    if choice.candidates:
        lines.append("candidates (predicted on the basis scenes, cheapest first):")
        for p in choice.candidates:
            errs = ", ".join(f"{q} {_fmt(p.errors.get(q))}" for q in QUANTITIES)
            wall = "?" if p.wall_time_s is None else f"{p.wall_time_s:.3g} s"
            lines.append(f"  {p.model:16s} {p.label:8s} {wall:>9s}  {errs}")
    return "\n".join(lines)
