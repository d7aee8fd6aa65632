"""What this machine can run: bounds on sizes (node counts, triangles, steps) checked before any
work, with the memory a size needs estimated and compared with the memory available.

Every check raises ddg.InputError with a one-line message naming the value and the allowed
range, so the command line exits 2 before it computes anything.
"""
from __future__ import annotations

import math
import numbers
import os

from .geometry.strip import InputError

from .geometry.strip import MAX_RECORDED_STEPS  # noqa: F401  (re-exported: one bound for every stepper)

#: Fraction of the memory available now that one run may plan to use.
MEMORY_FRACTION = 0.5

GIB = 2.0**30


def available_memory_bytes() -> float:
    """MemAvailable of /proc/meminfo (Linux), else the physical memory; bytes."""
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return float(line.split()[1]) * 1024.0
    except OSError:
        pass
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
    """Refuse a size whose estimated memory exceeds MEMORY_FRACTION of the memory available."""
    budget = MEMORY_FRACTION * available_memory_bytes() if budget_bytes is None else budget_bytes
    if estimate_bytes > budget:
        raise InputError(f"{name} = {value} needs about {estimate_bytes / GIB:.3g} GiB; this machine allows "
                         f"{budget / GIB:.3g} GiB for a run ({100 * MEMORY_FRACTION:g} % of the memory available)")


def check_steps(name: str, value) -> int:
    """A recorded step count in [1, MAX_RECORDED_STEPS]."""
    return check_integer(name, value, 1, MAX_RECORDED_STEPS)
