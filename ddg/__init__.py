"""Discrete-differential-geometry solvers for thin elastic strips (rod, plate, ribbon)."""
from . import api
from .api import run_ribbon, simulate
from .output import io
from .output.io import StoredRun
from .protocol.results import SimulationResult
from .protocol.validity import ValidityWarning
from .limits import InputError
from .geometry.strip import LoadingProtocol, Strip, shear_limit
from .solve.continuation import ContinuationOptions
from .solve.newton import NewtonOptions
from .version import __version__



def read_run(directory) -> StoredRun:
    """A run's output folder read back (path.csv, summary.json, branches.csv if any): a StoredRun
    with .rows, .summary, .column(name, stage), .arrays(), .to_dataframe()."""
    return StoredRun(directory)


__all__ = ["ContinuationOptions", "InputError", "LoadingProtocol", "NewtonOptions", "SimulationResult", "StoredRun",
           "Strip", "ValidityWarning", "api", "io", "read_run", "run_ribbon", "shear_limit", "simulate", "__version__"]
