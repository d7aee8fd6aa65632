"""A RESULTS file read and checked: the scenes another code submits, each with its thresholds and H_mid
curve, every value in its physical range, a malformed file refused in one line naming its line and
column (validation/score.py's docstring: "The results format")."""
from __future__ import annotations

import csv
import itertools
import math
import os
import stat
from dataclasses import dataclass, field
from pathlib import Path

from ddg.geometry.strip import SLENDERNESS_RANGE, InputError

from .scenes import MATCH_TOLERANCE, SCENE_COLUMNS, close

#: The largest RESULTS file read (bytes), checked before reading it. The benchmark's own H_mid curves
#: written as a results file (3295 points of 28 scenes) weigh 0.4 MB; 8 MiB is 20 times that, and a
#: bound on what is read into memory (/dev/zero, a runaway writer).
MAX_RESULTS_BYTES = 8 * 2**20
REQUIRED_COLUMNS = SCENE_COLUMNS + ("dW1_over_L", "dW2_over_L")
CURVE_COLUMNS = ("dW_over_L", "H_mid_over_L")
KINDS = ("thresholds", "H_mid")


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
        return poisson_ratio == self.poisson_ratio and close(
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
