"""`python -m ddg sweep`: a grid of runs as Dask tasks (being built; issue 15 item 7)."""
from __future__ import annotations


def add_arguments(parser) -> None:
    """The sweep command's options."""


def main(args) -> int:
    """Run the sweep; returns the exit code."""
    from ..geometry.strip import InputError

    raise InputError("ddg sweep is not available yet")
