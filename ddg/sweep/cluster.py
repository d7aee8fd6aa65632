"""The Dask side of a sweep and of the mesh-study generators: a client on a LocalCluster (default)
or on an existing scheduler, keyed tasks submitted to it as futures with retries, and the
command-line options that choose the cluster (--workers, --scheduler, --retries).

The only module of ddg that imports dask (lazily): `require_dask()` turns a missing install
into a one-line InputError naming the extra. A LocalCluster has one single-threaded worker
process per core; its scheduler gives a task whose worker dies `retries` more attempts
(distributed.scheduler.allowed-failures), and `retries` also re-runs a task that raised. An
existing scheduler keeps its own allowed-failures (3 by default). `run_all` is the loop every
command shares: submit the tasks, call back on the client as each one finishes, keep what
finished on Ctrl-C.
"""
from __future__ import annotations

import contextlib
import logging
import os
import socket
import sys
import uuid
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

from ..limits import InputError

DASK_EXTRA = "install the 'dask' extra: pip install ddg-strips[dask]"
#: Seconds to wait for an existing scheduler to answer.
CONNECT_TIMEOUT_S = 10
#: Most retries of a run: a run that fails 10 times fails for a reason that an 11th will not fix.
MAX_RETRIES = 10


def require_dask() -> None:
    """InputError with the extra to install unless dask and dask.distributed import."""
    import importlib

    try:
        importlib.import_module("dask")
        importlib.import_module("distributed")
    except ImportError:
        raise InputError(DASK_EXTRA) from None


def cores() -> int:
    """The cores this process may use (its CPU affinity), the LocalCluster's default worker count."""
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def default_scheduler() -> str | None:
    """Dask's own setting (DASK_SCHEDULER_ADDRESS or the `scheduler-address` key of a dask
    config file), None if unset: an existing cluster without a command-line option."""
    try:
        import dask
    except ImportError:
        return None
    return dask.config.get("scheduler-address", None) or None


@contextlib.contextmanager
def connect(scheduler: str | None = None, workers: int | None = None, retries: int = 2):
    """A dask.distributed Client: on `scheduler` (an address such as tcp://host:8786) or on a new
    LocalCluster of `workers` processes (default: the cores), one thread each; closed after."""
    require_dask()
    import dask
    from distributed import Client, LocalCluster

    if scheduler is not None:
        client = _client(scheduler, "--scheduler")
        try:
            yield client
        finally:
            client.close()
        return
    with dask.config.set({"distributed.scheduler.allowed-failures": retries}):
        cluster = LocalCluster(n_workers=workers or cores(), threads_per_worker=1, processes=True,
                               host="127.0.0.1", dashboard_address=None, silence_logs=logging.ERROR)
    try:
        client = Client(cluster)
        try:
            from .worker import IgnoreInterrupts

            # Ctrl-C reaches the terminal's whole process group: the client decides what is kept
            client.register_worker_plugin(IgnoreInterrupts(), name=IgnoreInterrupts.name)
            yield client
        finally:
            client.close()
    finally:
        cluster.close()


def _cannot_connect(scheduler: str, name: str, reason) -> InputError:
    text = " ".join(str(reason).split()) or type(reason).__name__
    return InputError(f"{name} {scheduler!r}: cannot connect within {CONNECT_TIMEOUT_S} s: {text}; give the "
                      "address of a running dask scheduler, e.g. tcp://host:8786")


def _client(scheduler: str, name: str, **options):
    """A Client on the scheduler at `scheduler`, or the one-line InputError naming it (`name`: the
    option or setting it came from)."""
    from distributed import Client

    try:
        return Client(scheduler, timeout=f"{CONNECT_TIMEOUT_S}s", **options)
    except Exception as exc:  # noqa: BLE001  (OSError, TimeoutError, ValueError for a malformed address)
        raise _cannot_connect(scheduler, name, exc) from None


def check_scheduler(scheduler: str, name: str = "--scheduler") -> None:
    """A scheduler answers at `scheduler`: connect, then close again; a one-line InputError naming the
    address otherwise. A TCP address is first tried with a bare socket, so that a port where nothing
    listens (connection refused) or a host that does not exist is refused at once instead of after
    Dask's CONNECT_TIMEOUT_S of retries. The commands call it (ready) before they create any folder:
    connect first, then mkdir, so an unreachable scheduler leaves nothing behind. It costs one
    connection more than the runs need (some tens of milliseconds on a live scheduler)."""
    require_dask()
    from distributed.comm.addressing import parse_address, parse_host_port

    try:
        protocol, location = parse_address(scheduler)
        host, port = parse_host_port(location) if protocol in ("tcp", "tls") else (None, None)
    except ValueError:   # no port, or a scheme Dask resolves itself (inproc, ucx): its Client decides
        host, port = None, None
    if port is not None:
        if not 1 <= port <= 65535:
            raise _cannot_connect(scheduler, name, f"port {port} outside [1, 65535]")
        try:
            socket.create_connection((host, port), timeout=CONNECT_TIMEOUT_S).close()
        except OSError as exc:   # refused, unknown host, unreachable network, timed out
            raise _cannot_connect(scheduler, name, exc.strerror or exc) from None
    _client(scheduler, name, set_as_default=False).close()


def describe(client) -> str:
    """'a LocalCluster of 2 workers' or 'the scheduler at tcp://host:8786 (4 workers)'."""
    workers = len(client.scheduler_info().get("workers", {}))
    cluster = getattr(client, "cluster", None)
    if cluster is not None and type(cluster).__name__ == "LocalCluster":
        return f"a LocalCluster of {workers} worker{'s' * (workers != 1)}"
    return f"the scheduler at {client.scheduler.address} ({workers} worker{'s' * (workers != 1)})"


@dataclass(frozen=True)
class Task:
    """One unit of work: `function(*args)` on a worker under the Dask `key` (unique per result:
    the same key in two submissions is one computation), the higher `priority` first; `tag` stays
    on the client (what the caller needs to file the result)."""

    key: str
    function: Callable
    args: tuple = ()
    priority: int = 0
    tag: Any = None


@dataclass
class Ran:
    """What run_all did: `where` the tasks ran ("" if there were none), `interrupted` the
    KeyboardInterrupt (or SIGTERM's RunInterrupted) that stopped it, None if it ran to the end."""

    where: str = ""
    interrupted: BaseException | None = None


class StudyLog:
    """The client side of a study generator's runs (fem_reference gold, validation.plate_gold), the
    `finished` callback of run_all: as each task ends, its line (`label(task, result)`: status, wall
    time, dW1/L, dW2/L) or its one-line error (`label(task, None)`), the failed and stopped tasks
    kept, then `after(task)` (its scene's study and the index rewritten)."""

    def __init__(self, label: Callable, after: Callable, quiet: bool = False):
        self.label, self.after, self.quiet = label, after, quiet
        self.failed: list[Task] = []
        self.stopped: list[Task] = []

    def __call__(self, task: Task, result: dict | None, error: str | None) -> None:
        error = error or (result or {}).get("error")
        if error is not None:
            self.failed.append(task)
            print(f"error: {self.label(task, None)}: {error}", file=sys.stderr, flush=True)
        else:
            if not self.quiet:
                print(f"{self.label(task, result)}: {result['status']}, {result['wall_time_s']:.0f} s, "
                      f"dW1/L {result['dW1_over_L']}, dW2/L {result['dW2_over_L']}", flush=True)
            if not result["converged"]:
                self.stopped.append(task)
        self.after(task)

    @property
    def exit_code(self) -> int:
        """1 if a run failed, 3 if one stopped short, else 0."""
        return 1 if self.failed else 3 if self.stopped else 0


class WorkerMismatch(RuntimeError):
    """A worker that must not run the task: other ddg sources, or it does not see the output folder."""


def run_all(tasks: list[Task], finished: Callable, *, scheduler: str | None = None, workers: int | None = None,
            retries: int = 2, code: str | None = None, shared=None) -> Ran:
    """Every task on Dask (`scheduler`, else a new LocalCluster of `workers` processes; none is
    started without tasks), `finished(task, result, error)` called here as each one ends: its
    result and None, or None and a one-line error for a task that still failed after its retries.

    With `code` (ddg.sweep.grid.code_version() here) a worker with other ddg sources refuses the
    tasks; with `shared` (a folder the tasks write into) a worker that does not see it refuses them
    (its files would land on its own disk): a probe file lies in `shared` while the tasks run.
    Ctrl-C stops it: the tasks not finished are cancelled, the interrupt is in Ran.interrupted;
    what `finished` has filed stays."""
    ran = Ran()
    if not tasks:
        return ran
    probe = None
    try:
        if shared is not None:
            probe = (str(Path(shared).resolve() / f".probe-{uuid.uuid4().hex}"), uuid.uuid4().hex)
            Path(probe[0]).write_text(probe[1])
        with connect(scheduler, workers, retries) as client:
            ran.where = describe(client)
            for task, result, error in run_tasks(client, tasks, retries, code, probe):
                finished(task, result, error)
    except KeyboardInterrupt as exc:
        ran.interrupted = exc
    finally:
        if probe is not None:
            Path(probe[0]).unlink(missing_ok=True)
    return ran


def run_tasks(client, tasks: list[Task], retries: int, code: str | None = None, probe: tuple[str, str] | None = None):
    """Submit every task as a CheckedCall (code and probe as in run_all); yields (task,
    result, None), or (task, None, error) for a task that still fails after its retries or whose
    workers died too often, as they finish. The tasks not finished when the caller stops
    (Ctrl-C, or it closes the generator) are cancelled."""
    from distributed import as_completed

    futures = {}
    for task in tasks:
        future = client.submit(CheckedCall(task.function, task.args, code, probe), key=task.key, retries=retries,
                                priority=task.priority)
        futures[future] = task
    try:
        for future in as_completed(list(futures)):
            task = futures.pop(future)
            try:
                result, error = future.result(), None
            except Exception as exc:  # noqa: BLE001  (KilledWorker, CancelledError, the task's own error)
                result, error = None, _task_error(exc, retries)
            finally:
                future.release()
            yield task, result, error
    finally:
        if futures:  # interrupted (or the caller stopped): the tasks not finished are dropped
            client.cancel(list(futures), force=True)


class CheckedCall:
    """`function(*args)` in a worker, after the checks of run_all: WorkerMismatch (retried, perhaps
    on another worker) if this worker's ddg sources differ from `code` or it cannot read the
    client's `probe` file (path, content). An object, not a tuple of arguments: Dask would run a
    tuple that begins with a callable (the sweep's task function) as a task of its own."""

    def __init__(self, function: Callable, args: tuple, code: str | None = None,
                 probe: tuple[str, str] | None = None):
        self.function, self.args, self.code, self.probe = function, args, code, probe

    def __call__(self):
        if self.code is not None:
            from .grid import code_version

            mine = code_version()
            if mine != self.code:
                raise WorkerMismatch(f"the worker on {socket.gethostname()} runs other ddg sources (code {mine}, "
                                     f"the client's {self.code}); install the same code on every worker")
        if self.probe is not None:
            try:
                seen = Path(self.probe[0]).read_text() == self.probe[1]
            except OSError:
                seen = False
            if not seen:
                raise WorkerMismatch(f"the worker on {socket.gethostname()} does not see the output folder "
                                     f"{Path(self.probe[0]).parent}; run workers that share it")
        return self.function(*self.args)


# ---------------------------------------------------------------------------- command-line options
def add_options(parser) -> None:
    """--workers, --scheduler and --retries (values read as text: checked_options gives the one-line errors)."""
    parser.add_argument("--workers", default=None, metavar="N",
                        help="worker processes of the LocalCluster (default: the cores; one run each at a time)")
    parser.add_argument("--scheduler", default=None, metavar="ADDRESS",
                        help="an existing Dask scheduler, e.g. tcp://host:8786 (dask-scheduler / dask-worker, "
                             "dask-jobqueue); default: DASK_SCHEDULER_ADDRESS if set, else a LocalCluster")
    parser.add_argument("--retries", default=2, metavar="N",
                        help="more attempts of a run whose worker died or that raised (default 2; an existing "
                             "scheduler's own allowed-failures applies to worker deaths)")


def checked_options(scheduler, workers, retries) -> tuple[str | None, int | None, int]:
    """(scheduler, workers, retries) of add_options' values, each checked (a one-line InputError
    naming the option), dask not imported."""
    from ..limits import check_integer

    retries = check_integer("--retries", _integer("--retries", retries), 0, MAX_RETRIES)
    if scheduler is not None:
        if not isinstance(scheduler, str) or not scheduler.strip() or any(c.isspace() for c in scheduler):
            raise InputError(f"--scheduler {scheduler!r} is not an address; give e.g. tcp://host:8786")
        if workers is not None:
            raise InputError("--workers applies to the LocalCluster only; the cluster at --scheduler has its own "
                             "workers")
    if workers is not None:
        most = max(4 * cores(), 8)
        workers = check_integer("--workers", _integer("--workers", workers), 1, most,
                                "each worker is a process running one run at a time; more than the cores share them")
    return scheduler, workers, retries


def ready(scheduler: str | None, workers: int | None, check: bool = True) -> str | None:
    """require_dask(), then the scheduler to use: `scheduler`, else Dask's own setting
    (DASK_SCHEDULER_ADDRESS) unless --workers asked for a LocalCluster, else None (a LocalCluster).
    With `check` (the default) a scheduler is connected to once (check_scheduler): the commands call
    this before they create their output folder."""
    require_dask()
    name = "--scheduler"
    if scheduler is None and workers is None:
        scheduler, name = default_scheduler(), "DASK_SCHEDULER_ADDRESS"
    if scheduler is not None and check:
        check_scheduler(scheduler, name)
    return scheduler


def _integer(name: str, value):
    if isinstance(value, str):
        try:
            return int(value.strip())
        except ValueError:
            raise InputError(f"{name} {value!r} is not an integer") from None
    return value


def _task_error(exc: BaseException, retries: int) -> str:
    name = type(exc).__name__
    if name == "KilledWorker":
        return "its worker process died at every attempt (killed, or out of memory)"
    return f"{name}: {' '.join(str(exc).split())} (after {retries} retries)"
