"""Discrete-differential-geometry solvers for thin elastic strips (rod, plate, ribbon)."""
from .geometry.strip import InputError, LoadingProtocol, Strip, shear_limit
from .solve.continuation import ContinuationOptions
from .solve.newton import NewtonOptions

__version__ = "0.1.0"


def simulate(*args, **kwargs):
    """See ddg.api.simulate."""
    from .api import simulate as _simulate

    return _simulate(*args, **kwargs)


__all__ = ["ContinuationOptions", "InputError", "LoadingProtocol", "NewtonOptions", "Strip", "shear_limit",
           "simulate", "__version__"]
