"""fem_reference.simulate(strip, protocol, resolution): the FEM run with the DDG models' outputs.

path.csv has ddg.analysis.observables.PATH_COLUMNS, then EXTRA_COLUMNS, then the FEM's own columns
(FEM_COLUMNS); summary.json every key of ddg.api.base_summary plus recorded_steps,
resolved_up_to_dW_over_L, the FEM's timing keys and its iteration and time breakdowns
(newton_iterations_by_phase: fem_reference.solver.ITERATION_PHASES, summing to newton_iterations,
then counts of failed solves, step halvings, snaps and chord steps; wall_time_by_phase_s:
fem_reference.solver.TIME_PHASES, summing to wall_time_s; wall_time_within_phases_s: the split of
threshold location and branch switching into the same sections). XDMF fields (P1 interpolations of the
displacement and rotations per recorded step) go to DIR/fields.xdmf for ParaView.
"""
from __future__ import annotations

import platform
import time
from pathlib import Path

import numpy as np

from ddg.geometry.strip import InputError, LoadingProtocol, Strip
from ddg.api import SimulationResult
from ddg.output.io import write_centerline_csv, write_path_csv, write_summary_json
from ddg.analysis.observables import resolved_up_to

from .materials import MATERIALS

FEM_COLUMNS = ("negative_eigenvalues", "half_turn_defect_over_L", "point_reflection_defect_over_L", "wall_time_s",
               "xdmf_time")
DEFAULT_RESOLUTION = 60
CENTERLINE_STATIONS = 101


def versions() -> dict:
    import basix
    import dolfinx
    import ffcx
    import gmsh
    import petsc4py
    import scipy
    import slepc4py
    import ufl

    import ddg

    return {"ddg": ddg.__version__, "python": platform.python_version(), "numpy": np.__version__,
            "scipy": scipy.__version__, "dolfinx": dolfinx.__version__, "ufl": ufl.__version__,
            "ffcx": ffcx.__version__, "basix": basix.__version__, "petsc4py": petsc4py.__version__,
            "slepc4py": slepc4py.__version__, "gmsh": gmsh.__version__}


class FemResult(SimulationResult):
    """The FEM run's rows, summary and centerlines (in units of L), written like the DDG models'
    results, with the FEM's own columns (FEM_COLUMNS) after the contract ones."""

    def write(self, out) -> None:
        out = Path(out)
        write_path_csv(out / "path.csv", self.rows, trailing=FEM_COLUMNS)
        if self.centerlines:
            length = float(self.summary["scene"]["length"])
            write_centerline_csv(out / "centerline.csv", self.rows, [c * length for c in self.centerlines], length)
        write_summary_json(out / "summary.json", self.summary)


class _SummaryModel:
    """What ddg.api.base_summary reads from a model: n_dof, free mask, mesh.as_dict()."""

    def __init__(self, n_dof, free, mesh_dict):
        self.n_dof, self.free = n_dof, free
        self.mesh = type("MeshInfo", (), {"as_dict": staticmethod(lambda: mesh_dict)})()


def _base_summary(strip, protocol, resolution, model) -> dict:
    from ddg.api import base_summary

    from .shell import EIGEN_NORMALISATION, FULL_DEGREE, REDUCED_DEGREE

    mesh = {**model.spec.as_dict(), "element": "Naghdi shell: u in [P2 + B3]^3, theta in [P2]^2",
            "locking": f"PSRI, alpha = b^2/h^2, full degree {FULL_DEGREE}, reduced degree {REDUCED_DEGREE}"}
    summary = base_summary("fem", strip, protocol, resolution, _SummaryModel(model.n_dof, model.free, mesh))
    summary["scene"]["clamp_convention"] = ("clamped edges x = 0 and x = L of the mesh: displacement prescribed, "
                                            "both rotation angles zero; free length exactly L")
    summary["lambda_min_normalisation"] = EIGEN_NORMALISATION
    summary["versions"] = versions()
    summary.update({"recorded_steps": 0, "resolved_up_to_dW_over_L": None, "path_wall_time_s": None,
                    "wall_time_per_step_s": None, "build_wall_time_s": None, "branch_switch": None})
    return summary


#: Bounds of the branch-switch start amplitude (units of L): above 0 (the amplitude continuation
#: starts there and doubles up to 0.01 L per step: from 1e-6 L that is 14 doublings, from 1e-300
#: a thousand solves, a hang in practice) and at most 0.1 L (the mode's linear range; the
#: continuation gives up at 0.5 L).
PERTURBATION_RANGE = (1e-6, 0.1)


def check_perturbation(value, name: str = "perturbation") -> float:
    """The branch-switch start amplitude / L, finite and within PERTURBATION_RANGE."""
    import math

    low, high = PERTURBATION_RANGE
    if isinstance(value, bool):
        raise InputError(f"{name} = {value!r} is a bool; it must be a number in [{low:g}, {high:g}] (units of L)")
    try:
        number = float(value)
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"{name} = {value!r} is not a number; "
                         f"allowed range [{low:g}, {high:g}] (units of L)") from None
    if not (math.isfinite(number) and low <= number <= high):
        raise InputError(f"{name} = {value!r} outside the allowed range [{low:g}, {high:g}] (branch-switch start "
                         "amplitude in units of L)")
    return number


def check_inputs(strip, protocol, resolution, across=None, material: str = "isotropic", out=None,
                 perturbation=None, names: dict | None = None):
    """Every input of a run checked before any FEM import or work, with one-line ddg InputErrors
    named as in `names` (the command line passes its option names). Returns the MeshSpec and
    the output directory (None without `out`)."""
    from .mesh import checked_spec

    names = {"resolution": "resolution", "across": "across", "out": "out", "perturbation": "perturbation",
             **(names or {})}
    if not isinstance(strip, Strip) or not isinstance(protocol, LoadingProtocol):
        raise InputError("simulate needs a ddg Strip and a ddg LoadingProtocol")
    spec = checked_spec(resolution, strip.width_ratio, across, names["resolution"], names["across"])
    if not isinstance(material, str) or material not in MATERIALS:
        raise InputError(f"material = {material!r} is not one of {MATERIALS}")
    if material == "dep" and strip.poisson_ratio != 0.0:
        raise InputError(f"poisson_ratio = {strip.poisson_ratio!r} with material 'dep' (its Poisson ratios are fixed); "
                         "use poisson_ratio = 0")
    if perturbation is not None:
        check_perturbation(perturbation, names["perturbation"])
    protocol.resolved_shear_ratio(strip)
    directory = None
    if out is not None:
        from ddg.output.io import check_output_directory

        directory = check_output_directory(out, names["out"])
    return spec, directory


def simulate(strip: Strip, protocol: LoadingProtocol, resolution: int = DEFAULT_RESOLUTION, out=None,
             options=None, across: int | None = None, fields: bool = True, progress: bool = False,
             newton_options=None, material: str = "isotropic") -> FemResult:
    """Run the two-stage protocol on the Naghdi shell with `resolution` elements along L.

    material: "isotropic" (the strip's Poisson ratio; the paper's shell) or "dep" (the DDG
    plate's continuum limit, fem_reference.shell.ShellParameters).

    Every input is checked before any work (one-line InputError; mesh bounds and memory:
    fem_reference.mesh.checked_spec; `out` writable: ddg.output.io.check_output_directory). Returns the
    rows (path.csv) and summary; with `out` the run's folder is a ddg.output.io.RunFolder: from the
    start summary.json says status "running", path.csv grows by one row per recorded step
    (SIGKILL loses at most the step being computed), and at the end every file is rewritten
    atomically with status "complete", "stopped" (did not converge; converged = False, the
    message says where, the converged part kept) or "interrupted". Ctrl-C or SIGTERM
    (KeyboardInterrupt) writes what was computed, then re-raises with the result attached as
    `exc.result` (None when interrupted before the first step)."""
    import signal

    from ddg.output.interrupts import deferred_signals, signal_name_of
    from ddg.output.io import STATUS_COMPLETE, STATUS_INTERRUPTED, STATUS_STOPPED, RunFolder

    from .mesh import keep_python_sigint

    for name, value in (("fields", fields), ("progress", progress)):
        if not isinstance(value, (bool, np.bool_)):
            raise InputError(f"{name} = {value!r} must be True or False")
    spec, directory = check_inputs(strip, protocol, resolution, across, material, out,
                                   getattr(options, "perturbation", None))
    resolution = int(resolution)  # checked integral by check_inputs
    shear_ratio = protocol.resolved_shear_ratio(strip)
    folder = RunFolder(directory, trailing=FEM_COLUMNS) if directory is not None else None  # old results removed
    sigint = signal.getsignal(signal.SIGINT)
    stage = "the model's build (mesh, forms)"
    try:
        from .continuation import (ContinuationFailure, ContinuationOptions, GUESS_COMPRESSION_LIMIT, Observer,
                                   Stepper, locate_dw1, locate_dw2, switch_branch, Branch)
        from .shell import NaghdiStrip, ShellParameters
        from .solver import Solver

        keep_python_sigint(sigint)  # dolfinx.io.gmshio imports gmsh, which sets SIGINT to SIG_DFL
        options = options or ContinuationOptions()
        t_build = time.perf_counter()
        L = strip.length
        params = ShellParameters(strip.thickness / L, strip.width_ratio, strip.poisson_ratio, material)
        model = NaghdiStrip(spec, params)
        keep_python_sigint(sigint)
        solver = Solver(model, newton_options)
        stepper = Stepper(model, solver, options)
        energy_unit = strip.plate_bending_stiffness  # E b^3 / 12, J per unit of the scaled energy
        observer = Observer(model, solver, energy_unit, options.eigenvalues)
        summary = _base_summary(strip, protocol, resolution, model)
        keep_python_sigint(sigint)  # versions() imports gmsh too
    except KeyboardInterrupt as exc:
        if folder is not None:
            folder.close()
        exc.result, exc.run_folder = None, None
        exc.run_message = f"interrupted by {signal_name_of(exc)} during {stage}; no step computed"
        raise
    summary["material"] = material
    summary["build_wall_time_s"] = time.perf_counter() - t_build
    summary["status"] = "running"
    summary["path_complete"] = False
    if folder is not None:
        folder.checkpoint(summary)
    dL = protocol.compression_ratio
    dW_end = protocol.shear_sign * shear_ratio
    rows: list[dict] = []
    centerlines: list[np.ndarray] = []
    xdmf = None
    written = [0]

    frames = [0]

    def record(kind, iterations, t0, switched=False):
        obs = observer.observe(kind, iterations, switched, time.perf_counter() - t0)
        rows.append(obs.row)
        centerlines.append(observer.centerline(CENTERLINE_STATIONS))
        if xdmf is not None:  # time stamps count frames (a replaced row keeps its frame)
            with clock.section("I/O"):
                model.update_output_fields()
                xdmf.write_function(model.u1, float(frames[0]))
                xdmf.write_function(model.theta1, float(frames[0]))
            obs.row["xdmf_time"] = frames[0]
            frames[0] += 1
        if progress:
            r = obs.row
            print(f"{kind:11s} dL/L={r['dL_over_L']:.4f} dW/L={r['dW_over_L']:+.4f} H/L={r['H_mid_over_L']:.5f} "
                  f"F={r['F_shear_norm']:+.4f} lam={r['lambda_min']:.4g} neg={r['negative_eigenvalues']} "
                  f"{r['phase']:4s} it={iterations} {r['wall_time_s']:.2f}s", flush=True)
        return obs

    def commit():
        """Append the rows recorded since the last call to path.csv (a shear step's row is final
        once its branch switch, which replaces it, is done)."""
        if folder is not None:
            with clock.section("I/O"):
                for row in rows[written[0]:]:
                    folder.append(row)
        written[0] = len(rows)

    clock = solver.clock
    t0_path = time.perf_counter()
    switched = False
    last_stable_u = None  # (load, state, history) of the last recorded stable U state
    last_stable_u_lambda = float("nan")  # its lambda_min
    last_us = None
    dw1_info = dw2_info = None
    step_times = []
    stopped = interrupted = error = None
    try:
        if directory is not None and fields:
            from dolfinx.io import XDMFFile

            with clock.section("I/O"):
                xdmf = XDMFFile(model.mesh.comm, str(directory / "fields.xdmf"), "w")
                xdmf.write_mesh(model.mesh)
        stage = "the compression stage"
        t0 = time.perf_counter()
        model.set_clamp(0.0, 0.0)
        record("compression", 0, t0)
        commit()
        for k in range(1, protocol.compression_steps + 1):
            t0 = time.perf_counter()
            target = dL * k / protocol.compression_steps
            if k == 1:
                guess_at = min(target, GUESS_COMPRESSION_LIMIT)
                model.set_clamp(guess_at, 0.0)
                model.inextensible_guess(guess_at)
                try:
                    with solver.counting("compression start"):
                        its = solver.newton()
                except Exception as exc:
                    raise ContinuationFailure(f"Newton from the inextensible guess at dL/L = {guess_at:g}: {exc}")
                stepper.branch.reset(stepper.load, model.get_state())
                stats = stepper.advance((target, 0.0))
                its += stats.newton_iterations
            else:
                its = stepper.advance((target, 0.0)).newton_iterations
            record("compression", its, t0)
            commit()
            step_times.append(time.perf_counter() - t0)
        summary["H_mid_over_L_compressed"] = rows[-1]["H_mid_over_L"]
        if folder is not None:
            with clock.section("I/O"):
                folder.checkpoint(summary)
        stepper.branch.reset(stepper.load, model.get_state())
        n_shear = protocol.shear_steps if dW_end != 0.0 else 0
        for k in range(1, n_shear + 1):
            stage = "the shear stage"
            t0 = time.perf_counter()
            target = (dL, dW_end * k / protocol.shear_steps)
            its = stepper.advance(target).newton_iterations
            obs = record("shear", its, t0)
            row = obs.row
            if not switched and row["phase"] == "U":
                if obs.negative == 0:
                    last_stable_u = (stepper.load, model.get_state(),
                                     Branch(list(stepper.branch.loads), list(stepper.branch.states)))
                    last_stable_u_lambda = row["lambda_min"]
                elif options.thresholds or options.branch_switching:
                    here = (stepper.load, model.get_state(),
                            Branch(list(stepper.branch.loads), list(stepper.branch.states)))
                    if options.thresholds and dw1_info is None and last_stable_u is not None:
                        stage = "threshold location (dW1, bisection on U)"
                        tt = time.perf_counter()
                        with clock.section("threshold location"):
                            dw1, it1 = locate_dw1(stepper, last_stable_u, target[1],
                                                  lambdas=(last_stable_u_lambda, row["lambda_min"]))
                            stepper.restore(here[0], here[1], here[2])
                        dw1_info = {"dW1": dw1, "iterations": it1, "time": time.perf_counter() - tt}
                    if options.branch_switching:
                        stage = "the branch switch (U to US)"
                        tt = time.perf_counter()
                        with clock.section("branch switching"):
                            if obs.mode is not None:  # the critical mode of this state, observed above
                                values, vectors = [obs.row["lambda_min"]], [obs.mode]
                            else:
                                values, vectors = solver.lowest_modes(1)
                            it_sw, amp = switch_branch(stepper, vectors[0], options.perturbation)
                        rows.pop()
                        centerlines.pop()
                        obs = record("shear", its + it_sw, t0, switched=True)
                        row = obs.row
                        switched = True
                        summary["branch_switch"] = {"dW_over_L": float(target[1]), "mode_eigenvalue": float(values[0]),
                                                    "start_amplitude_over_L": options.perturbation,
                                                    "amplitude_over_L": float(amp),
                                                    "unstable_U_lambda_min": float(values[0]),
                                                    "wall_time_s": time.perf_counter() - tt}
            if switched and row["phase"].startswith("US"):
                last_us = (stepper.load, model.get_state(),
                           Branch(list(stepper.branch.loads), list(stepper.branch.states)))
            elif (switched and row["phase"].startswith("S") and dw2_info is None and last_us is not None
                  and options.thresholds):
                here = (stepper.load, model.get_state(),
                        Branch(list(stepper.branch.loads), list(stepper.branch.states)))
                stage = "threshold location (dW2, bisection from US)"
                tt = time.perf_counter()
                with clock.section("threshold location"):
                    dw2, it2 = locate_dw2(stepper, last_us, target[1])
                    stepper.restore(here[0], here[1], here[2])
                dw2_info = {"dW2": dw2, "iterations": it2, "time": time.perf_counter() - tt}
            commit()
            step_times.append(time.perf_counter() - t0)
        stage = "the end of the run"
    except ContinuationFailure as exc:
        load = stepper.load
        share = 100.0 * abs(load[1]) / shear_ratio if shear_ratio > 0 else 0.0
        stopped = (f"stopped converging at dL/L = {load[0]:.6f}, dW/L = {load[1]:.6f} "
                   f"({share:.1f} % of dW_max): {exc}")
    except KeyboardInterrupt as exc:
        interrupted = exc
    except Exception as exc:  # a bug or a resource failure: keep what converged, then re-raise
        error = exc
    result = None
    try:
        with deferred_signals():  # a second Ctrl-C cannot cut the result files
            if xdmf is not None:
                with clock.section("I/O"):
                    xdmf.close()
            if dw1_info:
                summary["dW1_over_L"] = abs(dw1_info["dW1"])
            if dw2_info:
                summary["dW2_over_L"] = abs(dw2_info["dW2"])
            summary["threshold_wall_time_s"] = sum(d["time"] for d in (dw1_info, dw2_info) if d)
            summary["newton_iterations"] = solver.total_iterations
            path_wall = time.perf_counter() - t0_path
            summary["wall_time_s"] = path_wall + summary["build_wall_time_s"]
            summary["path_wall_time_s"] = path_wall
            breakdown = stepper.iteration_breakdown()
            summary["newton_iterations_by_phase"] = breakdown
            if options.thresholds:
                summary["threshold_newton_iterations"] = breakdown["threshold dW1"] + breakdown["threshold dW2"]
            summary["wall_time_by_phase_s"] = clock.breakdown(path_wall, {"build": summary["build_wall_time_s"]})
            summary["wall_time_within_phases_s"] = {k: dict(v) for k, v in clock.within.items()}
            summary["wall_time_per_step_s"] = float(np.mean(step_times)) if step_times else None
            summary["recorded_steps"] = len(rows)
            summary["resolved_up_to_dW_over_L"] = resolved_up_to(rows)
            path_complete = stopped is None and interrupted is None and error is None
            summary["path_complete"] = path_complete
            kept = f"{len(rows)} recorded steps kept" if rows else "no step had converged"
            if rows:
                kept += f" (the last at dL/L = {rows[-1]['dL_over_L']:.4f}, dW/L = {rows[-1]['dW_over_L']:.4f})"
            if error is not None:
                summary.update(status="error", converged=False,
                               message=f"internal error during {stage}: {type(error).__name__}: {error}; {kept}")
            elif interrupted is not None:
                summary.update(status=STATUS_INTERRUPTED, converged=False,
                               message=f"interrupted by {signal_name_of(interrupted)} during {stage}; {kept}")
            elif stopped is not None:
                summary.update(status=STATUS_STOPPED, converged=False, message=stopped)
            else:
                summary.update(status=STATUS_COMPLETE, converged=True, message="path complete")
            result = FemResult(rows, summary, centerlines=centerlines)
            if folder is not None:
                folder.finish(result)
    except KeyboardInterrupt as late:  # a signal held while the files were written
        if interrupted is None:
            interrupted = late
    finally:
        if folder is not None:
            folder.close()
    if error is not None:
        try:
            error.run_folder = None if directory is None else str(directory)
        except AttributeError:  # an exception type without attributes
            pass
        raise error
    if interrupted is not None:
        interrupted.result = result
        interrupted.run_message = summary["message"]
        interrupted.run_folder = None if directory is None else str(directory)
        raise interrupted
    return result
