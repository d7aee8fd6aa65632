"""Sweeps of runs over a grid of scenes, executed as tasks on Dask: `run_sweep` from Python
(ddg.sweep.run), `python -m ddg sweep` from the command line (ddg.sweep.command)."""
from .run import SweepResult, run_sweep

__all__ = ["SweepResult", "run_sweep"]
