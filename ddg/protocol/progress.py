"""Progress of a run on stderr: a one-line bar with an ETA when stderr is a terminal, plain lines
(every PLAIN_EVERY of the path, and each step after it) when it is not (logs, notebooks)."""
from __future__ import annotations

import sys
import time

#: In plain-text mode a line is written at each of these fractions of the recorded path.
PLAIN_EVERY = 0.1


def _duration(seconds: float) -> str:
    seconds = max(0.0, seconds)
    if seconds < 60:
        return f"{seconds:.0f} s"
    if seconds < 3600:
        return f"{seconds // 60:.0f} min {seconds % 60:02.0f} s"
    return f"{seconds // 3600:.0f} h {seconds % 3600 // 60:02.0f} min"


class ProgressBar:
    """Progress of the recorded path (a driver listener) and of the steps after it (announce).

    enabled: the caller asked for progress (CLI --progress or simulate(progress=True)); stream:
    stderr by default; on a terminal the bar is rewritten in place, else a plain line is written
    at each tenth of the path. The ETA extrapolates the mean wall time per recorded step so far
    (the shear steps past dW1 cost more than the compression's: it is a rough figure, and the
    steps after the path, thresholds and branches, are not in it; they are announced as they
    start and end)."""

    def __init__(self, total: int, enabled: bool, stream=None, what: str = "path", unit: str = "steps"):
        self.total, self.count = max(int(total), 1), 0
        self.what, self.unit = what, unit
        self.stream = sys.stderr if stream is None else stream
        self.enabled = bool(enabled)
        self.terminal = self.enabled and hasattr(self.stream, "isatty") and self.stream.isatty()
        self.started = time.perf_counter()
        self.next_plain = PLAIN_EVERY
        self.open_line = False
        self._announced: dict[str, float] = {}

    def __call__(self, stage: str, state, row: dict) -> None:
        self.update(f"{stage} dL/L={row['dL_over_L']:.4f} dW/L={row['dW_over_L']:.4f} {row.get('phase') or ''}")

    def eta(self) -> float | None:
        """Seconds left on the recorded path, from the mean time per recorded step so far."""
        if self.count == 0:
            return None
        elapsed = time.perf_counter() - self.started
        return elapsed / self.count * max(self.total - self.count, 0)

    def update(self, text: str) -> None:
        self.count += 1
        if not self.enabled:
            return
        frac = min(self.count / self.total, 1.0)
        eta = self.eta()
        tail = f"elapsed {_duration(time.perf_counter() - self.started)}" + \
            ("" if eta is None or frac >= 1.0 else f", ETA {_duration(eta)}")
        if self.terminal:
            bar = "#" * int(30 * frac)
            self.stream.write(f"\r[{bar:<30}] {100 * frac:5.1f}% {text} ({tail})   ")
            self.open_line = True
        elif frac + 1e-12 >= self.next_plain or self.count == self.total:
            self.stream.write(f"progress: {self.what} {100 * frac:3.0f}% ({self.count}/{self.total} {self.unit}) "
                              f"{text.strip()} "
                              f"({tail})\n")
            while self.next_plain <= frac + 1e-12:
                self.next_plain += PLAIN_EVERY
        self.stream.flush()

    def announce(self, stage: str, done: bool = False) -> None:
        """A step after the path (threshold location, branch tracing) starting, or done with its time."""
        if not self.enabled:
            return
        self._end_line()
        if done:
            took = time.perf_counter() - self._announced.pop(stage, time.perf_counter())
            self.stream.write(f"progress: {stage} done in {_duration(took)}\n")
        else:
            self._announced[stage] = time.perf_counter()
            self.stream.write(f"progress: {stage}...\n")
        self.stream.flush()

    def _end_line(self) -> None:
        if self.open_line:
            self.stream.write("\n")
            self.open_line = False

    def close(self) -> None:
        if self.enabled:
            self._end_line()
            self.stream.flush()
