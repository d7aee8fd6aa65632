"""Large arrays kept mapped from one Newton iteration to the next (glibc's malloc).

A plate's banded Hessian holds (bandwidth + 1) n doubles; on fine meshes that is tens to hundreds
of megabytes (the mid-edge plate on 28 rows at W/L = 1/6: 96 MB), and every iteration makes
several such arrays: the Hessian, its free block, the Cholesky factor's copy. glibc's malloc
serves a block above its mmap threshold (adjusted at run time, but never above 32 MiB) with fresh
pages from the kernel, so each of these arrays pays a page fault per 4 KiB page when it is first
written: zeroing and touching 96 MB took 90 ms, against 6 ms for the same block taken again from
the heap (docs/findings/measured.md). `keep_large_blocks` raises the mmap and trim thresholds
so that blocks up to LARGEST_HEAP_BLOCK come from the heap and stay mapped after they are freed:
the process keeps its peak memory instead of returning it between iterations.

It acts once per process, only under glibc, only when a model asks for a block above glibc's
own ceiling, and not at all with DDG_MALLOC=default in the environment.
"""
from __future__ import annotations

import ctypes
import os
import sys

#: glibc's ceiling for its self-adjusting mmap threshold on 64-bit systems (DEFAULT_MMAP_THRESHOLD_MAX)
GLIBC_DYNAMIC_CEILING = 32 * 1024 * 1024
#: blocks up to this size are served from the heap once keep_large_blocks has acted
LARGEST_HEAP_BLOCK = 1 << 30
#: mallopt's parameters (malloc.h)
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3

_state = {"done": False, "active": False}


def keep_large_blocks(nbytes: int) -> bool:
    """Serve blocks of up to LARGEST_HEAP_BLOCK bytes from the heap from now on, if a block of
    `nbytes` is above glibc's dynamic ceiling (module docstring). Returns whether the thresholds
    are raised (now or by an earlier call)."""
    if _state["done"] or nbytes <= GLIBC_DYNAMIC_CEILING:
        return _state["active"]
    _state["done"] = True
    if os.environ.get("DDG_MALLOC", "").strip().lower() == "default" or not sys.platform.startswith("linux"):
        return False
    try:
        libc = ctypes.CDLL("libc.so.6")
        version = libc.gnu_get_libc_version  # glibc only (musl has no mallopt thresholds)
    except (OSError, AttributeError):
        return False
    del version
    ok = libc.mallopt(_M_MMAP_THRESHOLD, LARGEST_HEAP_BLOCK) == 1
    ok = ok and libc.mallopt(_M_TRIM_THRESHOLD, LARGEST_HEAP_BLOCK) == 1
    _state["active"] = bool(ok)
    return _state["active"]
