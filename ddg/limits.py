"""What this machine can run: bounds on sizes (node counts, triangles, steps) checked before any
work, with the memory a size needs estimated and compared with the memory available.

Every check raises ddg.InputError with a one-line message naming the value and the allowed
range, so the command line exits 2 before it computes anything.
"""
from __future__ import annotations

import math
import numbers
import os

from .geometry.strip import MAX_RECORDED_STEPS  # noqa: F401  (re-exported: one bound for every stepper)
from .geometry.strip import InputError

#: Fraction of the machine's physical memory one run may plan to use. The physical memory, not
#: what happens to be free now, so that a size is accepted or refused the same way on a busy and an
#: idle machine (24 GiB here: runs up to 18 GiB).
MEMORY_FRACTION = 0.75

GIB = 2.0**30


def available_memory_bytes() -> float:
    """The memory a run may count on: the machine's physical memory in bytes (default 8 GiB where
    it cannot be read); tests replace it to make the checks independent of the machine."""
    try:
        return float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):
        return 8.0 * GIB


def check_integer(name: str, value, low: int, high: int, why: str = "") -> int:
    """value as an int in [low, high] (bools, fractions, NaN and text refused)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        if isinstance(value, numbers.Real) and not isinstance(value, bool) and math.isfinite(value) \
                and float(value).is_integer():
            value = int(value)
        else:
            raise InputError(f"{name} = {value!r} must be an integer in [{low}, {high}]")
    value = int(value)
    if not low <= value <= high:
        raise InputError(f"{name} = {value} outside the allowed range [{low}, {high}]{'; ' + why if why else ''}")
    return value


def check_memory(name: str, value, estimate_bytes: float, budget_bytes: float | None = None) -> None:
    """Refuse a size whose estimated memory exceeds MEMORY_FRACTION of the physical memory."""
    budget = MEMORY_FRACTION * available_memory_bytes() if budget_bytes is None else budget_bytes
    if estimate_bytes > budget:
        raise InputError(f"{name} = {value} needs about {estimate_bytes / GIB:.3g} GiB; this machine allows "
                         f"{budget / GIB:.3g} GiB for a run ({100 * MEMORY_FRACTION:g} % of its memory)")


def check_steps(name: str, value) -> int:
    """A recorded step count in [1, MAX_RECORDED_STEPS]."""
    return check_integer(name, value, 1, MAX_RECORDED_STEPS)
