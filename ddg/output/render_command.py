"""`python -m ddg render DIR`: draw a run's frames with pyvista (being built; issue 15 item 8)."""
from __future__ import annotations


def add_arguments(parser) -> None:
    """The render command's options."""


def main(args) -> int:
    """Render; returns the exit code."""
    from ..geometry.strip import InputError

    raise InputError("ddg render is not available yet")
