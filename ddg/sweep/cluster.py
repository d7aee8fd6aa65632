"""The Dask side of a sweep: a client on a LocalCluster (default) or on an existing scheduler,
and the runs submitted to it as futures with retries.

The only module of ddg that imports dask (lazily): `require_dask()` turns a missing install
into a one-line InputError naming the extra. A LocalCluster has one single-threaded worker
process per core; its scheduler gives a task whose worker dies `retries` more attempts
(distributed.scheduler.allowed-failures), and `retries` also re-runs a task that raised. An
existing scheduler keeps its own allowed-failures (3 by default).
"""
from __future__ import annotations

import contextlib
import hashlib
import logging
import os

from ..geometry.strip import InputError

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
        try:
            client = Client(scheduler, timeout=f"{CONNECT_TIMEOUT_S}s")
        except Exception as exc:  # noqa: BLE001  (OSError, TimeoutError, ValueError for a malformed address)
            raise InputError(f"--scheduler {scheduler!r}: cannot connect within {CONNECT_TIMEOUT_S} s: "
                             f"{' '.join(str(exc).split()) or type(exc).__name__}") from None
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


def describe(client) -> str:
    """'a LocalCluster of 2 workers' or 'the scheduler at tcp://host:8786 (4 workers)'."""
    workers = len(client.scheduler_info().get("workers", {}))
    cluster = getattr(client, "cluster", None)
    if cluster is not None and type(cluster).__name__ == "LocalCluster":
        return f"a LocalCluster of {workers} worker{'s' * (workers != 1)}"
    return f"the scheduler at {client.scheduler.address} ({workers} worker{'s' * (workers != 1)})"


def submit_runs(client, todo, task, retries: int, code: str, probe=None):
    """Submit each (spec, directory) as ddg.sweep.tasks.run_task(task, spec, directory, probe, code),
    the costliest first; yields (spec, directory, record) as they finish. A task that still fails
    after its retries, or whose workers died too often, gives a record with its error."""
    from distributed import as_completed

    from .grid import estimated_cost
    from .tasks import run_task

    futures = {}
    for spec, directory in todo:
        where = hashlib.sha256(str(directory).encode()).hexdigest()[:8]
        future = client.submit(run_task, task, spec, str(directory), probe, code,
                               key=f"ddg-run-{directory.name}-{where}", retries=retries,
                               priority=int(100 * estimated_cost(spec)))
        futures[future] = (spec, directory)
    try:
        for future in as_completed(list(futures)):
            spec, directory = futures.pop(future)
            try:
                record = future.result()
            except Exception as exc:  # noqa: BLE001  (KilledWorker, CancelledError, the task's own error)
                record = {"error": _task_error(exc, retries), "report_wall_time_s": None}
            finally:
                future.release()
            yield spec, directory, record
    finally:
        if futures:  # interrupted (or the caller stopped): the runs not finished are dropped
            client.cancel(list(futures), force=True)


def _task_error(exc: BaseException, retries: int) -> str:
    name = type(exc).__name__
    if name == "KilledWorker":
        return "its worker process died at every attempt (killed, or out of memory)"
    return f"{name}: {' '.join(str(exc).split())} (after {retries} retries)"
