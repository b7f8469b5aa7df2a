"""A live view of many runs (``dnnevo reproduce``): how many are done, running and queued, and an
ETA. On a terminal it is a tqdm bar; otherwise (a log file, CI) one plain line per finished run.

>>> import io
>>> out = io.StringIO()
>>> view = RunsView(2, stream=out)
>>> view.finished("sequence-1bit/seed-0", "done", wall=64.0, running=1)
>>> out.getvalue().split(";")[0]
'[1/2] done sequence-1bit/seed-0 (64 s)'
"""

from __future__ import annotations

import sys
import time
from typing import Any, TextIO

from dnnevo.evolution.progress import clock

__all__ = ["RunsView"]


class RunsView:
    """Counts ``total`` jobs, ``done`` of which were finished before this view began. With
    ``bar`` on a terminal it draws a tqdm bar; otherwise it writes a line per job."""

    def __init__(self, total: int, done: int = 0, *, stream: TextIO | None = None, bar: bool = True):
        self.stream = stream or sys.stderr
        self.tty = self.stream.isatty()
        self.total, self.done, self.failed = total, done, 0
        self.before = done
        self.t0 = time.perf_counter()
        self.bar: Any = None
        if bar and self.tty:
            from tqdm import tqdm  # here, not at the top: its import costs every command ~0.1 s

            self.bar = tqdm(total=total, initial=done, unit="run", file=self.stream, dynamic_ncols=True,
                            smoothing=0.0)

    def started(self, name: str) -> None:
        """Shows that the run ``name`` has begun (when runs go one at a time)."""
        if self.bar is None:
            self.stream.write(f"[{self.done + 1}/{self.total}] {name} ...\n")
            self.stream.flush()

    def finished(self, name: str, status: str, *, wall: float | None = None, message: str = "",
                 running: int | None = None) -> None:
        """Shows that run ``name`` has ended with ``status`` (``done``, ``failed``, ...) after
        ``wall`` seconds, with ``running`` runs still going if known (at most the runs left: a
        cluster may still count a run that has just ended)."""
        self.done += 1
        self.failed += status != "done"
        if running is not None:
            running = min(running, self.total - self.done)
        queued = self.total - self.done - (running or 0)
        state = f"{running} running, {queued} queued" if running is not None else f"{queued} to go"
        counts = f"{state}, {self.failed} not done" if self.failed else state
        if self.bar is not None:
            self.bar.set_postfix_str(counts, refresh=False)
            self.bar.update(1)
            return
        line = f"[{self.done}/{self.total}] {status} {name}"
        if wall is not None:
            line += f" ({wall:.0f} s)"
        if message:
            line += f": {message}"
        self.stream.write(f"{line}; {counts}; ETA {self._eta()}\n")
        self.stream.flush()

    def _eta(self) -> str:
        new = self.done - self.before
        if new == 0 or self.done >= self.total:
            return "0:00:00" if self.done >= self.total else "unknown"
        return clock((time.perf_counter() - self.t0) / new * (self.total - self.done))

    def close(self) -> None:
        """Ends the bar."""
        if self.bar is not None:
            self.bar.close()
