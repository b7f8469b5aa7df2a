"""Ctrl-C stops the long calls into the Rust core promptly with ``KeyboardInterrupt``.

Each call below is sized to run for tens of seconds (on a fast 2-core machine; longer elsewhere).
A timer sends SIGINT to this process shortly after the call starts; the call must end with
``KeyboardInterrupt`` within a few seconds, so the work really was stopped, not finished.
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
PROMPT = 10.0
"""Seconds by which the interrupted call must have ended: each call runs >= 25 s in full."""


def interrupted_after(call: Callable[[], Any]) -> float:
    """Runs ``call`` with SIGINT sent after DELAY; returns its wall time, which must end in
    KeyboardInterrupt."""
    assert threading.current_thread() is threading.main_thread()
    timer = threading.Timer(DELAY, os.kill, (os.getpid(), signal.SIGINT))
    start = time.perf_counter()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            call()
    finally:
        timer.cancel()
    return time.perf_counter() - start


def test_run_population_stops_on_ctrl_c() -> None:
    nets = [dnnevo.Network.random(10, 1, seed=i) for i in range(64)]
    inputs = np.zeros((1000, 1))
    # 64 networks x 1000 steps x 40000 substeps: about 36 s on a 2-core AVX2 machine.
    assert interrupted_after(lambda: dnnevo.run_population(
        nets, inputs, substeps=40_000, record=False)) < PROMPT


def test_evolution_step_stops_on_ctrl_c_and_keeps_the_population() -> None:
    config = dataclasses.replace(presets.get("sequence-1bit"), population=200_000)
    ga = dnnevo.GeneticAlgorithm(config, seed=0)
    before = ga.ask().genomes
    assert interrupted_after(ga.step) < PROMPT
    assert ga.generation == 0
    np.testing.assert_array_equal(ga.ask().genomes, before)


def test_sequence_assessment_stops_on_ctrl_c() -> None:
    config = presets.get("sequence-1bit")
    net = dnnevo.Network.random(config.size, config.n_inputs, seed=3)
    assert interrupted_after(lambda: sequence.assess(config, net, 300_000, 1)) < PROMPT


def test_nav1d_assessment_stops_on_ctrl_c() -> None:
    config = presets.get("nav1d-single")
    net = dnnevo.Network.random(config.size, config.n_inputs, seed=3)
    assert interrupted_after(lambda: nav1d.assess(config, net, 400_000, 1)) < PROMPT


def test_landmark_assessment_stops_on_ctrl_c() -> None:
    config = presets.get("landmark")
    net = dnnevo.Network.random(config.size, config.n_inputs, seed=3)
    assert interrupted_after(lambda: landmark.assess(config, net, 50_000, 1)) < PROMPT
