from .strip import InputError, LoadingProtocol, Strip, shear_limit

__all__ = ["InputError", "LoadingProtocol", "Strip", "shear_limit"]
