"""Discrete-differential-geometry solvers for thin elastic strips (rod, plate, ribbon)."""
from .geometry.strip import InputError, LoadingProtocol, Strip, shear_limit

__version__ = "0.1.0"

__all__ = ["InputError", "LoadingProtocol", "Strip", "shear_limit", "__version__"]
