"""Progress of a run on stderr: a one-line bar when stderr is a terminal."""
from __future__ import annotations

import sys


class ProgressBar:
    """A one-line progress bar on stderr when it is a terminal (a driver listener)."""

    def __init__(self, total: int, enabled: bool):
        self.total, self.count = total, 0
        self.enabled = enabled and sys.stderr.isatty()

    def __call__(self, stage: str, state, row: dict) -> None:
        self.update(f"{stage} dL/L={row['dL_over_L']:.4f} dW/L={row['dW_over_L']:.4f}")

    def update(self, text: str) -> None:
        self.count += 1
        if self.enabled:
            frac = self.count / self.total
            bar = "#" * int(30 * frac)
            sys.stderr.write(f"\r[{bar:<30}] {100 * frac:5.1f}% {text}   ")
            sys.stderr.flush()

    def close(self) -> None:
        if self.enabled:
            sys.stderr.write("\n")
