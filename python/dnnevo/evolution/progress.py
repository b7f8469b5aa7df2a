"""A one-line progress bar on stderr: the generation, the champion's fitness, the generation's
best and mean fitness, evaluations per second and the ETA.

The words are those of ``dnnevo run`` and ``dnnevo show``: the *champion* is the run's best
network so far, the one best.json holds, with its training fitness and, when it was chosen on
the task's validation trials, its validation rate, or score for a task without a success rule
(which never falls, while a new champion's training fitness may be lower than the last one's); *gen best* and *gen mean* are the training
fitness of the generation just scored. Without elitism (the paper's GA) the best network is not
kept, so gen best may drop while the champion stays.
"""

from __future__ import annotations

import shutil
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

    def update(self, generation: int, best: float, mean: float, evals_per_s: float,
               champion: float | None = None, validation_rate: float | None = None,
               validation_score: float | None = None) -> None:
        """Shows that ``generation`` (0-based) has been scored: its ``best`` and ``mean`` fitness,
        the ``champion``'s fitness and, when it was chosen on validation trials, its
        ``validation_rate``, or its ``validation_score`` for a task without a success rule (whose
        rate is 0 for every network). Rate or score never falls, while the training fitness of a
        new champion may be below the last one's: the validation is why it was chosen."""
        done = generation + 1
        elapsed = time.perf_counter() - self.t0
        rate = (done - self.start) / elapsed if elapsed > 0 else 0.0
        eta = (self.total - done) / rate if rate > 0 else 0.0
        width = 10
        filled = int(width * done / self.total)
        bar = "#" * filled + "-" * (width - filled)
        held = f"  champion {champion:.4f}" if champion is not None else ""
        if held and validation_rate is not None:
            held += f" (validation rate {validation_rate:.3f})"
        elif held and validation_score is not None:
            held += f" (validation score {validation_score:.4f})"
        line = (
            f"[{bar}] gen {done}/{self.total}{held}  gen best {best:.4f}  gen mean {mean:.4f}  "
            f"{evals_per_s:,.0f} evals/s  ETA {clock(eta)}"
        )
        if self.tty:
            # Cut to the terminal's width: a line that wraps cannot be redrawn in place.
            columns = shutil.get_terminal_size().columns
            self.stream.write("\r" + line[:max(columns - 1, 20)] + "\x1b[K")
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
