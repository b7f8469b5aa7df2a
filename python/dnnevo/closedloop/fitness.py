"""A closed-loop :class:`~dnnevo.closedloop.Environment` as a fitness function for
:func:`dnnevo.evolve`: each network's mean return over its episodes, on conditions that follow
the run's seed and generation.

>>> import dnnevo
>>> from dnnevo.closedloop import ClosedLoop, FarSeeker
>>> fitness = ClosedLoop(FarSeeker(), episodes=2, max_steps=10_000)
>>> config = dnnevo.EvolutionConfig(population=20, generations=2, size=5, n_inputs=1)
>>> result = dnnevo.evolve(fitness, config, seed=1, progress=False)
>>> result.history["best"].shape
(2,)
"""

from __future__ import annotations

import dataclasses
import hashlib
import inspect
import math
from collections.abc import Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

from dnnevo import _core
from dnnevo.closedloop.environment import Environment, checked
from dnnevo.closedloop.loop import DEFAULT_INTEGRATOR, FLAGS, Rollout, as_flags, rollout
from dnnevo.closedloop.source import fingerprint, legacy_fingerprint, plain_source, task_source
from dnnevo.config import PYTHON_TASK, EvolutionConfig, IntegratorConfig
from dnnevo.errors import ConfigError, TaskError

__all__ = ["ROLLOUT_KEYS", "ClosedLoop"]

#: The keys of a named task's ``task_params`` that set the rollout (every other key goes to the
#: environment's class), as :meth:`ClosedLoop.configured` records them.
ROLLOUT_KEYS = ("episodes", "max_steps", "validation_episodes", "rows")

#: Keys that ``task_params`` may not hold, because the run config sets them at its top level
#: (``tasks::RunConfig``): an environment's argument of such a name is not recorded.
SET_BY_RUN = ("size", "integrator", "precision")

#: Fresh episodes on which a run checks, at each change of champion, whether it meets the task
#: class's success rule (``dnnevo assess`` judges on as many as asked, 200 by default).
SUCCESS_EPISODES = 40

#: Episodes of the validation set on which a run chooses its champion (see
#: :meth:`ClosedLoop.validate`).
VALIDATION_EPISODES = 40


_MISSING = object()


def _plain(value: Any) -> bool:
    """Whether ``value`` is what a config file holds as it is: a bool, int, finite float or
    str, or a list or a table (str keys) of them."""
    if type(value) in (bool, int, str):
        return True
    if type(value) is float:
        return math.isfinite(value)
    if type(value) is list:
        return all(_plain(v) for v in value)
    if type(value) is dict:
        return all(type(k) is str and _plain(v) for k, v in value.items())
    return False


def close_copy(env: Any) -> None:
    """Closes an environment made only to be compared or checked, when it has ``close`` (a
    simulator, a vector environment: it releases what it holds); its own trouble in closing is
    not the caller's."""
    close = getattr(env, "close", None)
    if callable(close):
        try:
            close()
        except Exception:  # noqa: BLE001
            pass


def success_rule(env: Any, task: str) -> tuple[Any, float]:
    """The environment's ``success`` method and ``success_rate``, checked; a
    :class:`~dnnevo.ConfigError` says what is missing."""
    kind = type(env).__name__
    rule, threshold = getattr(env, "success", None), getattr(env, "success_rate", None)
    if threshold is None and (rule is None or hasattr(env, "success_rate")):  # None: turned off
        raise ConfigError(f"{task} has no success rule: give {kind} a success_rate (the fraction "
                          "of episodes that must succeed) and a method success(returns, lengths) "
                          "(docs/closed-loop.md#a-success-rule)")
    if rule is None or threshold is None:
        has, lacks = ("success_rate", "method success(returns, lengths)") if rule is None else \
            ("success method", "success_rate (the fraction of episodes that must succeed)")
        raise ConfigError(f"{kind} has a {has} but no {lacks}; a success rule needs both, and "
                          "success_rate = None says the class has none (docs/closed-loop.md#a-success-rule)")
    if isinstance(threshold, bool) or not (isinstance(threshold, float | int) and 0 < threshold <= 1):
        raise ConfigError(f"{kind}.success_rate is {threshold!r}; expected a number in (0, 1]")
    return rule, float(threshold)


class ClosedLoop:
    """``fitness(networks, *, generation, seed)``: the networks' mean returns in ``env``, for
    ``episodes`` episodes of at most ``max_steps`` time steps, each of ``substeps`` integration
    steps of ``dt`` (by default the run config's defaults, as for a task named in a config), the
    networks computing in ``precision`` (``"f64"``, or ``"f32"``: see
    :func:`~dnnevo.closedloop.rollout`).
    The champion is chosen on ``validation_episodes`` episodes of their own (:meth:`validate`).
    ``rows`` runs at most that many episodes at once, starting a waiting episode in a row whose
    episode ended (:func:`~dnnevo.closedloop.rollout`; the environment needs ``restart``);
    validation and judging, which may run more episodes per network, run at least one row per
    episode number.

    A run folder names it after the environment's class (or ``name``, ``"python:module.Class"``)
    and records the rollout's settings in ``config.toml``, with a digest of the class's source
    (its code: comments, docstrings and layout do not count), the environment's attributes and
    the settings; ``resume`` accepts it again only when the digest is the same. Wrap a freshly
    made environment: one that has run episodes has more attributes.
    """

    def __init__(self, env: Environment, *, episodes: int = 1, max_steps: int,
                 dt: float = DEFAULT_INTEGRATOR.dt, substeps: int = DEFAULT_INTEGRATOR.substeps,
                 method: str = DEFAULT_INTEGRATOR.method, name: str | None = None,
                 validation_episodes: int = VALIDATION_EPISODES, rows: int | None = None,
                 precision: str = "f64") -> None:
        if isinstance(env, type):
            raise ConfigError(f"env is the class {env.__name__}; ClosedLoop takes an environment made "
                              f"from it, {env.__name__}(...)")
        checked(env)
        if isinstance(validation_episodes, bool) or not isinstance(validation_episodes, int | np.integer) \
                or validation_episodes < 1:
            raise ConfigError(f"validation_episodes is {validation_episodes!r}; expected a whole "
                              "number of episodes, at least 1")
        for key, value in (("episodes", episodes), ("max_steps", max_steps)):
            if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < 1:
                raise ConfigError(f"{key} is {value!r}; expected a whole number, at least 1")
        # The integration's settings are checked where they are used, by the binding.
        integration: dict[str, Any] = dict(dt=dt, substeps=substeps, method=method)
        # A probe network slow enough for any step (the step's limit is checked against the
        # networks themselves, in each rollout).
        slow = 10.0 * dt if isinstance(dt, float | int) and 0 < dt < 1e300 else 1.0
        _core.Batch([_core.Network(tau=[max(1.0, slow)], theta=[0.0], weights=[[0.0]], sensor_weights=[[]])],
                    replicas=1, **integration)
        self.env = env
        # Half a rule is refused: a success method without any success_rate, or a rate that can
        # only be a rule's (in (0, 1]) without a method; a rule's rate out of range too. Other
        # attributes of those names (a statistic, an array) are no rule, as they always were.
        rule, rate = getattr(env, "success", None), getattr(env, "success_rate", None)
        a_rate = isinstance(rate, float | int) and not isinstance(rate, bool) and 0 < rate <= 1
        if callable(rule) and (rate is not None or not hasattr(env, "success_rate")) \
                or rule is None and a_rate:
            success_rule(env, type(env).__name__)
        if precision not in ("f64", "f32"):
            raise ConfigError(f"precision is {precision!r}; expected 'f64' or 'f32'")
        given = dict(episodes=episodes, max_steps=max_steps, dt=dt, substeps=substeps, method=method,
                     precision=precision)
        # A NumPy number stands for the Python one it holds, which a config file can record.
        self.settings: dict[str, Any] = {k: v.item() if isinstance(v, np.generic) else v
                                         for k, v in given.items()}
        self.validation_episodes = int(validation_episodes)
        if rows is not None and (isinstance(rows, bool) or not isinstance(rows, int | np.integer)
                                 or rows < episodes):
            raise ConfigError(f"rows is {rows!r}; expected a whole number of rows, at least "
                              f"episodes ({episodes}), or None (every episode at once)")
        if rows is not None and not callable(getattr(env, "restart", None)):
            raise ConfigError(f"rows is {rows}, but {type(env).__name__} has no restart method to start "
                              "a waiting episode in an ended one's row (docs/closed-loop.md#more-episodes-than-rows)")
        self.rows = None if rows is None else int(rows)
        kind = type(env)
        module, qualname = kind.__module__, kind.__qualname__
        if name is not None:
            module, _, qualname = name.removeprefix(PYTHON_TASK).rpartition(".")
        self.__module__, self.__qualname__ = module, qualname
        try:
            attributes = vars(env)
        except TypeError:  # a class with __slots__
            attributes = {k: getattr(env, k) for k in getattr(kind, "__slots__", ()) if hasattr(env, k)}
        recorded = self._recorded()
        self._parts = {"source": task_source(kind) or kind.__qualname__,
                       "attributes": fingerprint(attributes), "settings": fingerprint(recorded)}
        self.fitness_source = "\n".join(self._parts.values())
        # As made before digests took in what the class reads from its module (source.py): the
        # class's source as it was then, and without an analysis attribute added since.
        legacy = [legacy_fingerprint(attributes), legacy_fingerprint(recorded)]
        self._legacy_sources = ["\n".join([text or kind.__qualname__, *legacy])
                                for text in (plain_source(kind), plain_source(kind, ignored=True))]
        # As made before comments and layout were left out: the source as written.
        written = task_source(kind, raw=True) or kind.__qualname__
        self._legacy_sources.append("\n".join([written, self._parts["attributes"], self._parts["settings"]]))
        # As made before a class's preset was left out (as written, and by its tokens), for a
        # class that has one.
        for raw, now in ((True, written), (False, self._parts["source"])):
            with_preset = task_source(kind, raw=raw, keep=("preset",)) or kind.__qualname__
            if with_preset != now:
                self._legacy_sources.append("\n".join([with_preset, self._parts["attributes"],
                                                       self._parts["settings"]]))
        if any(isinstance(v, np.generic) for v in given.values()):
            # NumPy settings, as runs recorded them before they were made Python numbers (and
            # before comments and layout were left out)
            as_given = {**recorded, **{k: given[k] for k in recorded if k in given}}
            self._legacy_sources.append("\n".join([written, self._parts["attributes"],
                                                   fingerprint(as_given)]))

    def _recorded(self) -> dict[str, Any]:
        """The settings a run records: the rollout's (its precision only when ``"f32"``), the
        validation set's size when it is not the default and ``rows`` when set (so that runs from
        before they were settings keep their digest)."""
        recorded = dict(self.settings)
        if recorded["precision"] == "f64":
            del recorded["precision"]
        if self.validation_episodes != VALIDATION_EPISODES:
            recorded["validation_episodes"] = self.validation_episodes
        if self.rows is not None:
            recorded["rows"] = self.rows
        return recorded

    def digest(self) -> str:
        """SHA-256 of :attr:`fitness_source`, as ``config.toml``'s ``fitness_sha256`` records it."""
        return hashlib.sha256(self.fitness_source.encode()).hexdigest()

    def part_digests(self) -> dict[str, str]:
        """SHA-256 of each part of :attr:`fitness_source`, as ``config.toml``'s ``fitness_parts``
        records them, to say which part differs when a digest does: the class's ``source`` (with
        what it reads from its module, comments, docstrings and layout left out), the environment's
        ``attributes`` and the rollout's ``settings``. A run recorded before comments and layout
        were left out has another ``source`` part, so when its digest differs by another part,
        its source is said to differ too."""
        return {k: hashlib.sha256(v.encode()).hexdigest() for k, v in self._parts.items()}

    def digests(self) -> tuple[str, ...]:
        """Every digest a run of this task may record: :meth:`digest`, the ones runs recorded
        before digests took in what the class reads from its module (which they then could not
        check), and the one of runs recorded before comments and layout were left out (the
        source as written)."""
        return (self.digest(), *(hashlib.sha256(t.encode()).hexdigest() for t in self._legacy_sources))

    def arguments(self) -> dict[str, Any]:
        """The keyword arguments that make the environment again, where they can be told from
        it: each parameter of its class's ``__init__`` that the environment keeps as an
        attribute of the same name, with a value other than the default that a config file can
        hold (numbers, strings, booleans, and lists and tables of them), not one the run config
        sets (:data:`SET_BY_RUN`). Empty unless an environment made with them (and then closed,
        when it has ``close``) has this one's digest: all of what the digest sees, or nothing."""
        kind = type(self.env)
        try:
            parameters = inspect.signature(kind).parameters.values()
        except (TypeError, ValueError):
            return {}
        found: dict[str, Any] = {}
        for p in parameters:
            if p.kind not in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY) or p.name in ROLLOUT_KEYS + SET_BY_RUN:
                continue
            try:
                value = getattr(self.env, p.name, _MISSING)
            except Exception:  # noqa: BLE001 - a property that cannot be read yet
                continue
            if value is _MISSING or not _plain(value):
                continue
            if p.default is p.empty or not _plain(p.default) or value != p.default:
                found[p.name] = value
        if not found:
            return {}
        s = self.settings
        try:
            env = kind(**found)
        except Exception:  # noqa: BLE001 - then the arguments are not known
            return {}
        try:
            again = ClosedLoop(env, episodes=s["episodes"], max_steps=s["max_steps"], dt=s["dt"],
                               substeps=s["substeps"], method=s["method"], precision=s["precision"],
                               validation_episodes=self.validation_episodes, rows=self.rows,
                               name=f"{PYTHON_TASK}{self.__module__}.{self.__qualname__}")
            same = again.digest() == self.digest()
        except Exception:  # noqa: BLE001
            same = False
        finally:
            close_copy(env)
        return found if same else {}

    def configured(self, config: EvolutionConfig) -> EvolutionConfig:
        """``config`` saying what this fitness function runs: its name as ``task``, the rollout's
        episodes and step limit and the environment's :meth:`arguments` as ``task_params``, and
        its integration as ``integrator`` and ``precision``. A command that builds the task from
        the config builds it with those arguments (with the class's defaults when they could not
        be told), and the digest then tells whether that is the same task."""
        s = self._recorded()
        params = {**self.arguments(), **{k: s[k] for k in ROLLOUT_KEYS if k in s}}
        if config.precision not in ("f64", self.settings["precision"]):
            raise ConfigError(f"config.precision is {config.precision!r} but this ClosedLoop computes "
                              f"in {self.settings['precision']!r}; give ClosedLoop(..., "
                              f"precision={config.precision!r})")
        return dataclasses.replace(
            config,
            task=f"{PYTHON_TASK}{self.__module__}.{self.__qualname__}",
            integrator=IntegratorConfig(method=s["method"], dt=s["dt"], substeps=s["substeps"]),
            precision=str(self.settings["precision"]),
            task_params=params,
        )

    def judged(self, network: _core.Network, episodes: int, seed: int,
               purpose: str) -> tuple[npt.NDArray[np.bool_], float, Rollout]:
        """``network`` on ``episodes`` fresh episodes drawn from ``seed`` and ``purpose``, judged
        by the environment's success rule: which episodes succeeded, the rate success needs,
        and the rollout."""
        name = f"{PYTHON_TASK}{self.__module__}.{self.__qualname__}"
        rule, threshold = success_rule(self.env, name)
        result = rollout([network], self.env, seed=seed, purpose=purpose, **self._run(episodes))
        return self._rule(rule, result.returns[0], result.lengths[0]), threshold, result

    def validate(self, networks: Sequence[_core.Network], *, seed: int
                 ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """Each network's ``(rate, score)`` on the run's validation set: the same
        ``validation_episodes`` episodes (default :data:`VALIDATION_EPISODES`) at every
        generation, drawn from ``seed`` with
        ``purpose="validate"`` (never a training episode). The rate is the fraction of episodes
        that meet the environment's success rule (0 for an environment without one), the score
        the mean return. :func:`dnnevo.evolve` chooses the champion by them among the top
        ``config.validation_candidates`` by fitness; set it to 0 to choose by fitness alone."""
        result = rollout(networks, self.env, seed=seed, purpose="validate",
                         **self._run(self.validation_episodes))
        shape = result.returns.shape
        rule = getattr(self.env, "success", None)
        if not self.has_success_rule:
            rates = np.zeros(shape[0])
        else:
            ok = self._rule(rule, result.returns.ravel(), result.lengths.ravel())
            rates = ok.reshape(shape).mean(axis=1)
        return rates, result.returns.mean(axis=1)

    def _run(self, episodes: int) -> dict[str, Any]:
        """The rollout's settings for ``episodes`` episodes per network: at least one row per
        episode number when ``rows`` is set."""
        rows = None if self.rows is None else max(self.rows, episodes)
        return {**self.settings, "episodes": episodes, "rows": rows}

    def _rule(self, rule: Any, returns: npt.NDArray[np.float64],
              lengths: npt.NDArray[np.int64]) -> npt.NDArray[np.bool_]:
        """The success rule's verdict on the rows of the last rollout, checked."""
        kind = type(self.env).__name__
        try:
            ok = np.asarray(rule(returns, lengths))
        except Exception as e:
            raise TaskError(f"{kind}.success raised {type(e).__name__}: {e}") from e
        flags = as_flags(ok) if ok.shape == returns.shape else None
        if flags is None:
            raise TaskError(f"{kind}.success returned {ok.dtype} of shape {ok.shape}; expected "
                            f"{FLAGS} of shape {returns.shape}, one per episode")
        return flags

    @property
    def has_success_rule(self) -> bool:
        """Whether the environment has a success rule (a ``success`` method and a
        ``success_rate``); without one every network's validation rate is 0, and the validation
        score chooses."""
        return callable(getattr(self.env, "success", None)) and getattr(self.env, "success_rate", None) is not None

    def succeeds(self, network: _core.Network, seed: int) -> float:
        """1.0 when ``network`` meets the environment's success rule on
        :data:`SUCCESS_EPISODES` fresh episodes drawn from ``seed``, 0.0 when not, NaN when the
        environment has no rule."""
        if not self.has_success_rule:
            return float("nan")
        ok, threshold, _ = self.judged(network, SUCCESS_EPISODES, seed, "validate")
        return float(ok.mean() >= threshold)

    def __call__(self, networks: Sequence[_core.Network], *, generation: int = 0,
                 seed: int = 0) -> npt.NDArray[np.float64]:
        return rollout(networks, self.env, seed=seed, generation=generation,
                       **self._run(self.settings["episodes"])).fitness

    def __repr__(self) -> str:
        settings = ", ".join(f"{k}={v!r}" for k, v in self._recorded().items())
        return f"ClosedLoop({type(self.env).__name__}(), {settings})"

