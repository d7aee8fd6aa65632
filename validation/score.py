"""The scorecard: another code's thresholds and H_mid curve scored against the FEM benchmark,
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
import io
import sys
from pathlib import Path

from ddg.geometry.strip import InputError
from ddg.output.io import atomic_write_text, check_output_directory, write_table_csv

from .command_line import standalone
from .scoring.card import MISSING, SCORE_COLUMNS, figure, markdown, summary_line, write_scorecard
from .scoring.results import (CURVE_COLUMNS, KINDS, MAX_RESULTS_BYTES, RANGES, REQUIRED_COLUMNS, SubmittedScene,
                              read_results)
from .scoring.scenes import (BENCHMARK_POISSON_RATIO, BENCHMARK_RELEASES, BENCHMARK_VERSION, MATCH_TOLERANCE,
                             QUANTITIES, SCENE_COLUMNS, THRESHOLDS, BenchmarkScene, benchmark_digest, benchmark_rows,
                             curve_rows, load_benchmark, scene_cells)
from .scoring.scores import (H_MID_ERROR_BAR_FLOOR, Score, Scorecard, curve_score, score_results,
                             threshold_score)

__all__ = ["BENCHMARK_POISSON_RATIO", "BENCHMARK_RELEASES", "BENCHMARK_VERSION", "CURVE_COLUMNS",
           "H_MID_ERROR_BAR_FLOOR", "KINDS", "MATCH_TOLERANCE", "MAX_RESULTS_BYTES", "MISSING", "QUANTITIES", "RANGES",
           "REQUIRED_COLUMNS", "SCENE_COLUMNS", "SCORE_COLUMNS", "THRESHOLDS", "BenchmarkScene", "Score", "Scorecard",
           "SubmittedScene", "add_arguments", "benchmark_digest", "benchmark_rows", "curve_rows", "curve_score",
           "figure", "load_benchmark", "main", "markdown", "read_results", "run", "score_results", "summary_line",
           "threshold_score", "write_benchmark_files", "write_scorecard", "write_template"]


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
        writer.writerow(["thresholds"] + [repr(float(v)) for v in scene_cells(scene).values()] + [""] * 4)
    atomic_write_text(Path(path), buf.getvalue())


def add_arguments(parser) -> None:
    """The options of `python -m validation score`."""
    parser.description = ("Score another code's thresholds and H_mid curves (a CSV file) against the FEM benchmark: "
                          "DIR/score.csv, score.md, score.png.")
    parser.add_argument("results", nargs="?", default=None, metavar="RESULTS",
                        help="the CSV file to score (format: validation/score.py, or write a template with --template)")
    parser.add_argument("--out", default="out/score", help="output directory (default out/score)")
    parser.add_argument("--template", default=None, metavar="FILE",
                        help="write a RESULTS template with a row per benchmark scene to FILE and exit")
    parser.add_argument("--benchmark", default=None, metavar="DIR",
                        help="write the benchmark (benchmark.csv, benchmark_H_mid.csv, README.md) to DIR and exit")


def run(args) -> int:
    """`python -m validation score`: the template, the benchmark's files, or the scorecard of RESULTS.
    Every input is checked before anything is written; a bad one is one line on stderr and exit 2."""
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


def main(argv=None) -> int:
    """`python -m validation.score [options]`: the same as `python -m validation score [options]`."""
    return standalone("score", add_arguments, run, argv)


if __name__ == "__main__":
    raise SystemExit(main())
