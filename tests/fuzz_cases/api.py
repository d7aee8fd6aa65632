"""The API cases: small functions (Case.call) that build the objects (ddg.Strip, Strip.from_ratios,
LoadingProtocol, NewtonOptions, ContinuationOptions, DynamicOptions) and, if construction passes, call
ddg.simulate with a tiny scene; bad values (api_bad_cases) and valid edge values (api_valid_cases)."""
from __future__ import annotations

import math
from typing import Callable

from .case import ACCEPT, Case


_DEFAULT = object()


def _simulate(tmp, strip=_DEFAULT, protocol=_DEFAULT, **kwargs):
    """ddg.simulate on a tiny rod scene, with the given pieces replaced."""
    import ddg

    if strip is _DEFAULT:
        strip = ddg.Strip.from_ratios(0.05, 0.5)
    if protocol is _DEFAULT:
        protocol = ddg.LoadingProtocol(0.5, 0.05, compression_steps=2, shear_steps=2)
    kwargs.setdefault("out", str(tmp / "out"))
    kwargs.setdefault("resolution", 20)
    kwargs.setdefault("thresholds", False)
    kwargs.setdefault("branches", False)
    return ddg.simulate(strip, protocol, **kwargs)


def _strip(**kwargs):
    def call(tmp):
        import ddg

        base = {"length": 0.15, "width": 0.0075, "thickness": 0.127e-3}
        _simulate(tmp, strip=ddg.Strip(**{**base, **kwargs}))
    return call


def _from_ratios(**kwargs):
    def call(tmp):
        import ddg

        base = {"width_ratio": 0.05, "compression_ratio": 0.5}
        _simulate(tmp, strip=ddg.Strip.from_ratios(**{**base, **kwargs}))
    return call


def _protocol(**kwargs):
    def call(tmp):
        import ddg

        base = {"compression_ratio": 0.5, "shear_ratio": 0.05, "compression_steps": 2, "shear_steps": 2}
        _simulate(tmp, protocol=ddg.LoadingProtocol(**{**base, **kwargs}))
    return call


def _newton(**kwargs):
    def call(tmp):
        import ddg

        _simulate(tmp, options=ddg.ContinuationOptions(newton=ddg.NewtonOptions(**kwargs)))
    return call


def _continuation(**kwargs):
    def call(tmp):
        import ddg

        _simulate(tmp, options=ddg.ContinuationOptions(**kwargs))
    return call


def _call(**kwargs):
    def call(tmp):
        resolved = {k: (v(tmp) if callable(v) else v) for k, v in kwargs.items()}
        _simulate(tmp, **resolved)
    return call


def _dynamic(**kwargs):
    def call(tmp):
        from ddg.solve.dynamics import DynamicOptions

        _simulate(tmp, solver="dynamic", dynamic_options=DynamicOptions(**kwargs))
    return call


def _mutated(kind: str, name: str, value):
    """Build a valid options object, then set one field to a bad value (the dataclasses are mutable)."""
    def call(tmp):
        import ddg
        from ddg.solve.dynamics import DynamicOptions

        if kind == "dynamic":
            options = DynamicOptions()
            setattr(options, name, value)
            _simulate(tmp, solver="dynamic", dynamic_options=options)
            return
        options = ddg.ContinuationOptions()
        setattr(options.newton if kind == "newton" else options, name, value)
        _simulate(tmp, options=options)
    return call


NAN, INF = math.nan, math.inf


def _api_table() -> list[tuple[str, str, Callable]]:
    """(id, object, call) of the bad API inputs."""
    rows: list[tuple[str, str, Callable]] = []

    def add(obj, label, call):
        rows.append((f"api-{obj}-{label}", obj, call))

    # Strip: float range (1e300, 1e-300), non-finite, bools
    add("Strip", "length-1e300", _strip(length=1e300, width=0.01, thickness=1e-4))
    add("Strip", "length-1e300-scaled", _strip(length=1e300, width=5e298, thickness=1e297))
    add("Strip", "length-1e-300-scaled", _strip(length=1e-300, width=5e-302, thickness=1e-304))
    add("Strip", "thickness-1e-300", _strip(thickness=1e-300))
    add("Strip", "width-1e-300", _strip(width=1e-300, thickness=1e-301))
    for value in (NAN, INF, -1.0, 0.0, True, None, "abc"):
        add("Strip", f"length-{value!r}", _strip(length=value))
    for value in (5e-324, 1e-300, 1e300, NAN, INF, 0.0, True):
        add("Strip", f"young_modulus-{value!r}", _strip(young_modulus=value))
    for value in (0.5, -0.1, NAN, False, True):
        add("Strip", f"poisson_ratio-{value!r}", _strip(poisson_ratio=value))
    for value in (NAN, 0.0, -1.0):
        add("Strip", f"density-{value!r}", _strip(density=value))
    # Strip.from_ratios
    for value in (True, False, NAN, None, 1e-300, 1.5, "abc"):
        add("Strip.from_ratios", f"width_ratio-{value!r}", _from_ratios(width_ratio=value))
    for value in (True, 0.999999, 1.0, 0.0, NAN):
        add("Strip.from_ratios", f"compression_ratio-{value!r}", _from_ratios(compression_ratio=value))
    for value in (True, 1e12, 1e300, 5e-324, 0.0, NAN, INF):
        add("Strip.from_ratios", f"slenderness-{value!r}", _from_ratios(slenderness=value))
    # LoadingProtocol
    for value in (10**6, 5001, 0, -1, 2.5, True, None, NAN):
        add("LoadingProtocol", f"compression_steps-{value!r}", _protocol(compression_steps=value))
    for value in (10**6, 0, True):
        add("LoadingProtocol", f"shear_steps-{value!r}", _protocol(shear_steps=value))
    for value in (NAN, True, 0.0, 1.0):
        add("LoadingProtocol", f"compression_ratio-{value!r}", _protocol(compression_ratio=value))
    for value in (NAN, -0.1, "abc", 1e300, 0.9, True):
        add("LoadingProtocol", f"shear_ratio-{value!r}", _protocol(shear_ratio=value))
    for value in (0, 2, True, -1.5):
        add("LoadingProtocol", f"shear_sign-{value!r}", _protocol(shear_sign=value))
    # NewtonOptions
    for value in (0, -1, 2.5, True, 10**9, None):
        add("NewtonOptions", f"max_iterations-{value!r}", _newton(max_iterations=value))
    for value in (NAN, -1.0, INF):
        add("NewtonOptions", f"residual_tol-{value!r}", _newton(residual_tol=value))
    for value in (NAN, -1.0):
        add("NewtonOptions", f"step_tol-{value!r}", _newton(step_tol=value))
    for value in (0, 10**9):
        add("NewtonOptions", f"max_line_search-{value!r}", _newton(max_line_search=value))
    for value in (0, -1):
        add("NewtonOptions", f"give_up_after-{value!r}", _newton(give_up_after=value))
    for value in (NAN, -1.0, 1.5):
        add("NewtonOptions", f"give_up_ratio-{value!r}", _newton(give_up_ratio=value))
    for value in (NAN, 0.0, -0.5, 1.5, True, "x"):
        add("NewtonOptions", f"contraction_limit-{value!r}", _newton(contraction_limit=value))
    # ContinuationOptions
    for value in (0.0, -1.0, NAN, 2.0):
        add("ContinuationOptions", f"min_substep-{value!r}", _continuation(min_substep=value))
    for value in ("x", None):
        add("ContinuationOptions", f"predictor-{value!r}", _continuation(predictor=value))
    for value in (0, 2, True):
        add("ContinuationOptions", f"branch_sign-{value!r}", _continuation(branch_sign=value))
    add("ContinuationOptions", "newton-'x'", _continuation(newton="x"))
    add("ContinuationOptions", "easy_iterations--1", _continuation(easy_iterations=-1))
    for value in (NAN, 0.0, 1e300):
        add("ContinuationOptions", f"kick-{value!r}", _continuation(kick=value))
    add("ContinuationOptions", "jump_substep-nan", _continuation(jump_substep=NAN))
    add("ContinuationOptions", "grow_after-0", _continuation(grow_after=0))
    # simulate(...)
    for value in (["rod"], "spaghetti", None, ""):
        add("simulate", f"model-{value!r}", _call(model=value))
    add("simulate", "out-123", _call(out=123))
    add("simulate", "out-empty", _call(out=""))
    add("simulate", "out-existing-file", _call(out=lambda tmp: str(tmp / "file.txt")))
    add("simulate", "out-dev-null", _call(out="/dev/null"))
    add("simulate", "out-under-file", _call(out=lambda tmp: str(tmp / "file.txt" / "sub")))
    add("simulate", "out-name-300-chars", _call(out=lambda tmp: str(tmp / ("x" * 300))))
    for value in (10**9, 10**8, 0, -1, 2.5, True, "20", NAN):
        add("simulate", f"resolution-{value!r}", _call(resolution=value))
    add("simulate", "plate-resolution-100000000", _call(model="plate", resolution=10**8))
    add("simulate", "ribbon-resolution-100000000", _call(model="ribbon", resolution=10**8))
    for value in ("x", None):
        add("simulate", f"solver-{value!r}", _call(solver=value))
    add("simulate", "mesh-with-rod", _call(mesh="gmsh"))
    add("simulate", "frames-without-out", _call(frames=True, out=None))
    add("simulate", "dynamic-with-plate", _call(solver="dynamic", model="plate", resolution=200))
    add("simulate", "options-'x'", _call(options="x"))
    add("simulate", "strip-'x'", _call(strip="x"))
    add("simulate", "protocol-'x'", _call(protocol="x"))
    add("simulate", "dynamic-strip-'x'", _call(strip="x", solver="dynamic"))
    add("simulate", "dynamic-options-'x'", _call(solver="dynamic", dynamic_options="x"))
    add("simulate", "dynamic-resolution-1e9", _call(solver="dynamic", resolution=10**9))
    add("simulate", "dynamic-compression-steps-1e6",
        lambda tmp: _simulate(tmp, solver="dynamic",
                              protocol=__import__("ddg").LoadingProtocol(0.5, 0.05, compression_steps=10**6)))
    add("simulate", "options-NewtonOptions", lambda tmp: _simulate(tmp, options=__import__("ddg").NewtonOptions()))
    add("simulate", "plate-mesh-123", _call(model="plate", resolution=200, mesh=123))
    add("simulate", "plate-mesh-empty-file", _call(model="plate", resolution=200,
                                                   mesh=lambda tmp: str(tmp / "empty.msh")))
    # numpy bools and integers too large for a float
    import numpy as np

    add("Strip.from_ratios", "width_ratio-np.True_", _from_ratios(width_ratio=np.True_))
    add("Strip.from_ratios", "slenderness-np.True_", _from_ratios(slenderness=np.True_))
    add("Strip.from_ratios", "width_ratio-10**400", _from_ratios(width_ratio=10**400))
    add("Strip.from_ratios", "slenderness-10**400", _from_ratios(slenderness=10**400))
    add("Strip", "length-np.True_", _strip(length=np.True_))
    add("LoadingProtocol", "shear_ratio-np.True_", _protocol(shear_ratio=np.True_))
    add("LoadingProtocol", "compression_steps-np.True_", _protocol(compression_steps=np.True_))
    add("simulate", "resolution-np.True_", _call(resolution=np.True_))
    add("simulate", "resolution-10**400", _call(resolution=10**400))
    add("NewtonOptions", "max_iterations-np.True_", _newton(max_iterations=np.True_))
    # option objects are mutable dataclasses: a value set after construction must be refused at the call
    add("NewtonOptions", "mutated-max_iterations-0", _mutated("newton", "max_iterations", 0))
    add("NewtonOptions", "mutated-residual_tol-nan", _mutated("newton", "residual_tol", NAN))
    add("ContinuationOptions", "mutated-min_substep-0", _mutated("continuation", "min_substep", 0.0))
    add("ContinuationOptions", "mutated-predictor-x", _mutated("continuation", "predictor", "x"))
    add("DynamicOptions", "mutated-clamp_speed-0", _mutated("dynamic", "clamp_speed", 0.0))
    add("DynamicOptions", "mutated-time_step-nan", _mutated("dynamic", "time_step", NAN))
    # DynamicOptions (ddg.solve.dynamics)
    for value in (5e-324, 1e-9, 1e300, NAN, True):
        add("DynamicOptions", f"clamp_speed-{value!r}", _dynamic(clamp_speed=value))
    for value in (5e-324, NAN, 0.0):
        add("DynamicOptions", f"time_step-{value!r}", _dynamic(time_step=value))
    add("DynamicOptions", "damping-nan", _dynamic(damping=NAN))
    add("DynamicOptions", "max_halvings--1", _dynamic(max_halvings=-1))
    return rows


def api_bad_cases() -> list[Case]:
    return [Case(case_id, "api", option=obj, call=call) for case_id, obj, call in _api_table()]


def api_valid_cases() -> list[Case]:
    import numpy as np

    rows = (
        ("Strip.from_ratios-width_ratio-1", "Strip.from_ratios", _from_ratios(width_ratio=1)),
        ("Strip.from_ratios-slenderness-100", "Strip.from_ratios", _from_ratios(slenderness=100)),
        ("Strip-paper", "Strip", _strip()),
        ("Strip-poisson_ratio-0.49", "Strip", _strip(poisson_ratio=0.49)),
        ("LoadingProtocol-shear_ratio-0", "LoadingProtocol", _protocol(shear_ratio=0.0)),
        ("LoadingProtocol-shear_ratio-None", "LoadingProtocol", _protocol(shear_ratio=None)),
        ("LoadingProtocol-steps-1", "LoadingProtocol", _protocol(compression_steps=1, shear_steps=1)),
        ("LoadingProtocol-steps-5000", "LoadingProtocol", _protocol(compression_steps=5000, shear_steps=5000)),
        ("LoadingProtocol-shear_sign--1", "LoadingProtocol", _protocol(shear_sign=-1)),
        ("NewtonOptions-max_iterations-1", "NewtonOptions", _newton(max_iterations=1)),
        ("NewtonOptions-give_up_after-None", "NewtonOptions", _newton(give_up_after=None)),
        ("ContinuationOptions-predictor-tangent", "ContinuationOptions", _continuation(predictor="tangent")),
        ("ContinuationOptions-predictor-both", "ContinuationOptions", _continuation(predictor="both")),
        ("ContinuationOptions-branch_sign--1", "ContinuationOptions", _continuation(branch_sign=-1)),
        ("simulate-resolution-7", "simulate", _call(resolution=7)),
        ("simulate-resolution-numpy-int", "simulate", _call(resolution=np.int64(20))),
        ("simulate-plate-resolution-16", "simulate", _call(model="plate", resolution=16)),
        ("simulate-ribbon-resolution-7", "simulate", _call(model="ribbon", resolution=7)),
        ("simulate-out-None", "simulate", _call(out=None)),
        ("simulate-out-pathlib", "simulate", _call(out=lambda tmp: tmp / "pathlib-out")),
        ("simulate-dynamic", "simulate", _call(solver="dynamic")),
    )
    return [Case(f"valid-api-{case_id}", "api", option=obj, expect=ACCEPT, call=call) for case_id, obj, call in rows]
