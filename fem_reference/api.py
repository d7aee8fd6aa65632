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
from ddg.protocol.results import SimulationResult
from ddg.solve.blas_threads import requested_threads
from ddg.output.io import write_centerline_csv, write_path_csv, write_summary_json

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
    from ddg.protocol.results import base_summary

    from .shell import EIGEN_NORMALISATION

    element = model.shell_element  # fem_reference.elements.ShellElement
    mesh = {**model.spec.as_dict(), "element": element.description, "locking": element.locking}
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
                 perturbation=None, names: dict | None = None, element: str = "P2B3"):
    """Every input of a run checked before any FEM import or work, with one-line ddg InputErrors
    named as in `names` (the command line passes its option names). Returns the MeshSpec and
    the output directory (None without `out`)."""
    from .mesh import checked_spec

    names = {"resolution": "resolution", "across": "across", "out": "out", "perturbation": "perturbation",
             "element": "element", **(names or {})}
    if not isinstance(strip, Strip) or not isinstance(protocol, LoadingProtocol):
        raise InputError("simulate needs a ddg Strip and a ddg LoadingProtocol")
    requested_threads()   # DDG_BLAS_THREADS (the run's BLAS threads, ddg.solve.blas_threads)
    spec = checked_spec(resolution, strip.width_ratio, across, names["resolution"], names["across"],
                        element, names["element"])
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
             newton_options=None, material: str = "isotropic", centerline: bool = True,
             element: str = "P2B3") -> FemResult:
    """Run the two-stage protocol on the Naghdi shell with `resolution` elements along L.

    material: "isotropic" (the strip's Poisson ratio; the paper's shell) or "dep" (the DDG
    plate's continuum limit, fem_reference.shell.ShellParameters). centerline=False records no
    centerline (no centerline.csv: the gold and mesh studies read path.csv and summary.json only).
    element: the shell's finite element, "P2B3" (default) or "P3" (fem_reference.elements; recorded
    in summary.json's mesh.element).

    The loop is ddg.protocol's (ddg.protocol.driver.execute) with the shell as its stepper
    (fem_reference.protocol.ShellStepper: the branch switch at the first unstable U state) and
    dW1, dW2 located after the path from the brackets it left (fem_reference.protocol.threshold_steps).

    Every input is checked before any work (one-line InputError; mesh bounds and memory:
    fem_reference.mesh.checked_spec; `out` writable: ddg.output.io.check_output_directory). Returns the
    rows (path.csv) and summary; with `out` the run's folder is a ddg.output.io.RunFolder: from the
    start summary.json says status "running", path.csv grows by one row per recorded step
    (SIGKILL loses at most the step being computed), and at the end every file is rewritten
    atomically with status "complete", "stopped" (did not converge; converged = False, the
    message says where, the converged part kept), "interrupted" or "error". Ctrl-C or SIGTERM
    (KeyboardInterrupt) writes what was computed, then re-raises with the result attached as
    `exc.result` (None when interrupted before the first step), the summary's message as
    `exc.run_message` and the folder as `exc.run_folder`; another exception is re-raised
    after the converged part is written (status "error"), with `exc.run_folder`."""
    import signal

    from ddg.output.interrupts import signal_name_of
    from ddg.output.io import RunFolder

    from .mesh import keep_python_sigint

    for name, value in (("fields", fields), ("progress", progress), ("centerline", centerline)):
        if not isinstance(value, (bool, np.bool_)):
            raise InputError(f"{name} = {value!r} must be True or False")
    spec, directory = check_inputs(strip, protocol, resolution, across, material, out,
                                   getattr(options, "perturbation", None), element=element)
    resolution = int(resolution)  # checked integral by check_inputs
    folder = RunFolder(directory, trailing=FEM_COLUMNS) if directory is not None else None  # old results removed
    sigint = signal.getsignal(signal.SIGINT)
    t_build = time.perf_counter()
    try:
        from .continuation import ContinuationOptions, Observer, Stepper
        from .protocol import ShellStepper
        from .shell import NaghdiStrip, ShellParameters
        from .solver import Solver

        keep_python_sigint(sigint)  # dolfinx.io.gmshio imports gmsh, which sets SIGINT to SIG_DFL
        options = options or ContinuationOptions()
        params = ShellParameters(strip.thickness / strip.length, strip.width_ratio, strip.poisson_ratio, material)
        model = NaghdiStrip(spec, params)
        keep_python_sigint(sigint)
        solver = Solver(model, newton_options)
        energy_unit = strip.plate_bending_stiffness  # E b^3 / 12, J per unit of the scaled energy
        observer = Observer(model, solver, energy_unit, options.eigenvalues)
        shell = ShellStepper(Stepper(model, solver, options), observer, options, protocol.resolved_shear_ratio(strip))
        summary = _base_summary(strip, protocol, resolution, model)
        keep_python_sigint(sigint)  # versions() imports gmsh too
    except KeyboardInterrupt as exc:
        if folder is not None:
            folder.close()
        exc.result, exc.run_folder = None, None
        exc.run_message = (f"interrupted by {signal_name_of(exc)} during the model's build (mesh, forms); "
                           "no step computed")
        raise
    summary["material"] = material
    summary["build_wall_time_s"] = time.perf_counter() - t_build
    if folder is not None:
        folder.checkpoint(summary)
    try:
        return _execute(strip, protocol, model, solver, shell, summary, folder,
                        directory if fields else None, progress, t_build, centerline)
    except BaseException as exc:
        where = None if directory is None else str(directory)
        try:
            exc.run_folder = where
            if isinstance(exc, KeyboardInterrupt):
                exc.run_message = summary["message"]
        except AttributeError:  # an exception type without attributes
            pass
        raise
    finally:
        if folder is not None:
            folder.close()


def _execute(strip, protocol, model, solver, shell, summary, folder, fields_directory, progress, t_build,
             centerline=True):
    """The run through ddg.protocol.driver.execute: listeners (path.csv, centerlines, XDMF
    fields, progress lines), the threshold after-steps, the FEM's timing keys."""
    from ddg.protocol.driver import Loading, Run, execute

    from .protocol import threshold_steps

    clock = solver.clock
    centerlines: list[np.ndarray] = []
    xdmf = _FieldWriter(model, clock, fields_directory)

    def keep(stage, observed, row):
        if centerline:
            centerlines.append(shell.observer.centerline(CENTERLINE_STATIONS))
        xdmf.write(row)  # before path.csv: it sets the row's xdmf_time
        if folder is not None:
            with clock.section("I/O"):
                folder.append(row)
        if progress:
            print(f"{stage:11s} dL/L={row['dL_over_L']:.4f} dW/L={row['dW_over_L']:+.4f} "
                  f"H/L={row['H_mid_over_L']:.5f} F={row['F_shear_norm']:+.4f} lam={row['lambda_min']:.4g} "
                  f"neg={row['negative_eigenvalues']} {row['phase']:4s} it={row['newton_iterations']} "
                  f"{row['wall_time_s']:.2f}s", flush=True)

    def compressed(outcome) -> None:
        if folder is not None:
            with clock.section("I/O"):
                folder.checkpoint({**summary, "message": "running: compression complete, shearing"})

    run = Run(shell, Loading.equally_spaced(strip, protocol, in_units_of_length=True),
              lambda stage, observed: observed.row, summary, [keep], folder, threshold_steps(shell, summary),
              compressed, lambda outcome: FemResult(outcome.rows, summary, centerlines=centerlines),
              [xdmf.close], started=t_build)
    return execute(run)


class _FieldWriter:
    """fields.xdmf: the P1 displacement and rotations of every recorded step (time = frame
    number, the row's xdmf_time); opened at the first row, so a failure to open it is the run's
    error, written with the converged part. A no-op without a directory."""

    def __init__(self, model, clock, directory: Path | None):
        self.model, self.clock, self.directory = model, clock, directory
        self.file = None
        self.frames = 0

    def write(self, row: dict) -> None:
        if self.directory is None:
            return
        from dolfinx.io import XDMFFile

        with self.clock.section("I/O"):
            if self.file is None:
                self.file = XDMFFile(self.model.mesh.comm, str(self.directory / "fields.xdmf"), "w")
                self.file.write_mesh(self.model.mesh)
            self.model.update_output_fields()
            self.file.write_function(self.model.u1, float(self.frames))
            self.file.write_function(self.model.theta1, float(self.frames))
        row["xdmf_time"] = self.frames
        self.frames += 1

    def close(self) -> None:
        if self.file is not None:
            with self.clock.section("I/O"):
                self.file.close()
            self.file = None
