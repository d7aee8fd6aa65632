"""Which model is enough for a scene: the error map read back, a conservative prediction of each
model's error on a scene, and the cheapest model and resolution predicted within a tolerance
(`python -m ddg advise`, `ddg.simulate(..., model="auto", tolerance=...)`; the rule is RULE, v3).

The error map (data/error_map/error_map.csv, written by `python -m validation.error_map`) has one
row per (model, resolution, scene): for each quantity q of dW1/L, dW2/L and H_mid/L its error
against the scene's converged FEM reference, that reference's error bar and their sum `q_bound`
(for H_mid the largest pointwise sum over the shear path, 0.02 L away from the reference's and the
run's own thresholds), with the run's wall time. Rows of held-out scenes (role "held-out") never
predict: they check the prediction. The FEM rows are information only: ddg does not run the shell.

Rule v3, conservative and never an extrapolation. A scene is (dL/L, W/L, L/b) at the map's nu = 0
(another nu is refused: check_mapped_poisson_ratio), its L/b read relative to the paper's strip at
the same dL/L (paper_slenderness). Its basis is the corners of the map's box about it: the map
compressions bracketing dL/L (the one equal to it within SAME, else the nearest below and above), at
each the map widths bracketing W/L, at each of those the relative slendernesses bracketing the
scene's; if one bracket fails, the scene is outside the map. Each candidate is predicted on each
quantity on its own (a missing bound makes that quantity unknown for that candidate only):
- the rod's family, keyed by node count M: at each basis scene the bound of that M;
- the plates, keyed by element size h/L = (W/L) / rows (the sizes measured at the basis scenes, as
  even rows across the scene's W): at each basis scene the larger bound of the two measured meshes
  whose sizes bracket h (the one of that size where equal), none outside the sizes measured there.
The predicted error is the largest basis bound times the cross-validated margin; the predicted cost
the largest wall time of the meshes used. The choice is the cheapest candidate predicted within the
tolerance on every quantity asked that the map knows at the scene (a quantity no candidate has a
bound for there is reported unknown); if none is, the most accurate candidate, labelled as not
within the tolerance with its predicted error; outside the map, the candidate most accurate at the
nearest map scene (distance in log dL/L, log W/L, log relative L/b), labelled with an unknown error.

The cross-validated margin: errors are not monotone in the scene, so the largest bound of the
bracketing scenes can understate an interior scene's error. Leave-one-out on the fitting scenes:
each scene bracketed by the others is predicted from them with margin = 1, and the margin is the
largest ratio of a candidate's error there (`measured_error`: |q - reference|, the q_error column,
where the row has a bound) to its prediction, over every (candidate, quantity); never below 1
(cross_validated_margin), recomputed from whatever map is read. On a scene of the map itself its own
bound is the prediction. How the rule came to be and how it held on held-out scenes:
docs/findings/model_choice.md.
"""
from __future__ import annotations

import csv
import functools
import math
import os
from dataclasses import asdict, dataclass, field
from pathlib import Path

from .limits import InputError
from .geometry.strip import Strip
from .models import registry
from .models.names import MIDEDGE_PLATE

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
#: The plates: keyed by element size, not node count.
PLATE_MODELS = registry.names_in(registry.PLATES)
#: The prediction rule of this module (docstring); summary.json's auto block names it.
RULE = "v3"
#: The Poisson ratio of every scene of the map (the FEM references and the runs are at nu = 0).
MAP_POISSON_RATIO = 0.0
#: Used only when the map has no runnable row at all: the mid-edge plate on 18 rows.
FALLBACK_MODEL, FALLBACK_ROWS = MIDEDGE_PLATE, 18


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


def check_mapped_poisson_ratio(value) -> float:
    """nu as a float if the map has it (MAP_POISSON_RATIO); InputError naming it otherwise: the
    map's errors are measured at nu = 0, and nu moves the thresholds by as much as the tolerances
    asked (docs/findings/model_choice.md), so no error can be predicted."""
    nu = float(value)
    if abs(nu - MAP_POISSON_RATIO) > 1e-12:
        raise InputError(f"poisson_ratio = {value!r}: the error map is measured at nu = {MAP_POISSON_RATIO:g} only "
                         f"(nu moves dW1/L by 0.0078 at 0.25), so no model can be advised; choose a --model")
    return nu


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
    scenes kept out of the fitting set to check the prediction, validation/error_map/)."""
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


@functools.lru_cache(maxsize=None)
def paper_slenderness(compression_ratio: float) -> float:
    """L/b of the paper's strip (b = 0.127 mm) at this dL/L (its L grows with dL/L)."""
    return Strip.from_ratios(0.05, compression_ratio, None).slenderness


@dataclass(frozen=True)
class Scene:
    """A scene of the map: dL/L, W/L, L/b."""
    compression_ratio: float
    width_ratio: float
    slenderness: float

    @property
    def name(self) -> str:
        return scene_name(self.compression_ratio, self.width_ratio, self.slenderness)

    @property
    def relative_slenderness(self) -> float:
        """(L/b) / (L/b)_paper at the same dL/L: the paper's thickness over this one's."""
        return self.slenderness / paper_slenderness(self.compression_ratio)


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
    """The map scenes at the corners of the box about `scene` (module docstring, rule v3), and "";
    or [] and why it is outside."""
    scenes = map_scenes(rows)
    compressions = _bracket([s.compression_ratio for s in scenes], scene.compression_ratio)
    if compressions is None:
        have = ", ".join(f"{c:.4g}" for c in sorted({s.compression_ratio for s in scenes})) or "none"
        return [], f"dL/L = {scene.compression_ratio:.4g} is outside the map's compressions ({have})"
    basis = []
    for c in compressions:
        at_c = [s for s in scenes if _same(s.compression_ratio, c)]
        widths = _bracket([s.width_ratio for s in at_c], scene.width_ratio)
        if widths is None:
            lo, hi = min(s.width_ratio for s in at_c), max(s.width_ratio for s in at_c)
            return [], (f"W/L = {scene.width_ratio:.4g} is outside the map's range [{lo:.4g}, {hi:.4g}] at "
                        f"dL/L = {c:.4g}")
        for w in widths:
            at = [s for s in at_c if _same(s.width_ratio, w)]
            relative = _bracket([s.relative_slenderness for s in at], scene.relative_slenderness)
            if relative is None:
                have = ", ".join(f"{s.slenderness:.0f}" for s in sorted(at, key=lambda s: s.slenderness))
                return [], (f"L/b = {scene.slenderness:.4g} ({scene.relative_slenderness:.3g} times the paper's at "
                            f"dL/L = {scene.compression_ratio:.4g}) is outside the map's L/b at W/L = {w:.4g}, "
                            f"dL/L = {c:.4g} (it has L/b = {have}, read as {_relative_list(at)} times the paper's)")
            basis += [s for s in at if any(_same(s.relative_slenderness, r) for r in relative)]
    return basis, ""


def _relative_list(scenes) -> str:
    return ", ".join(f"{s.relative_slenderness:.3g}" for s in sorted(scenes, key=lambda s: s.slenderness))


# ------------------------------------------------------------------------------------ prediction
def at_scene(row, s: Scene) -> bool:
    """The map row is of scene s (dL/L, W/L and L/b the same to SAME)."""
    return (_same(float(row["compression_ratio"]), s.compression_ratio)
            and _same(float(row["width_ratio"]), s.width_ratio) and _same(float(row["slenderness"]), s.slenderness))


def element_size(row) -> float | None:
    """A plate row's element size h/L = (W/L) / rows (rows of triangles across W); None for the
    rod's family (keyed by its node count M)."""
    if row["model"] not in PLATE_MODELS or row.get("resolution") is None:
        return None
    return float(row["width_ratio"]) / float(row["resolution"])


def even_rows(width_ratio: float, size: float) -> int:
    """The even number of rows of triangles across W nearest W / h (at least 2): the plate mesh of
    element size `size` (units of L) on a strip of W/L = `width_ratio`."""
    return max(2, 2 * int(round(width_ratio / size / 2)))


@dataclass
class Prediction:
    """A candidate (model, resolution) on a scene: predicted error per quantity (None: unknown for
    this candidate, see why), predicted wall time (s), the basis scenes, and for a plate its element
    size h/L and the map meshes each basis scene's bound came from."""
    model: str
    resolution: int
    label: str
    errors: dict
    wall_time_s: float | None
    basis: list[str]
    why: dict = field(default_factory=dict)
    element_size: float | None = None
    meshes: dict = field(default_factory=dict)

    def within(self, tolerance: float, quantities) -> bool:
        return all(self.errors.get(q) is not None and self.errors[q] <= tolerance for q in quantities)

    def worst(self, quantities) -> float:
        values = [self.errors.get(q) for q in quantities]
        return math.inf if not values or any(v is None for v in values) else max(values)


def _predict(model, resolution, label, size, basis, used, margin) -> Prediction:
    """One candidate from its map rows at each basis scene (`used`: a list of rows per scene, two
    for a plate between two measured meshes): per quantity the largest bound, times `margin`."""
    errors, why = {}, {}
    for q in QUANTITIES:
        values = []
        for s, found in zip(basis, used):
            if not found:
                why[q] = f"no row at {s.name}"
                break
            missing = [r for r in found if r.get(f"{q}_bound") is None]
            if missing:
                r = missing[0]
                why[q] = f"{q} missing at {s.name}, {r['resolution_label']}: {r.get('reason') or 'no value'}"
                break
            values += [r[f"{q}_bound"] for r in found]
        errors[q] = max(values) * margin if q not in why else None
    times = [max(r["wall_time_s"] for r in found) for found in used
             if found and all(r.get("wall_time_s") is not None for r in found)]
    wall = max(times) if len(times) == len(basis) else None
    meshes = {s.name: [r["resolution_label"] for r in found] for s, found in zip(basis, used)}
    return Prediction(model, resolution, label, errors, wall, [s.name for s in basis], why, size, meshes)


def _meshes_about(found: list[dict], size: float) -> list[dict] | None:
    """The plate rows of one scene whose element sizes bracket `size`: the one of that size, else
    the nearest coarser and the nearest finer; None outside the measured sizes (no extrapolation)."""
    sizes = _bracket([element_size(r) for r in found], size)
    if sizes is None:
        return None
    return [next(r for r in found if _same(element_size(r), h)) for h in sizes]


def predictions(rows, basis: list[Scene], scene: Scene | None = None, runnable=None, margin: float = 1.0,
                plate_rows=()) -> list[Prediction]:
    """Each candidate of the map (not NOT_RUN; among `runnable` model names if given) predicted on
    `scene` from the `basis` scenes by rule v3 (module docstring): the rod's family keyed by node
    count, the plates by element size (the sizes measured at the basis scenes, as even rows across
    the scene's W, and `plate_rows` besides). Cheapest first."""
    scene = scene if scene is not None else basis[0]
    usable = [r for r in rows if r["model"] not in NOT_RUN and (runnable is None or r["model"] in runnable)
              and r.get("resolution") is not None]
    per_basis = [[r for r in usable if at_scene(r, s)] for s in basis]
    out = []
    keys = dict.fromkeys((r["model"], int(r["resolution"]), r["resolution_label"]) for r in usable
                         if r["model"] not in PLATE_MODELS)
    for model, resolution, label in keys:
        used = [[r for r in found if r["model"] == model and r["resolution_label"] == label][-1:]
                for found in per_basis]
        out.append(_predict(model, resolution, label, None, basis, used, margin))
    for model in dict.fromkeys(r["model"] for r in usable if r["model"] in PLATE_MODELS):
        meshes = [[r for r in found if r["model"] == model] for found in per_basis]
        sizes = {element_size(r) for found in meshes for r in found}
        options = sorted({even_rows(scene.width_ratio, h) for h in sizes} | {int(n) for n in plate_rows})
        for n in options:
            size = scene.width_ratio / n
            used = [_meshes_about(found, size) for found in meshes]
            if any(u is None for u in used):
                continue          # outside the measured element sizes at a basis scene
            out.append(_predict(model, n, f"R{n}", size, basis, used, margin))
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
#: A scene of the map itself (its dL/L, W/L and L/b all in the map): the bound measured there, no
#: margin (nothing is interpolated).
ON_A_MAP_SCENE = Margin(1.0, 0, 0, "on a map scene: measured there")


def compared_at(rows, scene: Scene, basis: list[Scene], runnable=None, margin: float = 1.0,
                quantities=QUANTITIES) -> list[tuple[Prediction, str, float, float]]:
    """Leave one out: `scene`'s own rows are set aside, the other `rows` predict each candidate on
    `scene` from `basis` (times `margin`; the plates also at the rows measured at `scene`), and each
    prediction meets the candidate's measured error at `scene` (module docstring: |q - reference|,
    the q_error column, where the row has a bound, i.e. a complete run and a reference value with an
    error bar): (prediction, quantity, predicted, measured) wherever both exist."""
    mine = {(r["model"], r["resolution_label"]): r for r in rows if at_scene(r, scene)}
    others = [r for r in rows if not at_scene(r, scene)]
    plate_rows = {int(r["resolution"]) for r in mine.values() if r["model"] in PLATE_MODELS}
    out = []
    for p in predictions(others, basis, scene, runnable, margin, plate_rows):
        row = mine.get((p.model, p.label))
        if row is None:
            continue
        for q in quantities:
            predicted, measured = p.errors.get(q), measured_error(row, q)
            if predicted is not None and measured is not None:
                out.append((p, q, predicted, measured))
    return out


def measured_error(row, q: str) -> float | None:
    """What a prediction of q is checked against at a scene: |q - reference| (the q_error column),
    where the row has a bound (a complete run, a reference value with an error bar); else None."""
    if row.get(f"{q}_bound") is None:
        return None
    return row.get(f"{q}_error")


def cross_validated_margin(rows, runnable=None) -> Margin:
    """Leave-one-out on the fitting rows (held-out rows are dropped first): each scene bracketed
    by the others is predicted from them with margin = 1; the margin is the largest ratio of the
    measured to the predicted error over every (candidate, quantity) compared, and never below 1."""
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
    """What `advise` recommends for a scene (auto_block() is what summary.json stores). `within`:
    predicted within the tolerance on every quantity asked that the map knows at the scene;
    `unknown`: the quantities asked that no candidate has a bound for there (with why)."""
    model: str
    resolution: int
    label: str
    reason: str
    predicted_errors: dict
    basis_scenes: list
    map_file: str
    tolerance: float
    quantities: tuple
    scene: Scene
    inside_map: bool
    within: bool
    wall_time_s: float | None = None
    cost_basis: str = ""
    candidates: list = field(default_factory=list, repr=False)
    margin: Margin | None = None
    unknown: dict = field(default_factory=dict)
    element_size: float | None = None

    @property
    def safe(self) -> bool:
        """Not predicted within the tolerance (outside the map, or no candidate within): the
        summary's `safe_choice` key, kept for readers of earlier summaries."""
        return not self.within

    def verdict(self) -> str:
        if self.within:
            return f"predicted within {self.tolerance:g}"
        if not self.inside_map:
            return "OUTSIDE THE MAP: error unknown"
        return (f"NOT WITHIN THE TOLERANCE {self.tolerance:g}: the most accurate candidate, predicted "
                f"{_fmt(self.worst())}")

    def worst(self) -> float | None:
        values = [self.predicted_errors.get(q) for q in self.quantities if q not in self.unknown]
        return None if not values or any(v is None for v in values) else max(values)

    def auto_block(self) -> dict:
        return {"chosen_model": self.model, "resolution": self.resolution, "resolution_label": self.label,
                "reason": self.reason, "predicted_errors": dict(self.predicted_errors),
                "basis_scenes": list(self.basis_scenes), "map_file": self.map_file, "tolerance": self.tolerance,
                "quantities": list(self.quantities), "inside_map": self.inside_map, "safe_choice": self.safe,
                "within_tolerance": self.within, "verdict": self.verdict(), "rule": RULE,
                "unknown_quantities": dict(self.unknown), "element_size_over_L": self.element_size,
                "predicted_wall_time_s": self.wall_time_s, "cost_basis": self.cost_basis,
                "margin": None if self.margin is None else self.margin.value,
                "margin_basis": None if self.margin is None else self.margin.text(),
                "scene": asdict(self.scene) | {"name": self.scene.name}}


def _fmt(value) -> str:
    return "unknown" if value is None else f"{value:.4f}"


def choose(width_ratio, compression_ratio, slenderness=None, tolerance=None, quantities=None, rows=None,
           path=None, runnable=None, margin: Margin | None = None, poisson_ratio=0.0) -> Choice:
    """The cheapest candidate predicted within `tolerance` on `quantities` at the scene (W/L,
    dL/L, L/b; L/b None: the paper's thickness), from the map `rows` (default: read from `path`,
    $DDG_ERROR_MAP or DEFAULT_MAP); else the most accurate candidate, labelled as not within the
    tolerance, with its predicted error; outside the map the model most accurate over the map,
    labelled with an unknown error (module docstring). `margin` None: the map's cross-validated
    margin (RULE_V1_MARGIN: rule v1). Inputs are checked first (InputError), nu among them."""
    tolerance = check_tolerance(tolerance)
    quantities = check_quantities(quantities)
    strip = Strip.from_ratios(width_ratio, compression_ratio, slenderness, poisson_ratio=poisson_ratio)
    check_mapped_poisson_ratio(strip.poisson_ratio)
    scene = Scene(float(compression_ratio), float(width_ratio), float(strip.slenderness))
    if rows is None:
        file, _ = map_file(path)
        rows = load_map(file)
        where = str(file.relative_to(ROOT)) if file.is_relative_to(ROOT) else str(file)
    else:
        where = str(path) if path is not None else "(rows given)"
    rows = fitting(rows)
    basis, outside = basis_scenes(rows, scene) if rows else ([], f"the error map {where} has no rows")
    if not basis:
        return _outside(scene, tolerance, quantities, where, rows, runnable, outside)
    if margin is None:
        margin = ON_A_MAP_SCENE if len(basis) == 1 else cross_validated_margin(rows, runnable)
    found = predictions(rows, basis, scene, runnable, margin.value)
    unknown = {q: next(iter(p.why[q] for p in found if q in p.why), "no candidate") for q in quantities
               if all(p.errors.get(q) is None for p in found)}
    judged = tuple(q for q in quantities if q not in unknown)
    names = "/".join(judged)
    unknown_text = "".join(f"; {q}: no candidate's error is known here ({why})" for q, why in unknown.items())
    basis_text = (f"the largest bound over the bracketing map scenes {', '.join(s.name for s in basis)}, times the "
                  f"{margin.text()}")
    eligible = [p for p in found if judged and p.within(tolerance, judged) and p.wall_time_s is not None]
    if eligible:
        p = eligible[0]
        errors = ", ".join(f"{q} {_fmt(p.errors[q])}" for q in judged)
        reason = (f"the cheapest of {len(eligible)} candidates predicted within {tolerance:g} on {names} "
                  f"(predicted error + reference error bar: {errors}; {basis_text}){unknown_text}")
        return _choice(p, reason, scene, basis, where, tolerance, quantities, True, True, found, margin, unknown)
    ranked = [p for p in found if judged and math.isfinite(p.worst(judged))]
    if not ranked:
        return _outside(scene, tolerance, quantities, where, rows, runnable,
                        f"no candidate has a bound on {'/'.join(quantities)} at the bracketing scenes "
                        f"{', '.join(s.name for s in basis)}{unknown_text}", basis=basis, candidates=found,
                        margin=margin, unknown=unknown)
    best = min(ranked, key=lambda p: (p.worst(judged), math.inf if p.wall_time_s is None else p.wall_time_s))
    errors = ", ".join(f"{q} {_fmt(best.errors[q])}" for q in judged)
    reason = (f"no candidate is predicted within {tolerance:g} on {names}: the most accurate, NOT within the "
              f"tolerance (predicted error + reference error bar: {errors}; {basis_text}){unknown_text}")
    return _choice(best, reason, scene, basis, where, tolerance, quantities, True, False, found, margin, unknown)


def _choice(p: Prediction, reason, scene, basis, where, tolerance, quantities, inside, within, found, margin,
            unknown) -> Choice:
    cost = (f"largest wall time of {p.model} {' / '.join(dict.fromkeys(x for v in p.meshes.values() for x in v))} "
            f"on the basis scenes")
    return Choice(p.model, p.resolution, p.label, reason, {q: p.errors.get(q) for q in QUANTITIES},
                  [s.name for s in basis], where, tolerance, quantities, scene, inside, within, p.wall_time_s, cost,
                  found, margin, unknown, p.element_size)


def _distance(a: Scene, b: Scene) -> float:
    return math.hypot(math.log(a.compression_ratio / b.compression_ratio), math.log(a.width_ratio / b.width_ratio),
                      math.log(a.relative_slenderness / b.relative_slenderness))


def _worst_bound(row, quantities) -> float:
    values = [row.get(f"{q}_bound") for q in quantities]
    return math.inf if not values or None in values else max(values)


def _outside(scene, tolerance, quantities, where, rows, runnable, why, basis=(), candidates=(), margin=None,
             unknown=None) -> Choice:
    """Outside the map (or nothing known at the basis): no error is predicted. The choice is the
    candidate most accurate at the nearest map scene (distance in log dL/L, log W/L and log relative
    L/b): the least largest bound on `quantities` there, at its node count (the rod's family) or its
    element size on this scene's width (the plates)."""
    usable = [r for r in rows if r["model"] not in NOT_RUN and (runnable is None or r["model"] in runnable)
              and r.get("resolution") is not None]
    nearest = min(map_scenes(usable), key=lambda s: _distance(s, scene), default=None)
    if nearest is None:
        model, resolution, wall, size = FALLBACK_MODEL, FALLBACK_ROWS, None, scene.width_ratio / FALLBACK_ROWS
        label, cost = f"R{resolution}", "unknown (the map has no run of a model ddg runs)"
        measured = f"the map has no run of a model ddg runs, so the mid-edge plate on {FALLBACK_ROWS} rows"
    else:
        here = [r for r in usable if at_scene(r, nearest)]
        best = min(here, key=lambda r: (_worst_bound(r, quantities), r.get("wall_time_s") or math.inf))
        model, resolution, size = best["model"], int(best["resolution"]), None
        if model in PLATE_MODELS:   # the same element size on this scene's width
            size = element_size(best)
            resolution = even_rows(scene.width_ratio, size)
            size = scene.width_ratio / resolution
        label = f"R{resolution}" if model in PLATE_MODELS else f"M{resolution}"
        wall = best.get("wall_time_s")
        cost = f"wall time of {model} {best['resolution_label']} at the nearest map scene {nearest.name}"
        bound = _worst_bound(best, quantities)
        measured = (f"the candidate most accurate at the nearest map scene {nearest.name} ({model} "
                    f"{best['resolution_label']}, largest bound on {'/'.join(quantities)} there "
                    f"{'unknown' if not math.isfinite(bound) else f'{bound:.4f}'}), at its "
                    f"{'element size' if model in PLATE_MODELS else 'node count'}")
    reason = f"outside the error map: {why}; nothing is extrapolated, so no error is predicted: {measured}"
    return Choice(model, resolution, label, reason, {q: None for q in QUANTITIES}, [s.name for s in basis], where,
                  tolerance, quantities, scene, False, False, wall, cost, list(candidates), margin,
                  dict(unknown or {}), size)


def study_mesh(model: str, strip: Strip, rows: int):
    """The study mesh of a plate model with `rows` rows of triangles across W, as the mesh studies
    build it (validation/plate_gold.py): exactly equilateral for the plate, ghost-clamp for the
    mid-edge plate."""
    from .geometry.plate_mesh import equilateral_mesh, ghost_clamp_mesh

    if model == MIDEDGE_PLATE:
        return ghost_clamp_mesh(strip.length, strip.width, rows=rows)
    return equilateral_mesh(strip.length, strip.width, rows)


# ------------------------------------------------------------------------------------ printing
def format_choice(choice: Choice) -> str:
    """The choice in words: model, resolution, verdict, predicted errors with their basis, cost,
    and the table of candidates."""
    s = choice.scene
    lines = [f"scene: W/L = {s.width_ratio:.4g}, dL/L = {s.compression_ratio:g}, L/b = {s.slenderness:.4g} "
             f"(W^2/(bL) = {s.width_ratio**2 * s.slenderness:.3g}); tolerance {choice.tolerance:g} on "
             f"{', '.join(choice.quantities)}; map {choice.map_file} (rule {RULE})"]
    size = "" if choice.element_size is None else f", element size h/L = {choice.element_size:.5f}"
    lines.append(f"choice: {choice.model} {choice.label} (resolution {choice.resolution}{size}): {choice.verdict()}")
    lines.append(f"reason: {choice.reason}")
    for q in QUANTITIES:
        mark = "" if q in choice.quantities else " (not asked)"
        if q in choice.unknown:
            mark += " (no candidate's error is known here)"
        lines.append(f"  predicted |{q} error| + reference error bar: {_fmt(choice.predicted_errors[q])}{mark}")
    if choice.basis_scenes:
        lines.append(f"  basis: {', '.join(choice.basis_scenes)}")
    if choice.margin is not None:
        lines.append(f"  {choice.margin.text()}")
    cost = "unknown" if choice.wall_time_s is None else f"about {choice.wall_time_s:.3g} s"
    lines.append(f"cost: {cost} ({choice.cost_basis})")
    if choice.candidates:
        lines.append("candidates (predicted on this scene from the basis scenes, cheapest first; "
                     "'-': unknown for that candidate):")
        lines.append(f"  {'model':20s} {'mesh':6s} {'wall':>9s}  " + "  ".join(f"{q:>7s}" for q in QUANTITIES)
                     + "  within")
        for p in choice.candidates:
            wall = "?" if p.wall_time_s is None else f"{p.wall_time_s:.3g} s"
            errs = "  ".join("      -" if p.errors.get(q) is None else f"{p.errors[q]:7.4f}" for q in QUANTITIES)
            judged = [q for q in choice.quantities if q not in choice.unknown]
            ok = "yes" if judged and p.within(choice.tolerance, judged) else "no"
            mark = " <- chosen" if (p.model, p.label) == (choice.model, choice.label) else ""
            lines.append(f"  {p.model:20s} {p.label:6s} {wall:>9s}  {errs}  {ok}{mark}")
    return "\n".join(lines)
