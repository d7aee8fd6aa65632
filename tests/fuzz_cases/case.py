"""The record of one fuzz case (Case), what it expects (REFUSE, ACCEPT, RUN), and at_most, the hard
time limit a case runs under (also used by tests/validation/test_score.py)."""
from __future__ import annotations

import contextlib
import signal
from dataclasses import dataclass, field
from typing import Callable


REFUSE = "refuse"   # bad input: exit 2 / InputError, one line, nothing computed


ACCEPT = "accept"   # valid edge case: validation passes (the solver is reached, then stopped)


RUN = "run"         # valid edge case, run for real on a tiny scene (about 1 s each)


@dataclass(frozen=True)
class Case:
    id: str
    prog: str                     # "ddg", "fem", "validation" or a validation module (the command lines), or "api"
    argv: tuple = ()
    option: str = ""              # the option or object under test, for grouping the failures
    expect: str = REFUSE
    call: Callable | None = field(default=None, compare=False)  # api: call(tmp_path)
    env: tuple = ()               # (name, value) environment variables set for the case
    names: str = ""               # the error line must contain it (the value refused)
    untouched: bool = False       # the case's folder must be as it was: nothing created, nothing changed
    limit_s: float = 0.0          # a hard time limit below the file's 30 s (a read that could block)


@contextlib.contextmanager
def at_most(seconds: float, error: type = TimeoutError):
    """SIGALRM after `seconds` raises `error`: a call that blocks (a read from a FIFO) fails the test
    instead of hanging it."""
    def alarm(signum, frame):
        raise error(f"still running after {seconds:g} s")

    previous = signal.signal(signal.SIGALRM, alarm)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
