"""Large arrays kept mapped from one Newton iteration to the next (glibc's malloc).

A plate's banded Hessian holds (bandwidth + 1) n doubles, megabytes to hundreds of megabytes on
fine meshes, and every iteration makes three such arrays (the Hessian, its free
block, the Cholesky factor's copy) and frees them. glibc serves a block above its mmap threshold
(self-adjusting, at most 32 MiB) with fresh pages from the kernel, and returns the heap's free top
to the kernel once it exceeds the trim threshold (twice the mmap one), which three freed
Hessian-sized blocks do: either way the next iteration's arrays are fresh pages again, and each
pays a page fault per 4 KiB page when first written, where a block taken again from the heap is
already mapped (measured in benchmarks/results/plate_iteration.md and docs/findings/measured.md).
`keep_large_blocks` raises both thresholds to LARGEST_HEAP_BLOCK, so
that such blocks come from the heap and stay mapped after they are freed: the process keeps its
peak memory instead of returning it between iterations.

It acts once per process, only under glibc, only when a model asks for a Hessian above ACT_ABOVE
bytes, and not at all with DDG_MALLOC=default in the environment.
"""
from __future__ import annotations

import ctypes
import os
import sys

#: a Hessian above this makes the process keep large blocks (the rods' and the coarse plates' stay
#: below it: their arrays are small enough for glibc's own adjustment)
ACT_ABOVE = 1024 * 1024
#: blocks up to this size are served from the heap once keep_large_blocks has acted
LARGEST_HEAP_BLOCK = 1 << 30
#: mallopt's parameters (malloc.h)
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3

_state = {"done": False, "active": False}


def keep_large_blocks(nbytes: int) -> bool:
    """Serve blocks of up to LARGEST_HEAP_BLOCK bytes from the heap from now on, if a Hessian of
    `nbytes` is above ACT_ABOVE (module docstring). Returns whether the thresholds are raised (now
    or by an earlier call)."""
    if _state["done"] or nbytes <= ACT_ABOVE:
        return _state["active"]
    _state["done"] = True
    if os.environ.get("DDG_MALLOC", "").strip().lower() == "default" or not sys.platform.startswith("linux"):
        return False
    try:
        libc = ctypes.CDLL("libc.so.6")
    except OSError:
        return False
    if not hasattr(libc, "gnu_get_libc_version"):  # glibc only (musl has no mallopt thresholds)
        return False
    ok = libc.mallopt(_M_MMAP_THRESHOLD, LARGEST_HEAP_BLOCK) == 1
    ok = ok and libc.mallopt(_M_TRIM_THRESHOLD, LARGEST_HEAP_BLOCK) == 1
    _state["active"] = bool(ok)
    return _state["active"]
