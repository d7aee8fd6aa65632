"""Compile and cache the numba kernels once, so that a user's first run pays no JIT cost.

    python -m ddg warmup [--jobs N] [PART ...]

A part is a model of the API (`rod`, `plate`, `plate-midedge`, the ribbons: each model's
kernels, evaluated with every argument type its solvers use, and for the rod family the compiled
Newton load step and pseudo-arclength corrector) or `arrays` (the array interfaces of analysis and
the banded linear algebra every model uses). No part: all of them, spread over N worker
processes (default: the machine's cores, at most 4). numba stores the machine code next to the
modules (`cache=True`, in `__pycache__`); later processes load it instead of compiling. A model
left out here compiles its kernels in the user's first run, and a kernel compiles on first use
anyway: the warm-up only moves that cost to install time (scripts/setup.sh calls it).
benchmarks/compile_time.py measures each part and kernel from an empty cache.
"""
from __future__ import annotations

import os
import sys
import time

import numpy as np

from .models import registry
from .models.names import (CROSS_SECTION_RIBBON, MIDEDGE_PLATE, PLATE, RIBBON, ROD, SANO_WADA_RIBBON, TRAPEZE_RIBBON,
                           WUNDERLICH_RIBBON)

#: The rod family's parts: their compiled energy and loops are compiled per kind of width terms
#: (ddg.models.rod_assembly.ENERGIES); the plates share nothing with them.
ROD_FAMILY = registry.names_in(registry.ROD_FAMILY)
PLATES = registry.names_in(registry.PLATES)
PARTS = ROD_FAMILY + PLATES + ("arrays",)


def _strip():
    from .geometry.strip import Strip

    return Strip.from_ratios(1 / 6, 0.5)


def _evaluate_every_way(model, rng) -> None:
    q = model.reset()
    q = q + 1e-3 * model.strip.length * rng.standard_normal(q.shape)
    model.commit(q)
    for gradient, hessian in ((False, False), (True, False), (True, True)):
        model.evaluate(q, gradient=gradient, hessian=hessian)


def _rod_family(name: str, rng) -> None:
    """The model's compiled energy, then the compiled Newton load step and corrector on it."""
    from .solve.arclength import ArclengthTracer
    from .solve.newton import NewtonOptions, newton
    from .solve.state import State

    strip = _strip()
    entry = registry.MODELS[name]
    extra = {"zeta": 0.01 * strip.length} if name == WUNDERLICH_RIBBON else {}
    model = entry.model_class(strip, 9, **extra)
    _evaluate_every_way(model, rng)
    model = entry.model_class(strip, 9, **extra)
    compression = 0.3 * strip.length
    q = model.apply_clamps(model.buckled_guess(compression), compression, 0.0)
    result = newton(model, q, NewtonOptions())
    start = State(result.q, result.evaluation, compression, 0.0, True)
    ArclengthTracer(model, NewtonOptions()).trace(start, max_points=1)


def _plate(name: str, rng) -> None:
    from .energies.hinge_bending import hinge_bending_energy, triangle_normals
    from .models.midedge_plate import MEMBRANES

    strip = _strip()
    model_class = registry.MODELS[name].model_class
    if name == MIDEDGE_PLATE:
        for membrane in MEMBRANES:
            _evaluate_every_way(model_class(strip, 40, membrane=membrane), rng)
        return
    plate = model_class(strip, 40)
    _evaluate_every_way(plate, rng)
    xp = plate.reset().reshape(-1, 3)
    triangle_normals(xp, plate.mesh.triangles)
    for gradient, hessian in ((False, False), (True, False), (True, True)):
        hinge_bending_energy(xp, plate.mesh.triangles, plate.mesh.hinge_triangles, plate.hinge_stiffness,
                             gradient=gradient, hessian=hessian)


def _arrays(rng) -> None:
    """The array interfaces of analysis and the banded linear algebra of every model."""
    from .energies.rod_curvature import material_curvatures, strain_derivatives
    from .energies.stretch import stretching_energy
    from .geometry.frames import parallel_transport, reference_twist
    from .solve.banded import SymmetricBanded
    from .solve.lanczos import lowest_eigenvalue

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
    # Lanczos on the Cholesky factor, LDL^T of an indefinite band (both paths)
    for bandwidth in (3, 40):
        band = np.zeros((bandwidth + 1, 60))
        band[0] = np.linspace(-1.0, 3.0, 60)
        band[1, :-1] = 0.1
        SymmetricBanded(band).solve(np.ones(60))
        band[0] += 2.0
        spd = SymmetricBanded(band)
        if spd.cholesky():
            lowest_eigenvalue(spd.cholesky_factor, np.ones(60))


def compile_part(part: str) -> float:
    """Compile (or load) one part's kernels; returns its seconds."""
    if part not in PARTS:
        from .limits import InputError

        raise InputError(f"warm-up part {part!r} is not one of {', '.join(PARTS)}")
    start = time.perf_counter()
    rng = np.random.default_rng(0)
    if part in ROD_FAMILY:
        _rod_family(part, rng)
    elif part in PLATES:
        _plate(part, rng)
    else:
        _arrays(rng)
    return round(time.perf_counter() - start, 3)


def compile_kernels(parts=None) -> dict:
    """Compile the parts (default all) in this process, one after the other; seconds per part."""
    return {part: compile_part(part) for part in (PARTS if parts is None else parts)}


def _worker(part: str) -> tuple[str, float]:
    return part, compile_part(part)


#: The parts whose kernels are the same (the rod's kind of width terms): warmed in one process, in order.
SAME_KERNELS = (ROD, RIBBON, SANO_WADA_RIBBON)
#: The order in which parts are handed to the workers: the longest first, then the parts that share
#: none of its kernels (the plates, the array interfaces), so that the other rod-family parts start
#: once it has cached the kernels they share with it (frames, stencils, stretched chain rule).
WARM_ORDER = (CROSS_SECTION_RIBBON, MIDEDGE_PLATE, PLATE, "arrays", ROD, WUNDERLICH_RIBBON, TRAPEZE_RIBBON)


def compile_in_parallel(parts=None, jobs: int | None = None) -> dict:
    """compile_kernels over `jobs` worker processes (spawned: each has its own numba), in
    WARM_ORDER. The parts that compile the same kernels go to one worker in order (the rod's, then
    the ribbons that share its compiled energy and solvers, which load them from the cache);
    other parts share only small kernels, which two workers may both compile."""
    parts = list(PARTS if parts is None else parts)
    jobs = max(1, min(jobs or min(os.cpu_count() or 1, 4), len(parts)))
    if jobs == 1:
        return compile_kernels(parts)
    import concurrent.futures as cf
    import multiprocessing as mp

    same = [p for p in SAME_KERNELS if p in parts]
    queues = {p: [p] for p in parts if p not in SAME_KERNELS}
    if same:
        queues[ROD] = same
    order = sorted(queues, key=lambda p: WARM_ORDER.index(p) if p in WARM_ORDER else len(WARM_ORDER))
    timings = {}
    with cf.ProcessPoolExecutor(max_workers=jobs, mp_context=mp.get_context("spawn")) as pool:
        for done in pool.map(compile_kernels, [queues[p] for p in order]):
            timings.update(done)
    return {p: timings[p] for p in parts}


def main(parts=None, jobs: int | None = None) -> int:
    start = time.perf_counter()
    timings = compile_in_parallel(parts, jobs)
    listed = ", ".join(f"{k} {v:.1f} s" for k, v in timings.items())
    print(f"ddg kernels compiled and cached in {time.perf_counter() - start:.1f} s ({listed})")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:] or None))
