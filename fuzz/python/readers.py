"""The Python file readers the fuzzers drive, one per kind of file, shared by the Atheris harness
(``fuzz/python/fuzz_reader.py``) and the reduced pass in CI (``tests/test_fuzz.py``).

Each reader writes the bytes it is given as its file, into an empty folder, beside valid files
of the other kinds where its reader needs them (taken from the seed corpus, ``fuzz/corpus/``),
and calls the public reader, then uses what it returned as a command would. Any input may be
refused, but only with a :class:`~dnnevo.errors.DnnevoError`: any other exception, a crash or a
hang is a finding.

======================  ===========================  ==============================================
reader                  file                         public reader
======================  ===========================  ==============================================
``network``             ``best.json``                ``Network.load``, ``RunDir.read_best``
``checkpoint``          ``checkpoint.json``          ``RunDir.read_checkpoint``, then the GA restored
``config``              ``config.toml``              ``RunDir.read_config``
``log``                 ``log.csv``                  ``RunDir.read_log``
``sweep``               ``sweep.json``               ``runs.check_settings``
``results``             ``EXPERIMENT/seed-N.json``   ``experiments.results.load``, then every table
``reproduce``           ``reproduce.json``           the same
``provenance``          ``provenance.json``          the same
======================  ===========================  ==============================================
"""

from __future__ import annotations

import json
import re
import shutil
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any

from dnnevo import EvolutionConfig, Network
from dnnevo.config import with_later_defaults
from dnnevo.errors import DnnevoError
from dnnevo.evolution.ga import GeneticAlgorithm
from dnnevo.experiments import examples, plan, report, results
from dnnevo.runs import RunDir, check_settings

__all__ = ["ALLOWED", "CORPUS", "READERS", "Reader", "read"]

CORPUS = Path(__file__).resolve().parents[1] / "corpus"
"""``fuzz/corpus/``: a folder of seed files per reader."""

ALLOWED: tuple[type[BaseException], ...] = (DnnevoError,)
"""What a reader may raise for a damaged file."""


@dataclass(frozen=True)
class Reader:
    """One kind of file and how its reader is driven."""

    name: str
    """The reader's name, also its corpus folder's."""
    read: Callable[[bytes, Path], None]
    """Writes the bytes as the file into the empty folder given, and reads it."""

    @property
    def corpus(self) -> Path:
        """Its seed files (and the files the fuzzers found worth keeping)."""
        return CORPUS / self.name


def read(reader: Reader, data: bytes) -> None:
    """Drives ``reader`` on ``data`` in a fresh temporary folder."""
    folder = Path(tempfile.mkdtemp(prefix=f"dnnevo-fuzz-{reader.name}-"))
    try:
        reader.read(data, folder)
    finally:
        shutil.rmtree(folder, ignore_errors=True)


# -- the valid files a reader's file needs beside it, from the seed corpus ------------------------

@cache
def _seed(reader: str, name: str) -> bytes:
    return (CORPUS / reader / name).read_bytes()


@cache
def _run_config() -> tuple[EvolutionConfig, dict[str, Any]]:
    """The seed run's config and its ``[run]`` table."""
    with tempfile.TemporaryDirectory() as tmp:
        (Path(tmp) / "config.toml").write_bytes(_seed("config", "seed-config.toml"))
        return RunDir(tmp).read_config()


@cache
def _sweep_settings() -> dict[str, Any]:
    """The settings ``dnnevo sweep`` checks the seed sweep's ``sweep.json`` against: the seed's
    own, with the settings added since it was written at their defaults, as today's command
    would make them."""
    settings: dict[str, Any] = json.loads(_seed("sweep", "seed-sweep.json"))
    return {**settings, "config": with_later_defaults(settings["config"])}


# -- the readers -----------------------------------------------------------------------------------

def _network(data: bytes, folder: Path) -> None:
    path = folder / "best.json"
    path.write_bytes(data)
    net = Network.load(path)
    assert Network.from_json(net.to_json()) == net, "a network changed on its way through to_json"
    config, table = _run_config()
    RunDir(folder).read_best(config, table)


def _checkpoint(data: bytes, folder: Path) -> None:
    (folder / "checkpoint.json").write_bytes(data)
    cp = RunDir(folder).read_checkpoint()
    ga = GeneticAlgorithm.from_state_dict(cp.state)
    ga.ask()
    _ = ga.best


def _config(data: bytes, folder: Path) -> None:
    (folder / "config.toml").write_bytes(data)
    config, _ = RunDir(folder).read_config()
    assert EvolutionConfig.from_toml(config.to_toml()) == config, "a config changed through TOML"


def _log(data: bytes, folder: Path) -> None:
    (folder / "log.csv").write_bytes(data)
    rows = RunDir(folder).read_log()
    config, _ = _run_config()
    if len(rows) <= config.generations:
        RunDir(folder).read_log(config)


def _sweep(data: bytes, folder: Path) -> None:
    path = folder / "sweep.json"
    path.write_bytes(data)
    check_settings(path, _sweep_settings(), what="sweep")


_JOB = re.compile(r'"job"\s*:\s*"([a-z0-9-]+)/seed-([0-9]{1,3})"')
_KEYS = ("summary", "results-table", *(f"summary:{f}" for f in plan.FAMILIES), *plan.FAMILIES, "machine")


def _results_folder(folder: Path, *, reproduce: bytes | None = None, provenance: bytes | None = None,
                    result: bytes | None = None) -> None:
    """A results folder of the seed reproduction's files, with the fuzzed one in its place: a job
    result goes where its own ``job`` field says (when it names one), so that it can be read."""
    if reproduce is None:
        reproduce = _seed("reproduce", "seed-reproduce.json")
    if provenance is None:
        provenance = _seed("provenance", "seed-provenance.json")
    (folder / results.SETTINGS_FILE).write_bytes(reproduce)
    (folder / results.PROVENANCE_FILE).write_bytes(provenance)
    if result is None:
        result, where = _seed("results", "seed-landmark-robot-0.json"), ("landmark-robot", "0")
    else:
        m = _JOB.search(result.decode("utf-8", "replace"))
        known = {e.name for e in plan.EXPERIMENTS}
        where = (m[1], m[2]) if m and m[1] in known else ("landmark", "0")
    (folder / where[0]).mkdir()
    (folder / where[0] / f"seed-{where[1]}.json").write_bytes(result)
    found = results.load(folder)
    for key in _KEYS:
        report.markdown(results.blocks(found, key))


def _results(data: bytes, folder: Path) -> None:
    _results_folder(folder, result=data)


def _reproduce(data: bytes, folder: Path) -> None:
    _results_folder(folder, reproduce=data)


def _provenance(data: bytes, folder: Path) -> None:
    _results_folder(folder, provenance=data)


def _example(data: bytes, folder: Path) -> None:
    path = folder / "example.json"
    path.write_bytes(data)
    examples.markdown(examples.read(path))


READERS: dict[str, Reader] = {r.name: r for r in (
    Reader("network", _network),
    Reader("checkpoint", _checkpoint),
    Reader("config", _config),
    Reader("log", _log),
    Reader("sweep", _sweep),
    Reader("results", _results),
    Reader("reproduce", _reproduce),
    Reader("provenance", _provenance),
    Reader("example", _example),
)}
"""Every reader, by name."""
