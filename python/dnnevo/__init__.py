"""dnnevo: evolve continuous-time recurrent neural networks that react, sequence and learn.

>>> import numpy as np, dnnevo
>>> net = dnnevo.Network(tau=[1.0, 2.0], theta=[0.0, 0.0],
...                      weights=[[0.0, 1.0], [1.0, 0.0]], sensor_weights=[[1.0], [0.0]])
>>> trace = net.run(np.ones((3, 1)), dt=0.1, substeps=10)
>>> trace.states.shape
(3, 2)
"""

from __future__ import annotations

from dnnevo import _startup

_startup.begin_import()  # Ctrl-C during the command's start-up: one line, after the imports (_startup.py)

from dnnevo import _core, plot, presets  # noqa: E402
from dnnevo._core import (
    LANES,
    Batch,
    Network,
    Trace,
    __version__,
    build_info,
    compose,
    run_population,
    use_kernel,
)
from dnnevo.config import EvolutionConfig, IntegratorConfig, Ranges
from dnnevo.errors import (
    ConfigError,
    DnnevoError,
    FitnessError,
    FormatError,
    InvalidArgumentError,
    InvalidNetworkError,
    TaskError,
)
from dnnevo.evolution.evolve import EvolutionResult, evaluate, evolve, resume
from dnnevo.evolution.ga import GeneticAlgorithm
from dnnevo.genomes import stack_genomes

_core.apply_simd_env()  # DNNEVO_SIMD, if set, names the kernel; a bad value fails the import

_startup.end_import()

__all__ = [
    "LANES",
    "Batch",
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
    "stack_genomes",
    "DnnevoError",
    "FitnessError",
    "FormatError",
    "InvalidArgumentError",
    "InvalidNetworkError",
    "Network",
    "TaskError",
    "Trace",
    "__version__",
    "build_info",
    "compose",
    "run_population",
    "use_kernel",
]
