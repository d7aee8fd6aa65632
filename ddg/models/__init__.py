"""The discrete models: the rod (DAR, Eq. 6), the plate (DEP, Eq. 11) and the Sadowsky ribbon
(Eq. A.5); each assembles its energies (ddg.energies) into a banded gradient and Hessian."""
from .rod import RodModel

__all__ = ["RodModel"]
