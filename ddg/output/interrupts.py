"""Ctrl-C and SIGTERM as exceptions that let a run write what it has computed.

SIGINT already raises KeyboardInterrupt; `terminate_as_interrupt()` makes SIGTERM raise
RunInterrupted (a KeyboardInterrupt) too, so one `except KeyboardInterrupt` keeps every
converged step on either signal. `deferred_signals()` holds both signals while result files
are written, so a second Ctrl-C cannot cut a file in half. Exit codes: 128 + the signal
number (130 for SIGINT, 143 for SIGTERM).
"""
from __future__ import annotations

import contextlib
import os
import signal
import threading


class RunInterrupted(KeyboardInterrupt):
    """A run stopped by a signal; .signal_name is SIGINT or SIGTERM, .exit_code 128 + its number."""

    def __init__(self, signal_name: str = "SIGINT"):
        super().__init__(signal_name)
        self.signal_name = signal_name

    @property
    def exit_code(self) -> int:
        return 128 + int(getattr(signal, self.signal_name, signal.SIGINT))


def signal_name_of(exc: BaseException) -> str:
    return exc.signal_name if isinstance(exc, RunInterrupted) else "SIGINT"


def exit_code_of(exc: BaseException) -> int:
    return exc.exit_code if isinstance(exc, RunInterrupted) else 128 + int(signal.SIGINT)


def interrupt_behind(exc: BaseException) -> KeyboardInterrupt | None:
    """The KeyboardInterrupt an error was raised while handling, if any (else None).

    A signal whose Python handler runs while compiled code is on the stack comes back as some
    other error with the interrupt as its __context__: SystemError("... returned a result with an
    exception set") from a numba dispatcher, ImportError("initialization failed") when Ctrl-C hits
    an extension module's import. That is an interrupt, not an internal error."""
    seen: set[int] = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, KeyboardInterrupt):
            return exc
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
    return None


def _raise_terminated(signum, frame):
    raise RunInterrupted("SIGTERM")


def _raise_interrupted(signum, frame):
    raise RunInterrupted("SIGINT")


def terminate_as_interrupt() -> None:
    """SIGTERM (and SIGINT) raise RunInterrupted in the main thread (command-line entry points)."""
    if threading.current_thread() is threading.main_thread():
        # a signal the caller ignores stays ignored (a shell starts background jobs with SIGINT ignored)
        if signal.getsignal(signal.SIGTERM) != signal.SIG_IGN:
            signal.signal(signal.SIGTERM, _raise_terminated)
        if signal.getsignal(signal.SIGINT) != signal.SIG_IGN:
            signal.signal(signal.SIGINT, _raise_interrupted)


@contextlib.contextmanager
def deferred_signals():
    """Hold SIGINT and SIGTERM while the block runs (writing result files); re-deliver the last
    one afterwards. A no-op outside the main thread."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    received: list[int] = []
    previous = {}

    def hold(signum, frame):
        received.append(signum)

    for sig in (signal.SIGINT, signal.SIGTERM):
        previous[sig] = signal.signal(sig, hold)
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
        if received:
            handler = previous.get(received[-1])
            if callable(handler):
                handler(received[-1], None)
            elif handler == signal.SIG_DFL:
                os.kill(os.getpid(), received[-1])
