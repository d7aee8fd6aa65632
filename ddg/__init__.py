"""Discrete-differential-geometry solvers for thin elastic strips (rod, plate, ribbon)."""
from .geometry.strip import InputError, LoadingProtocol, Strip, shear_limit

__version__ = "0.1.0"


def simulate(*args, **kwargs):
    """See ddg.api.simulate."""
    from .api import simulate as _simulate

    return _simulate(*args, **kwargs)


__all__ = ["InputError", "LoadingProtocol", "Strip", "shear_limit", "simulate", "__version__"]
