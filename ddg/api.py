"""Python API: ddg.simulate(strip, protocol, model="rod") mirrors `python -m ddg simulate`.

The entry points check their inputs, build the model, the stepper and the listeners, and hand
them to the one loading loop (ddg.protocol.driver.execute): `simulate` (rod, plate, ribbon;
static or implicit Euler), `run_ribbon` (the Sadowsky ribbon started directly or from the rod).
"""
from __future__ import annotations

import dataclasses
import os
from dataclasses import replace
from pathlib import Path

import numpy as np

from .analysis.observables import observe
from .limits import InputError
from .geometry.strip import LoadingProtocol, Strip
from .models import registry
from .models.names import MIDEDGE_PLATE, RIBBON, ROD
from .models.ribbon import RIBBON_INITS
from .protocol.after import BranchStep, Brackets, ThresholdStep
from .protocol.driver import AfterStep, Loading, Run, execute
from .protocol.progress import ProgressBar
from .protocol.results import DynamicResult, RibbonResult, SimulationResult, base_summary
from .protocol.steppers import ImplicitEulerStepper, RodDrivenStepper, StaticStepper, dynamic_loading
from .solve.blas_threads import requested_threads as requested_blas_threads
from .solve.continuation import ContinuationOptions
from .solve.probe import SILENT, Probe

__all__ = ["simulate", "run_ribbon", "simulate_dynamic", "make_model", "SimulationResult", "RibbonResult",
           "DynamicResult"]

#: Default resolution per model (ddg.models.registry): rod family M nodes, plates target triangles.
DEFAULT_RESOLUTION = {name: entry.default_resolution for name, entry in registry.MODELS.items()}
#: The models on the rod's centreline and frame (resolution = node count M).
ROD_FAMILY = registry.names_in(registry.ROD_FAMILY)


#: Stations along the centerline exported per recorded step (centerline.csv).
CENTERLINE_STATIONS = 101


def make_model(name: str, strip: Strip, resolution: int | None = None, mesh=None, zeta: float | None = None,
               membrane: str | None = None):
    """The model `name` of the strip at `resolution` (rod: nodes M; plate: target triangles).

    zeta (m): the regularisation length of the ribbon (Eq. A.5) and of the Wunderlich ribbon's
    ruling slope (ddg.energies.wunderlich); other models refuse it.

    mesh (plate only): a PlateMesh, the path of a mesh file meshio reads, or "gmsh" for an
    unstructured gmsh mesh with about `resolution` triangles; default the structured mesh.
    """
    entry = registry.entry(name)
    cls = entry.model_class
    resolution = check_resolution(name, resolution)
    if membrane is not None and not entry.accepts(registry.MEMBRANE):
        raise InputError(f"membrane applies to the model {_listed(registry.MEMBRANE)} only, not {name!r}")
    extra = {"membrane": membrane} if membrane is not None else {}
    if zeta is not None:
        if not entry.accepts(registry.ZETA):
            raise InputError(f"zeta applies to the models {_listed(registry.ZETA)} only, not {name!r}")
        if mesh is not None:
            raise InputError(f"a mesh is used by the plate models only, not {name!r}")
        return cls(strip, resolution, zeta=zeta)
    if mesh is None:
        return cls(strip, resolution, **extra)
    if not entry.accepts(registry.MESH):
        raise InputError(f"a mesh is used by the plate models only, not {name!r}")
    from .geometry.plate_mesh import PlateMesh

    if not entry.accepts(registry.MESH_FILE):
        if not isinstance(mesh, PlateMesh):
            raise InputError(f"mesh = {mesh!r}: the mid-edge plate takes a PlateMesh from "
                             "ddg.geometry.plate_mesh.ghost_clamp_mesh (no mesh files)")
        return cls(strip, mesh=mesh, **extra)

    if not isinstance(mesh, (PlateMesh, str, os.PathLike)) or isinstance(mesh, bool):
        raise InputError(f"mesh = {mesh!r} must be a PlateMesh, a mesh file path or 'gmsh'")
    if not isinstance(mesh, PlateMesh):
        from .geometry import mesh_io

        if str(mesh) == "gmsh":
            mesh = mesh_io.gmsh_mesh(strip.length, strip.width, resolution)
        else:
            mesh = mesh_io.read_mesh(mesh, strip.length, strip.width)
    return cls(strip, mesh=mesh)


def _frame_writer(model, directory: Path):
    """Frames of a plate as its triangles, of a rod or ribbon as the strip of width W it stands for
    (ddg.output.frame_fields)."""
    from .output.frame_fields import frame_cells
    from .output.frames import FrameWriter

    cells, flat = frame_cells(model)
    return FrameWriter(directory, cells, reference=flat, cell_type="triangle")


def _listed(option: str) -> str:
    """The models accepting `option`, quoted and joined as the error messages say them."""
    return " and ".join(repr(name) for name in registry.accepting(option))


def _model_class(name: str):
    return registry.entry(name).model_class


def check_model_name(model) -> str:
    """model as one of the available names (a one-line InputError otherwise)."""
    return registry.entry(model).name


def check_resolution(model: str, resolution, strip: Strip | None = None, mesh=None) -> int:
    """The resolution of `model` within what the model needs and the machine can run.

    rod, ribbon: node count M in [MIN_NODES, MAX_NODES]; plate: target triangle count in
    [16, MAX_TRIANGLES], its memory estimated (ddg.geometry.plate_mesh) and compared with the
    memory available (ddg.limits.check_memory)."""
    from .geometry.centerline import MIN_NODES
    from .limits import check_integer

    check_model_name(model)
    if resolution is None:
        return DEFAULT_RESOLUTION[model]
    if model in ROD_FAMILY:
        return check_integer("resolution (node count M)", resolution, MIN_NODES, MAX_NODES,
                             "M = 200 already resolves the thresholds to 1e-4 L")
    value = check_integer("resolution (target triangle count)", resolution, 16, MAX_TRIANGLES)
    if strip is not None and (mesh is None or str(mesh) == "gmsh"):
        from .geometry import plate_mesh
        from .limits import check_memory

        estimate = getattr(plate_mesh, "plate_memory_estimate_bytes", None)
        if estimate is not None:
            # the mid-edge plate: about twice the DOFs and twice the bandwidth of the paper's plate
            factor = 4.0 if model == MIDEDGE_PLATE else 1.0
            check_memory("resolution (target triangle count)", value,
                         factor * estimate(strip.length, strip.width, value))
    return value


#: Largest rod/ribbon node count: the error of the thresholds is ~1.8 / M^2 (dW1/L: 0.0044 at
#: M = 20, 0.0020 at 30, 0.0006 at 50, measured); 5000 nodes cost ~40 s per path and gain nothing.
MAX_NODES = 5000
#: Largest plate triangle count accepted before the memory estimate is even consulted.
MAX_TRIANGLES = 1_000_000




def _open_folder(out, summary: dict):
    """The RunFolder of `out` (None if out is None), marked in progress with this summary."""
    if out is None:
        return None
    from .output.io import RunFolder

    return RunFolder(out, summary)


def _recorders(model, folder, progress_bar, writer=None, compression_ratio: float = 0.0, centerline: bool = True):
    """Listeners every model's run has: path.csv row by row, the centerline per row (unless
    centerline=False: then no centerline.csv either), frames, progress; returns (listeners, centerlines)."""
    centerlines: list[np.ndarray] = []
    recorded = [0]   # rows so far: the frame number

    def keep_centerline(stage, state, row):
        recorded[0] += 1
        if centerline:
            centerlines.append(model.centerline_positions(state.q, CENTERLINE_STATIONS)[0])

    listeners = []
    if folder is not None:
        listeners.append(lambda stage, state, row: folder.append(row))
    listeners.append(keep_centerline)
    if writer is not None:
        from .output.frame_fields import frame_content

        def write_frame(stage, state, row):
            points, cells = frame_content(model, state.q)
            # ParaView's time: dW/L on the shear, dL/L - dL_end/L (<= 0) on the compression
            time = row["dW_over_L"] if stage == "shear" else row["dL_over_L"] - compression_ratio
            writer.write(points, step=recorded[0] - 1, dL_over_L=row["dL_over_L"], dW_over_L=row["dW_over_L"],
                         stage=stage, cell_data=cells, time=time)

        listeners.append(write_frame)
    listeners.append(progress_bar)
    return listeners, centerlines


def _checked_options(options) -> ContinuationOptions:
    if options is not None and not isinstance(options, ContinuationOptions):
        raise InputError(f"options = {options!r} must be a ddg.ContinuationOptions")
    return replace(options) if options is not None else ContinuationOptions()  # re-validated


def _checked_scene(strip, protocol) -> None:
    if not isinstance(strip, Strip):
        raise InputError(f"strip = {strip!r} must be a ddg.Strip")
    if not isinstance(protocol, LoadingProtocol):
        raise InputError(f"protocol = {protocol!r} must be a ddg.LoadingProtocol")


def _checked_flags(**flags) -> None:
    for name, value in flags.items():
        if not isinstance(value, (bool, np.bool_)):
            raise InputError(f"{name} = {value!r} must be True or False")


def simulate(
    strip: Strip,
    protocol: LoadingProtocol,
    model: str = ROD,
    resolution: int | None = None,
    out: str | Path | None = None,
    options: ContinuationOptions | None = None,
    progress: bool = False,
    solver: str = "static",
    dynamic_options=None,
    mesh=None,
    frames: bool = False,
    thresholds: bool = True,
    branches: bool | None = None,
    probe: Probe | None = None,
    tolerance: float | None = None,
    quantities=None,
    error_map=None,
    zeta: float | None = None,
    centerline: bool = True,
    membrane: str | None = None,
) -> SimulationResult:
    """Run the two-stage protocol (compress by dL, then shear by dW) on one model.

    solver="static" (default): Newton continuation of equilibria; solver="dynamic": the
    paper's implicit-Euler time marching (Eq. 7) with the clamp moved at a finite speed
    (rod only; see ddg.solve.dynamics). Returns every recorded equilibrium (rows of
    path.csv), the summary and the deformed centerline (w = 0) per row; writes them to `out`
    (path.csv, summary.json, centerline.csv) if given. `out` is checked writable before any
    work; from the start summary.json says status "running" and path.csv grows by one row per
    recorded step, so a killed run keeps every converged step and is never mistaken for a
    finished one. A run that stops converging keeps the converged part (status "stopped");
    Ctrl-C or SIGTERM (KeyboardInterrupt) writes what was computed (status "interrupted"),
    then re-raises with the result attached as `exc.result`.
    frames=True also writes out/frames/frame_NNNNN.vtu per
    recorded step and out/frames/frames.pvd (ParaView). mesh: see make_model. thresholds=True
    locates dW1 and dW2 from stability after the path (ddg.solve.thresholds; summary keys
    dW1_over_L, dW2_over_L, dW2_S_stable_over_L) when the recorded path brackets them; a
    threshold whose states the discretisation does not resolve is reported null, with its
    value and the reason under `unresolved_thresholds` and in `warnings`.
    branches=True (with thresholds; default None: True for the rod, False for the plate, whose
    diagram costs more than its path: docs/findings/measured.md) then traces every
    branch of the shear stage by pseudo-arclength continuation, stable and unstable parts,
    through folds (U, US+, US-, and S from the first S state of the path; ddg.solve.branches):
    rows in result.branch_rows and out/branches.csv (path.csv's columns after a `branch`
    column), per-branch summary under the summary key `branches`.
    probe: a ddg.solve.probe.Probe told of every Newton solve of the path and every recorded
    step with its wall time (benchmarks, progress displays).
    zeta (m): the regularisation length of model "ribbon" (Eq. A.5, default 1e4 L) and of
    "ribbon-wunderlich"'s ruling slope (default the Sano-Wada value sqrt((1 - nu) / 60) W^2 / b);
    summary keys zeta, zeta_over_L. The ribbons with width ("ribbon-sano-wada", "ribbon-trapeze",
    "ribbon-cross-section", "ribbon-wunderlich", ddg.models.wide_ribbons) run like the rod (resolution = nodes M).
    membrane (model "plate-midedge" only): "psri" (default: alpha = b^2/h^2 of the constant-strain
    triangles, the rest node-smoothed, against membrane locking) or "full" (constant-strain
    triangles alone); ddg.models.midedge_plate.MEMBRANES, summary key membrane.
    centerline=False records no centerline (result.centerlines empty, no out/centerline.csv): for
    studies that read only path.csv and summary.json (the gold and mesh studies in data/).
    model="auto" with `tolerance` (units of L; `quantities` of dW1, dW2, H_mid, default all;
    `error_map` a CSV, default $DDG_ERROR_MAP or data/error_map/error_map.csv): the cheapest
    model and resolution the error map predicts within the tolerance on this scene, else the most
    accurate one labelled as not within it (outside the map: error unknown; ddg.advise rule v3,
    simulate_auto), run; summary key `auto` says which and why.
    """
    _checked_scene(strip, protocol)
    requested_blas_threads()   # DDG_BLAS_THREADS refused before any work
    if isinstance(model, str) and model == "auto":
        return simulate_auto(strip, protocol, tolerance, quantities, error_map, resolution=resolution, out=out,
                             options=options, progress=progress, solver=solver, dynamic_options=dynamic_options,
                             mesh=mesh, frames=frames, thresholds=thresholds, branches=branches, probe=probe,
                             centerline=centerline)
    if tolerance is not None or quantities is not None or error_map is not None:
        raise InputError(f"tolerance = {tolerance!r} (and quantities, error_map) apply to model='auto' only, "
                         f"not model = {model!r}")
    if not isinstance(solver, str) or solver not in ("static", "dynamic"):
        raise InputError(f"solver = {solver!r} is not available; choose 'static' or 'dynamic'")
    check_model_name(model)
    if options is not None and not isinstance(options, ContinuationOptions):
        raise InputError(f"options = {options!r} must be a ddg.ContinuationOptions")
    _checked_flags(progress=progress, frames=frames, thresholds=thresholds, centerline=centerline)
    if probe is not None and not isinstance(probe, Probe):
        raise InputError(f"probe = {probe!r} must be a ddg.solve.probe.Probe")
    if branches is not None and not isinstance(branches, (bool, np.bool_)):
        raise InputError(f"branches = {branches!r} must be True, False or None")
    resolution = check_resolution(model, resolution, strip, mesh)
    if zeta is not None and not registry.entry(model).accepts(registry.ZETA):
        raise InputError(f"zeta applies to the models {_listed(registry.ZETA)} only, not {model!r}")
    protocol.resolved_shear_ratio(strip)
    if out is not None:
        from .output.io import check_output_directory

        check_output_directory(out)
    if solver == "dynamic":
        if model != ROD:
            raise InputError(f"solver = 'dynamic' is available for model {ROD!r} only, not {model!r}")
        if frames or mesh is not None:
            raise InputError("frames and mesh are options of the static solver; drop them or use solver='static'")
        return simulate_dynamic(strip, protocol, resolution, dynamic_options, out=out)
    if dynamic_options is not None:
        raise InputError("dynamic_options apply to solver='dynamic' only")
    branches = (not registry.entry(model).resolves_width) if branches is None else bool(branches)
    instance = make_model(model, strip, resolution, mesh, zeta=zeta, membrane=membrane)
    if frames and out is None:
        raise InputError("frames=True needs an output directory (out)")
    options = _checked_options(options)
    extra = {"zeta": instance.zeta, "zeta_over_L": instance.zeta / strip.length} if hasattr(instance, "zeta") \
        else None
    return _static_run(model, instance, strip, protocol, resolution, options, out, progress, thresholds, branches,
                       frames=frames, probe=probe, summary_extra=extra, centerline=centerline)


def simulate_model(instance, protocol: LoadingProtocol, *, options: ContinuationOptions | None = None,
                   out: str | Path | None = None, thresholds: bool = True, branches: bool = False,
                   centerline: bool = True, probe: Probe | None = None) -> SimulationResult:
    """The two-stage protocol on a model the caller built (a static run, as `simulate`): e.g. a
    ddg.models.midedge_plate.MidedgePlateModel on a mesh of one's own or with a fixed membrane
    share (the mesh studies of validation.midedge_convergence). The strip is the model's."""
    strip = instance.strip
    _checked_scene(strip, protocol)
    protocol.resolved_shear_ratio(strip)
    _checked_flags(thresholds=thresholds, centerline=centerline)
    if out is not None:
        from .output.io import check_output_directory

        check_output_directory(out)
    return _static_run(instance.name, instance, strip, protocol, None, _checked_options(options), out, False,
                       thresholds, bool(branches), probe=probe, centerline=centerline)


def _static_run(name, instance, strip, protocol, resolution, options, out, progress, thresholds, branches,
                frames=False, summary_extra=None, stepper=None, result=SimulationResult, probe=None,
                centerline=True):
    """A static run of `instance` (or of `stepper`'s model) through the driver: the rows,
    the thresholds from the model's own stability, the branches (if asked)."""
    loading = Loading.equally_spaced(strip, protocol)
    summary = base_summary(name, strip, protocol, resolution, instance)
    summary.update(summary_extra or {})
    folder = _open_folder(out, summary)
    writer = _frame_writer(instance, Path(out) / "frames") if frames else None
    bar = ProgressBar(len(loading.compression) + len(loading.shear) + 1, progress)
    listeners, centerlines = _recorders(instance, folder, bar, writer, protocol.compression_ratio, centerline)
    stepper = stepper or StaticStepper(instance, options, probe=probe)
    after, on_compressed, branch_step = [], [], None
    extra_rows = {}
    if isinstance(stepper, RodDrivenStepper):
        rod, rod_rows = stepper.rod, []
        extra_rows["rod_rows"] = rod_rows
        rod_brackets = Brackets(rod)

        def rod_row(stage, state, row):
            rod_rows.append(observe(rod, stepper.driven, stage, options.eigenvalues))
            rod_brackets(stage, stepper.driven, rod_rows[-1])

        listeners.insert(0, rod_row)
        if thresholds and options.eigenvalues:
            after.append(ThresholdStep(summary, rod, options, rod_brackets, rows=rod_rows, prefix="rod_"))
    elif thresholds and options.eigenvalues:
        brackets = Brackets(instance)
        listeners.insert(1 if folder is not None else 0, brackets)
        after.append(ThresholdStep(summary, instance, options, brackets))
        if branches and loading.shear:
            branch_step = BranchStep(summary, instance, options, loading.shear[-1], brackets)
            on_compressed.append(branch_step.remember_compressed)
            after.append(branch_step)
    if folder is not None:
        shearing = "running: compression complete, shearing"
        on_compressed.append(lambda outcome: folder.checkpoint({**summary, "message": shearing}))

    def compressed(outcome):
        for hook in on_compressed:
            hook(outcome)

    def make_result(outcome):
        return result(outcome.rows, summary, outcome.state, instance, centerlines,
                      branch_step.rows if branch_step is not None else [], **extra_rows)

    closers = [bar.close] + ([writer.close] if writer is not None else [])
    run = Run(stepper, loading, lambda stage, state: observe(instance, state, stage, options.eigenvalues), summary,
              listeners, folder, [AfterStep(step.stage, step.run, step.checkpoint) for step in after], compressed,
              make_result, closers, probe or SILENT, announce=bar.announce)
    return execute(run)


def run_ribbon(strip: Strip, protocol: LoadingProtocol, init: str = "direct", zeta: float | None = None,
               resolution: int | None = None, out=None, options: ContinuationOptions | None = None,
               thresholds: bool = True, progress: bool = False, probe: Probe | None = None,
               centerline: bool = True) -> RibbonResult:
    """The ribbon (Eq. A.5) through the two-stage protocol, started "direct" or from the "rod".

    Rows, summary and centerlines as ddg.simulate (path.csv, summary.json, centerline.csv);
    summary adds ribbon_init, zeta, zeta_over_L. init="direct" locates dW1 from the ribbon's own
    stability where its path leaves U (None if it never does); init="rod" reports the rod's
    thresholds as rod_dW1_over_L, rod_dW2_over_L and writes the rod's rows to rod_path.csv.
    probe, centerline: as in simulate (for init="rod", the rod's solves).
    """
    from .models.ribbon import RibbonModel
    from .models.rod import RodModel

    requested_blas_threads()
    if init not in RIBBON_INITS:
        raise InputError(f"ribbon init = {init!r} is not available; choose one of {list(RIBBON_INITS)}")
    if not isinstance(strip, Strip) or not isinstance(protocol, LoadingProtocol):
        raise InputError("run_ribbon needs a ddg.Strip and a ddg.LoadingProtocol")
    resolution = check_resolution(RIBBON, resolution)
    _checked_flags(centerline=centerline)
    if out is not None:
        from .output.io import check_output_directory

        check_output_directory(out)
    options = _checked_options(options)
    ribbon = RibbonModel(strip, resolution, zeta=zeta)
    stepper = RodDrivenStepper(ribbon, RodModel(strip, resolution), options, probe) if init == ROD \
        else StaticStepper(ribbon, options, folds=False, probe=probe)
    L = strip.length
    return _static_run(RIBBON, ribbon, strip, protocol, resolution, options, out, progress, thresholds, False,
                       summary_extra={"ribbon_init": init, "zeta": ribbon.zeta, "zeta_over_L": ribbon.zeta / L},
                       stepper=stepper, result=RibbonResult, probe=probe, centerline=centerline)


def simulate_dynamic(strip: Strip, protocol: LoadingProtocol, resolution: int = 100, options=None,
                     out: str | Path | None = None) -> DynamicResult:
    """The two-stage protocol of ddg.simulate (model "rod") by implicit-Euler time marching.

    Stage 1 moves the clamp at s = L along -x at options.clamp_speed until dL = protocol
    .compression_ratio L; stage 2 moves it along y (sign protocol.shear_sign) until
    dW = protocol.resolved_shear_ratio(strip) L. Rows (the columns of ddg.analysis.observables
    .observe) are recorded at the static solver's loads, which the time steps hit exactly; the
    summary has the static summary's keys plus "solver": "implicit-euler", the options under
    scene["dynamics"]. On a Newton failure the step is halved up to options.max_halvings times;
    then the run stops with converged=False, keeping the rows so far.
    """
    from .models.rod import RodModel
    from .solve.dynamics import DynamicOptions

    _checked_scene(strip, protocol)
    requested_blas_threads()   # DDG_BLAS_THREADS refused before any work
    if options is not None and not isinstance(options, DynamicOptions):
        raise InputError(f"options = {options!r} must be a ddg.solve.dynamics.DynamicOptions")
    options = dataclasses.replace(options) if options is not None else DynamicOptions()  # re-validated
    options.check_scene(strip, protocol)
    model = RodModel(strip, resolution)
    summary = base_summary(ROD, strip, protocol, resolution, model)
    summary["solver"] = "implicit-euler"
    summary["scene"]["dynamics"] = dataclasses.asdict(options)
    folder = _open_folder(out, summary)
    stepper = ImplicitEulerStepper(model, options)
    listeners = [lambda stage, state, row: folder.append(row)] if folder is not None else []

    def make_result(outcome):
        return DynamicResult(outcome.rows, summary, outcome.state, model, trace=stepper.trace)

    run = Run(stepper, dynamic_loading(strip, protocol, options),
              lambda stage, state: observe(model, state, stage, options.eigenvalues), summary, listeners, folder,
              make_result=make_result)
    return execute(run)


def run_candidate(strip: Strip, protocol: LoadingProtocol, model: str, resolution: int, out=None,
                  options: ContinuationOptions | None = None, progress: bool = False, thresholds: bool = True,
                  branches: bool = False, probe: Probe | None = None, centerline: bool = True) -> SimulationResult:
    """One candidate of the error map run as the map runs it (ddg.advise): the rod and the
    ribbons at M = `resolution` nodes (the Sadowsky ribbon from the flat strip, as `--model
    ribbon`), the plates on the study mesh of `resolution` rows of triangles across W
    (ddg.advise.study_mesh); no branch tracing unless asked; centerline as in simulate."""
    from .advise import study_mesh

    if registry.entry(model).resolves_width:
        return simulate(strip, protocol, model=model, mesh=study_mesh(model, strip, resolution), out=out,
                        options=options, progress=progress, thresholds=thresholds, branches=branches, probe=probe,
                        centerline=centerline)
    if model == RIBBON:
        return run_ribbon(strip, protocol, "direct", None, resolution, out=out, options=options,
                          thresholds=thresholds, progress=progress, probe=probe, centerline=centerline)
    return simulate(strip, protocol, model=model, resolution=resolution, out=out, options=options, progress=progress,
                    thresholds=thresholds, branches=branches, probe=probe, centerline=centerline)


def simulate_auto(strip: Strip, protocol: LoadingProtocol, tolerance, quantities=None, error_map=None, *,
                  resolution=None, out=None, options=None, progress=False, solver="static", dynamic_options=None,
                  mesh=None, frames=False, thresholds=True, branches=None, probe=None,
                  centerline=True) -> SimulationResult:
    """ddg.simulate(..., model="auto"): ddg.advise.choose on this scene (rule v3), then run_candidate
    with the choice: the cheapest candidate predicted within the tolerance, else the most accurate
    one labelled as not within it, or outside the map the model the map measured most accurate,
    labelled with an unknown error. summary["auto"]: chosen_model, resolution, verdict,
    within_tolerance, reason, predicted_errors, basis_scenes, map_file (ddg.advise.Choice
    .auto_block). Inputs are checked before any work; nu other than the map's is refused."""
    from .advise import choose
    from .output.io import check_output_directory, write_summary_json

    if tolerance is None:
        raise InputError("model = 'auto' needs a tolerance (units of L) in (0, 1], e.g. tolerance=0.01")
    if resolution is not None or mesh is not None:
        raise InputError(f"model = 'auto' chooses the resolution and mesh; drop resolution = {resolution!r} "
                         f"and mesh = {mesh!r}")
    if solver != "static" or dynamic_options is not None or frames:
        raise InputError(f"model = 'auto' runs the static solver without frames, not solver = {solver!r}"
                         + (" with frames" if frames else ""))
    _checked_flags(progress=progress, thresholds=thresholds, centerline=centerline)
    if branches is not None and not isinstance(branches, (bool, np.bool_)):
        raise InputError(f"branches = {branches!r} must be True, False or None")
    options = _checked_options(options)
    if probe is not None and not isinstance(probe, Probe):
        raise InputError(f"probe = {probe!r} must be a ddg.solve.probe.Probe")
    protocol.resolved_shear_ratio(strip)
    choice = choose(strip.width_ratio, protocol.compression_ratio, strip.slenderness, tolerance, quantities,
                    path=error_map, runnable=set(DEFAULT_RESOLUTION), poisson_ratio=strip.poisson_ratio)
    if out is not None:
        check_output_directory(out)
    branches = bool(branches) if branches is not None else False
    common = dict(options=options, progress=progress, thresholds=thresholds, branches=branches, probe=probe,
                  centerline=centerline)
    block = choice.auto_block()
    result = run_candidate(strip, protocol, choice.model, choice.resolution, out=out, **common)
    result.summary["auto"] = block
    if out is not None:
        write_summary_json(Path(out) / "summary.json", result.summary)
    return result
