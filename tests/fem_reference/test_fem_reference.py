"""FEniCSx Naghdi shell reference (fem_reference): elastica, symmetry, stability, branch switch,
output contract, mesh convergence. Skipped where dolfinx is not installed (CI installs it)."""
from __future__ import annotations

import json

import numpy as np
import pytest

pytest.importorskip("dolfinx", reason="fem_reference needs dolfinx (Debian python3-dolfinx, scripts/setup.sh)")
pytest.importorskip("slepc4py", reason="fem_reference needs slepc4py (Debian python3-slepc4py, scripts/setup.sh)")

from ddg.analysis.analytic import clamped_elastica_midpoint_height  # noqa: E402
from ddg.geometry.strip import LoadingProtocol, Strip  # noqa: E402
from ddg.output.io import read_path_csv  # noqa: E402
from ddg.analysis.observables import EXTRA_COLUMNS, PATH_COLUMNS  # noqa: E402

#: Elements along L of the fast tests (10 across W = L/6, 6585 unknowns); the elastica test uses
#: ELASTICA (36 x 10): H_mid/L error at dL/L = 1/2 is -0.54 % at 24 x 10 and -0.03 % at 60 x 10.
MODEST = 24
ELASTICA = 36


def _model(width_ratio, compression_ratio, resolution=MODEST, across=None):
    from fem_reference.continuation import ContinuationOptions, Stepper
    from fem_reference.mesh import MeshSpec
    from fem_reference.shell import NaghdiStrip, ShellParameters
    from fem_reference.solver import Solver

    strip = Strip.from_ratios(width_ratio, compression_ratio)
    model = NaghdiStrip(MeshSpec.from_resolution(resolution, width_ratio, across),
                        ShellParameters(strip.thickness / strip.length, width_ratio))
    solver = Solver(model)
    return model, solver, Stepper(model, solver, ContinuationOptions())


def _compress(model, solver, stepper, compression, steps=6):
    guess = min(compression / steps, 0.2)
    model.set_clamp(guess, 0.0)
    model.inextensible_guess(guess)
    solver.newton()
    stepper.branch.reset(stepper.load, model.get_state())
    for k in range(1, steps + 1):
        stepper.advance((compression * k / steps, 0.0))


@pytest.fixture(scope="module")
def compressed_sixth():
    """W/L = 1/6 strip compressed to dL/L = 1/2 (modest mesh), shared by several tests."""
    model, solver, stepper = _model(1 / 6, 0.5)
    _compress(model, solver, stepper, 0.5)
    return model, solver, stepper, model.get_state()


@pytest.mark.parametrize("compression_ratio", [0.25, 0.5])
def test_compression_matches_clamped_elastica(tmp_path, compression_ratio):
    """H_mid/L of the buckled W/L = 1/6 strip within 0.5 % of the exact clamped elastica (a
    modest mesh, 36 x 10 elements); the run writes the contract's files."""
    from fem_reference.api import simulate

    strip = Strip.from_ratios(1 / 6, compression_ratio)
    protocol = LoadingProtocol(compression_ratio, shear_ratio=0.0, compression_steps=5, shear_steps=1)
    result = simulate(strip, protocol, ELASTICA, out=tmp_path)
    assert result.converged, result.summary["message"]
    exact = clamped_elastica_midpoint_height(compression_ratio)
    error = result.summary["H_mid_over_L_compressed"] / exact - 1.0
    assert abs(error) < 5e-3, f"H_mid/L error {error:+.2e} at dL/L = {compression_ratio}"
    # output contract
    rows = read_path_csv(tmp_path / "path.csv")
    header = list(rows[0].keys())
    assert header[: len(PATH_COLUMNS)] == list(PATH_COLUMNS)
    assert header[len(PATH_COLUMNS): len(PATH_COLUMNS) + 4] == list(EXTRA_COLUMNS[:4])
    assert rows[-1]["phase"] == "U" and rows[0]["stage"] == "compression"
    summary = json.loads((tmp_path / "summary.json").read_text())

    for key in ("model", "scene", "H_mid_over_L_compressed", "dW_max_over_L", "dW1_over_L", "dW2_over_L",
                "dW2_S_stable_over_L", "threshold_wall_time_s", "n_dof", "n_free_dof", "newton_iterations",
                "wall_time_s", "converged", "message", "mesh", "lambda_min_normalisation", "versions",
                "recorded_steps", "resolved_up_to_dW_over_L"):
        assert key in summary, key
    assert summary["model"] == "fem" and "dolfinx" in summary["versions"]
    assert summary["recorded_steps"] == len(rows) == 1 + 5
    assert (tmp_path / "fields.xdmf").exists() and (tmp_path / "centerline.csv").exists()


def test_summary_has_every_base_summary_key():
    """Every key ddg.api.base_summary gives a DDG run is in the FEM summary too."""
    from ddg.api import base_summary
    from ddg.models.rod import RodModel
    from fem_reference.api import simulate

    strip = Strip.from_ratios(1 / 20, 0.25)
    protocol = LoadingProtocol(0.25, shear_ratio=0.0, compression_steps=2, shear_steps=1)
    expected = base_summary("rod", strip, protocol, 20, RodModel(strip, 20))
    summary = simulate(strip, protocol, 12).summary
    assert set(expected) <= set(summary)


def test_summary_breaks_down_iterations_and_wall_time_by_phase(tmp_path):
    """summary.json's newton_iterations_by_phase: one entry per ITERATION_PHASES summing to
    newton_iterations (compression start, accepted steps, the dW1 bisection and the branch
    switch all used on a 12 x 10 mesh sheared past the pitchfork), then the counts of failed
    solves, step halvings, snaps and chord steps; threshold_newton_iterations = the dW1 and dW2 phases;
    wall_time_by_phase_s: every TIME_PHASES entry, non-negative except the remainder "other",
    summing to wall_time_s."""
    from fem_reference.api import simulate
    from fem_reference.solver import ITERATION_PHASES, TIME_PHASES

    strip = Strip.from_ratios(1 / 6, 0.5)
    protocol = LoadingProtocol(0.5, shear_ratio=0.25, compression_steps=2, shear_steps=3)
    simulate(strip, protocol, 12, out=tmp_path)
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["converged"], summary["message"]
    by_phase = summary["newton_iterations_by_phase"]
    assert set(ITERATION_PHASES) | {"failed solves", "step halvings", "snaps", "chord steps",
                                    "round-off convergences"} == set(by_phase)
    assert sum(by_phase[p] for p in ITERATION_PHASES) == summary["newton_iterations"]
    for phase in ("compression start", "accepted steps", "threshold dW1", "branch switching"):
        assert by_phase[phase] > 0, (phase, by_phase)
    assert by_phase["other"] == 0
    assert summary["threshold_newton_iterations"] == by_phase["threshold dW1"] + by_phase["threshold dW2"]
    times = summary["wall_time_by_phase_s"]
    assert set(TIME_PHASES) <= set(times)
    assert all(times[p] >= 0.0 for p in times if p != "other"), times
    assert sum(times.values()) == pytest.approx(summary["wall_time_s"], rel=1e-9)
    assert times["I/O"] > 0.0 and times["threshold location"] > 0.0 and times["branch switching"] > 0.0
    assert set(summary["wall_time_within_phases_s"]) == {"threshold location", "branch switching"}


def test_shear_directions_mirror_and_no_lateral_motion_at_zero(compressed_sixth):
    """+dW and -dW give mirror images (y -> -y) to 1e-9 L; no lateral motion at dW = 0."""
    model, solver, stepper, state = compressed_sixth
    stepper.restore((0.5, 0.0), state)
    u0 = model.displacement_nodes()
    # no lateral motion at dW = 0: the centerline stays in the plane y = 0 and the shape is its own
    # mirror image (u_y odd, u_x and u_z even in y; the free edges move by ~3e-6 L in y, measured)
    assert np.max(np.abs(u0[model.centerline_nodes, 1])) < 1e-10
    mirrored = u0[model.mirror] * np.array([1.0, -1.0, 1.0])
    assert np.max(np.abs(u0 - mirrored)) < 1e-10
    shapes, forces = {}, {}
    for sign in (1, -1):
        stepper.restore((0.5, 0.0), state)
        for k in range(1, 3):
            stepper.advance((0.5, sign * 0.05 * k))
        shapes[sign] = model.positions()
        forces[sign] = model.clamp_reaction()
    plus, minus = shapes[1], shapes[-1][model.mirror]
    assert np.max(np.abs(plus[:, [0, 2]] - minus[:, [0, 2]])) < 1e-9
    assert np.max(np.abs(plus[:, 1] + minus[:, 1])) < 1e-9
    assert abs(forces[1][1] + forces[-1][1]) < 1e-8 * abs(forces[1][1])
    assert np.max(np.abs(plus[:, 1])) > 1e-2  # it did move


def test_inertia_counts_negative_eigenvalues_and_branch_switch_is_real(compressed_sixth):
    """Past the pitchfork the symmetric mesh stays on U with one negative eigenvalue (MUMPS
    inertia = SLEPc count); the switch along the critical mode lands on a stable US+ state that
    does not depend on the starting perturbation (1e-4 L and 1e-2 L: same state)."""
    from fem_reference.continuation import phase_of, switch_branch

    model, solver, stepper, state = compressed_sixth
    stepper.restore((0.5, 0.0), state)
    for dw in (0.1, 0.2, 0.245):
        stepper.advance((0.5, dw))
    assert phase_of(model, model.positions())[0] == "U"
    negative = solver.negative_eigenvalues()
    values, vectors = solver.lowest_modes(3)
    assert negative == 1 == int(np.sum(values < 0.0)), (negative, values)
    u_state = model.get_state()
    heights = []
    for perturbation in (1e-4, 1e-2):
        stepper.restore((0.5, 0.245), u_state)
        switch_branch(stepper, vectors[0], perturbation)
        phase = phase_of(model, model.positions())[0]
        assert phase == "US+"
        assert solver.negative_eigenvalues() == 0
        assert solver.lowest_modes(1)[0][0] > 0.0
        heights.append(model.positions()[model.centre_node, 2])
    assert abs(heights[0] - heights[1]) < 1e-8
    assert abs(heights[0] - model.positions()[model.centre_node, 2]) < 1e-8


def _bending_energy(material: str, rotation_field) -> float:
    """Bending energy (total - membrane - shear) of a small linear rotation field, u = 0."""
    from dolfinx import fem

    from fem_reference.mesh import MeshSpec
    from fem_reference.shell import NaghdiStrip, ShellParameters

    model = NaghdiStrip(MeshSpec.from_resolution(8, 1 / 6, None), ShellParameters(1e-3, 1 / 6, 0.0, material))
    model.q.x.array[:] = 0.0
    model.q.sub(1).interpolate(rotation_field)
    model.q.x.scatter_forward()
    total, membrane, shear = (model.mesh.comm.allreduce(fem.assemble_scalar(f)) for f in
                              (model.energy_form, model.membrane_energy_form, model.shear_energy_form))
    return total - membrane - shear


def test_dep_material_twists_four_thirds_stiffer_and_bends_alike():
    """Material "dep" (the DDG plate's continuum limit, nu_b = -1/3, D = E b^3/12): a uniform twist
    kappa_xy costs (1 - nu_b) = 4/3 of the nu = 0 shell, a cylindrical bend kappa_xx the same;
    both equal D/2 (nu_b tr^2 + (1 - nu_b) kappa:kappa) times the area (units D = 1, L = 1)."""
    tau, area = 1e-4, 1 / 6

    def twist(x):  # director d_y = tau x: kappa_xy = -tau/2
        return np.vstack([-tau * x[0], 0.0 * x[0]])

    def bend(x):  # director d_x = tau x: kappa_xx = -tau
        return np.vstack([0.0 * x[0], tau * x[0]])

    twist_iso, twist_dep = _bending_energy("isotropic", twist), _bending_energy("dep", twist)
    bend_iso, bend_dep = _bending_energy("isotropic", bend), _bending_energy("dep", bend)
    assert twist_iso == pytest.approx(0.5 * 2 * (tau / 2) ** 2 * area, rel=1e-6)
    assert twist_dep == pytest.approx(4 / 3 * twist_iso, rel=1e-6)
    assert bend_iso == pytest.approx(0.5 * tau**2 * area, rel=1e-6)
    assert bend_dep == pytest.approx(bend_iso, rel=1e-6)


def test_bad_input_exit_code_2(capsys):
    from fem_reference.cli import main

    assert main(["simulate", "--width-ratio", "0.1667", "--compression-ratio", "1.5", "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("error:") and "\n" not in err


@pytest.mark.slow
def test_h_mid_converges_with_the_mesh():
    """H_mid/L on the U branch at dL/L = 1/2, dW/L = 0.15 (W/L = 1/6): the error against the finest
    mesh falls with h at a measured rate (fitted log-log slope >= 1.5; P2 elements)."""
    resolutions = (12, 24, 48, 96)  # 2, 4, 8, 16 elements across
    heights = []
    for n in resolutions:
        model, solver, stepper = _model(1 / 6, 0.5, n, across=n // 6)  # similar meshes
        _compress(model, solver, stepper, 0.5)
        for dw in (0.05, 0.1, 0.15):
            stepper.advance((0.5, dw))
        heights.append(model.positions()[model.centre_node, 2])
    errors = np.abs(np.array(heights[:-1]) - heights[-1])
    slope = np.polyfit(np.log(1.0 / np.array(resolutions[:-1])), np.log(errors), 1)[0]
    assert np.all(np.diff(errors) < 0), errors
    assert slope > 1.5, (slope, errors)
    assert errors[-1] < 2e-3
