"""The one compress-then-shear loop: every model and stepper runs the protocol through `execute`.

A run is a `Run`: a stepper (what reaches the next recorded load: static continuation, implicit
Euler, the rod-driven ribbon, the FEM shell's continuation), the recorded loads (`Loading`), how
a state becomes a row of path.csv (`observe`), listeners told of every recorded row (run folder,
centerlines, frames, progress, threshold brackets), and the steps after the path (thresholds,
branch tracing). `follow` walks the loads; `execute` runs the steps after it, fills the
summary's status and writes the run's files, in that order and outside any `finally`:

- the stepper cannot reach a load (its `failure` exception): the path stops there, the
  converged part is kept, status "stopped" with the stepper's message; the steps after the path
  still run on what was recorded;
- Ctrl-C or SIGTERM (KeyboardInterrupt): what was computed is written, status "interrupted",
  and the interrupt is re-raised with the result attached (`exc.result`);
- any other exception is a bug or a resource failure: the rows so far are written with status
  "error" and a message naming it, then it is re-raised (never a silent wrong answer).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Callable, Protocol, Sequence

from ..geometry.strip import LoadingProtocol, Strip
from ..output.interrupts import interrupt_behind
from ..solve.blas_threads import blas_threads
from ..solve.probe import SILENT, Probe
from ..solve.state import BranchOrientation, half_turn_odd_part
from .validity import add_validity_warnings, raise_warnings
from .results import SimulationResult, finish_summary


@dataclass(frozen=True)
class Loading:
    """The recorded clamp displacements (m): compression targets dL_k along -x, then shear
    targets dW_k along y at the full compression (paper section 2, Fig. 2)."""
    compression: tuple[float, ...]
    shear: tuple[float, ...]
    shear_compression: float  # dL held during the shear stage (the last compression target)

    @classmethod
    def equally_spaced(cls, strip: Strip, protocol: LoadingProtocol, in_units_of_length: bool = False) -> "Loading":
        """protocol.compression_steps equal steps to dL, then protocol.shear_steps equal steps to
        dW (none when dW = 0); in m, or in units of L with in_units_of_length (a model scaled to
        L = 1, the FEM shell: dL/L k/n exactly as the ratios give it)."""
        L = 1.0 if in_units_of_length else strip.length
        dL = protocol.compression_ratio * L
        dW = protocol.shear_sign * protocol.resolved_shear_ratio(strip) * L
        n_shear = protocol.shear_steps if dW != 0.0 else 0
        return cls(tuple(dL * k / protocol.compression_steps for k in range(1, protocol.compression_steps + 1)),
                   tuple(dW * k / protocol.shear_steps for k in range(1, n_shear + 1)), dL)


class Stepper(Protocol):
    """What the driver needs of a solver.

    failure: the exception class meaning "this load cannot be reached" (the path stops, the
    converged part is kept); failure_message(exc) turns it into summary.json's message. A
    failure whose `reached` attribute is a state converged at that load (the FEM shell's unstable
    U when the branch switch from it fails) has that state recorded before the path stops.
    rest(): the recorded state at dL = dW = 0. advance(state, compression, shear, stage, index):
    the recorded state at the next load (index counts the stage's loads from 0).
    summarise(summary): the stepper's own counts (Newton iterations, phases, folds) into the
    summary at the end."""

    model: object
    failure: type

    def rest(self): ...

    def advance(self, state, compression: float, shear: float, stage: str, index: int): ...

    def failure_message(self, exc: BaseException) -> str: ...

    def summarise(self, summary: dict) -> None: ...


#: listener(stage, state, row): told of every recorded row, in order, after it is appended
Listener = Callable[[str, object, dict], None]


@dataclass
class PathOutcome:
    """What the loop reached: the rows, the last recorded state, and how the path ended."""
    rows: list[dict] = field(default_factory=list)
    state: object = None
    compressed: object = None         # the state at the end of compression, if reached
    complete: bool = False
    stopped: str | None = None        # the stepper's failure message
    interrupted: BaseException | None = None
    error: BaseException | None = None
    stage: str = "the compression stage"  # where the run was when it ended (for the message)


@dataclass
class AfterStep:
    """A step after the path (threshold location, branch tracing): `run(outcome)` fills the
    summary (and may return rows for the result); `stage` names it in messages, `checkpoint` is
    summary.json's message while it runs."""
    stage: str
    run: Callable[[PathOutcome], None]
    checkpoint: str = ""


@dataclass
class Run:
    """Everything one run of the protocol needs; see the module docstring."""
    stepper: Stepper
    loading: Loading
    observe: Callable[[str, object], dict]
    summary: dict
    listeners: Sequence[Listener] = ()
    folder: object = None                                    # ddg.output.io.RunFolder or None
    after: Sequence[AfterStep] = ()
    on_compressed: Callable[[PathOutcome], None] | None = None
    make_result: Callable[[PathOutcome], SimulationResult] | None = None
    close: Sequence[Callable[[], None]] = ()                 # writers and progress bars to close
    probe: Probe = SILENT                                    # told of every recorded step and its wall time
    started: float | None = None                             # perf_counter() at the run's start (else execute's)
    announce: Callable[..., None] | None = None              # told (stage) / (stage, done=True) around each AfterStep


def follow(run: Run) -> PathOutcome:
    """Walk the recorded loads: rest, compression, shear; never raises for a failed step or an
    interrupt (they end the walk and are kept in the outcome)."""
    stepper, out = run.stepper, PathOutcome()
    clock = [time.perf_counter()]
    model = getattr(stepper, "model", None)
    # ddg's models name branches by continuity (BranchOrientation); a model without symmetry
    # partners (the FEM shell, whose states are observations) keeps the labels it gives
    orientation = BranchOrientation() if hasattr(model, "symmetry_partners") else None

    def record(stage: str, state) -> None:
        row = run.observe(stage, state)
        if orientation is not None and row.get("phase") and hasattr(state, "q"):
            row["phase"] = orientation.label(row["phase"], lambda: half_turn_odd_part(
                model, state.q, state.compression, state.shear))
        out.rows.append(row)
        out.state = state
        for listener in run.listeners:
            listener(stage, state, row)
        now = time.perf_counter()
        run.probe.step(stage, row, now - clock[0])
        clock[0] = now

    kind = "compression"  # the stage of the rows being recorded
    try:
        state = stepper.rest()
        record("compression", state)
        for k, target in enumerate(run.loading.compression):
            state = stepper.advance(state, target, 0.0, "compression", k)
            record("compression", state)
        out.compressed = state
        run.summary["H_mid_over_L_compressed"] = out.rows[-1]["H_mid_over_L"]
        if run.on_compressed is not None:
            run.on_compressed(out)
        out.stage, kind = "the shear stage", "shear"
        compression = run.loading.shear_compression
        for k, target in enumerate(run.loading.shear):
            state = stepper.advance(state, compression, target, "shear", k)
            record("shear", state)
        out.complete = True
    except KeyboardInterrupt as exc:
        out.interrupted = exc
    except Exception as exc:  # noqa: BLE001  (sorted below: the stepper's failure, or an error re-raised later)
        interrupt = interrupt_behind(exc)
        if interrupt is not None:
            out.interrupted = interrupt
        elif isinstance(exc, stepper.failure):
            out.stopped = stepper.failure_message(exc)
            if getattr(exc, "reached", None) is not None:  # converged at the load, the step's goal not reached
                try:
                    record(kind, exc.reached)
                except KeyboardInterrupt as late:
                    out.interrupted = late
        else:
            out.error = exc
    return out


def _model_stop_note(run: Run, out) -> None:
    """A stopped path's model may know why it could not go on beyond what Newton saw (the
    Wunderlich ribbon at its ruling factor's pole): its `stop_note(q)` at the last converged state
    is added to the message and the warnings."""
    note = getattr(getattr(run.stepper, "model", None), "stop_note", None)
    if out.stopped is None or out.state is None or note is None:
        return
    text = note(out.state.q)
    if text:
        run.summary["message"] = f"{run.summary['message']}; {text}"
        run.summary["warnings"].append(text)


def execute(run: Run) -> SimulationResult:
    """follow(run), then the steps after the path, the summary, the run's files; returns the
    result, or re-raises an interrupt or an error after writing what was computed. The whole run
    has the BLAS threads of ddg.solve.blas_threads (one by default), restored afterwards."""
    with blas_threads():
        return _execute(run)


def _execute(run: Run) -> SimulationResult:
    t0 = run.started if run.started is not None else time.perf_counter()
    out = follow(run)
    for closer in run.close:
        closer()
    if out.interrupted is None and out.error is None and out.state is not None:
        try:
            for step in run.after:
                out.stage = step.stage
                if run.folder is not None:
                    run.folder.checkpoint({**run.summary, "message": step.checkpoint or f"running: {step.stage}"})
                if run.announce is not None:
                    run.announce(step.stage)
                step.run(out)
                if run.announce is not None:
                    run.announce(step.stage, done=True)
        except KeyboardInterrupt as exc:
            out.interrupted = exc
        except Exception as exc:  # noqa: BLE001  (written as status "error", then re-raised)
            out.interrupted = interrupt_behind(exc)
            if out.interrupted is None:
                out.error = exc
    run.summary["wall_time_s"] = time.perf_counter() - t0
    run.stepper.summarise(run.summary)
    finish_summary(run.summary, out.rows, path_complete=out.complete, stopped=out.stopped,
                   interrupted=out.interrupted, stage=out.stage, error=out.error)
    _model_stop_note(run, out)
    if out.error is None:
        add_validity_warnings(run.summary, out.rows)
    result = (run.make_result(out) if run.make_result is not None
              else SimulationResult(out.rows, run.summary, out.state, run.stepper.model))
    if run.folder is not None:
        run.folder.finish(result)
    raised = out.interrupted if out.interrupted is not None else out.error
    if raised is not None:
        raised.result = result
        raise raised
    raise_warnings(run.summary)
    return result


def distinct(values: Sequence[float], tolerance: float) -> list[float]:
    """values without the ones within tolerance of an earlier one (a fold met by several substeps)."""
    kept: list[float] = []
    for v in values:
        if all(abs(v - w) > tolerance for w in kept):
            kept.append(float(v))
    return kept
