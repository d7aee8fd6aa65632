"""The scorecard: another code's thresholds and H_mid curve scored against the FEM benchmark (issue 33),
`python -m validation score RESULTS [--out DIR]`, `python -m validation score --template FILE` and
`python -m validation score --benchmark DIR`.

The benchmark (version BENCHMARK_VERSION)
-----------------------------------------
Every scene with a finished FEM gold study in data/fem_gold: the scenes of fem_reference.gold.all_scenes()
(the paper's ten, MAP_SCENES, NEW_MAP_SCENES, HELD_OUT_SCENES) whose folder has richardson.json on at
least two meshes, read by validation.estimates.load_study. The strip is clamped at both ends, its ends
brought together by dL (dL/L), then sheared sideways by dW (section 2 of Huang, Wang, Li, Jawed); per
scene: dL/L, W/L, L/b (the paper's strip, b = 0.127 mm with the clamps 75 mm apart after compression,
where the scene names none: ddg.Strip.from_ratios), nu = 0 (the gold runs' material), and the converged
values with error bars of the FEM shell's mesh study (fem_reference.convergence.estimate, the rule of
data/fem_gold/README.md: Richardson extrapolation with the observed order and Roache's grid convergence
index where the finest three meshes are asymptotic, else the finest value with three times the spread;
two meshes: the finer value, three times their difference; plus the threshold's bisection bracket):
dW1/L (the pitchfork U -> US), dW2/L (the snap US -> S) and the midpoint height H_mid/L against dW/L
with a pointwise error bar. A study may lack a threshold (its runs stopped short of it: the benchmark
says so, and scores nothing there). Lengths are in units of L.

Benchmark files (`--benchmark DIR`, write_benchmark_files)
----------------------------------------------------------
DIR/benchmark.csv, one row per scene: version (BENCHMARK_VERSION), scene (the data/fem_gold folder),
compression_ratio (dL/L), width_ratio (W/L), slenderness (L/b), poisson_ratio (0), then for q in dW1, dW2:
q_over_L (the converged value), q_error_bar, q_basis (how the error bar was made), q_meshes (the meshes
it rests on); H_mid_points (points of the curve) and source (the study's richardson.json). An empty cell:
no value. DIR/benchmark_H_mid.csv, one row per point of each scene's H_mid curve: version, scene, the
four scene columns, dW_over_L, H_mid_over_L, error_bar. DIR/README.md: this section, the version and a
digest of the studies the files were made from (benchmark_digest: the version names a release, the
digest tells whether the data under it changed).

The results format (RESULTS; `--template FILE` writes one with a row per benchmark scene)
-----------------------------------------------------------------------------------------
A CSV file (UTF-8; lines starting with # are comments; blank lines are skipped) with a header line and
the columns compression_ratio, width_ratio, slenderness, poisson_ratio, dW1_over_L, dW2_over_L (required)
and kind, dW_over_L, H_mid_over_L (optional; other columns are ignored). A row of kind "thresholds" (the
default, and every row without a kind column) gives one scene's dW1/L and dW2/L, at most one such row
per scene, an empty cell where the code found no such threshold; its dW_over_L and H_mid_over_L cells
stay empty. A row of kind "H_mid" gives one point (dW_over_L, H_mid_over_L) of the scene's H_mid curve
(both required; dW1_over_L and dW2_over_L empty), any number of rows per scene, each dW/L once. Two
rows are of one scene when their dL/L, W/L and L/b agree within MATCH_TOLERANCE (0.1 %) relative and
their nu is equal. Every value a finite number in its physical range (RANGES): 0 < dL/L < 1,
0 < W/L < 1, 10 <= L/b <= 1e5 (the strips ddg.Strip accepts), 0 <= nu < 0.5, 0 <= dW/L <= 1 (the
clamps' shear never reaches L: dW_max/L < 1, Eq. B.1), -1 <= H_mid/L <= 1 (the midpoint lies L/2 of
arclength from a clamp). RESULTS must be a regular file (not a FIFO or a device) of at most
MAX_RESULTS_BYTES (8 MiB; the benchmark's own curves as a results file weigh 0.4 MB), checked before
it is opened. A malformed file is refused with one line naming its line and column, before anything
is written (exit 2).

Scores (score.csv, score.md, score.png in --out, default out/score; a line per scene on stdout)
---------------------------------------------------------------------------------------------
A submitted scene matches a benchmark scene when dL/L, W/L and L/b agree within MATCH_TOLERANCE
relative and nu = 0; one that matches none is reported ("no benchmark scene at ...") and not scored.
Per benchmark scene and quantity: for dW1/L and dW2/L the difference submitted - benchmark, |difference|
in units of the benchmark's error bar (in_error_bars) and whether it is within it (|difference| <=
error bar). For H_mid/L, over the benchmark curve's points inside the submitted curve's dW range and
more than THRESHOLD_BAND = 0.02 from the benchmark's and the submitted thresholds (validation.claims,
validation.error_map.row_errors: near a threshold H_mid turns or jumps, and a small shift of the
threshold, scored by its own row, shows as a large H_mid difference), the submitted curve linearly
interpolated there: the largest |difference| (signed, with the point it is at and the error bar
there) and the largest |difference| / pointwise error bar (in_error_bars; within when every point is
within its bar). The pointwise bar counts as at least H_MID_ERROR_BAR_FLOOR = 1e-7 L (below it the
bars are round-off: past the snap H_mid is zero by symmetry on every mesh). score.png (matplotlib,
extra `plot`): dW1/L and dW2/L against W/L per dL/L and L/b, the benchmark with its error bars and the
submitted points. Exit 0 when scored, whatever the scores.
"""
from __future__ import annotations

import csv
import hashlib
import io
import itertools
import math
import os
import stat
import sys
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ddg.geometry.strip import SLENDERNESS_RANGE, InputError
from ddg.output.io import atomic_write_text, check_output_directory, save_figure, write_table_csv

from .benchmark import basis_meshes, estimate_basis, fraction_label
from .claims import THRESHOLD_BAND
from .estimates import Estimate, Study, difference_away_from_thresholds, load_study
from .reference import FEM_GOLD, ROOT

#: Every release of the benchmark and the digest of the studies it was made from (benchmark_digest):
#: a new or extended mesh study in data/fem_gold, or a new error-bar rule, is a new release.
#: tests/test_score.py checks that the committed studies are BENCHMARK_VERSION's, so changed data cannot
#: keep an old version. What each release changed: docs/reference/benchmark.rst, "Releases".
BENCHMARK_RELEASES = {
    "2026.11-1": "e7a809c515e9c367",   # 28 scenes
    "2026.11-2": "b42ced51e49a96e2",   # dL/L = 1/3, W/L = 1/6 on a fourth mesh (216 x 28)
    "2026.11-3": "473e7825cf89c444",   # dL/L = 1/3, W/L = 1/3 on a fourth mesh (216 x 54)
}
#: The benchmark's release: the newest of BENCHMARK_RELEASES.
BENCHMARK_VERSION = list(BENCHMARK_RELEASES)[-1]
#: The gold runs' Poisson ratio (summary.json scene.poisson_ratio; ddg.Strip's default).
BENCHMARK_POISSON_RATIO = 0.0
#: Relative tolerance on dL/L, W/L and L/b for a submitted row to be a benchmark scene (0.1 %).
MATCH_TOLERANCE = 1e-3
#: The largest RESULTS file read (bytes), checked before reading it. The benchmark's own H_mid curves
#: written as a results file (3295 points of 28 scenes) weigh 0.4 MB; 8 MiB is 20 times that, and a
#: bound on what is read into memory (/dev/zero, a runaway writer).
MAX_RESULTS_BYTES = 8 * 2**20
#: The least pointwise error bar of H_mid/L the scores divide by (units of L). The studies' bars below it
#: are round-off, not discretisation error: past the snap (the S shape) H_mid is zero by symmetry, every
#: FEM mesh gives it to 1e-14 L and the bar is 1e-15 L there, where a code's solver tolerance rather than
#: its accuracy would decide the score; where |H_mid| > 1e-6 L the smallest bar of the studies is
#: 5.3e-7 L (dL/L = 1/3, W/L = 1/10), 5 times this floor.
H_MID_ERROR_BAR_FLOOR = 1e-7
THRESHOLDS = ("dW1", "dW2")
QUANTITIES = ("dW1_over_L", "dW2_over_L", "H_mid_over_L")
SCENE_COLUMNS = ("compression_ratio", "width_ratio", "slenderness", "poisson_ratio")
REQUIRED_COLUMNS = SCENE_COLUMNS + ("dW1_over_L", "dW2_over_L")
CURVE_COLUMNS = ("dW_over_L", "H_mid_over_L")
KINDS = ("thresholds", "H_mid")
SCORE_COLUMNS = ("benchmark_version", "scene", "label", "compression_ratio", "width_ratio", "slenderness",
                 "poisson_ratio", "quantity", "submitted", "benchmark", "error_bar", "difference", "in_error_bars",
                 "within", "at_dW_over_L", "points", "line", "note")
MISSING = "\u2013"   # en dash, as validation.benchmark


@dataclass(frozen=True)
class BenchmarkScene:
    """One scene of the benchmark: its data/fem_gold folder, dL/L, W/L, L/b and the FEM study."""
    name: str
    compression_ratio: float
    width_ratio: float
    slenderness: float
    study: Study

    @property
    def label(self) -> str:
        """e.g. "dL1/2 W1/20 Lb1181"."""
        return (f"dL{fraction_label(self.compression_ratio)} W{fraction_label(self.width_ratio)} "
                f"Lb{self.slenderness:.0f}")

    def matches(self, submitted: SubmittedScene) -> bool:
        return submitted.poisson_ratio == BENCHMARK_POISSON_RATIO and _close(
            (submitted.compression_ratio, submitted.width_ratio, submitted.slenderness),
            (self.compression_ratio, self.width_ratio, self.slenderness))


def _close(values, references) -> bool:
    return all(abs(v - r) <= MATCH_TOLERANCE * abs(r) for v, r in zip(values, references))


def load_benchmark(root: Path = FEM_GOLD) -> list[BenchmarkScene]:
    """The benchmark's scenes (module docstring), in fem_reference.gold.all_scenes() order: those whose
    folder in `root` has a study (richardson.json) on at least two meshes."""
    import ddg
    from fem_reference.gold import all_scenes

    scenes = []
    for name, compression, width, slenderness in all_scenes():
        study = load_study("fem", compression, width, root=root, name=name)
        if study is None or len(study.meshes) < 2:
            continue
        if slenderness is None:
            slenderness = ddg.Strip.from_ratios(width, compression).slenderness
        scenes.append(BenchmarkScene(name, compression, width, float(slenderness), study))
    return scenes


def benchmark_digest(scenes: list[BenchmarkScene]) -> str:
    """A digest of the studies (richardson.json) the benchmark is read from: 16 hex digits."""
    digest = hashlib.sha256()
    for scene in scenes:
        source = Path(scene.study.source)   # relative to the checkout where it is inside it (load_study)
        digest.update(scene.name.encode())
        digest.update((source if source.is_absolute() else ROOT / source).read_bytes())
    return digest.hexdigest()[:16]


def _scene_cells(scene: BenchmarkScene) -> dict:
    return {"compression_ratio": scene.compression_ratio, "width_ratio": scene.width_ratio,
            "slenderness": scene.slenderness, "poisson_ratio": BENCHMARK_POISSON_RATIO}


def benchmark_rows(scenes: list[BenchmarkScene]) -> list[dict]:
    """benchmark.csv's rows (module docstring); None where a value is missing."""
    rows = []
    for scene in scenes:
        row = {"version": BENCHMARK_VERSION, "scene": scene.name, **_scene_cells(scene)}
        for key in THRESHOLDS:
            estimate = scene.study.threshold(key)
            row[f"{key}_over_L"] = None if estimate is None else estimate.value
            row[f"{key}_error_bar"] = None if estimate is None else estimate.error_bar
            row[f"{key}_basis"] = estimate_basis(estimate)
            row[f"{key}_meshes"] = None if estimate is None else "/".join(basis_meshes(scene.study, key))
        row["H_mid_points"] = 0 if scene.study.curve is None else len(scene.study.curve.dw)
        row["source"] = scene.study.source
        rows.append(row)
    return rows


def curve_rows(scenes: list[BenchmarkScene]) -> list[dict]:
    """benchmark_H_mid.csv's rows: every point of every scene's H_mid/L curve."""
    rows = []
    for scene in scenes:
        curve = scene.study.curve
        if curve is None:
            continue
        for dw, h, bar in zip(curve.dw, curve.value, curve.error_bar):
            rows.append({"version": BENCHMARK_VERSION, "scene": scene.name, **_scene_cells(scene),
                         "dW_over_L": float(dw), "H_mid_over_L": float(h), "error_bar": float(bar)})
    return rows


def _docstring_section(title: str) -> str:
    """The section of this module's docstring under the heading that starts with `title`."""
    lines = (__doc__ or "").splitlines()   # none under python -OO
    if not any(line.startswith(title) for line in lines):
        return "(the format is described in validation/score.py)"
    start = next(k for k, line in enumerate(lines) if line.startswith(title)) + 2   # past the underline
    end = next((k - 1 for k in range(start + 1, len(lines)) if set(lines[k]) == {"-"}), len(lines))
    return "\n".join(lines[start:end]).strip()


def write_benchmark_files(out: Path, scenes: list[BenchmarkScene]) -> list[Path]:
    """OUT/benchmark.csv, OUT/benchmark_H_mid.csv and OUT/README.md (module docstring), atomically."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    write_table_csv(out / "benchmark.csv", benchmark_rows(scenes))
    points = curve_rows(scenes)
    write_table_csv(out / "benchmark_H_mid.csv", points, None if points else
                    ["version", "scene", *SCENE_COLUMNS, "dW_over_L", "H_mid_over_L", "error_bar"])
    text = (f"# Thin-strip shear benchmark, version {BENCHMARK_VERSION}\n\n"
            f"{len(scenes)} scenes; data digest {benchmark_digest(scenes)} (validation.score.benchmark_digest). "
            f"Written by `python -m validation score --benchmark DIR` (validation/score.py).\n\n"
            f"{_docstring_section('The benchmark (version')}\n\n## Files\n\n"
            f"{_docstring_section('Benchmark files')}\n\n## Scoring a code: `python -m validation score RESULTS`\n\n"
            f"{_docstring_section('The results format')}\n\n{_docstring_section('Scores (')}\n")
    atomic_write_text(out / "README.md", text)
    return [out / "benchmark.csv", out / "benchmark_H_mid.csv", out / "README.md"]


def write_template(path: Path, scenes: list[BenchmarkScene]) -> None:
    """A RESULTS template: a comment naming the benchmark and the format, then one thresholds row per
    benchmark scene with its dL/L, W/L, L/b and nu (full precision) and the values left empty."""
    buf = io.StringIO()
    buf.write(f"# Results for the thin-strip shear benchmark {BENCHMARK_VERSION} (python -m validation score; the "
              "format: validation/score.py).\n# Fill dW1_over_L and dW2_over_L (units of L; empty where your code "
              "finds no such threshold); add rows of kind H_mid with dW_over_L and H_mid_over_L for the curve.\n")
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(("kind",) + REQUIRED_COLUMNS + CURVE_COLUMNS)
    for scene in scenes:
        writer.writerow(["thresholds"] + [repr(float(v)) for v in _scene_cells(scene).values()] + [""] * 4)
    atomic_write_text(Path(path), buf.getvalue())


# --- the submitted results --------------------------------------------------------------------------


@dataclass
class SubmittedScene:
    """One scene of RESULTS: dL/L, W/L, L/b, nu, its thresholds (None: not found or not given) and its
    H_mid curve as (dW/L, H_mid/L, line) points; `line` is the scene's first line in RESULTS."""
    compression_ratio: float
    width_ratio: float
    slenderness: float
    poisson_ratio: float
    line: int
    thresholds_line: int | None = None
    dW1: float | None = None
    dW2: float | None = None
    curve: list[tuple[float, float, int]] = field(default_factory=list)
    #: dW/L -> line of each point of `curve` (a repeated dW/L found without a scan of the curve)
    point_lines: dict[float, int] = field(default_factory=dict, repr=False, compare=False)

    def same(self, compression_ratio, width_ratio, slenderness, poisson_ratio) -> bool:
        return poisson_ratio == self.poisson_ratio and _close(
            (compression_ratio, width_ratio, slenderness), (self.compression_ratio, self.width_ratio, self.slenderness))

    def describe(self) -> str:
        return (f"dL/L = {self.compression_ratio:g}, W/L = {self.width_ratio:g}, L/b = {self.slenderness:g}, "
                f"nu = {self.poisson_ratio:g}")

    def threshold(self, key: str) -> float | None:
        return {"dW1": self.dW1, "dW2": self.dW2}[key]


#: The allowed range of each column: (test, the range in words). Physical bounds, so that no value
#: reaches the scores or the figure that the scene cannot have: L/b as ddg.Strip accepts it; the
#: clamps' sideways shear dW at most L (dW_max/L < 1 for every W/L and dL/L, Eq. B.1); the midpoint
#: no farther than L from the clamps' plane (it lies L/2 of arclength from a clamp: |H_mid| <= L/2
#: for an inextensible strip; the bound leaves a code's own error room).
RANGES = {"compression_ratio": (lambda x: 0 < x < 1, "outside (0, 1)"),
          "width_ratio": (lambda x: 0 < x < 1, "outside (0, 1)"),
          "slenderness": (lambda x: SLENDERNESS_RANGE[0] <= x <= SLENDERNESS_RANGE[1],
                          f"outside [{SLENDERNESS_RANGE[0]:g}, {SLENDERNESS_RANGE[1]:g}] (the strips ddg.Strip "
                          "accepts)"),
          "poisson_ratio": (lambda x: 0 <= x < 0.5, "outside [0, 0.5)"),
          **{c: (lambda x: 0 <= x <= 1, "outside [0, 1] (the magnitude of the clamps' sideways shear, at most "
                                        "dW_max/L < 1, Eq. B.1)")
             for c in ("dW1_over_L", "dW2_over_L", "dW_over_L")},
          "H_mid_over_L": (lambda x: -1 <= x <= 1, "outside [-1, 1] (the midpoint lies L/2 of arclength from a "
                                                   "clamp)")}


def _text_of(path: Path, name: str) -> str:
    """The text of RESULTS, read only if it is a regular file of at most MAX_RESULTS_BYTES (os.stat
    before any open or read: a FIFO would block the open, /dev/zero never ends); opened non-blocking and
    checked again on the open file, so that a FIFO swapped in after the stat cannot block either."""
    shown = repr(str(path))
    try:
        info = os.stat(path)
    except FileNotFoundError:
        raise InputError(f"{name} {shown} does not exist") from None
    except (OSError, ValueError) as exc:   # a symlink loop, a name too long, a NUL byte
        raise InputError(f"{name} {shown} cannot be read: {getattr(exc, 'strerror', None) or exc}") from None
    _regular_and_small(info, name, shown)
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
        with os.fdopen(fd, "rb") as fh:
            _regular_and_small(os.fstat(fh.fileno()), name, shown)
            data = fh.read(MAX_RESULTS_BYTES + 1)
    except OSError as exc:
        raise InputError(f"{name} {shown} cannot be read: {exc.strerror or exc}") from None
    if len(data) > MAX_RESULTS_BYTES:   # it grew after the stat
        raise InputError(f"{name} {shown} is larger than {MAX_RESULTS_BYTES // 2**20} MiB, the most a results file "
                         "may weigh")
    if b"\0" in data:
        raise InputError(f"{name} {str(path)!r} is not a CSV file: it holds NUL bytes (binary data)")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data[:exc.start].count(b"\n") + 1
        raise InputError(f"{name} {str(path)!r} is not a CSV file: line {line} is not UTF-8 text") from None


def _regular_and_small(info: os.stat_result, name: str, shown: str) -> None:
    if stat.S_ISDIR(info.st_mode):
        raise InputError(f"{name} {shown} is a directory, not a CSV file")
    if not stat.S_ISREG(info.st_mode):
        kind = ("a FIFO" if stat.S_ISFIFO(info.st_mode) else "a device" if stat.S_ISCHR(info.st_mode)
                or stat.S_ISBLK(info.st_mode) else "a socket" if stat.S_ISSOCK(info.st_mode) else "not a file")
        raise InputError(f"{name} {shown} is {kind}, not a regular file; give a CSV file")
    if info.st_size > MAX_RESULTS_BYTES:
        raise InputError(f"{name} {shown} is {info.st_size / 2**20:.1f} MiB; a results file may weigh at most "
                         f"{MAX_RESULTS_BYTES // 2**20} MiB")


def read_results(path, name: str = "RESULTS") -> list[SubmittedScene]:
    """The scenes of a RESULTS file (module docstring), in the order they first appear. A malformed
    file raises a one-line InputError naming its line and column."""
    path = Path(path)
    text = _text_of(path, name)
    where = str(path)
    # comments as empty lines, so that the reader's line numbers are the file's
    lines = ["\n" if line.lstrip().startswith("#") else line for line in text.splitlines(keepends=True)]
    reader = csv.reader(lines)
    header = None
    scenes: list[SubmittedScene] = []
    index: dict[tuple, list[SubmittedScene]] = {}
    try:
        for cells in reader:
            line = reader.line_num
            if not any(c.strip() for c in cells):
                continue
            if header is None:
                header = _header(cells, where, line)
                continue
            if len(cells) != len(header):
                raise InputError(f"{where} line {line}: {len(cells)} cells, the header has {len(header)} columns")
            _add_row(scenes, index, dict(zip(header, (c.strip() for c in cells))), where, line)
    except csv.Error as exc:
        raise InputError(f"{where} line {reader.line_num}: not CSV ({exc})") from None
    if header is None:
        raise InputError(f"{where} is empty: expected a header line with the columns {', '.join(REQUIRED_COLUMNS)}")
    return scenes


def _header(cells: list[str], where: str, line: int) -> list[str]:
    header = [c.strip() for c in cells]
    repeated = sorted({c for c in header if c and header.count(c) > 1})
    if repeated:
        raise InputError(f"{where} line {line}: column {repeated[0]} appears twice in the header")
    missing = [c for c in REQUIRED_COLUMNS if c not in header]
    if missing:
        raise InputError(f"{where} line {line}: column {missing[0]} is missing from the header (required: "
                         f"{', '.join(REQUIRED_COLUMNS)}; optional: kind, {', '.join(CURVE_COLUMNS)})")
    return header


def _number(row: dict, column: str, where: str, line: int, required: bool) -> float | None:
    cell = row.get(column, "")
    if cell == "":
        if required:
            raise InputError(f"{where} line {line}, column {column}: empty; a number is required")
        return None
    try:
        value = float(cell)
    except ValueError:
        raise InputError(f"{where} line {line}, column {column}: {cell!r} is not a number") from None
    if not math.isfinite(value):
        raise InputError(f"{where} line {line}, column {column}: {cell!r} is not a finite number")
    test, words = RANGES[column]
    if not test(value):
        raise InputError(f"{where} line {line}, column {column}: {value:g} {words}")
    return value


#: The width of a cell of the scene index in log(dL/L), log(W/L), log(L/b): two values within
#: MATCH_TOLERANCE relative lie in the same or neighbouring cells.
_CELL = -math.log1p(-MATCH_TOLERANCE)


def _cells(key: list[float]) -> tuple[int, ...]:
    return tuple(math.floor(math.log(v) / _CELL) for v in key[:3])


def _scene_of(index: dict, key: list[float]) -> SubmittedScene | None:
    """The first scene (in file order) the row's dL/L, W/L, L/b, nu belong to (SubmittedScene.same),
    looked up in the cells about the key: each row costs 27 look-ups, not a scan of every scene."""
    cells, nu = _cells(key), key[3]
    found = [s for shift in itertools.product((-1, 0, 1), repeat=3)
             for s in index.get((nu,) + tuple(c + d for c, d in zip(cells, shift)), ()) if s.same(*key)]
    return min(found, key=lambda s: s.line, default=None)


def _add_row(scenes: list[SubmittedScene], index: dict, row: dict, where: str, line: int) -> None:
    kind = row.get("kind", "") or "thresholds"
    if kind not in KINDS:
        raise InputError(f"{where} line {line}, column kind: {kind!r} is not one of {', '.join(KINDS)}")
    key = [_number(row, c, where, line, True) for c in SCENE_COLUMNS]
    scene = _scene_of(index, key)
    if scene is None:
        scene = SubmittedScene(*key, line)
        scenes.append(scene)
        index.setdefault((key[3],) + _cells(key), []).append(scene)
    if kind == "thresholds":
        for column in CURVE_COLUMNS:
            if row.get(column, "") != "":
                raise InputError(f"{where} line {line}, column {column}: a thresholds row leaves it empty (give "
                                 f"the H_mid curve on rows of kind H_mid)")
        if scene.thresholds_line is not None:
            raise InputError(f"{where} line {line}, columns {', '.join(SCENE_COLUMNS)}: a second thresholds row "
                             f"of the scene of line {scene.thresholds_line} ({scene.describe()})")
        scene.thresholds_line = line
        scene.dW1 = _number(row, "dW1_over_L", where, line, False)
        scene.dW2 = _number(row, "dW2_over_L", where, line, False)
        return
    for column in CURVE_COLUMNS:
        if column not in row:
            raise InputError(f"{where} line {line}, column {column}: missing from the header; an H_mid row needs "
                             f"the columns {' and '.join(CURVE_COLUMNS)}")
    for column in ("dW1_over_L", "dW2_over_L"):
        if row[column] != "":
            raise InputError(f"{where} line {line}, column {column}: an H_mid row leaves it empty (give the "
                             f"thresholds on the scene's thresholds row)")
    dw, h = (_number(row, c, where, line, True) for c in CURVE_COLUMNS)
    earlier = scene.point_lines.get(dw)
    if earlier is not None:
        raise InputError(f"{where} line {line}, column dW_over_L: dW/L = {dw:g} is already on line {earlier} "
                         f"of the scene's H_mid curve ({scene.describe()})")
    scene.curve.append((dw, h, line))
    scene.point_lines[dw] = line


# --- the scores ---------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Score:
    """One benchmark scene and quantity (QUANTITIES) scored (module docstring): submitted and benchmark
    values (for H_mid/L at the point of largest |difference|, at_dW_over_L, of `points` compared), the
    benchmark's error bar there, the signed difference, in_error_bars and within; None where not scored,
    `note` saying why."""
    scene: BenchmarkScene
    quantity: str
    submitted: float | None = None
    benchmark: float | None = None
    error_bar: float | None = None
    difference: float | None = None
    in_error_bars: float | None = None
    within: bool | None = None
    at_dW_over_L: float | None = None
    points: int | None = None
    line: int | None = None
    note: str = ""

    @property
    def scored(self) -> bool:
        return self.in_error_bars is not None

    def row(self) -> dict:
        """score.csv's row."""
        return {"benchmark_version": BENCHMARK_VERSION, "scene": self.scene.name, "label": self.scene.label,
                **_scene_cells(self.scene), "quantity": self.quantity, "submitted": self.submitted,
                "benchmark": self.benchmark, "error_bar": self.error_bar, "difference": self.difference,
                "in_error_bars": self.in_error_bars, "within": self.within, "at_dW_over_L": self.at_dW_over_L,
                "points": self.points, "line": self.line, "note": self.note}


def threshold_score(scene: BenchmarkScene, submitted: SubmittedScene | None, key: str) -> Score:
    """dW1/L or dW2/L of a submitted scene (None: not submitted) against the benchmark's."""
    estimate: Estimate | None = scene.study.threshold(key)
    ours = None if submitted is None else submitted.threshold(key)
    line = None if submitted is None else submitted.thresholds_line
    base = Score(scene, f"{key}_over_L", ours, None if estimate is None else estimate.value,
                 None if estimate is None else estimate.error_bar, line=line)
    if estimate is None:
        return _with(base, note="no benchmark value: the FEM study has none")
    if submitted is None or submitted.thresholds_line is None:
        return _with(base, note="not submitted")
    if ours is None:
        return _with(base, note="empty: not found by the submitted code")
    difference = ours - estimate.value
    if not estimate.error_bar:
        return _with(base, difference=difference, note="the benchmark value has no error bar")
    return _with(base, difference=difference, in_error_bars=abs(difference) / estimate.error_bar,
                 within=abs(difference) <= estimate.error_bar)


def curve_score(scene: BenchmarkScene, submitted: SubmittedScene | None) -> Score:
    """The submitted H_mid/L curve against the benchmark's (module docstring)."""
    curve = scene.study.curve
    base = Score(scene, "H_mid_over_L", line=None if submitted is None or not submitted.curve
                 else submitted.curve[0][2])
    if submitted is None or not submitted.curve:
        return _with(base, note="not submitted")
    if curve is None:
        return _with(base, note="no benchmark curve: the FEM study has none")
    if len(submitted.curve) < 2:
        return _with(base, note="the submitted curve has one point; two or more are needed")
    dw, h = (np.array(v) for v in zip(*sorted((p[0], p[1]) for p in submitted.curve)))
    own = [submitted.dW1, submitted.dW2]
    keep, difference = difference_away_from_thresholds(curve, scene.study.thresholds() + own, dw, h, THRESHOLD_BAND)
    if not np.any(keep):
        return _with(base, note=f"no benchmark point inside the submitted curve's range (dW/L {dw[0]:g} to "
                                f"{dw[-1]:g}) more than {THRESHOLD_BAND:g} from the thresholds")
    bar = np.maximum(curve.error_bar[keep], H_MID_ERROR_BAR_FLOOR)
    worst = int(np.argmax(np.abs(difference)))
    note = (f"largest |difference| at dW/L = {curve.dw[keep][worst]:.4f} of {int(keep.sum())} points; "
            f"in_error_bars: the largest pointwise |difference| / error bar")
    if dw[-1] < curve.dw[-1] - 1e-9:
        note += f"; compared up to dW/L = {dw[-1]:.4f} (the benchmark goes to {curve.dw[-1]:.4f})"
    return _with(base, submitted=float(difference[worst] + curve.value[keep][worst]),
                 benchmark=float(curve.value[keep][worst]), error_bar=float(curve.error_bar[keep][worst]),
                 difference=float(difference[worst]), in_error_bars=float(np.max(np.abs(difference) / bar)),
                 within=bool(np.all(np.abs(difference) <= bar)), at_dW_over_L=float(curve.dw[keep][worst]),
                 points=int(keep.sum()), note=note)


def _with(score: Score, **changes) -> Score:
    return replace(score, **changes)


@dataclass
class Scorecard:
    """The scores of every benchmark scene (three per scene, QUANTITIES order), the submitted scene each
    matched (None: not submitted) and the submitted scenes that match none."""
    scenes: list[BenchmarkScene]
    matched: dict[str, SubmittedScene]
    unmatched: list[SubmittedScene]
    scores: list[Score]

    def of(self, scene: BenchmarkScene) -> list[Score]:
        return [s for s in self.scores if s.scene.name == scene.name]


def score_results(scenes: list[BenchmarkScene], submitted: list[SubmittedScene]) -> Scorecard:
    """Each submitted scene matched to a benchmark scene (module docstring) and scored."""
    matched, unmatched = {}, []
    for entry in submitted:
        scene = next((s for s in scenes if s.matches(entry)), None)
        if scene is None:
            unmatched.append(entry)
        else:   # two submitted scenes cannot match one: they would be within 0.2 % of each other
            matched[scene.name] = entry
    scores = []
    for scene in scenes:
        entry = matched.get(scene.name)
        scores += [threshold_score(scene, entry, key) for key in THRESHOLDS] + [curve_score(scene, entry)]
    return Scorecard(scenes, matched, unmatched, scores)


# --- the outputs ------------------------------------------------------------------------------------


def _verdict(score: Score) -> str:
    return "within" if score.within else "outside"


def summary_line(scene: BenchmarkScene, scores: list[Score]) -> str:
    """One line per scored scene, e.g. "dL1/2 W1/20 Lb1181: dW1 0.3412 vs 0.3393 +- 0.0019 (1.0 bars)
    within; dW2 ...; H_mid ..."."""
    parts = []
    for s in scores:
        name = s.quantity.replace("_over_L", "")
        if s.quantity == "H_mid_over_L":
            if s.scored:
                parts.append(f"H_mid max |diff| {abs(s.difference):.3g} at dW/L {s.at_dW_over_L:.3f} (+- "
                             f"{s.error_bar:.2g} there; {s.in_error_bars:.1f} bars) {_verdict(s)}")
            else:
                parts.append(f"H_mid {s.note}")
        elif s.scored:
            parts.append(f"dW{name[-1]} {s.submitted:.4f} vs {s.benchmark:.4f} +- {s.error_bar:.4f} "
                         f"({s.in_error_bars:.1f} bars) {_verdict(s)}")
        else:
            parts.append(f"{name} {s.note}" if s.submitted is None else f"{name} {s.submitted:.4f} ({s.note})")
    return f"{scene.label}: " + "; ".join(parts)


def _cell(value, spec: str = "{:.4f}") -> str:
    if value is None:
        return MISSING
    if isinstance(value, bool):
        return "yes" if value else "no"
    return spec.format(value)


def markdown(card: Scorecard, source: str) -> str:
    """score.md: the counts, the table (one line per scene and quantity) and its legend."""
    scored = [s for s in card.scores if s.scored]
    lines = [f"# Scorecard against the thin-strip shear benchmark {BENCHMARK_VERSION} (validation/score.py)", "",
             f"Results: {source}. Scenes submitted: {len(card.matched)} of {len(card.scenes)}; quantities scored: "
             f"{len(scored)}, within the benchmark's error bar: {sum(bool(s.within) for s in scored)}.", ""]
    if card.unmatched:
        lines += [f"No benchmark scene at: {'; '.join(f'{u.describe()} (line {u.line})' for u in card.unmatched)}.",
                  ""]
    lines += ["| scene | quantity | submitted | benchmark \u00b1 error bar | difference | in error bars | within | "
              "note |", "|---|---|---:|---:|---:|---:|---|---|"]
    for s in card.scores:
        spec, bar_spec = ("{:.4g}", "{:.2g}") if s.quantity == "H_mid_over_L" else ("{:.4f}", "{:.4f}")
        bench = MISSING if s.benchmark is None else (
            spec.format(s.benchmark) + ("" if s.error_bar is None else " \u00b1 " + bar_spec.format(s.error_bar)))
        note = "" if s.scored and s.quantity != "H_mid_over_L" else s.note
        lines.append(f"| {s.scene.label} | {s.quantity.replace('_over_L', '/L')} | {_cell(s.submitted, spec)} | "
                     f"{bench} | {_cell(s.difference, '{:+.3g}')} | {_cell(s.in_error_bars, '{:.1f}')} | "
                     f"{_cell(s.within)} | {note} |")
    legend = (f"dW1/L (U -> US) and dW2/L (US -> S) in units of L; the benchmark is the FEM shell's converged value "
              f"with its error bar (data/fem_gold, the rule of its README.md). difference = submitted - benchmark; "
              f"in error bars = |difference| / error bar; within: |difference| <= error bar. H_mid/L: over the "
              f"benchmark curve's points inside the submitted curve's range and more than {THRESHOLD_BAND:g} from "
              f"the benchmark's and the submitted thresholds, the largest |difference| (the submitted, benchmark "
              f"and error bar columns at that point) and the largest |difference| / pointwise error bar (the bar "
              f"counted as at least {H_MID_ERROR_BAR_FLOOR:g} L); within: every point within its bar. "
              f"{MISSING}: none. The benchmark's files: `python -m validation score --benchmark DIR`.")
    return "\n".join(lines) + "\n\n" + legend + "\n"


def figure(card: Scorecard, path: Path) -> Path | None:
    """score.png: dW1/L and dW2/L against W/L, one colour per dL/L and L/b, the benchmark with its error
    bars (open circles) and the submitted values (crosses); None with one line naming the extra if
    matplotlib is missing."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("figure skipped: matplotlib is missing (pip install 'ddg-strips[plot]')", file=sys.stderr)
        return None
    series = sorted({(s.compression_ratio, round(s.slenderness)) for s in card.scenes}, key=lambda k: (-k[0], k[1]))
    colours = {k: f"C{i % 10}" for i, k in enumerate(series)}
    fig, axes = plt.subplots(1, 2, figsize=(9.5, 4.0))
    for ax, key, title in zip(axes, THRESHOLDS, ("dW1/L (U -> US)", "dW2/L (US -> S)")):
        for group in series:
            members = sorted((s for s in card.scenes if (s.compression_ratio, round(s.slenderness)) == group),
                             key=lambda s: s.width_ratio)
            bench = [(s.width_ratio, s.study.threshold(key)) for s in members if s.study.threshold(key) is not None]
            if bench:
                ax.errorbar([w for w, _ in bench], [e.value for _, e in bench],
                            yerr=[e.error_bar or 0.0 for _, e in bench], color=colours[group], marker="o",
                            mfc="none", ms=5, lw=0.8, capsize=2.5,
                            label=f"dL/L = {fraction_label(group[0])}, L/b = {group[1]}")
            ours = [(s.width_ratio, card.matched[s.name].threshold(key)) for s in members
                    if s.name in card.matched and card.matched[s.name].threshold(key) is not None]
            if ours:
                ax.plot([w for w, _ in ours], [v for _, v in ours], ls="", marker="x", ms=7, color=colours[group])
        ax.set_xscale("log")
        widths = sorted({s.width_ratio for s in card.scenes})
        ax.set_xticks(widths, [fraction_label(w) for w in widths], fontsize=7)
        ax.minorticks_off()
        ax.set_xlabel("W/L")
        ax.set_title(title, fontsize=9)
        ax.tick_params(labelsize=7)
    axes[0].legend(fontsize=6, frameon=False)
    fig.text(0.01, 0.01, f"benchmark {BENCHMARK_VERSION}: FEM converged value \u00b1 error bar (open circles); "
             "submitted: crosses", fontsize=7)
    fig.tight_layout(rect=(0, 0.04, 1, 1))
    save_figure(fig, path, dpi=100)
    plt.close(fig)
    return path


def write_scorecard(card: Scorecard, out: Path, source: str) -> list[Path]:
    """OUT/score.csv, OUT/score.md and OUT/score.png (when matplotlib is installed)."""
    out = Path(out)
    write_table_csv(out / "score.csv", [s.row() for s in card.scores], list(SCORE_COLUMNS))
    atomic_write_text(out / "score.md", markdown(card, source))
    png = figure(card, out / "score.png")
    return [out / "score.csv", out / "score.md"] + ([png] if png is not None else [])


def run(args) -> int:
    """`python -m validation score` (validation/__main__.py parses the arguments): the template, the
    benchmark's files, or the scorecard of RESULTS. Every input is checked before anything is written;
    a bad one is one line on stderr and exit 2."""
    try:
        actions = [a for a in (args.results is not None, args.template is not None, args.benchmark is not None) if a]
        if len(actions) != 1:
            raise InputError("give one of RESULTS (to score it), --template FILE or --benchmark DIR")
        scenes = load_benchmark()
        if args.template is not None:
            target = Path(args.template)
            if target.is_dir():
                raise InputError(f"--template = {args.template!r} is a directory; give a file name")
            if target.exists() and not target.is_file():   # the template replaces its target (atomic rename)
                raise InputError(f"--template = {args.template!r} exists and is not a regular file (a FIFO or "
                                 "a device); give a file name")
            try:
                target.parent.mkdir(parents=True, exist_ok=True)
                write_template(target, scenes)
            except OSError as exc:
                raise InputError(f"--template = {args.template!r} cannot be written: {exc.strerror or exc}") from None
            print(f"template: {target} ({len(scenes)} scenes of benchmark {BENCHMARK_VERSION})")
            return 0
        if args.benchmark is not None:
            written = write_benchmark_files(check_output_directory(args.benchmark, "--benchmark"), scenes)
            print(f"benchmark {BENCHMARK_VERSION} ({len(scenes)} scenes): {', '.join(map(str, written))}")
            return 0
        if Path(args.out).exists() and not Path(args.out).is_dir():
            raise InputError(f"--out = {args.out!r} exists and is not a directory")
        submitted = read_results(args.results)
        out = check_output_directory(args.out, "--out")
    except InputError as exc:
        sys.stderr.write(f"error: {exc}\n")
        return 2
    card = score_results(scenes, submitted)
    written = write_scorecard(card, out, str(args.results))
    for scene in card.scenes:
        if scene.name in card.matched:
            print(summary_line(scene, card.of(scene)))
    missing = [s.label for s in card.scenes if s.name not in card.matched]
    if missing:
        print(f"not submitted: {len(missing)} of {len(card.scenes)} benchmark scenes ({', '.join(missing)})")
    for entry in card.unmatched:
        print(f"no benchmark scene at {entry.describe()} (line {entry.line}): not scored")
    print(f"score (benchmark {BENCHMARK_VERSION}): {', '.join(map(str, written))}")
    return 0
