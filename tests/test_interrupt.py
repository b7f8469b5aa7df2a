"""Ctrl-C stops the long calls into the Rust core promptly with ``KeyboardInterrupt``.

Each call below is sized, from a short timed run on this machine, to run about 20 seconds in
full. A timer sends SIGINT to this process half a second after the call starts; the call must end
with ``KeyboardInterrupt`` less than a second after the signal, the README's promise.
"""

from __future__ import annotations

import dataclasses
import os
import signal
import threading
import time
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

import dnnevo
from dnnevo.tasks import landmark
from dnnevo.tasks import nav1d
from dnnevo import presets
from dnnevo.tasks import sequence

DELAY = 0.5
"""Seconds from the call's start to SIGINT."""
LATENCY = 1.0
"""Seconds from SIGINT to KeyboardInterrupt: the README promises "a fraction of a second"."""
FULL = 20.0
"""Seconds each call would run in full, sized on this machine: far beyond DELAY + LATENCY, so an
interrupted call was stopped, not finished."""


def sized(call: Callable[[int], Any], small: int, cap: int) -> int:
    """The size at which ``call(size)`` runs about FULL seconds here, from one timed run at
    ``small`` (the work grows in proportion to the size), at most ``cap`` (memory grows too)."""
    start = time.perf_counter()
    call(small)
    seconds = max(time.perf_counter() - start, 1e-3)
    size = max(small, min(cap, int(small * FULL / seconds)))
    # A call that could end on its own soon after the signal would pass without being stopped.
    assert seconds * size / small > 4 * (DELAY + LATENCY), f"size {size} would run too briefly"
    return size


def interrupted_after(call: Callable[[], Any]) -> float:
    """Runs ``call`` with SIGINT sent after DELAY; returns the seconds from the signal to the
    KeyboardInterrupt the call must end in."""
    assert threading.current_thread() is threading.main_thread()
    sent: list[float] = []

    def interrupt() -> None:
        sent.append(time.perf_counter())
        os.kill(os.getpid(), signal.SIGINT)

    timer = threading.Timer(DELAY, interrupt)
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            call()
    finally:
        timer.cancel()
    assert sent, "the call ended before the signal was sent: size it larger"
    return time.perf_counter() - sent[0]


def test_run_population_stops_on_ctrl_c() -> None:
    nets = [dnnevo.Network.random(10, 1, seed=i) for i in range(64)]
    inputs = np.zeros((1000, 1))

    def run(substeps: int) -> Any:
        return dnnevo.run_population(nets, inputs, substeps=substeps, record=False)

    substeps = sized(run, 200, 10**7)
    assert interrupted_after(lambda: run(substeps)) < LATENCY


def test_evolution_step_stops_on_ctrl_c_and_keeps_the_population() -> None:
    def scored(population: int) -> dnnevo.GeneticAlgorithm:
        config = dataclasses.replace(presets.get("sequence-1bit"), population=population)
        return dnnevo.GeneticAlgorithm(config, seed=0)

    ga = scored(sized(lambda p: scored(p).step(), 500, 400_000))
    before = ga.ask().genomes
    assert interrupted_after(ga.step) < LATENCY
    assert ga.generation == 0
    np.testing.assert_array_equal(ga.ask().genomes, before)


def test_sequence_assessment_stops_on_ctrl_c() -> None:
    config = presets.get("sequence-1bit")
    net = dnnevo.Network.random(config.size, config.n_inputs, seed=3)
    trials = sized(lambda n: sequence.assess(config, net, n, 1), 2000, 2_000_000)
    assert interrupted_after(lambda: sequence.assess(config, net, trials, 1)) < LATENCY


def test_nav1d_assessment_stops_on_ctrl_c() -> None:
    config = presets.get("nav1d-single")
    net = dnnevo.Network.random(config.size, config.n_inputs, seed=3)
    chains = sized(lambda n: nav1d.assess(config, net, n, 1), 2000, 2_000_000)
    assert interrupted_after(lambda: nav1d.assess(config, net, chains, 1)) < LATENCY


def test_landmark_assessment_stops_on_ctrl_c() -> None:
    config = presets.get("landmark")
    net = dnnevo.Network.random(config.size, config.n_inputs, seed=3)
    trials = sized(lambda n: landmark.assess(config, net, n, 1), 200, 200_000)
    assert interrupted_after(lambda: landmark.assess(config, net, trials, 1)) < LATENCY


def test_the_equilibrium_search_stops_on_ctrl_c() -> None:
    from dnnevo import analysis

    net = dnnevo.Network.random(12, 2, seed=4)
    starts = sized(lambda n: analysis.equilibria(net, [0.0, 0.0], starts=n), 2048, 1 << 24)
    assert interrupted_after(lambda: analysis.equilibria(net, [0.0, 0.0], starts=starts)) < LATENCY
