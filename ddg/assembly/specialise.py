"""One implementation of a compiled kernel, compiled apart for each value of a compile-time name.

numba compiles a kernel with everything it calls linked in and optimised again, so a kernel that
branches at run time over every model's terms costs every model the compile of all of them (the
rod family's energy with the three ribbons' width terms, and each solver that calls it, took
minutes). `specialise(function, suffix, KIND=...)` compiles `function` with some of its global
names bound to constants: an int that the kernel's `if KIND == ...` tests (numba removes the
branches a constant decides before typing them, so a branch not taken is never compiled), or the
compiled function it calls (a solver bound to one model's energy). Each specialisation is cached
under its own name (the function's qualified name with the suffix: its own index file, so parallel
warm-up processes do not race on one), and compiles on its first call only.
"""
from __future__ import annotations

import types

from numba import njit


def specialise(function, suffix: str, **names):
    """numba.njit(cache=True) of a plain Python `function` with the global `names` bound to the
    given values, cached apart as `<qualname>_<suffix>`. The function's other globals are those of
    its module when this is called (call it after the module has defined them)."""
    namespace = dict(function.__globals__)
    namespace.update(names)
    twin = types.FunctionType(function.__code__, namespace, function.__name__, function.__defaults__,
                              function.__closure__)
    twin.__qualname__ = f"{function.__qualname__}_{suffix}"
    twin.__doc__ = function.__doc__
    twin.__module__ = function.__module__
    return njit(cache=True)(twin)
