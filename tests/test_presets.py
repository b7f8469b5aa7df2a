"""Every preset builds, evolves and yields a champion that survives the network file format."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import pytest

import dnnevo
from dnnevo import presets


@pytest.mark.parametrize("name", presets.names())
def test_every_preset_runs(name: str, tmp_path: Path) -> None:
    full = presets.get(name)
    assert full.task in dnnevo._core.task_names()
    config = dataclasses.replace(full, population=6, generations=2, elitism=0, validation_candidates=2)
    result = dnnevo.evolve(name, config, seed=1, progress=False, threads=1)
    assert len(result.history["best"]) == 2 and math.isfinite(result.best_fitness)
    assert (result.best.size, result.best.n_inputs) == (full.size, full.n_inputs)
    result.best.save(tmp_path / "best.json")
    assert dnnevo.Network.load(tmp_path / "best.json") == result.best
