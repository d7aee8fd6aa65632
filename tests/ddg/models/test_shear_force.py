"""The lateral clamp force F_shear_norm = F_y L / (E b^3) checked independently of its computation.

ddg.analysis.observables.observe reports F = model.clamp_force(gradient): dE/d(clamp translation), the force
the moving clamp applies to the strip (positive along the clamp's motion when the energy grows with
it). By virtual work, along a path of equilibria F_y = dE/dW, W the clamp's lateral displacement
(signed: dW_over_L < 0 for shear_sign = -1). Between two recorded states on one branch,
(E_{k+1} - E_k) / (W_{k+1} - W_k) is the mean of F_y over the step, which the trapezoid
(F_k + F_{k+1}) / 2 gives up to -(W_{k+1} - W_k)^2 F''/12: the discrepancy falls as the step squared
(checked by halving the step), so a wrong force (a missing term, a wrong sign or unit) cannot hide
in it. Energy and force come from different code (the energy sum and the gradient at the clamp).

Then the plate's force against the FEM shell's reaction force at W/L = 1/6, dL/L = 1/2 on the U
branch (data/fem_gold, 120 x 20 elements, nu = 0; data/fem_dep, 90 x 15, the plate's material),
itself checked against the shell's energy the same way.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import ddg
from ddg.output.io import StoredRun

DATA = Path(__file__).resolve().parents[3] / "data"
GOLD = DATA / "fem_gold" / "dL0.5_W0.1667"
DEP = DATA / "fem_dep" / "dL0.5_W0.1667_N90"
FINE = DATA / "fem_fine" / "dL0.5_W0.1667_N90"   # the nu = 0 shell on DEP's mesh
#: dW/L window of the plate-vs-FEM comparison: on U for both (dW1/L = 0.2575 plate, 0.2640 FEM),
#: from where the force has grown well above zero (it starts as dW^2: relative differences blur there).
WINDOW = (0.05, 0.20)


def virtual_work_discrepancy(rows, strip, upto: float = np.inf) -> tuple[float, int]:
    """Largest |(E_{k+1} - E_k) / (W_{k+1} - W_k) - (F_k + F_{k+1}) / 2| over consecutive recorded
    states, from the compressed state (the last compression row, W = 0) through the shear rows with
    |dW/L| <= upto, relative to the largest |F| compared; intervals that end in a branch switch or
    change phase are skipped. Returns (discrepancy, intervals compared)."""
    L = strip.length
    states = [r for r in rows if r["stage"] == "compression"][-1:]
    states += [r for r in rows if r["stage"] == "shear" and abs(r["dW_over_L"]) <= upto + 1e-12]
    w = np.array([r["dW_over_L"] for r in states]) * L
    energy = np.array([r["energy"] for r in states])
    force = np.array([r["F_shear_norm"] for r in states]) * strip.force_unit  # N, along +y
    keep = np.array([not r.get("branch_switched") and str(r["phase"]) == str(p["phase"])
                     for p, r in zip(states[1:-1], states[2:])])
    keep = np.r_[True, keep]  # the first interval: compressed (U) to the first shear state
    slope = np.diff(energy) / np.diff(w)
    trapezoid = 0.5 * (force[1:] + force[:-1])
    gap = np.abs(slope - trapezoid)[keep]
    return float(gap.max() / np.abs(force).max()), int(keep.sum())


def shear_run(model, width_ratio, resolution, shear_ratio, steps, shear_sign=1):
    strip = ddg.Strip.from_ratios(width_ratio, 1 / 2)
    protocol = ddg.LoadingProtocol(1 / 2, shear_ratio=shear_ratio, compression_steps=20, shear_steps=steps,
                                   shear_sign=shear_sign)
    result = ddg.simulate(strip, protocol, model=model, resolution=resolution, thresholds=False, branches=False)
    assert result.converged, result.summary["message"]
    shear = [r for r in result.rows if r["stage"] == "shear"]
    assert all(r["phase"] == "U" and r["stable"] for r in shear)  # the stable U branch throughout
    return strip, result


def test_rod_clamp_force_is_the_derivative_of_the_energy():
    """Rod, W/L = 1/20, dL/L = 1/2, M = 100, sheared to dW/L = 0.3 on U (dW1/L = 0.3516).
    Measured (relative to max |F|): 1.13e-4 with 30 steps, 2.82e-5 with 60, ratio 4.00 (step^2);
    the same 2.82e-5 shearing the other way, where F and dW change sign together."""
    strip, coarse = shear_run("rod", 1 / 20, 100, 0.3, 30)
    _, fine = shear_run("rod", 1 / 20, 100, 0.3, 60)
    (d30, n30), (d60, n60) = (virtual_work_discrepancy(r.rows, strip) for r in (coarse, fine))
    assert (n30, n60) == (30, 60)
    assert d60 < 1e-4, d60  # 3.5 times the measured 2.82e-5
    assert 3.5 < d30 / d60 < 4.5, (d30, d60)  # the trapezoid's O(step^2): measured 4.00
    _, mirror = shear_run("rod", 1 / 20, 100, 0.3, 60, shear_sign=-1)
    assert mirror.rows[-1]["F_shear_norm"] == pytest.approx(-fine.rows[-1]["F_shear_norm"], rel=1e-9)
    assert fine.rows[-1]["F_shear_norm"] > 0  # the clamp pushes the way it moves
    d_mirror, _ = virtual_work_discrepancy(mirror.rows, strip)
    assert d_mirror < 1e-4, d_mirror


def test_plate_clamp_force_is_the_derivative_of_the_energy():
    """Plate, W/L = 1/6, dL/L = 1/2, 546 triangles, sheared to dW/L = 0.2 on U. Measured (relative
    to max |F|): 1.59e-3 with 10 steps, 4.0e-4 with 20, ratio 3.99 (step^2)."""
    strip, coarse = shear_run("plate", 1 / 6, 400, 0.2, 10)
    _, fine = shear_run("plate", 1 / 6, 400, 0.2, 20)
    (d10, n10), (d20, n20) = (virtual_work_discrepancy(r.rows, strip) for r in (coarse, fine))
    assert (n10, n20) == (10, 20)
    assert d20 < 1.5e-3, d20  # 3.75 times the measured 4.0e-4
    assert 3.5 < d10 / d20 < 4.5, (d10, d20)  # measured 3.99


def _stored(directory: Path) -> StoredRun:
    if not (directory / "path.csv").exists():
        pytest.skip(f"no FEM run in {directory} (python -m fem_reference gold; see data/fem_gold/README.md)")
    return StoredRun(directory)


def test_fem_reaction_force_is_the_derivative_of_its_energy():
    """The reference's reaction force passes the same check (its 120 recorded shear steps, dW/L
    0.006 apart, 33 of them up to the end of the comparison window, all on U): measured 1.5e-4
    relative to max |F| on the gold run (120 x 20) and 1.3e-4 on the DEP-material run (90 x 15)."""
    strip = ddg.Strip.from_ratios(1 / 6, 1 / 2)
    for directory in (GOLD, DEP):
        run = _stored(directory)
        assert run.summary["scene"]["length"] == pytest.approx(strip.length)
        assert {r["phase"] for r in run.rows if r["stage"] == "shear" and r["dW_over_L"] <= WINDOW[1]} == {"U"}
        discrepancy, compared = virtual_work_discrepancy(run.rows, strip, upto=WINDOW[1])
        assert compared > 30
        assert discrepancy < 6e-4, (directory.name, discrepancy)  # 3.9 times the measured 1.5e-4


def force_difference(plate, fem) -> np.ndarray:
    """plate F / FEM F - 1 at the FEM's shear states in WINDOW (the plate interpolated linearly in
    dW; both on U there)."""
    dw_fem, f_fem = fem.column("dW_over_L", "shear"), fem.column("F_shear_norm", "shear")
    dw, f = plate.column("dW_over_L", "shear"), plate.column("F_shear_norm", "shear")
    inside = (dw_fem >= WINDOW[0]) & (dw_fem <= WINDOW[1])
    for run in (plate, fem):
        phases = {r["phase"] for r in run.rows if r["stage"] == "shear" and WINDOW[0] <= r["dW_over_L"] <= WINDOW[1]}
        assert phases == {"U"}, phases
    return np.interp(dw_fem[inside], dw, f) / f_fem[inside] - 1.0


class ForceBeyondTheReferenceErrorBar(AssertionError):
    """The plate's clamp force differs from the FEM reaction force by more than the bound."""


#: Bound on |plate F / FEM gold F - 1|, fixed from the reference's error bar: the gold run's force on
#: this window moves by 7.7-8.2 % from 60 to 120 elements and by 1.3-1.6 % from 90 to 120; a power law
#: through the three, point by point (orders 2.9-3.7), puts the 120-element force 0.7-1.2 % above the
#: converged one. 3 % is 2.5-4 times that error bar.
FEM_FORCE_BOUND = 0.03


def _mesh(run) -> str:
    mesh = run.summary["mesh"]
    return f"{mesh['elements_along_L']} x {mesh['elements_across_W']}"


def _percent(difference: np.ndarray) -> str:
    return f"{100 * difference.min():+.1f} to {100 * difference.max():+.1f} %"


def _force_figures(plate, gold, difference) -> str:
    """The expected failure's figures, from the runs the comparison reads: the plate against the
    gold shell, the shell with the plate's material against the nu = 0 shell on its own mesh
    (data/fem_fine), and the plate against the former."""
    dep, fine = _stored(DEP), _stored(FINE)
    return (f"measured: plate F / FEM F - 1 is {_percent(difference)} for dW/L in [{WINDOW[0]:g}, {WINDOW[1]:g}] "
            f"(the plate on {plate.summary['mesh']['triangles']} triangles, the FEM gold shell nu = 0 on "
            f"{_mesh(gold)}), against a {100 * FEM_FORCE_BOUND:g} % bound from the shell's error bar; the shell with "
            f"the plate's material (data/fem_dep, {_mesh(dep)}) is itself {_percent(force_difference(dep, fine))} "
            f"from the nu = 0 shell on its mesh (data/fem_fine), and the plate "
            f"{_percent(force_difference(plate, dep))} from it "
            f"(test_plate_clamp_force_matches_the_shell_with_its_material)")


def test_plate_clamp_force_matches_the_fem_reaction(request, plate_sixth_fine):
    """Not met: a strict expected failure (ForceBeyondTheReferenceErrorBar only) whose reason is
    computed from the runs compared (_force_figures)."""
    gold = _stored(GOLD)
    difference = force_difference(plate_sixth_fine, gold)
    request.applymarker(pytest.mark.xfail(strict=True, raises=ForceBeyondTheReferenceErrorBar,
                                          reason=_force_figures(plate_sixth_fine, gold, difference)))
    assert len(difference) > 20
    worst = float(np.max(np.abs(difference)))
    if worst > FEM_FORCE_BOUND:
        raise ForceBeyondTheReferenceErrorBar(
            f"plate F / FEM F - 1 from {difference.min():+.4f} to {difference.max():+.4f} for dW/L in {WINDOW}, "
            f"bound {FEM_FORCE_BOUND}")


def test_plate_clamp_force_matches_the_shell_with_its_material(plate_sixth_fine):
    """Against the FEM shell with the plate's material (membrane nu = 1/3, bending nu_b = -1/3;
    data/fem_dep, 90 x 15) the plate's force is 1.2-2.0 % higher for dW/L in [0.05, 0.20]. Bound
    5 %: 2.5 times the measured 2.0 %, and about twice that shell's own mesh error bar (measured on
    the nu = 0 shell: 1.3-1.6 % from 90 to 120 elements, plus the 120-element run's 0.7-1.2 %), which
    the measured difference is within."""
    difference = force_difference(plate_sixth_fine, _stored(DEP))
    assert len(difference) > 20
    assert np.max(np.abs(difference)) < 0.05, (difference.min(), difference.max())


def test_plate_clamp_force_of_the_cross_model_run_is_the_derivative_of_its_energy(plate_sixth_fine):
    """The 5740-triangle run compared with the FEM passes the virtual-work check on U (its 60 steps
    to dW_max are dW/L = 0.012 apart). Measured 3.9e-4 relative to max |F| up to dW/L = 0.24."""
    strip = ddg.Strip.from_ratios(1 / 6, 1 / 2)
    discrepancy, compared = virtual_work_discrepancy(plate_sixth_fine.rows, strip, upto=0.24)
    assert compared == 20
    assert discrepancy < 1.5e-3, discrepancy  # 3.8 times the measured 3.9e-4
