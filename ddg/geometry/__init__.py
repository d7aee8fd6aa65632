"""Geometry of the strip: the validated Strip and LoadingProtocol, the centerline and clamps,
frames, plate meshes (structured, from arrays, from files and gmsh)."""
from ..limits import InputError
from .strip import LoadingProtocol, Strip, shear_limit

__all__ = ["InputError", "LoadingProtocol", "Strip", "shear_limit"]
