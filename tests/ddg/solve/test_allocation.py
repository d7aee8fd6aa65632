"""Large blocks kept in the heap (ddg.solve.allocation): a fine plate's Hessian-sized array, freed
and asked again, comes from memory the process already has, not from fresh pages (no timing: the
allocator's own counters, glibc's mallinfo2). Each case runs in a child process: the setting is
process-wide."""
from __future__ import annotations

import ctypes
import os
import subprocess
import sys

import pytest

CHILD = r"""
import ctypes, sys
import numpy as np
from ddg.solve.allocation import keep_large_blocks

class MallInfo2(ctypes.Structure):
    _fields_ = [(name, ctypes.c_size_t) for name in
                ("arena", "ordblks", "smblks", "hblks", "hblkhd", "usmblks", "fsmblks", "uordblks", "fordblks",
                 "keepcost")]

libc = ctypes.CDLL("libc.so.6")
libc.mallinfo2.restype = MallInfo2
print(keep_large_blocks(int(sys.argv[1])), keep_large_blocks(int(sys.argv[1])))
block = np.zeros(64 * 1024 * 1024 // 8)
block[::512] = 1.0
info = libc.mallinfo2()
print(info.hblkhd >= 64 * 1024 * 1024, info.arena >= 64 * 1024 * 1024)
"""


def glibc_with_mallinfo2() -> bool:
    try:
        return hasattr(ctypes.CDLL("libc.so.6"), "mallinfo2")
    except OSError:
        return False


pytestmark = pytest.mark.skipif(not (sys.platform.startswith("linux") and glibc_with_mallinfo2()),
                                reason="glibc >= 2.33 only (mallopt thresholds, mallinfo2)")


def child(nbytes: int, **env) -> list[str]:
    out = subprocess.run([sys.executable, "-c", CHILD, str(nbytes)], capture_output=True, text=True, check=True,
                         env={**os.environ, **env}, timeout=120)
    return out.stdout.split()


@pytest.mark.parametrize("megabytes", [8.6, 96])
def test_a_plates_hessian_makes_large_blocks_come_from_the_heap(megabytes):
    """A Hessian of 8.6 or 96 MB (the mid-edge plate's on 12 or 28 rows at W/L = 1/6): a 64 MB array
    is then in the heap (arena), not mapped apart (hblkhd), and stays so on a second call."""
    assert child(int(megabytes * 1024 * 1024)) == ["True", "True", "False", "True"]


def test_small_hessians_and_the_opt_out_leave_malloc_alone():
    """A rod's Hessian (below 1 MiB) leaves glibc's own adjustment; so does DDG_MALLOC=default: the
    64 MB array is mapped apart."""
    assert child(100 * 1024) == ["False", "False", "True", "False"]
    assert child(96 * 1024 * 1024, DDG_MALLOC="default") == ["False", "False", "True", "False"]
