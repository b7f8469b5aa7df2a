"""The live view of ``dnnevo reproduce``: a bar on a terminal, one line per run elsewhere."""

from __future__ import annotations

import io

from dnnevo.experiments.runsview import RunsView


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_a_terminal_gets_a_bar_that_counts_runs() -> None:
    out = _Terminal()
    view = RunsView(3, 1, stream=out)
    view.finished("sequence-1bit/seed-0", "failed", wall=5.0, running=1)
    view.close()
    assert view.bar is not None and view.bar.n == 2
    assert "2/3" in out.getvalue() and "1 not done" in out.getvalue()


def test_a_log_gets_one_line_per_run_and_no_bar() -> None:
    out = io.StringIO()
    view = RunsView(2, stream=out)
    view.started("landmark/seed-0")
    view.finished("landmark/seed-0", "done", wall=3.0)
    view.close()
    assert view.bar is None
    started, finished = out.getvalue().splitlines()
    assert started == "[1/2] landmark/seed-0 ..."
    assert finished.startswith("[1/2] done landmark/seed-0 (3 s); 1 to go; ETA ")


def test_no_more_runs_are_running_than_are_left() -> None:
    # Dask's scheduler may still count the run that has just ended: 15 of 16 done, it says 2.
    out = io.StringIO()
    view = RunsView(16, 14, stream=out)
    view.finished("sequence-2bit-paper/seed-3", "done", wall=443.0, running=2)
    assert "; 1 running, 0 queued; " in out.getvalue()
