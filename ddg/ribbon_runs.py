"""Transitional: run_ribbon now lives in ddg.api (the one loading loop, ddg.protocol); this alias
goes once the callers that other work in progress still has are moved."""
from .api import run_ribbon  # noqa: F401
