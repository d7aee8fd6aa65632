"""Compile and cache every numba kernel once, so that a user's first run pays no JIT cost.

    python -m ddg warmup

runs each compiled kernel on a tiny model with every argument type the solvers use (energy only,
gradient, gradient and Hessian; rod, ribbons, plate; the array interfaces used in analysis). numba
stores the machine code next to the modules (`cache=True`, in `__pycache__`); later processes
load it (~0.2 s for all kernels) instead of compiling (838 s with an empty cache on a 2-core machine
beside other runs, measured in the CI of 7337dec; 456 s idle before the wide ribbons' terms joined
the compiled solvers). scripts/setup.sh calls it.
"""
from __future__ import annotations

import time

import numpy as np


def compile_kernels() -> dict:
    """Run every kernel once; returns the seconds spent per group (compiling where not cached)."""
    from .energies.hinge_bending import hinge_bending_energy, triangle_normals
    from .energies.rod_curvature import material_curvatures, strain_derivatives
    from .energies.stretch import stretching_energy
    from .geometry.frames import parallel_transport, reference_twist
    from .geometry.strip import Strip
    from .models.plate import PlateModel
    from .models.ribbon import RibbonModel
    from .models.rod import RodModel
    from .models.midedge_plate import MEMBRANES, MidedgePlateModel
    from .models.wide_ribbons import CrossSectionRibbon, SanoWadaRibbon, TrapezeRibbon, WunderlichRibbon
    from .solve.banded import SymmetricBanded
    from .solve.lanczos import lowest_eigenvalue

    strip = Strip.from_ratios(1 / 6, 0.5)
    rng = np.random.default_rng(0)
    timings = {}

    def timed(name, work):
        start = time.perf_counter()
        work()
        timings[name] = round(time.perf_counter() - start, 3)

    def models():
        # every model the API offers (ddg.api.DEFAULT_RESOLUTION): a model left out here compiles its
        # kernels in the user's first run (the cross-section ribbon's took 80 s and 2.2 GB, measured)
        for model in (RodModel(strip, 9), RibbonModel(strip, 9), SanoWadaRibbon(strip, 9), TrapezeRibbon(strip, 9),
                      CrossSectionRibbon(strip, 9), WunderlichRibbon(strip, 9, zeta=0.01 * strip.length),
                      PlateModel(strip, 40), *(MidedgePlateModel(strip, 40, membrane=m) for m in MEMBRANES)):
            q = model.reset()
            q = q + 1e-3 * strip.length * rng.standard_normal(q.shape)
            model.commit(q)
            for gradient, hessian in ((False, False), (True, False), (True, True)):
                model.evaluate(q, gradient=gradient, hessian=hessian)

    def arrays():
        x = np.cumsum(rng.standard_normal((6, 3)), axis=0)
        t = x[1:] - x[:-1]
        t /= np.linalg.norm(t, axis=1)[:, None]
        d1 = np.cross(t, rng.standard_normal(t.shape))
        d1 /= np.linalg.norm(d1, axis=1)[:, None]
        m2 = np.cross(t, d1)
        parallel_transport(d1, t, t[::-1].copy())
        reference_twist(d1, t)
        reference_twist(d1, t, np.zeros(len(t) - 1))
        material_curvatures(x, d1, m2)
        strain_derivatives(x, d1, m2)
        for gradient, hessian in ((False, False), (True, False), (True, True)):
            stretching_energy(t, np.ones(len(t)), 1.0, gradient=gradient, hessian=hessian)
        plate = PlateModel(strip, 40)
        xp = plate.reset().reshape(-1, 3)
        triangle_normals(xp, plate.mesh.triangles)
        # linear algebra: Lanczos on the Cholesky factor, LDL^T of an indefinite band (both paths)
        for bandwidth in (3, 40):
            band = np.zeros((bandwidth + 1, 60))
            band[0] = np.linspace(-1.0, 3.0, 60)
            band[1, :-1] = 0.1
            SymmetricBanded(band).solve(np.ones(60))
            band[0] += 2.0
            spd = SymmetricBanded(band)
            if spd.cholesky():
                lowest_eigenvalue(spd.cholesky_factor, np.ones(60))
        for gradient, hessian in ((False, False), (True, False), (True, True)):
            hinge_bending_energy(xp, plate.mesh.triangles, plate.mesh.hinge_triangles, plate.hinge_stiffness,
                                 gradient=gradient, hessian=hessian)

    def solvers():
        # the compiled Newton load step and pseudo-arclength corrector of the rod family
        # (ddg.solve.compiled_newton): one specialisation serves the rod and the Sadowsky ribbons
        from .solve.arclength import ArclengthTracer
        from .solve.newton import NewtonOptions, newton
        from .solve.state import State

        model = RodModel(strip, 9)
        compression = 0.3 * strip.length
        q = model.apply_clamps(model.buckled_guess(compression), compression, 0.0)
        result = newton(model, q, NewtonOptions())
        start = State(result.q, result.evaluation, compression, 0.0, True)
        ArclengthTracer(model, NewtonOptions()).trace(start, max_points=1)

    timed("models", models)
    timed("compiled solvers", solvers)
    timed("array interfaces", arrays)
    return timings


def main() -> int:
    start = time.perf_counter()
    timings = compile_kernels()
    parts = ", ".join(f"{k} {v:.1f} s" for k, v in timings.items())
    print(f"ddg kernels compiled and cached in {time.perf_counter() - start:.1f} s ({parts})")
    return 0
