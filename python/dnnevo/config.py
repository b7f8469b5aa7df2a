"""Evolution settings: a frozen dataclass that reads and writes TOML.

Every field has one meaning and one default here; presets (``dnnevo.presets``) override fields by
name. A run folder's ``config.toml`` is this dataclass plus the run's seed and dnnevo's version,
so a run can always be repeated from its folder.
"""

from __future__ import annotations

import copy
import dataclasses
import inspect
import json
import math
import os
import re
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

import numpy as np
import tomli_w

from dnnevo import _core
from dnnevo.errors import ConfigError, DnnevoError, beer_hint, did_you_mean, with_article

__all__ = ["EvolutionConfig", "IntegratorConfig", "Ranges", "apply_overrides", "with_later_defaults"]

_DEFAULTS: dict[str, Any] = json.loads(_core.RUN_DEFAULTS)
"""The Rust core's defaults for a run (``tasks::RunConfig``): every default below is read from
them, and every value is checked there (:meth:`EvolutionConfig.__post_init__`), so Python and Rust
cannot drift. Python checks types only."""

#: Settings added after run folders began to carry a config digest. At their defaults they are
#: left out of the digest (``dnnevo.runs.config_digest``), and a stored config without them reads as
#: having their defaults (:func:`with_later_defaults`), so folders written before them still resume.
LATER_SETTINGS = ("mutation", "mutation_scale", "champion_step_check", "precision")


def with_later_defaults(stored: Any) -> Any:
    """A config dict read from a file (a sweep's or a reproduction's record), with each of
    :data:`LATER_SETTINGS` it lacks set to its default; anything else is returned as it is.

    >>> with_later_defaults({"population": 10})["champion_step_check"]
    False
    """
    if not isinstance(stored, Mapping):
        return stored
    return {**{name: _DEFAULTS[name] for name in LATER_SETTINGS}, **stored}


def _known_keywords(cls: type) -> type:
    """``cls`` (a dataclass) whose constructor names a misspelt keyword in a
    :class:`~dnnevo.ConfigError`, with the closest setting, instead of Python's TypeError."""
    init = cls.__init__  # type: ignore[misc]
    names = [f.name for f in fields(cls)]

    def checked(self: Any, *args: Any, **kwargs: Any) -> None:
        for key in kwargs:
            if key not in names:
                hint = did_you_mean(key, names) or f"; its settings: {', '.join(names)}"
                raise ConfigError(f"{cls.__name__} has no setting {key!r}{hint}")
        init(self, *args, **kwargs)

    checked.__doc__, checked.__signature__ = init.__doc__, inspect.signature(init)  # type: ignore[attr-defined]
    cls.__init__ = checked  # type: ignore[misc]
    return cls


@_known_keywords
@dataclass(frozen=True)
class Ranges:
    """Allowed interval of each parameter kind; genes are drawn and resampled uniformly in it."""

    tau: tuple[float, float] = tuple(_DEFAULTS["ranges"]["tau"])  # type: ignore[assignment]
    theta: tuple[float, float] = tuple(_DEFAULTS["ranges"]["theta"])  # type: ignore[assignment]
    weights: tuple[float, float] = tuple(_DEFAULTS["ranges"]["weights"])  # type: ignore[assignment]
    sensor_weights: tuple[float, float] = tuple(_DEFAULTS["ranges"]["sensor_weights"])  # type: ignore[assignment]

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            try:
                lo, hi = (float(v) for v in value)
            except (TypeError, ValueError):
                raise ConfigError(f"ranges.{f.name} is {value!r}; expected [low, high]") from None
            object.__setattr__(self, f.name, (lo, hi))


#: Prefix of ``config.task`` for a task written in Python: ``"python:module.Name"``, a
#: closed-loop environment class (``dnnevo.closedloop``) or, from ``evolve``, a fitness function.
PYTHON_TASK = "python:"


@_known_keywords
@dataclass(frozen=True)
class IntegratorConfig:
    """How networks are integrated: each input row is held for ``substeps`` steps of ``dt``."""

    method: str = _DEFAULTS["integrator"]["method"]
    """``"euler"`` or ``"rk4"``."""
    dt: float = _DEFAULTS["integrator"]["dt"]
    substeps: int = _DEFAULTS["integrator"]["substeps"]

    def __post_init__(self) -> None:
        _check_type(self, "method", str, "integrator.")
        _check_type(self, "dt", float, "integrator.")
        _check_type(self, "substeps", int, "integrator.")


@_known_keywords
@dataclass(frozen=True)
class EvolutionConfig:
    """Everything an evolution run needs besides its seed.

    >>> cfg = EvolutionConfig(population=50, generations=10)
    >>> EvolutionConfig.from_toml(cfg.to_toml()) == cfg
    True
    """

    task: str = _DEFAULTS["task"]
    """Built-in task name (see ``dnnevo tasks``), or ``"python:module.Class"`` for a closed-loop
    task written in Python (``dnnevo.closedloop``); set from the function when ``evolve`` gets a
    Python callable."""
    population: int = _DEFAULTS["population"]
    generations: int = _DEFAULTS["generations"]
    crossover_rate: float = _DEFAULTS["crossover_rate"]
    mutation_rate: float = _DEFAULTS["mutation_rate"]
    """Probability that each gene of a child mutates (a per-gene rate)."""
    mutation: str = _DEFAULTS["mutation"]
    """``"uniform"``: a mutated gene is redrawn over its range (the paper's); ``"creep"``: it moves
    by a bell-shaped step of ``mutation_scale`` times its range's width, reflected at the ends."""
    mutation_scale: float = _DEFAULTS["mutation_scale"]
    """With ``mutation = "creep"``: the step's standard deviation as a fraction of the range."""
    elitism: int = _DEFAULTS["elitism"]
    """How many of the best individuals are copied unchanged (0 = the paper's GA)."""
    validation_candidates: int = _DEFAULTS["validation_candidates"]
    """How many of each generation's best individuals by training fitness are re-scored on the
    task's validation set (fresh conditions, fixed for the run) to choose the champion; 0 chooses
    the champion by training fitness, as the paper does. Evolution itself is unchanged."""
    champion_step_check: bool = _DEFAULTS["champion_step_check"]
    """Validate a candidate that would replace the champion again with a step ten times finer
    (``dt/10``, ten times the substeps) and count the worse of its two validations, so that a
    network that is right only at the run's step does not become champion. Costs a few
    validations per change of champion; evolution itself is unchanged."""
    selection: str = _DEFAULTS["selection"]
    """``"proportional"`` (the paper's) or ``"rank"``."""
    fill: str = _DEFAULTS["fill"]
    """With seed networks: fill the rest of the population with ``"mutants"`` or ``"random"``."""
    size: int = _DEFAULTS["size"]
    """Neurons per network."""
    n_inputs: int = _DEFAULTS["n_inputs"]
    """Sensors per network; a built-in task checks it matches."""
    integrator: IntegratorConfig = field(default_factory=IntegratorConfig)
    precision: str = _DEFAULTS["precision"]
    """The floating-point type a built-in task's networks compute in: ``"f64"`` (the reference
    for every published result and preset) or ``"f32"``, opt-in single precision: each input
    rounded to ``f32`` as the network reads it, every state and rate ``f32``, with bits of their
    own that are the same on every CPU (see ``docs/benchmarks.md`` for what it gains and
    ``docs/closed-loop.md`` for when to stay in ``f64``). The world and the scores stay ``f64``."""
    ranges: Ranges = field(default_factory=Ranges)
    task_params: Mapping[str, Any] = field(default_factory=dict)
    """Task-specific settings, passed to the task as they are."""

    def __post_init__(self) -> None:
        for name, kind in _TYPES.items():
            _check_type(self, name, kind)
        if isinstance(self.integrator, Mapping):
            object.__setattr__(self, "integrator", _build(IntegratorConfig, self.integrator, "integrator"))
        if isinstance(self.ranges, Mapping):
            object.__setattr__(self, "ranges", _build(Ranges, self.ranges, "ranges"))
        if not isinstance(self.integrator, IntegratorConfig):
            raise ConfigError(f"integrator is {self.integrator!r}; expected a table")
        if not isinstance(self.ranges, Ranges):
            raise ConfigError(f"ranges is {self.ranges!r}; expected a table")
        if not isinstance(self.task_params, Mapping):
            raise ConfigError(f"task_params is {self.task_params!r}; expected a table")
        object.__setattr__(self, "task_params", _plain(self.task_params, "task_params"))
        d = self.to_dict()
        _check_finite(d, "")
        _check_counts(d)
        object.__setattr__(self, "_native", _core.RunConfig(json.dumps(d)))
        object.__setattr__(self, "_task_params", copy.deepcopy(self.task_params))

    @property
    def native(self) -> _core.RunConfig:
        """The settings as the Rust core parsed and validated them, once, when this config was
        made: ``Evolution`` and ``evaluate`` take it, and ``native.builtin()`` is the built-in
        task built from it. ``task_params`` changed in place afterwards is refused here, since
        the core would not see it: make a new config with ``dataclasses.replace``."""
        if self.task_params != self.__dict__["_task_params"]:
            raise ConfigError("config.task_params was changed in place after the config was made; "
                              "make a new config with dataclasses.replace(config, task_params=...)")
        native: _core.RunConfig = self.__dict__["_native"]
        return native

    # -- conversions -------------------------------------------------------------------------

    def to_dict(self) -> dict[str, Any]:
        """A plain dict (tuples become lists), as written to TOML."""
        d = dataclasses.asdict(self)
        d["ranges"] = {k: list(v) for k, v in d["ranges"].items()}
        return d

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> EvolutionConfig:
        """Builds a config from a dict; unknown keys are an error that names them."""
        return _build(cls, d, "config")

    def to_toml(self, run: Mapping[str, Any] | None = None) -> str:
        """TOML text; ``run`` (seed, dnnevo version, ...) is written as a ``[run]`` table."""
        d = self.to_dict()
        if run:
            d = {"run": dict(run), **d}
        return tomli_w.dumps(d)

    @classmethod
    def from_toml(cls, text: str) -> EvolutionConfig:
        """Reads TOML text written by :meth:`to_toml` (a ``[run]`` table is ignored); :meth:`load`
        reads a file."""
        if not isinstance(text, str):
            raise ConfigError(f"from_toml takes TOML text, not {with_article(type(text).__name__)}; "
                              "EvolutionConfig.load(path) reads a file")
        try:
            d = tomllib.loads(text)
            d.pop("run", None)
            return cls.from_dict(d)
        except tomllib.TOMLDecodeError as e:
            hint = ("; it looks like a file's path: EvolutionConfig.load(path) reads a file"
                    if "\n" not in text.strip() and text.strip().endswith(".toml") else "")
            raise ConfigError(f"not valid TOML: {e}{hint}") from None
        except RecursionError:
            raise ConfigError("tables or arrays nested too deeply") from None

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> EvolutionConfig:
        """Reads a config file: a run folder's ``config.toml`` (its ``[run]`` table is ignored; the
        run's own checks are :class:`~dnnevo.runs.RunDir`'s) or one written by hand. An error
        names the file."""
        where = Path(path)
        try:
            text = where.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as e:
            raise ConfigError(f"cannot read {where}: {getattr(e, 'strerror', None) or e}") from None
        try:
            return cls.from_toml(text)
        except ConfigError as e:
            raise ConfigError(f"{where}: {e}") from None

    def to_json(self) -> str:
        """The config as JSON text, the form the Rust core reads."""
        return json.dumps(self.to_dict())



_TYPES: dict[str, type] = {
    "task": str, "population": int, "generations": int, "crossover_rate": float,
    "mutation_rate": float, "mutation": str, "mutation_scale": float, "elitism": int,
    "validation_candidates": int, "champion_step_check": bool, "selection": str, "fill": str, "size": int, "n_inputs": int,
    "precision": str,
}
"""The type of each plain field of :class:`EvolutionConfig`; the values are checked in Rust."""


def _check_type(obj: Any, name: str, kind: type, prefix: str = "") -> None:
    """``obj.name`` has the type ``kind``: a str; a bool; an int (not a bool; a negative one is
    refused by :func:`_check_counts`); or a float, which an int may stand for."""
    value = getattr(obj, name)
    if isinstance(value, np.generic):  # a NumPy number stands for the Python one it holds
        value = value.item()
        object.__setattr__(obj, name, value)
    if kind is bool:
        ok = isinstance(value, bool)
        expected = "true or false"
    elif kind is str:
        ok = isinstance(value, str)
        expected = "a string"
    elif kind is int:
        ok = isinstance(value, int) and not isinstance(value, bool)
        expected = "an integer"
    else:
        ok = isinstance(value, int | float) and not isinstance(value, bool)
        expected = "a number"
    if not ok:
        raise ConfigError(f"{prefix}{name} is {value!r}; expected {expected}")


_LARGEST_PARSABLE = 2**64 - 1
"""The largest count the Rust core can parse; any real limit is far lower, and the core names it."""


def _check_counts(d: dict[str, Any]) -> None:
    """A count the Rust core cannot even parse gets a message naming the setting: a negative one
    the message Rust gives for 0, so that ``population = -5`` and ``population = 0`` read alike
    ("it must be at least 2"), and one beyond 64 bits that it is too large."""
    counts: list[tuple[str, str | None]] = [(name, None) for name, kind in _TYPES.items() if kind is int]
    for name, sub in [*counts, ("integrator", "substeps")]:
        value = d[name] if sub is None else d[name][sub]
        key = name if sub is None else f"{name}.{sub}"
        if value > _LARGEST_PARSABLE:
            raise ConfigError(f"{key} is {value}; it must be at most {_LARGEST_PARSABLE}")
        if value >= 0:
            continue
        probe = {**d, name: 0 if sub is None else {**d[name], sub: 0}}
        rule = "it must be at least 0"
        try:
            _core.RunConfig(json.dumps(probe))
        except ConfigError as e:
            said = str(e)
            if said.startswith(f"{key} is 0; "):
                rule = said[len(f"{key} is 0; "):]
        raise ConfigError(f"{key} is {value}; {rule}")


def _plain(value: Any, where: str) -> Any:
    """``value`` as a config file holds it: NumPy numbers as the Python numbers they hold, tuples
    as lists, tables as dicts; anything a TOML file cannot hold (None, an array, an object) is a
    :class:`ConfigError` naming where it is."""
    if isinstance(value, np.generic) and not isinstance(value, np.bytes_ | np.void):
        value = value.item()
    if isinstance(value, bool | int | float | str):
        return value
    if isinstance(value, Mapping):
        for k in value:
            if not isinstance(k, str):
                raise ConfigError(f"{where} has the key {k!r}; keys of a table are strings")
        return {k: _plain(v, f"{where}.{k}") for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_plain(v, f"{where}[{i}]") for i, v in enumerate(value)]
    if isinstance(value, np.ndarray):
        raise ConfigError(f"{where} is an array; a config holds lists (give array.tolist())")
    what = "None" if value is None else f"of type {type(value).__name__}"
    raise ConfigError(f"{where} is {what}; a config holds numbers, strings, booleans, and lists "
                      "and tables of them")


def _check_finite(value: Any, where: str) -> None:
    """Every number in ``value`` (nested tables and arrays, walked without recursion) is finite:
    the tasks read JSON, which has no NaN or infinity."""
    stack = [(value, where)]
    while stack:
        v, at = stack.pop()
        if isinstance(v, float) and not math.isfinite(v):
            raise ConfigError(f"{at} is {v}; every number must be finite")
        if isinstance(v, Mapping):
            stack.extend((x, f"{at}.{k}" if at else str(k)) for k, x in v.items())
        elif isinstance(v, list | tuple):
            stack.extend((x, f"{at}[{i}]") for i, x in enumerate(v))


def _build(cls: type, d: Mapping[str, Any], where: str) -> Any:
    if not isinstance(d, Mapping):
        raise ConfigError(f"{where} is {d!r}; expected a table")
    known = {f.name for f in fields(cls)}
    unknown = sorted(set(d) - known)
    if unknown:
        raise ConfigError(
            f"{where} has unknown key {unknown[0]!r}; known keys: {', '.join(sorted(known))}"
        )
    try:
        return cls(**d)
    except TypeError as e:
        raise ConfigError(f"{where}: {e}") from None


_NOT_TOML = {"True": "true", "False": "false", "TRUE": "true", "FALSE": "false", "None": None,
             "null": None, "NaN": None}
"""Values that a ``--set`` would read as strings but that were surely meant as something else:
Python's booleans (TOML's are lowercase) and values TOML has no form for."""


def _parse_value(text: str, key: str) -> Any:
    """A ``--set`` value for ``key``: TOML syntax (``3``, ``0.5``, ``true``, ``["0", "1"]``), else
    a string; a value in :data:`_NOT_TOML` is refused, since as a string it would be true (a
    Python class's ``if self.switch:``) where the user wrote false."""
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        pass
    if text in _NOT_TOML:
        meant = _NOT_TOML[text]
        fix = (f"write {key}={meant} for a boolean" if meant is not None
               else "a setting holds numbers, strings, booleans (true, false) and lists")
        raise ConfigError(f"--set {key}={text}: {text} is not a TOML value; {fix}, or "
                          f"{key}='\"{text}\"' for the string")
    if text[:1] in "[{" and (word := re.search(rf"\b({'|'.join(_NOT_TOML)})\b", text)):
        # A list or table meant as one, which would be kept as a string of its text.
        raise ConfigError(f"--set {key}={text}: not a TOML value, since {word.group(1)} is not one; "
                          "booleans are true and false")
    return text


def _with_key(node: Any, path: list[str], value: Any, key: str, default: Any = None) -> Any:
    """``node`` (a table or a list) with ``path`` set to ``value``: ``task_params.training.cone_deg``
    reaches into the nested table, as in the config file, and a number picks an entry of a list
    (``task_params.sim.sonars.0.lobe_deg``); ``key`` is the setting's whole name, for the error.
    ``default`` is what the task fills in at ``node`` (None when nothing is known): a table or
    list the path needs and ``node`` lacks starts from it, so its other parts keep their defaults;
    with no default, a missing table starts empty.

    >>> _with_key({"a": 1, "b": {"c": 2}}, ["b", "d"], 3, "task_params.b.d")
    {'a': 1, 'b': {'c': 2, 'd': 3}}
    >>> _with_key({"s": [{"x": 1}, {"x": 2}]}, ["s", "1", "x"], 5, "task_params.s.1.x")
    {'s': [{'x': 1}, {'x': 5}]}
    >>> _with_key({}, ["s", "0", "x"], 5, "task_params.s.0.x", {"s": [{"x": 1, "y": None}], "t": 2})
    {'s': [{'x': 5}]}
    >>> _with_key({"a": 1}, ["a", "c"], 3, "task_params.a.c")
    Traceback (most recent call last):
      ...
    dnnevo.errors.ConfigError: task_params.a.c cannot be set: task_params.a is 1, not a table
    >>> _with_key({"s": [{"x": 1}]}, ["s", "2", "x"], 5, "task_params.s.2.x")
    Traceback (most recent call last):
      ...
    dnnevo.errors.ConfigError: task_params.s.2.x cannot be set: task_params.s is a list of 1, so its entries are 0 to 0
    """
    head, rest = path[0], path[1:]
    here = key[: len(key) - len(".".join(path)) - 1]  # the name of node itself
    if isinstance(node, list):
        if not (head.isdecimal() and int(head) < len(node)):
            entries = f"its entries are 0 to {len(node) - 1}" if node else "it has no entry to change"
            raise ConfigError(f"{key} cannot be set: {here} is a list of {len(node)}, so {entries}")
        i = int(head)
        below = default[i] if isinstance(default, list) and i < len(default) else None
        return [*node[:i], _with_key(node[i], rest, value, key, below) if rest else value, *node[i + 1:]]
    if not isinstance(node, dict):
        raise ConfigError(f"{key} cannot be set: {here} is {node!r}, not a table")
    if not rest:
        return {**node, head: value}
    below = default.get(head) if isinstance(default, dict) else None
    inner = node.get(head)
    if inner is None:
        inner = _without_nulls(below) if isinstance(below, dict | list) else None
    if inner is None:
        if rest[0].isdecimal():
            raise ConfigError(f"{key} cannot be set: {here}.{head} is not a list the config or the task "
                              "has; give the whole list")
        inner = {}
    return {**node, head: _with_key(inner, rest, value, key, below)}


def _task_params(config: EvolutionConfig) -> dict[str, Any] | None:
    """``config``'s task settings as the core fills them in, every default included; None for a
    task written in Python, whose settings only it knows."""
    try:
        params: dict[str, Any] = config.native.builtin().params()
    except DnnevoError:
        return None
    return params


def _without_nulls(x: Any) -> Any:
    """``x`` with every ``None`` entry of its tables left out, at any depth: TOML has no null, and
    an unset optional part is left out as the core reads it."""
    if isinstance(x, dict):
        return {k: _without_nulls(v) for k, v in x.items() if v is not None}
    if isinstance(x, list):
        return [_without_nulls(v) for v in x]
    return x


def apply_overrides(config: EvolutionConfig, assignments: list[str]) -> EvolutionConfig:
    """Applies ``key=value`` overrides, e.g. ``population=50``, ``integrator.dt=0.05``,
    ``ranges.tau=[1, 5]``, ``task_params.targets=["01", "10"]`` or
    ``task_params.sim.sonars.0.lobe_deg=10``. A built-in task's table or list that the config
    does not hold (``sim`` here, or ``sonars`` in a ``sim`` that lacks it) starts from what the
    task fills in for the config as given, so that one part of it changes and the rest is kept."""
    d = config.to_dict()
    # What the task fills in, read from the config as given (before any override).
    defaults = _task_params(config) if any(a.strip().startswith("task_params.") for a in assignments) else None
    for item in assignments:
        key, sep, raw = item.partition("=")
        key = key.strip()
        if not sep or not key:
            raise ConfigError(f"--set {item!r} is not key=value")
        value = _parse_value(raw.strip(), key)
        head, _, sub = key.partition(".")
        if head not in d:
            raise ConfigError(f"unknown setting {key!r}{beer_hint(key) or did_you_mean(key, d)}; "
                              f"known settings: {', '.join(sorted(d))}")
        if sub:
            if not isinstance(d[head], dict):
                raise ConfigError(f"{head} is not a table, so {key!r} cannot be set")
            if head != "task_params" and sub not in d[head]:
                hint = beer_hint(key) or did_you_mean(key, [f"{head}.{k}" for k in d[head]])
                raise ConfigError(
                    f"unknown setting {key!r}{hint}; {head} has {', '.join(sorted(d[head]))}"
                )
            if head == "task_params":
                d[head] = _with_key(d[head], sub.split("."), value, key, defaults)
            else:
                d[head] = _with_key(d[head], [sub], value, key)
        else:
            d[head] = value
    return EvolutionConfig.from_dict(d)
