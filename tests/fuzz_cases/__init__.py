"""The cases of tests/test_fuzz_inputs.py (issue 13, "no traceback on any input"), generated from tables.

The package's modules, whose names it re-exports (fuzz_cases.Case, fuzz_cases.BAD_VALUES, ...):
case (the Case record, what a case expects, at_most), command_lines (the bad command lines of ddg and
fem_reference: the base commands and the table of bad values), edge_cases (valid edge cases, the
cases run for real, the cases run as a subprocess), api (the API cases), validation_commands (issue 47
item 3: the validation commands, ddg sweep, schedulers, DDG_BLAS_THREADS) and report (the failing
cases of a DDG_FUZZ_RECORD file by cause); all_in_process_cases collects the cases run in the process.

Placeholders in argv: {tmp} is the case's temporary directory (cwd of the case), {out} a fresh
output directory inside it. Every case's {tmp} holds file.txt (a regular file), empty.msh (an
empty file), dir/ (an empty directory), garbage.msh (binary noise), header.msh (a gmsh header
without nodes), mesh.xyz (an unknown format), loop (a symlink to itself), dangling (a symlink to
nothing), run-corrupt/ (summary.json not JSON), run-keys/ (summary.json without the keys), fifo (a
named pipe: opening it for reading blocks) and the results files of `validation score` (RESULTS_FILES).

Everything is deterministic: no random numbers, the same cases in the same order on every run.
"""
from __future__ import annotations

from .api import api_bad_cases, api_valid_cases
from .case import ACCEPT, REFUSE, RUN, Case, at_most
from .command_lines import (BAD_VALUES, BELOW_MINIMUM, DDG_CENTERLINE_ERROR, DDG_CURVATURES, DDG_SIMULATE,
                            DDG_SIMULATE_TAIL, FEM_CONVERGENCE, FEM_GOLD, FEM_SCENE, FEM_SIMULATE, OUT_BAD,
                            SCENE_OPTIONS, SIZE_BAD, STEPS_BAD, ddg_bad_cases, ddg_simulate, fem_bad_cases, value_label)
from .edge_cases import run_cases, subprocess_cases, valid_cases
from .report import report
from .validation_commands import (ERROR_MAP, NO_SCHEDULER, PLATE_GOLD, REPORT, RESULTS_FILES, RESULTS_HEADER, SCORE,
                                  SUBCOMMANDS, SWEEP, VALIDATION_MAINS, issue47_api_cases, issue47_bad_cases,
                                  issue47_valid_cases)

__all__ = ["ACCEPT", "BAD_VALUES", "BELOW_MINIMUM", "Case", "DDG_CENTERLINE_ERROR", "DDG_CURVATURES", "DDG_SIMULATE",
           "DDG_SIMULATE_TAIL", "ERROR_MAP", "FEM_CONVERGENCE", "FEM_GOLD", "FEM_SCENE", "FEM_SIMULATE",
           "NO_SCHEDULER", "OUT_BAD", "PLATE_GOLD", "REFUSE", "REPORT", "RESULTS_FILES", "RESULTS_HEADER", "RUN",
           "SCENE_OPTIONS", "SCORE", "SIZE_BAD", "STEPS_BAD", "SUBCOMMANDS", "SWEEP", "VALIDATION_MAINS",
           "all_in_process_cases", "api_bad_cases", "api_valid_cases", "at_most", "ddg_bad_cases", "ddg_simulate",
           "fem_bad_cases", "issue47_api_cases", "issue47_bad_cases", "issue47_valid_cases", "report", "run_cases",
           "subprocess_cases", "valid_cases", "value_label"]


def all_in_process_cases() -> list[Case]:
    cases = ddg_bad_cases() + fem_bad_cases() + api_bad_cases() + valid_cases() + api_valid_cases()
    cases += issue47_bad_cases() + issue47_valid_cases()
    cases += issue47_api_cases()
    ids = [c.id for c in cases]
    duplicates = sorted({i for i in ids if ids.count(i) > 1})
    assert not duplicates, f"duplicate case ids: {duplicates}"
    return cases
