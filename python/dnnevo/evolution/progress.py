"""A one-line progress bar on stderr: generation, best, mean, evaluations per second, ETA."""

from __future__ import annotations

import sys
import time
from typing import TextIO

__all__ = ["Progress", "clock"]


class Progress:
    """Redraws one line on a terminal; prints a line every ``every`` generations otherwise."""

    def __init__(self, total: int, start: int = 0, stream: TextIO | None = None, every: int = 25):
        self.total, self.start = total, start
        self.stream = stream or sys.stderr
        self.tty = self.stream.isatty()
        self.every = every
        self.t0 = time.perf_counter()

    def update(self, generation: int, best: float, mean: float, evals_per_s: float) -> None:
        """Shows that ``generation`` (0-based) has been scored."""
        done = generation + 1
        elapsed = time.perf_counter() - self.t0
        rate = (done - self.start) / elapsed if elapsed > 0 else 0.0
        eta = (self.total - done) / rate if rate > 0 else 0.0
        width = 24
        filled = int(width * done / self.total)
        bar = "#" * filled + "-" * (width - filled)
        line = (
            f"[{bar}] gen {done}/{self.total}  best {best:.4f}  mean {mean:.4f}  "
            f"{evals_per_s:,.0f} evals/s  ETA {clock(eta)}"
        )
        if self.tty:
            self.stream.write("\r" + line + "\x1b[K")
            self.stream.flush()
        elif done % self.every == 0 or done == self.total:
            self.stream.write(line + "\n")

    def close(self) -> None:
        """Ends the line."""
        if self.tty:
            self.stream.write("\n")
            self.stream.flush()


def clock(seconds: float) -> str:
    """``seconds`` as H:MM:SS."""
    s = int(round(seconds))
    return f"{s // 3600}:{s // 60 % 60:02d}:{s % 60:02d}"
