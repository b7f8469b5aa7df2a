"""Dynamical analysis of a network: how it works, not only what it does.

With its sensors held at a constant input vector, a network is an autonomous dynamical system
``tau_i dv_i/dt = -v_i + sum_j w_ij f(v_j - theta_j) + c_i`` (``c = sensor_weights @ input``). Its
behaviour is organised by its attractors, and an input that changes moves, creates or destroys
them (Beer 1995, "On the dynamics of small continuous-time recurrent neural networks").

- :mod:`.dynamics`: equilibria with their stability, limit cycles, bifurcations of one input,
  and which attractor a state settles to; it knows no task;
- :mod:`.trials`: a task's real trials recorded for the analysis, and replayed;
- :mod:`.lesions`: a neuron clamped or a connection cut, and the champion judged again;
- :mod:`.events`: windows of recorded trials aligned on the moments something happens, for a
  task's own views (``dnnevo.robots.pursuit``: a pursuer appearing);
- :mod:`.figures`: phase portraits, bifurcation diagrams, lesion tables and basins.

The numerical work is in Rust (``ctrnn::analysis``), whose results come back as read-only
objects (:class:`Equilibrium`, :class:`Cycle`, :class:`Bifurcation`, ...); these modules add the
Python-side records (``Attractors``, ``LesionTable``, ...) as dataclasses. ``dnnevo analyze`` runs it all on a run's champion.

>>> import dnnevo
>>> from dnnevo import analysis
>>> # One self-exciting neuron (w = 8) with its threshold at the centre (theta = w / 2): bistable.
>>> net = dnnevo.Network(tau=[1.0], theta=[4.0], weights=[[8.0]], sensor_weights=[[1.0]])
>>> [e.stability for e in analysis.equilibria(net, [0.0])]
['stable_node', 'unstable_node', 'stable_node']
>>> b = analysis.bifurcation(net, 0, -4.0, 4.0, steps=41)
>>> [(e.kind, round(e.value, 4)) for e in b.events]
[('fold', -1.0657), ('fold', 1.0657)]
"""

from dnnevo.analysis.dynamics import (
    RETRY_STARTS,
    STABILITIES,
    Attractors,
    Bifurcation,
    Cycle,
    CycleBranch,
    CycleEnd,
    Equilibrium,
    Event,
    attractors,
    bifurcation,
    equilibria,
    limit_cycles,
    settles_to,
    vector_field,
)
from dnnevo.analysis.figures import (
    STABILITY_COLORS,
    plot_basins,
    plot_bifurcation,
    plot_lesions,
    plot_phase_portrait,
)
from dnnevo.analysis.lesions import CLAMP_LIMIT, Lesion, LesionTable, clamp, cut, lesions
from dnnevo.analysis.trials import analysed_task, recorded_trials, replay, trial_outputs

__all__ = [
    "CLAMP_LIMIT",
    "RETRY_STARTS",
    "STABILITIES",
    "STABILITY_COLORS",
    "Attractors",
    "Bifurcation",
    "Cycle",
    "CycleBranch",
    "CycleEnd",
    "Equilibrium",
    "Event",
    "Lesion",
    "LesionTable",
    "analysed_task",
    "attractors",
    "bifurcation",
    "clamp",
    "cut",
    "equilibria",
    "lesions",
    "limit_cycles",
    "plot_basins",
    "plot_bifurcation",
    "plot_lesions",
    "plot_phase_portrait",
    "recorded_trials",
    "replay",
    "settles_to",
    "trial_outputs",
    "vector_field",
]


def __dir__() -> list[str]:
    """The public names only: ``dir(dnnevo.analysis)`` lists ``__all__``, not the dunders and
    submodules a package shows (the submodules stay importable, e.g. ``dnnevo.analysis.dynamics``)."""
    return sorted(__all__)
