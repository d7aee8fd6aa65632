"""What a LocalCluster's worker processes do at start (a Dask worker plugin, registered by the client)."""
from __future__ import annotations

import signal
import threading


class IgnoreInterrupts:
    """Worker plugin: the worker process ignores SIGINT. Ctrl-C in a terminal reaches every process
    of its group; the sweep's client, not each worker, decides what is kept, then closes the
    cluster (without this, each worker would print its own KeyboardInterrupt traceback)."""

    name = "ddg-ignore-sigint"

    def setup(self, worker) -> None:
        if threading.current_thread() is threading.main_thread():
            signal.signal(signal.SIGINT, signal.SIG_IGN)
