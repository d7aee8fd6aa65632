from .rod import RodModel

__all__ = ["RodModel"]
