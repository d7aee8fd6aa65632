"""Discrete-differential-geometry solvers for thin elastic strips (rod, plate, ribbon)."""
from .api import run_ribbon, simulate
from .geometry.strip import InputError, LoadingProtocol, Strip, shear_limit
from .solve.continuation import ContinuationOptions
from .solve.newton import NewtonOptions
from .version import __version__

__all__ = ["ContinuationOptions", "InputError", "LoadingProtocol", "NewtonOptions", "Strip", "run_ribbon",
           "shear_limit", "simulate", "__version__"]
