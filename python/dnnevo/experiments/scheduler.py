"""Running many runs (the jobs of ``dnnevo reproduce``, the seeds of ``dnnevo sweep``): in this
process, one after another, or on a Dask cluster, where the unit of work is one :class:`Task`,
usually one evolution run.

A task starts when the tasks it needs are done. A task that fails is reported and the tasks that
need it are skipped; the others go on. On Dask:

- the default cluster is a :class:`distributed.LocalCluster` of ``workers`` processes, one task
  at a time each; ``scheduler`` connects to a running cluster instead (its workers must see the
  same folders, e.g. on a shared filesystem);
- a worker that dies is replaced and its task is run again, which resumes the run from its last
  checkpoint, so the result's bits are those of an uninterrupted run;
- every worker must run the dnnevo this process runs, the same version built from the same
  commit (:func:`check_workers`), since another could give other results;
- a cluster that is lost (its scheduler dies, or the network drops for longer than Dask waits)
  ends the command in one line; every run keeps its last checkpoint, and the same command
  continues them to the same results.

Dask is optional (``pip install "dnnevo[cluster]"``); without it only :func:`run_in_process`
works.

>>> from dnnevo.experiments.runsview import RunsView
>>> import io
>>> tasks = [Task("a", (), abs, (-2,)), Task("b", ("a",), divmod, (7, 0)), Task("c", ("b",), abs, (1,))]
>>> outcomes = run_in_process(tasks, RunsView(3, stream=io.StringIO()), errors=(ZeroDivisionError,))
>>> [(o.task.id, o.status, o.result) for o in outcomes.values()]
[('a', 'done', 2), ('b', 'failed', None), ('c', 'skipped', None)]
"""

from __future__ import annotations

import concurrent.futures
import contextlib
import importlib.util
import logging
import os
import uuid
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from dnnevo import _core
from dnnevo.errors import ConfigError, DnnevoError
from dnnevo.experiments.runsview import RunsView

__all__ = ["CLUSTER_EXTRA", "Outcome", "Task", "check_options", "check_workers", "dask_client", "describe", "identity",
           "run_in_process", "run_on_dask"]

CLUSTER_EXTRA = 'pip install "dnnevo[cluster]"'
"""How to install Dask for dnnevo."""


@dataclass(frozen=True)
class Task:
    """``fn(*args, **kwargs)`` once the tasks ``needs`` (ids) are done. On Dask, ``fn`` must be
    importable by the workers (a module's function, or a :func:`functools.partial` of one)."""

    id: str
    needs: tuple[str, ...]
    fn: Callable[..., Any]
    args: tuple[Any, ...] = ()
    kwargs: dict[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class Outcome:
    """What became of one task."""

    task: Task
    status: str
    """``done``, ``failed`` or ``skipped`` (a task it needs did not finish)."""
    result: Any = None
    message: str = ""


def _blocked(task: Task, outcomes: dict[str, Outcome]) -> str | None:
    """The first task ``task`` needs that did not finish, if any."""
    return next((n for n in task.needs if outcomes.get(n) is None or outcomes[n].status != "done"), None)


def run_in_process(tasks: Sequence[Task], view: RunsView, *,
                   errors: tuple[type[BaseException], ...] = (DnnevoError,)) -> dict[str, Outcome]:
    """Runs ``tasks`` (each after the ones it needs) one after another in this process. A task
    that raises one of ``errors`` has failed; any other exception ends the whole."""
    outcomes: dict[str, Outcome] = {}
    for task in tasks:
        missing = _blocked(task, outcomes)
        if missing is not None:
            outcome = Outcome(task, "skipped", message=f"{missing} did not finish")
        else:
            view.started(task.id)
            try:
                outcome = Outcome(task, "done", task.fn(*task.args, **task.kwargs))
            except errors as e:
                outcome = Outcome(task, "failed", message=str(e))
        outcomes[task.id] = outcome
        view.finished(task.id, outcome.status, wall=_wall(outcome.result), message=outcome.message)
    return outcomes


def run_on_dask(tasks: Sequence[Task], view: RunsView, client: Any) -> dict[str, Outcome]:
    """Submits ``tasks`` to the Dask ``client``, each with the futures of the tasks it needs as
    extra arguments after its own, so the scheduler runs it after them."""
    token = uuid.uuid4().hex[:8]
    futures: dict[str, Any] = {}
    here = identity()
    for task in tasks:
        needed = [futures[n] for n in task.needs]
        futures[task.id] = client.submit(_checked_call, here, task.fn, task.args, task.kwargs, *needed,
                                         key=f"{task.id}-{token}", pure=False)
    by_key = {f.key: task for task, f in zip(tasks, futures.values(), strict=True)}
    ended: dict[str, tuple[bool, Any]] = {}  # (finished, its result or its error), as it ended
    done: Iterator[Any] | None = None
    while True:
        try:  # only waiting on the cluster is a sign of losing it, not writing the view
            if done is None:
                done = iter(_distributed().as_completed(list(futures.values())))
            future = next(done, None)
            if future is None:
                break
            task = by_key[future.key]
            if future.status not in ("finished", "error"):  # cancelled or lost with the scheduler
                raise concurrent.futures.CancelledError(f"{task.id} was {future.status}")
            ok = future.status == "finished"
            ended[task.id] = (ok, future.result() if ok else future.exception())
        except LOST as e:
            raise DnnevoError(f"lost the Dask cluster after {len(ended)} of {len(tasks)} tasks "
                              f"({type(e).__name__}: {e or 'no reason given'}); every run keeps its last "
                              "checkpoint: run the same command again to continue") from None
        view.finished(task.id, "done" if ok else "failed", wall=_wall(ended[task.id][1]) if ok else None,
                      running=_running(client))
    # Decided in order: a task whose need did not finish is skipped, whatever its future says.
    outcomes: dict[str, Outcome] = {}
    for task in tasks:
        ok, value = ended[task.id]
        missing = _blocked(task, outcomes)
        if missing is not None:
            outcomes[task.id] = Outcome(task, "skipped", message=f"{missing} did not finish")
        elif ok:
            outcomes[task.id] = Outcome(task, "done", value)
        else:
            text = str(value) if isinstance(value, DnnevoError) else f"{type(value).__name__}: {value}"
            outcomes[task.id] = Outcome(task, "failed", message=text)
    return outcomes


LOST = (OSError, TimeoutError, concurrent.futures.CancelledError)
"""What waiting on a cluster that is gone raises: a closed connection (an ``OSError``), a timeout,
or futures the scheduler cancelled as it went."""


def identity() -> dict[str, str]:
    """What a process's results depend on besides its inputs: dnnevo's version and the commit its
    core was built from (every kernel gives the same bits, so the CPU is not part of it)."""
    info = _core.build_info()
    return {"version": str(info["version"]), "commit": str(info["commit"])}


def check_workers(client: Any, expected: Mapping[str, str] | None = None) -> None:
    """Every worker of ``client`` runs the dnnevo ``expected`` names (default: this process's
    :func:`identity`), or a one-line :class:`ConfigError` names the first that does not: its
    results could differ from this process's."""
    want = dict(expected or identity())
    try:
        found = client.run(identity)
    except Exception as e:  # noqa: BLE001 - a worker without dnnevo cannot even run the check
        raise ConfigError(f"cannot ask the Dask workers which dnnevo they run ({type(e).__name__}: "
                          f"{e}); install this dnnevo on every worker") from None
    for address, theirs in sorted(found.items()):
        if theirs != want:
            raise ConfigError(f"the Dask worker at {address} runs dnnevo {theirs.get('version')} built "
                              f"from {theirs.get('commit')}, this command dnnevo {want['version']} built "
                              f"from {want['commit']}; its results could differ, so the cluster is "
                              "refused: install the same dnnevo on every worker")


def _wall(result: Any) -> float | None:
    """A run's wall time, from its result (a dict or an object with ``wall_s``), if it has one."""
    wall = result.get("wall_s") if isinstance(result, dict) else getattr(result, "wall_s", None)
    return float(wall) if isinstance(wall, int | float) else None


def _call(fn: Callable[..., Any], args: tuple[Any, ...], kwargs: dict[str, Any], *needed: Any) -> Any:
    """``fn(*args, **kwargs)``; ``needed`` (results of the tasks it waited for) is dropped."""
    return fn(*args, **kwargs)


def _checked_call(expected: dict[str, str], fn: Callable[..., Any], args: tuple[Any, ...],
                  kwargs: dict[str, Any], *needed: Any) -> Any:
    """:func:`_call` on a worker that runs the dnnevo ``expected`` names, checked again here:
    a worker that joined the cluster after :func:`check_workers` is held to it too."""
    theirs = identity()
    if theirs != expected:
        raise ConfigError(f"this Dask worker runs dnnevo {theirs['version']} built from {theirs['commit']}, "
                          f"the command dnnevo {expected['version']} built from {expected['commit']}; its "
                          "results could differ, so it refused the task: install the same dnnevo on every worker")
    return _call(fn, args, kwargs, *needed)


def _running(client: Any) -> int | None:
    """How many tasks the cluster's workers are running now, if it says."""
    try:
        assigned = sum(len(keys) for keys in client.processing().values())
        return min(assigned, sum(client.nthreads().values()))
    except Exception:  # noqa: BLE001 - only a progress figure; never worth failing the run for
        return None


def check_options(*, workers: int | None, scheduler: str | None) -> None:
    """The Dask options make sense and Dask is installed; else a one-line :class:`ConfigError`,
    before anything is written."""
    if scheduler is not None and workers is not None:
        raise ConfigError("--workers sizes the local cluster; a --scheduler's cluster has its own workers")
    if importlib.util.find_spec("distributed") is None:
        raise ConfigError(f"Dask is not installed; {CLUSTER_EXTRA}")


def _distributed() -> Any:
    """The ``distributed`` package, imported here and only when a Dask cluster is used: it is an
    optional extra (``pip install "dnnevo[cluster]"``), and its import takes about a second."""
    import distributed

    return distributed


@contextlib.contextmanager
def dask_client(*, workers: int | None, scheduler: str | None) -> Iterator[Any]:
    """A Dask client: of a new local cluster of ``workers`` processes (default: one per core),
    one task at a time each, or of the running cluster at ``scheduler``. The cluster and its
    workers end with the block; a running cluster's workers finish the tasks they hold."""
    check_options(workers=workers, scheduler=scheduler)
    distributed = _distributed()

    # A client that loses its scheduler logs it before the command can say so in one line.
    logging.getLogger("distributed.client").setLevel(logging.CRITICAL)
    if scheduler is not None:
        try:
            client = distributed.Client(scheduler, timeout="20s")
        except (OSError, ValueError, TypeError) as e:
            raise ConfigError(f"cannot reach the Dask scheduler at {scheduler}: {e}") from None
        with client:
            check_workers(client)
            yield client
        return
    n = workers if workers is not None else (os.cpu_count() or 1)
    # The scheduler serves HTTP (the dashboard with bokeh) even without a dashboard: on a free
    # port, never 8787, which another cluster on this machine may hold. A task's own error is
    # reported by the caller, not as the workers' log of its traceback.
    with distributed.LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=":0",
                      silence_logs=logging.CRITICAL) as cluster, distributed.Client(cluster) as client:
        check_workers(client)
        yield client


def describe(client: Any, scheduler: str | None) -> str:
    """Where ``client``'s tasks run, in words, with the dashboard's address when there is one."""
    where = scheduler or f"a local Dask cluster of {len(client.scheduler_info()['workers'])} workers"
    link = getattr(client, "dashboard_link", None) if importlib.util.find_spec("bokeh") else None
    return where + (f"; dashboard {link}" if link else "")
