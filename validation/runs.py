"""Runs of the validation report: what to run (RunSpec), where its result is cached, running many.

A run is one `ddg.simulate` call (rod, plate or ribbon) on one scene. Its results (path.csv,
summary.json, branches.csv) are cached under CACHE/<key>/, where key is a hash of the run's inputs
and of the ddg source code, so a rerun computes only what changed and an interrupted report
resumes without losing finished runs (a run counts as finished once CACHE/<key>/spec.json exists;
it is written last, atomically). The specification, the cache and the Dask runner are those of
`python -m ddg sweep` (ddg.sweep: grid, tasks, cache, cluster): one implementation for both.
FEM reference curves are not run here: they are read from the gold data in data/fem_gold
(validation/reference.py load_gold), which `python -m fem_reference gold --out data/fem_gold`
regenerates (data/fem_gold/README.md).
"""
from __future__ import annotations

import sys
from pathlib import Path

from ddg.sweep.cache import Progress, run_cached
from ddg.sweep.grid import RunSpec, code_version, estimated_cost
from ddg.sweep.tasks import RunResult, execute_one, load

ROOT = Path(__file__).resolve().parent.parent

__all__ = ["Progress", "RunResult", "RunSpec", "code_version", "estimated_cost", "execute_one", "load", "run_all"]


def execute_quietly(*args, **kwargs):
    """execute_one without printing its ddg.ValidityWarning: each run's summary.json keeps them
    (`warnings`), and the report reads them from there. `execute_one` is looked up in this module
    at each call, so a test may replace it."""
    import warnings

    from ddg import ValidityWarning

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ValidityWarning)
        return execute_one(*args, **kwargs)


def run_all(specs: list[RunSpec], cache: Path, jobs: int = 1, progress: bool = True,
            scheduler: str | None = None) -> dict[RunSpec, RunResult]:
    """Every spec's result, from the cache where present, else computed: as Dask tasks on a
    LocalCluster of `jobs` worker processes, or on `scheduler` (an existing cluster's address;
    default: Dask's DASK_SCHEDULER_ADDRESS setting, if any). With jobs = 1 and no scheduler, the
    runs are computed here one at a time. A run that failed is missing from the result;
    KeyboardInterrupt propagates (the finished runs stay cached)."""
    from ddg.sweep.cluster import default_scheduler, require_dask

    scheduler = scheduler or default_scheduler()
    in_process = jobs <= 1 and scheduler is None
    if not in_process:
        try:
            require_dask()
        except ValueError as exc:  # ddg.InputError: dask is missing; run here, one at a time
            sys.stderr.write(f"note: {exc}; running the report's runs in this process, one at a time\n")
            in_process = True
    outcome = run_cached(specs, cache, execute_quietly, workers=jobs, scheduler=scheduler, progress=progress,
                         in_process=in_process)
    if outcome.interrupted is not None:
        raise outcome.interrupted
    return outcome.results
