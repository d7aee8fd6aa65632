"""fem_reference.simulate(strip, protocol, resolution): the FEM run with the DDG models' outputs.

path.csv has ddg.observables.PATH_COLUMNS, then EXTRA_COLUMNS, then the FEM's own columns
(FEM_COLUMNS); summary.json every key of ddg.api.base_summary plus recorded_steps,
resolved_up_to_dW_over_L and the FEM's timing keys. XDMF fields (P1 interpolations of the
displacement and rotations per recorded step) go to DIR/fields.xdmf for ParaView.
"""
from __future__ import annotations

import platform
import time
from pathlib import Path

import numpy as np

from ddg.geometry.strip import InputError, LoadingProtocol, Strip
from ddg.api import SimulationResult
from ddg.io import write_centerline_csv, write_path_csv, write_summary_json
from ddg.observables import resolved_up_to

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


def simulate(strip: Strip, protocol: LoadingProtocol, resolution: int = DEFAULT_RESOLUTION, out=None,
             options=None, across: int | None = None, fields: bool = True, progress: bool = False,
             newton_options=None, material: str = "isotropic") -> FemResult:
    """Run the two-stage protocol on the Naghdi shell with `resolution` elements along L.

    material: "isotropic" (the strip's Poisson ratio; the paper's shell) or "dep" (the DDG
    plate's continuum limit, fem_reference.shell.ShellParameters).

    Returns the rows (path.csv) and summary; writes them to `out` (also when the run stops
    early: converged = False, message says where)."""
    from .continuation import (ContinuationFailure, ContinuationOptions, GUESS_COMPRESSION_LIMIT, Observer,
                               Stepper, locate_dw1, locate_dw2, switch_branch, Branch)
    from .mesh import MeshSpec
    from .shell import NaghdiStrip, ShellParameters
    from .solver import Solver

    if not isinstance(strip, Strip) or not isinstance(protocol, LoadingProtocol):
        raise InputError("simulate needs a ddg Strip and a ddg LoadingProtocol")
    if not isinstance(resolution, int) or isinstance(resolution, bool) or resolution < 4:
        raise InputError(f"resolution = {resolution!r} must be an integer >= 4 (elements along L)")
    from .shell import MATERIALS

    if material not in MATERIALS:
        raise InputError(f"material = {material!r} is not one of {MATERIALS}")
    if material == "dep" and strip.poisson_ratio != 0.0:
        raise InputError(f"poisson_ratio = {strip.poisson_ratio!r} with material 'dep' (its Poisson ratios are fixed); "
                         "use poisson_ratio = 0")
    shear_ratio = protocol.resolved_shear_ratio(strip)
    options = options or ContinuationOptions()
    t_build = time.perf_counter()
    L = strip.length
    spec = MeshSpec.from_resolution(resolution, strip.width_ratio, across)
    params = ShellParameters(strip.thickness / L, strip.width_ratio, strip.poisson_ratio, material)
    model = NaghdiStrip(spec, params)
    solver = Solver(model, newton_options)
    stepper = Stepper(model, solver, options)
    energy_unit = strip.plate_bending_stiffness  # E b^3 / 12, J per unit of the scaled energy
    observer = Observer(model, solver, energy_unit, options.eigenvalues)
    summary = _base_summary(strip, protocol, resolution, model)
    summary["material"] = material
    summary["build_wall_time_s"] = time.perf_counter() - t_build
    dL = protocol.compression_ratio
    dW_end = protocol.shear_sign * shear_ratio
    rows: list[dict] = []
    centerlines: list[np.ndarray] = []
    xdmf = None
    if out is not None and fields:
        from dolfinx.io import XDMFFile

        Path(out).mkdir(parents=True, exist_ok=True)
        xdmf = XDMFFile(model.mesh.comm, str(Path(out) / "fields.xdmf"), "w")
        xdmf.write_mesh(model.mesh)

    frames = [0]

    def record(stage, iterations, t0, switched=False):
        obs = observer.observe(stage, iterations, switched, time.perf_counter() - t0)
        rows.append(obs.row)
        centerlines.append(observer.centerline(CENTERLINE_STATIONS))
        if xdmf is not None:  # time stamps count frames (a replaced row keeps its frame)
            model.update_output_fields()
            xdmf.write_function(model.u1, float(frames[0]))
            xdmf.write_function(model.theta1, float(frames[0]))
            obs.row["xdmf_time"] = frames[0]
            frames[0] += 1
        if progress:
            r = obs.row
            print(f"{stage:11s} dL/L={r['dL_over_L']:.4f} dW/L={r['dW_over_L']:+.4f} H/L={r['H_mid_over_L']:.5f} "
                  f"F={r['F_shear_norm']:+.4f} lam={r['lambda_min']:.4g} neg={r['negative_eigenvalues']} "
                  f"{r['phase']:4s} it={iterations} {r['wall_time_s']:.2f}s", flush=True)
        return obs

    t0_path = time.perf_counter()
    switched = False
    last_stable_u = None  # (load, state, history) of the last recorded stable U state
    last_us = None
    dw1_info = dw2_info = None
    step_times = []
    try:
        t0 = time.perf_counter()
        model.set_clamp(0.0, 0.0)
        record("compression", 0, t0)
        for k in range(1, protocol.compression_steps + 1):
            t0 = time.perf_counter()
            target = dL * k / protocol.compression_steps
            if k == 1:
                guess_at = min(target, GUESS_COMPRESSION_LIMIT)
                model.set_clamp(guess_at, 0.0)
                model.inextensible_guess(guess_at)
                try:
                    its = solver.newton()
                except Exception as exc:
                    raise ContinuationFailure(f"Newton from the inextensible guess at dL/L = {guess_at:g}: {exc}")
                stepper.branch.reset(stepper.load, model.get_state())
                stats = stepper.advance((target, 0.0))
                its += stats.newton_iterations
            else:
                its = stepper.advance((target, 0.0)).newton_iterations
            record("compression", its, t0)
            step_times.append(time.perf_counter() - t0)
        summary["H_mid_over_L_compressed"] = rows[-1]["H_mid_over_L"]
        stepper.branch.reset(stepper.load, model.get_state())
        n_shear = protocol.shear_steps if dW_end != 0.0 else 0
        for k in range(1, n_shear + 1):
            t0 = time.perf_counter()
            target = (dL, dW_end * k / protocol.shear_steps)
            its = stepper.advance(target).newton_iterations
            obs = record("shear", its, t0)
            row = obs.row
            if not switched and row["phase"] == "U":
                if obs.negative == 0:
                    last_stable_u = (stepper.load, model.get_state(),
                                     Branch(list(stepper.branch.loads), list(stepper.branch.states)))
                elif options.thresholds or options.branch_switching:
                    here = (stepper.load, model.get_state(),
                            Branch(list(stepper.branch.loads), list(stepper.branch.states)))
                    if options.thresholds and dw1_info is None and last_stable_u is not None:
                        tt = time.perf_counter()
                        dw1, it1 = locate_dw1(stepper, last_stable_u, target[1])
                        dw1_info = {"dW1": dw1, "iterations": it1, "time": time.perf_counter() - tt}
                        stepper.restore(here[0], here[1], here[2])
                    if options.branch_switching:
                        tt = time.perf_counter()
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
                tt = time.perf_counter()
                dw2, it2 = locate_dw2(stepper, last_us, target[1])
                dw2_info = {"dW2": dw2, "iterations": it2, "time": time.perf_counter() - tt}
                stepper.restore(here[0], here[1], here[2])
            step_times.append(time.perf_counter() - t0)
        summary["converged"] = True
        summary["message"] = "path complete"
    except ContinuationFailure as exc:
        load = stepper.load
        share = 100.0 * abs(load[1]) / shear_ratio if shear_ratio > 0 else 0.0
        summary["message"] = (f"stopped converging at dL/L = {load[0]:.6f}, dW/L = {load[1]:.6f} "
                              f"({share:.1f} % of dW_max): {exc}")
    finally:
        if xdmf is not None:
            xdmf.close()
        if dw1_info:
            summary["dW1_over_L"] = abs(dw1_info["dW1"])
        if dw2_info:
            summary["dW2_over_L"] = abs(dw2_info["dW2"])
        summary["threshold_wall_time_s"] = sum(d["time"] for d in (dw1_info, dw2_info) if d)
        summary["newton_iterations"] = solver.total_iterations
        summary["wall_time_s"] = time.perf_counter() - t0_path + summary["build_wall_time_s"]
        summary["path_wall_time_s"] = time.perf_counter() - t0_path
        summary["wall_time_per_step_s"] = float(np.mean(step_times)) if step_times else None
        summary["recorded_steps"] = len(rows)
        summary["resolved_up_to_dW_over_L"] = resolved_up_to(rows)
        result = FemResult(rows, summary, centerlines=centerlines)
        if out is not None:
            result.write(out)
    return result
