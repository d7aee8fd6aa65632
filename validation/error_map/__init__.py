"""The error map: the error of every model at every resolution on every scene with a converged FEM
reference, and its wall time:
`python -m validation error-map --out data/error_map [--only SCENE ...] [--models MODEL ...]
[--workers N | --scheduler ADDRESS] [--retries 2]` (old spelling `python -m validation.error_map`).

Scenes (scenes): the ten of the benchmark (dL/L in {1/2, 1/4} x W/L in {1/20, 1/12, 1/6, 1/3, 1/2},
the paper's strip: L/b = 1181 at dL/L = 1/2, 787 at 1/4), each referenced by the FEM shell's mesh
study in data/fem_gold (validation.estimates.load_study: Richardson extrapolation with the observed
order and Roache's grid convergence index where asymptotic, else the finest value with the
spread), the map's further scenes of fem_reference.gold with such a study, and the narrow strip
W/L = 1/20, dL/L = 1/2 at L/b = 300 and 100 (data/narrow_limit: the FEM on 64 x 8 and 96 x 12
elements, read as a two-mesh study by validation.estimates.study_from_runs: the finer value, the
spread as error bar) where no study replaces it.

Rows (rows), one per (model, resolution, scene): the rod at M = 50/100/200 and every other model of
the rod's family registered in ddg.api.DEFAULT_RESOLUTION at run time (the ribbons) at M =
51/101/201, run here (compute); the plate at each mesh of its study (data/plate_gold/<scene>/R*,
data/narrow_limit/Lb*/plate_R*), the mid-edge plate where data/midedge_gold has it and the FEM at
each mesh of its study (data/fem_gold/<scene>/N*x*, data/narrow_limit/Lb*/fem_N*), read, not rerun.
Per row, for q in dW1/L, dW2/L: |q - reference| (q_error), the reference's error bar
(q_ref_error_bar) and their sum (q_bound); for H_mid/L, on the reference curve's dW grid inside the
run's range and more than THRESHOLD_BAND = 0.02 from the reference's dW1 and dW2 and from the run's
own (validation.claims), the largest |H_mid - reference| (H_mid_error), the largest reference error
bar (H_mid_ref_error_bar) and the largest pointwise sum (H_mid_bound, as
validation.estimates.Study.mesh_error); the wall time of the run (summary.json wall_time_s: path
and thresholds) and a reason where a value is missing. A bound is left empty where the run did not
complete its path (its comparison would cover part of the path only). ddg.advise reads the q_bound
columns.

Resumable: a row is written to OUT/error_map.csv (atomically, the whole table) as soon as it is
computed; a rerun keeps a row whose model, resolution and scene match with the same source hash
(the ddg sources, validation.runs.code_version, for the runs made here; the run's summary.json for
the stored ones), the same reference hash (the reference study's files) and the same rules
(rows.RULES_VERSION), and recomputes any other. Then OUT/README.md (readme_writer; the held-out
check of the prediction, held_out) and two figures (plots, drawn by validation.figures;
matplotlib, extra `plot`): OUT/speed_accuracy.png and OUT/enough_map.png.

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
line; command).
"""
from __future__ import annotations

from ddg.advise import QUANTITIES

from ..claims import THRESHOLD_BAND
from ..figures.error_map import FAMILY_MARKERS
from ..reference import FEM_GOLD, ROOT
from ..table import Table
from .command import add_arguments, main, run
from .compute import MAX_TIMEOUT, RUN_TIMEOUT, build, run_row, stored_row
from .held_out import HELD_OUT_FIRST, HELD_OUT_SECOND, TOLERANCES, held_out_check, held_out_targets, load_rows
from .plots import figures
from .readme_writer import held_out_section, readme
from .rows import (COLUMNS, CSV_NAME, FAILED, KEY, REFERENCE_PATH_SLACK, RULES_VERSION, cheapest_within,
                   combined_error, is_current, open_table, put_row, read_table, row_errors, within)
from .scenes import (HELD_OUT_SCENES, MAP_SCENES, NARROW, NARROW_SLENDERNESS, NEW_MAP_SCENES, PLATE_MODELS,
                     RIBBON_RESOLUTIONS, ROD_RESOLUTIONS, UNREAD_STUDY_KEYS, ReferenceScene, StoredMesh,
                     check_selection, map_models, missing_scenes, reference_scenes, rod_family, study_hash)

#: The old private name of scenes.study_hash, which tests import from here.
_study_hash = study_hash

__all__ = ["COLUMNS", "CSV_NAME", "FAILED", "FAMILY_MARKERS", "FEM_GOLD", "HELD_OUT_FIRST", "HELD_OUT_SCENES",
           "HELD_OUT_SECOND", "KEY", "MAP_SCENES", "MAX_TIMEOUT", "NARROW", "NARROW_SLENDERNESS", "NEW_MAP_SCENES",
           "PLATE_MODELS", "QUANTITIES", "REFERENCE_PATH_SLACK", "RIBBON_RESOLUTIONS", "ROD_RESOLUTIONS", "ROOT",
           "RULES_VERSION", "RUN_TIMEOUT", "ReferenceScene", "StoredMesh", "THRESHOLD_BAND", "TOLERANCES", "Table",
           "UNREAD_STUDY_KEYS", "add_arguments", "build", "cheapest_within", "check_selection", "combined_error",
           "figures", "held_out_check", "held_out_section", "held_out_targets", "is_current", "load_rows", "main",
           "map_models", "missing_scenes", "open_table", "put_row", "read_table", "readme", "reference_scenes",
           "rod_family", "row_errors", "run", "run_row", "stored_row", "study_hash", "within"]
