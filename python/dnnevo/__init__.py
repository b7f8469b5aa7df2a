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

_startup.defer_interrupts()  # the command's start-up: Ctrl-C waits for dnnevo.cli.command.main

import sys as _sys  # noqa: E402
from types import TracebackType as _TracebackType


def _interrupted_import(kind: type[BaseException], value: BaseException,
                        tb: _TracebackType | None) -> None:
    """While dnnevo imports (e.g. the ``dnnevo`` command starting up), Ctrl-C is one line. Python
    may wrap the interrupt in another error (3.11 turns one raised while a class is created into a
    RuntimeError from ``__set_name__``), so the whole chain of causes is looked at."""
    _sys.excepthook = _sys.__excepthook__
    seen: BaseException | None = value
    while seen is not None and not isinstance(seen, KeyboardInterrupt):
        seen = seen.__cause__ or seen.__context__
    if issubclass(kind, KeyboardInterrupt) or seen is not None:
        _sys.stderr.write("dnnevo: interrupted\n")
    elif isinstance(value, DnnevoError) and _startup.is_the_command():
        _sys.stderr.write(f"dnnevo: error: {value}\n")  # e.g. a bad DNNEVO_SIMD
    else:
        _sys.__excepthook__(kind, value, tb)


if _sys.excepthook is _sys.__excepthook__:
    _sys.excepthook = _interrupted_import

from dnnevo.errors import DnnevoError  # noqa: E402

from dnnevo import _core, plot
from dnnevo import presets# noqa: E402
from dnnevo._core import (
    LANES,
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
    FitnessError,
    FormatError,
    InvalidArgumentError,
    InvalidNetworkError,
)
from dnnevo.evolution.evolve import EvolutionResult, evaluate, evolve, resume
from dnnevo.evolution.ga import GeneticAlgorithm

_core.apply_simd_env()  # DNNEVO_SIMD, if set, names the kernel; a bad value fails the import

if _sys.excepthook is _interrupted_import:
    _sys.excepthook = _sys.__excepthook__

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
    "build_info",
    "compose",
    "run_population",
    "use_kernel",
]
