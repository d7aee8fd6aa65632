"""The sweep from Python: `run_sweep` runs a grid of scenes as Dask tasks (or takes them from the
cache), writes DIR/sweep.csv (DIR/sweep.parquet with pyarrow) and the phase diagram, and returns the
table. `python -m ddg sweep` (ddg.sweep.command) is this function behind a parser.

    from ddg.sweep import run_sweep

    if __name__ == "__main__":        # LocalCluster workers are new processes importing this file
        result = run_sweep(["rod"], width_ratios=[0.05, 1 / 6], compression_ratios=[0.5],
                           resolutions=[50, 100, 200], out="out/sweep", workers=2)
        result.rows[0]["dW1_over_L"], result.complete, result.files

Every value is checked before any work (InputError naming the value and its allowed range); a
missing dask install or an unreachable scheduler is an InputError too, raised before the output
folder is created (the scheduler is connected to first). Each run is cached in
DIR/runs/<key>/ by a hash of its inputs and of the ddg sources, so a second call computes only what
is missing. Ctrl-C tables the finished runs, then raises KeyboardInterrupt.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from ..limits import InputError
from ..models.names import ROD
from .cache import Outcome

#: The paper's widths (the FEM gold scenes): W/L = 1/20, 1/12, 1/6, 1/3, 1/2.
PAPER_WIDTHS = (0.05, 1 / 12, 1 / 6, 1 / 3, 0.5)
#: Most values a list takes (as the other commands' list options).
MAX_LIST_VALUES = 50


@dataclass
class SweepResult:
    """What a sweep did: `rows` the table (sweep.csv's columns, ddg.sweep.table.COLUMNS, one dict per
    run that finished or failed, in grid order), `files` the files written (table, figures), `outcome`
    the cache's account (computed, cached, errors, retried runs, where they ran, wall time), `out`
    the sweep folder, `interrupted` the KeyboardInterrupt or signal that stopped it (None if none)."""

    rows: list[dict]
    files: list[Path]
    outcome: Outcome
    out: Path
    interrupted: BaseException | None = None
    notes: list[str] = field(default_factory=list)

    @property
    def runs(self) -> int:
        """The grid's run count (each has its folder in the outcome, finished or not)."""
        return len(self.outcome.directories)

    @property
    def complete(self) -> bool:
        """True if every run of the grid finished with status complete."""
        return self.interrupted is None and len(self.rows) == self.runs and not self.incomplete

    @property
    def incomplete(self) -> list[dict]:
        """The rows of the runs that did not complete (status stopped, error, ...)."""
        return [r for r in self.rows if r["status"] != "complete"]

    def to_dataframe(self):
        """The table as a pandas DataFrame (extra [dataframe])."""
        from ..output.io import require_pandas

        return require_pandas("result.rows gives the same table as dicts").DataFrame(self.rows)


def run_sweep(models=(ROD,), width_ratios=PAPER_WIDTHS, compression_ratios=(0.5, 0.25), slendernesses=None,
              resolutions=None, *, out="out/sweep", compression_steps: int = 40, shear_steps: int = 120,
              workers: int | None = None, scheduler: str | None = None, retries: int = 2, progress: bool = False,
              figure: bool = True) -> SweepResult:
    """Run every combination of `models` x `compression_ratios` x `width_ratios` x `slendernesses`
    (L/b; None: the paper's strip, b = 0.127 mm with the clamps 75 mm apart after compression) x
    `resolutions` (rod/ribbon node counts M, plate target triangle counts; None: each model's
    default) as Dask tasks: on `scheduler` (an address, e.g. "tcp://host:8786"; default
    DASK_SCHEDULER_ADDRESS if set) or on a LocalCluster of `workers` single-threaded processes
    (default one per core). Each run records `compression_steps` and `shear_steps` equilibria and
    locates dW1 and dW2 (no branch tracing). Writes OUT/runs/<key>/ per run, OUT/sweep.csv and, if
    `figure` and matplotlib imports, OUT/phase_diagram.png/.pdf (the paper's Fig. 8 with the FEM
    gold's thresholds). Returns a SweepResult; raises InputError before any work for a bad value,
    and KeyboardInterrupt after tabling the finished runs if interrupted."""
    result = sweep(models, width_ratios, compression_ratios, slendernesses, resolutions, out=out,
                   compression_steps=compression_steps, shear_steps=shear_steps, workers=workers,
                   scheduler=scheduler, retries=retries, progress=progress, figure=figure)
    if result.interrupted is not None:
        raise result.interrupted
    return result


def sweep(models, width_ratios, compression_ratios, slendernesses=None, resolutions=None, *, out,
          compression_steps=40, shear_steps=120, workers=None, scheduler=None, retries=2, progress=False,
          figure=True, names=None) -> SweepResult:
    """run_sweep without re-raising an interruption (the command line turns it into an exit code).
    `names` maps each argument to the name its errors use (the command line's option names)."""
    from ..output.interrupts import deferred_signals
    from ..output.io import check_output_directory
    from ..solve.blas_threads import requested_threads
    from . import cluster
    from .cache import run_cached
    from .grid import grid
    from .table import sweep_rows, write_table

    n = {"models": "models", "width_ratios": "width_ratios", "compression_ratios": "compression_ratios",
         "slendernesses": "slendernesses", "resolutions": "resolutions", "out": "out", **(names or {})}
    specs = grid(checked_models(n["models"], models), checked_ratios(n["width_ratios"], width_ratios, 1.0),
                 checked_ratios(n["compression_ratios"], compression_ratios, 1.0),
                 [None] if slendernesses is None else checked_ratios(n["slendernesses"], slendernesses, float("inf")),
                 [None] if resolutions is None else checked_integers(n["resolutions"], resolutions),
                 compression_steps, shear_steps)
    scheduler, workers, retries = cluster.checked_options(scheduler, workers, retries)
    requested_threads()   # a bad DDG_BLAS_THREADS would fail every run on its worker
    scheduler = cluster.ready(scheduler, workers)   # connected to once: an unreachable one leaves no folder
    out = check_output_directory(out, n["out"])

    outcome = run_cached(specs, out / "runs", workers=workers, scheduler=scheduler, retries=retries,
                         progress=progress)
    notes = []
    with deferred_signals():  # a second Ctrl-C does not cut the table in half
        rows = sweep_rows(specs, outcome, out)
        files = write_table(out, rows)
        if figure:
            try:
                from .figure import write_phase_diagram

                files += write_phase_diagram(out, rows)[0]
            except ImportError:
                notes.append("matplotlib is not installed: the phase diagram was skipped "
                             "(install the 'plot' extra: pip install ddg-strips[plot])")
    notes += [f"{spec.label}: an earlier attempt did not finish (its worker was killed or stopped); the run was "
              "redone" for spec in outcome.retried]
    return SweepResult(rows, files, outcome, out, outcome.interrupted, notes)


def list_values(values) -> list[str]:
    """A list option's values: a string of comma- or space-separated values, or a sequence of them
    (each item may itself be comma-separated, as the command line passes them)."""
    if isinstance(values, (str, int, float)):
        values = [values]
    return [v.strip() for text in values for v in str(text).replace(",", " ").split() if v.strip()]


def counted(name: str, values: list) -> list:
    """`values`, if there are 1 to MAX_LIST_VALUES of them; InputError naming `name` otherwise."""
    if not 1 <= len(values) <= MAX_LIST_VALUES:
        raise InputError(f"{name} has {len(values)} values; allowed 1 to {MAX_LIST_VALUES}")
    return values


def checked_models(name: str, values) -> list[str]:
    """The model names, each one of ddg.sweep.grid.MODELS."""
    from .grid import MODELS

    models = counted(name, list_values(values))
    for v in models:
        if v not in MODELS:
            raise InputError(f"{name} {v!r} is not available; choose from {', '.join(MODELS)}")
    return models


def checked_ratios(name: str, values, high: float) -> list[float]:
    """Numbers in (0, high]; `name` may carry a symbol after the option ("--width-ratios W/L")."""
    from ..limits import check_ratios

    return check_ratios(name, counted(name.split()[0], list_values(values)), 0.0, high)


def checked_integers(name: str, values) -> list[int]:
    """Integers (the resolutions; each model's range is checked with the grid)."""
    from ..api import MAX_NODES, MAX_TRIANGLES
    from ..geometry.centerline import MIN_NODES

    out = []
    for v in counted(name, list_values(values)):
        try:
            out.append(int(v))
        except ValueError:
            raise InputError(f"{name} {v!r} is not an integer; allowed: rod/ribbon M in [{MIN_NODES}, {MAX_NODES}], "
                             f"plate triangles in [16, {MAX_TRIANGLES}]") from None
    return out
