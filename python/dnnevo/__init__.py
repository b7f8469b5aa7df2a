"""dnnevo: evolve continuous-time recurrent neural networks that react, sequence and learn.

>>> import numpy as np, dnnevo
>>> net = dnnevo.Network(tau=[1.0, 2.0], theta=[0.0, 0.0],
...                      weights=[[0.0, 1.0], [1.0, 0.0]], sensor_weights=[[1.0], [0.0]])
>>> trace = net.run(np.ones((3, 1)), dt=0.1, substeps=10)
>>> trace.states.shape
(3, 2)
"""

from __future__ import annotations

from dnnevo import plot, presets
from dnnevo._core import LANES, Network, Trace, __version__, compose, run_population
from dnnevo.config import EvolutionConfig, IntegratorConfig, Ranges
from dnnevo.errors import (
    ConfigError,
    DnnevoError,
    FitnessError,
    FormatError,
    InvalidArgumentError,
    InvalidNetworkError,
)
from dnnevo.evolve import EvolutionResult, evaluate, evolve, resume
from dnnevo.ga import GeneticAlgorithm

__all__ = [
    "LANES",
    "ConfigError",
    "EvolutionConfig",
    "EvolutionResult",
    "GeneticAlgorithm",
    "IntegratorConfig",
    "Ranges",
    "evaluate",
    "evolve",
    "plot",
    "presets",
    "resume",
    "DnnevoError",
    "FitnessError",
    "FormatError",
    "InvalidArgumentError",
    "InvalidNetworkError",
    "Network",
    "Trace",
    "__version__",
    "compose",
    "run_population",
]
