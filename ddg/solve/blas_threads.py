"""BLAS threads during a run: the band factorisations single-threaded.

The solvers' linear algebra is banded Cholesky, LDL^T and LU of bandwidth 10-200 (ddg.solve.banded)
and shift-invert Lanczos on them: too small for a multi-threaded BLAS to gain, and a threaded BLAS
whose other thread waits for a busy core spins (what that costs: docs/findings/measured.md, "BLAS
threads"; benchmarks/plate_linear_algebra.py and benchmarks/plate_under_load.py measure it).

`blas_threads()` is the context every run executes in (ddg.protocol.driver.execute, so the
command line, the API, sweeps and the report alike): the BLAS libraries this process has loaded
run with DDG_BLAS_THREADS threads (default 1, at most MAX_THREADS = 256; "keep" leaves them as they
are), and get their previous setting back when the run ends, so a program that calls ddg keeps its
own. It acts on the libraries threadpoolctl controls, if that package is installed, else on an
OpenBLAS found among the process's loaded libraries (Linux: /proc/self/maps; Debian's
libopenblas0-pthread); where neither applies it does nothing and says so in `describe()`.
"""
from __future__ import annotations

import ctypes
import os
import threading
from contextlib import contextmanager

from ..limits import InputError

__all__ = ["blas_threads", "requested_threads", "describe"]

#: Environment variable: the BLAS threads of a run (an integer in 1..MAX_THREADS, or "keep").
ENVIRONMENT = "DDG_BLAS_THREADS"
#: Most BLAS threads a run may ask for: above the cores of any machine this runs on (OpenBLAS's own
#: builds stop at their compile-time NUM_THREADS, 64 to 512), so a larger value is a typo, not a
#: choice; each thread is a pthread with its own buffers, and 1e9 of them is no run at all.
MAX_THREADS = 256


def requested_threads() -> int | None:
    """The threads DDG_BLAS_THREADS asks for: 1 by default, None for "keep"; a one-line InputError
    naming the value and the allowed range otherwise (the command lines call this before any work,
    exit 2)."""
    value = os.environ.get(ENVIRONMENT, "1").strip()
    if value.lower() == "keep":
        return None
    try:
        threads = int(value)
    except ValueError:
        threads = 0
    if not 1 <= threads <= MAX_THREADS:
        shown = repr(value) if len(value) <= 40 else repr(value[:40]) + "..."
        raise InputError(f"{ENVIRONMENT} = {shown} must be an integer in [1, {MAX_THREADS}] or 'keep'")
    return threads


def _openblas_libraries() -> list:
    """ctypes handles of the loaded libraries that export openblas_set_num_threads (each OpenBLAS
    once: Debian's libblas.so.3 and liblapack.so.3 resolve the symbol in libopenblas)."""
    import scipy.linalg  # noqa: F401  (loads BLAS and LAPACK)

    try:
        with open("/proc/self/maps") as maps:
            paths = sorted({line.split()[-1] for line in maps if "openblas" in line and ".so" in line})
    except OSError:
        paths = []
    handles, seen = [], set()
    for path in paths + ["libopenblas.so.0"]:
        try:
            lib = ctypes.CDLL(path)
            address = ctypes.cast(lib.openblas_set_num_threads, ctypes.c_void_p).value
        except (OSError, AttributeError):
            continue
        if address not in seen:
            seen.add(address)
            handles.append(lib)
    return handles


class _Control:
    """get() / set(n) of the process's BLAS threads through threadpoolctl or OpenBLAS's own calls."""

    def __init__(self):
        self.kind, self._libraries = "none", []
        try:
            import threadpoolctl  # noqa: F401
            self.kind = "threadpoolctl"
        except ImportError:
            self._libraries = _openblas_libraries()
            if self._libraries:
                self.kind = "openblas"

    def get(self):
        if self.kind == "threadpoolctl":
            from threadpoolctl import threadpool_info

            return [(i.get("user_api"), i.get("num_threads")) for i in threadpool_info()]
        return [int(lib.openblas_get_num_threads()) for lib in self._libraries]

    def limit(self, threads: int):
        """Sets `threads`; returns a callable that restores the previous setting."""
        if self.kind == "threadpoolctl":
            from threadpoolctl import threadpool_limits

            limiter = threadpool_limits(limits=threads, user_api="blas")
            return limiter.restore_original_limits
        previous = self.get()
        for lib in self._libraries:
            lib.openblas_set_num_threads(ctypes.c_int(threads))

        def restore():
            for lib, n in zip(self._libraries, previous):
                lib.openblas_set_num_threads(ctypes.c_int(n))
        return restore


_CONTROL = None


def _control() -> _Control:
    global _CONTROL
    if _CONTROL is None:
        _CONTROL = _Control()
    return _CONTROL


def describe() -> dict:
    """What a run's summary records: the threads asked for (None: kept) and how they are set."""
    threads = requested_threads()
    return {"requested": threads, "control": _control().kind if threads is not None else "kept"}


_LOCK = threading.Lock()
_ACTIVE = {"depth": 0, "restore": None}


@contextmanager
def blas_threads():
    """Run the body with the BLAS threads of DDG_BLAS_THREADS (module docstring), then restore.
    Nested or concurrent runs in one process (threads) share the setting: the first to enter sets
    it, the last to leave restores the caller's."""
    threads = requested_threads()
    control = _control() if threads is not None else None
    if control is None or control.kind == "none":
        yield
        return
    with _LOCK:
        if _ACTIVE["depth"] == 0:
            _ACTIVE["restore"] = control.limit(threads)
        _ACTIVE["depth"] += 1
    try:
        yield
    finally:
        with _LOCK:
            _ACTIVE["depth"] -= 1
            if _ACTIVE["depth"] == 0:
                _ACTIVE["restore"]()
                _ACTIVE["restore"] = None
