"""The ground floor for inputs: InputError and the validators every layer uses, and what this
machine can run (bounds on sizes: node counts, triangles, steps, checked before any work, with the
memory a size needs estimated and compared with the memory available).

Every check raises InputError with a one-line message naming the value and the allowed range, so
the command line exits 2 before it computes anything. Nothing here imports the rest of ddg.
"""
from __future__ import annotations

import math
import numbers
import os

import numpy as np

#: Largest recorded steps per stage. A recorded step costs an eigenvalue solve and an observation
#: (3-10 ms on the rod, ~0.1 s on a 2000-triangle plate): 5000 steps take minutes; 1e5 would take
#: hours and gain nothing (the continuation subdivides steps where it must).
MAX_RECORDED_STEPS = 5000


class InputError(ValueError):
    """A scene or solver input outside its allowed range (one-line message)."""


def is_bool(value) -> bool:
    """True and False (Python's or numpy's) are not numbers here: width_ratio=True is a mistake."""
    return isinstance(value, bool) or type(value).__name__ == "bool_"


def require(condition: bool, message: str) -> None:
    """InputError(message) unless condition."""
    if not condition:
        raise InputError(message)


def check_positive(name: str, value) -> float:
    """value as a positive finite float (not a bool)."""
    if is_bool(value):
        raise InputError(f"{name} = {value!r} is a bool; it must be a positive number")
    try:
        value = float(value)
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"{name} = {value!r} is not a number; it must be a positive number") from None
    require(math.isfinite(value) and value > 0.0, f"{name} = {value!r} must be a positive finite number")
    return value


def check_within(name: str, value: float, low: float, high: float, unit: str, why: str) -> float:
    """value within [low, high] (in `unit`), else InputError saying `why` the range is what it is."""
    require(low <= value <= high,
            f"{name} = {value:g}{unit} outside the allowed range [{low:g}, {high:g}]{unit}; {why}")
    return value


def check_option(owner: str, name: str, value, kind: str, low=None, high=None, *, low_open: bool = False,
                 allow_none: bool = False):
    """One field of an options object: kind 'int', 'float' or 'bool', within [low, high] (low
    excluded if low_open); a one-line InputError naming the value and the allowed range."""
    if value is None and allow_none:
        return None
    where = f"{owner}({name}={value!r})"
    lo = "(" if low_open else "["
    span = f"{lo}{low:g}, {high:g}]" if low is not None and high is not None else ""
    if kind == "bool":
        if not isinstance(value, (bool, np.bool_)):
            raise InputError(f"{where}: must be True or False")
        return bool(value)
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise InputError(f"{where}: must be {'an integer' if kind == 'int' else 'a number'} in {span}"
                         + (" or None" if allow_none else ""))
    if kind == "int":
        if isinstance(value, (float, np.floating)) and not float(value).is_integer():
            raise InputError(f"{where}: must be an integer in {span}")
        value = int(value)
    else:
        value = float(value)
        if not math.isfinite(value):
            raise InputError(f"{where}: must be a finite number in {span}")
    if (low is not None and (value <= low if low_open else value < low)) or (high is not None and value > high):
        raise InputError(f"{where}: outside the allowed range {span}")
    return value


def check_ratios(name: str, values, low: float, high: float, low_inclusive: bool = False) -> list[float]:
    """Parse a list of ratios within (low, high] ([low, high] with low_inclusive); InputError naming
    the bad value otherwise."""
    out = []
    bracket = "[" if low_inclusive else "("
    for v in values:
        try:
            f = float(v)
        except (TypeError, ValueError):
            raise InputError(f"{name} = {v!r} is not a number; allowed {bracket}{low:g}, {high:g}]") from None
        if not ((low <= f if low_inclusive else low < f) and f <= high):
            raise InputError(f"{name} = {f:g} outside the allowed range {bracket}{low:g}, {high:g}]")
        out.append(f)
    return out


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
