"""Named experiments: each preset is an :class:`EvolutionConfig` with the paper's settings, and a
``--quick`` variant (small population, few generations) for tests and demos.

Every number of a preset lives here; ``dnnevo presets`` lists them.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

from dnnevo.closedloop import named
from dnnevo.config import PYTHON_TASK, EvolutionConfig, IntegratorConfig, apply_overrides
from dnnevo.errors import ConfigError, did_you_mean

__all__ = ["Preset", "get", "names", "unseeded_warning", "PRESETS"]


@dataclass(frozen=True)
class Preset:
    """One named experiment."""

    summary: str
    config: EvolutionConfig
    quick: dict[str, Any] = field(default_factory=dict)
    """Overrides of the ``--quick`` variant."""
    seeded_by: str = ""
    """The ``--seed-from`` options the experiment is meant to start from (``dnnevo run`` and
    ``sweep`` warn when they are missing); empty when it starts from random networks."""


_QUICK = {"population": 60, "generations": 8}


def _sequence(targets: list[str], size: int, generations: int, mutation: float,
              perf_base: float | str) -> EvolutionConfig:
    """A paper sequence-learning experiment: population 1000, crossover 0.3, 2 trials per
    target, 10 triggers per trial."""
    return EvolutionConfig(
        task="sequence",
        population=1000,
        generations=generations,
        crossover_rate=0.3,
        mutation_rate=mutation,
        size=size,
        n_inputs=2,
        task_params={"targets": targets, "trials_per_target": 2, "perf_base": perf_base},
    )


#: ``--quick`` for a task written in Python: a demo's population and generations.
PYTHON_QUICK = {"population": 20, "generations": 5}


def _classic(task: str, *, size: int, n_inputs: int, generations: int, **task_params: Any) -> EvolutionConfig:
    """A classic benchmark of ``dnnevo.classic``: population 100, rank selection, 5 elites, the
    paper's mutation at 0.05 per gene, one Euler step of 0.1 per control step (unless replaced)."""
    return EvolutionConfig(task=f"{PYTHON_TASK}dnnevo.classic.{task}", population=100, generations=generations,
                           selection="rank", elitism=5, mutation_rate=0.05, size=size, n_inputs=n_inputs,
                           integrator=IntegratorConfig(substeps=1), task_params=task_params)


_TWO_BIT = ["0", "1", "01", "10"]

# Not in the paper: the direct route with more neurons and a GA that keeps its best (rank
# selection, 20 elites); the paper's 10-neuron direct route fails here as it did there.
_DIRECT16 = dataclasses.replace(_sequence(_TWO_BIT, 16, 500, 0.002, "generation-mean"), selection="rank",
                                elitism=20)
# _DIRECT16 with the score clamped once per evaluation (see the preset that uses it).
_DIRECT16_CLAMP_EVAL = dataclasses.replace(_DIRECT16, task_params={**_DIRECT16.task_params, "clamp": "evaluation"})


# The paper's incremental route with the GA of sequence-2bit-direct16-clamp-eval (not the
# paper's), for the paper's 500 generations. The first population is seeded (the preset cannot
# do that alone): member i composes member i of a 1-bit run's and of an alternating run's last
# populations and 6 unconnected random neurons, without cross weights. The champion is chosen on
# 128 validation trials per target (not 32), each would-be champion validated at the run's step
# and at dt/10: with 32 trials and no step check, a third of the final champions were step
# artefacts or undecided on fresh trials (README).
_INCREMENTAL16 = Preset(
    "the paper's incremental route (§5.3) as it works here: 16 neurons, rank selection, elitism "
    "20, score clamped once, champions validated on 128 trials per target and at dt/10; 1000 x 500",
    dataclasses.replace(_DIRECT16_CLAMP_EVAL, champion_step_check=True,
                        task_params={**_DIRECT16_CLAMP_EVAL.task_params, "validation_trials": 128}),
    _QUICK,
    "--seed-from a sequence-1bit run --seed-from a sequence-2bit-alternating run "
    "--seed-populations --spare-neurons 6",
)


def _varied_landmark(**training: float) -> EvolutionConfig:
    """Landmark recognition trained on varied trials (``task_params.training``): 10 trials per
    landmark, a population of 400 for 1000 generations with rank selection and 10 elites."""
    return EvolutionConfig(task="landmark", population=400, generations=1000, crossover_rate=0.5,
                           mutation_rate=0.01, elitism=10, selection="rank", size=8, n_inputs=1,
                           task_params={"trials_per_landmark": 10, "training": training})


def _nav1d(generations: int, size: int, n_inputs: int, **task_params: Any) -> EvolutionConfig:
    """A paper navigation experiment: population 1000, crossover 0.5, mutation 0.025."""
    return EvolutionConfig(
        task="nav1d",
        population=1000,
        generations=generations,
        crossover_rate=0.5,
        mutation_rate=0.025,
        size=size,
        n_inputs=n_inputs,
        task_params={"reinforcement_input": n_inputs == 2, **task_params},
    )

# Not in the paper, which failed at it (see the nav1d-single preset).
_SINGLE = _nav1d(300, 8, 2, objective="single", environments=["far", "near"], trials_per_environment=5,
                 chains_per_environment=2, max_steps=300)

PRESETS: dict[str, Preset] = {
    "sequence-1bit": Preset(
        "paper §5.2: learn 0* or 1* from reinforcement; 5 neurons, 1000 x 500",
        _sequence(["0", "1"], 5, 500, 0.01, 0.5),
        _QUICK,
    ),
    # Not given by the paper: we use the 1-bit settings, the nearest experiment it describes.
    "sequence-2bit-alternating": Preset(
        "paper §5.3, first step: learn (01)* or (10)*; 5 neurons, 1000 x 500 (1-bit settings)",
        _sequence(["01", "10"], 5, 500, 0.01, 0.5),
        _QUICK,
    ),
    # The paper's incremental route read literally; it fails here (README), sequence-2bit works.
    "sequence-2bit-paper": Preset(
        "paper §5.3 read literally: 0*, 1*, (01)*, (10)* from composites, 10 neurons",
        _sequence(_TWO_BIT, 10, 500, 0.002, "generation-mean"),
        _QUICK,
        "--seed-from a sequence-1bit run --seed-from a sequence-2bit-alternating run",
    ),
    "sequence-2bit-direct": Preset(
        "paper §5.3, the route that failed: the 2-bit task from random 10-neuron networks",
        _sequence(_TWO_BIT, 10, 500, 0.002, "generation-mean"),
        _QUICK,
    ),
    "sequence-2bit-direct16": Preset(
        "beyond the paper (§5.3): the 2-bit task from random 16-neuron networks, rank selection, "
        "elitism 20; 1000 x 500",
        _DIRECT16,
        _QUICK,
    ),
    # Not in the paper: sequence-2bit-direct16 with the score clamped once per evaluation (the
    # mean of the trials' unclamped scores, then max(0, .)) instead of per trial, so that failing
    # one target costs fitness; with the per-trial clamp most seeds end one target short.
    "sequence-2bit-direct16-clamp-eval": Preset(
        "beyond the paper (§5.3): sequence-2bit-direct16 with the score clamped once per "
        "evaluation, not per trial; 1000 x 500",
        _DIRECT16_CLAMP_EVAL,
        _QUICK,
    ),
    # The paper's route as it works here is `sequence-2bit`; the README's rows made before it had
    # that name keep the name they were made under (ALIASES).
    "sequence-2bit-incremental16": _INCREMENTAL16,
    "sequence-2bit": _INCREMENTAL16,
    # The paper solved these in generations 0, 2 and 5; 30 generations leave room for bad seeds.
    "nav1d-far": Preset(
        "paper §4.2: reach the goal in landmark-far environments; 5 neurons, 1000 x 30",
        _nav1d(30, 5, 1, objective="goal", environments=["far"]),
        _QUICK,
    ),
    "nav1d-near": Preset(
        "paper §4.2: reach the goal in landmark-near environments; 5 neurons, 1000 x 30",
        _nav1d(30, 5, 1, objective="goal", environments=["near"]),
        _QUICK,
    ),
    "nav1d-classifier": Preset(
        "paper §4.2: tell landmark-far from landmark-near in one trial; 5 neurons, 1000 x 30",
        _nav1d(30, 5, 2, objective="classify", environments=["far", "near"]),
        _QUICK,
    ),
    # Not in the paper, which failed at it (§4.2). Our choices: 8 neurons (the three 5-neuron
    # subnetworks had 15 between them, with 6 doing the real work); chains of 5 trials without a
    # reset, 2 per environment type, scored on trials 2-5; a 300-step time limit (a direct
    # search needs under 100) so that a generation costs a third of the paper's 1000-step limit.
    "nav1d-single": Preset(
        "beyond the paper (§4.2): one network learns its environment in trial 1 and reaches the "
        "goal in trials 2-5; 8 neurons, 1000 x 300",
        _SINGLE,
        _QUICK,
    ),
    # Not in the paper: nav1d-single seeded from a chained near seeker (the first population is
    # that champion composed with 3 unconnected random neurons, its motors staying the motors),
    # with the fitness paying for the near seeker's strategy in trial 1 (near_first_weight, see
    # docs/nav1d.md), rank selection, 20 elites and champions validated at dt/10 as well.
    "nav1d-single-incremental": Preset(
        "beyond the paper (§4.2): one network for the whole task, seeded from a chained near "
        "seeker, near_first_weight 0.5, rank selection, elitism 20, champions checked at dt/10; "
        "8 neurons, 1000 x 500",
        dataclasses.replace(_SINGLE, generations=500, selection="rank", elitism=20, champion_step_check=True,
                            task_params={**_SINGLE.task_params, "near_first_weight": 0.5}),
        _QUICK,
        "--seed-from a chained nav1d-near run --spare-neurons 3",
    ),
    # The paper solved it by generation 15; 100 generations (4 s) leave room for slower seeds.
    "landmark": Preset(
        "paper §3: tell two landmarks apart from a wall-following robot's sonar; "
        "8 neurons, 100 x 100, 6 trials",
        EvolutionConfig(task="landmark", population=100, generations=100, crossover_rate=0.5,
                        mutation_rate=0.025, size=8, n_inputs=1,
                        task_params={"trials_per_landmark": 3}),
        {"population": 30, "generations": 5},
    ),
    # Not in the paper. Trained with varied trials (Jakobi-style: crates/tasks/src/landmark/
    # training.rs) so that champions transfer to the robot-like test, which training never sees:
    # every variation at half the strength first tried, 2 of the 10 trials per landmark ideal, a
    # larger population with rank selection and elitism, and champions validated on varied trials.
    "landmark-robust": Preset(
        "beyond the paper (§3): landmark recognition trained on varied trials, to pass the "
        "robot-like test; 8 neurons, 400 x 1000, 20 trials",
        _varied_landmark(ideal_trials_per_landmark=2, landmark_shift=0.15, landmark_turn_deg=5.0,
                         landmark_scale=0.08, follower_speed=0.08, follower_distance=0.05, cone_deg=8.0,
                         trial_seconds=3.0, input_gain=0.15, input_offset=0.025, input_noise_sd=0.015),
        {"population": 30, "generations": 5},
    ),
    # Not in the paper. landmark-robust's training widened to as far as a real robot may differ,
    # the room's size and the sonar's axis varied too (issue 47; each range and why:
    # docs/landmark.md, "A wider envelope"). Judged in the second set of held-out worlds
    # (dnnevo.tasks.landmark_worlds.SECOND), fixed before any run of it was judged.
    "landmark-wide": Preset(
        "beyond the paper (§3): landmark recognition trained on a wide envelope of robots and rooms, "
        "to transfer to worlds that differ in kind; 8 neurons, 400 x 1000, 20 trials",
        _varied_landmark(ideal_trials_per_landmark=2, landmark_shift=0.3, landmark_turn_deg=10.0,
                         landmark_scale=0.15, follower_speed=0.2, follower_distance=0.15, cone_deg=15.0,
                         trial_seconds=3.0, input_gain=0.15, input_offset=0.05, input_noise_sd=0.03,
                         room_scale=0.2, sonar_axis_deg=15.0),
        {"population": 30, "generations": 5},
    ),
    "sequence-3bit": Preset(
        "paper §5.4: (011)*, (101)*, (110)*; 10 neurons, 1000 x 700, perf_base 2/3",
        _sequence(["011", "101", "110"], 10, 700, 0.002, 2 / 3),
        _QUICK,
    ),
    # The field's classic benchmarks, not in the paper: tasks written in Python with the
    # closed-loop protocol (dnnevo.classic), run by the examples/ scripts that report their results
    # (docs/classic.md). The world and the network move together, one Euler step per control step.
    "legged-walker": Preset(
        "Beer and Gallagher's one-legged walker with its angle sensor (docs/classic.md); "
        "5 neurons, 100 x 100, 4 random starts",
        _classic("walker.LeggedWalker", size=5, n_inputs=1, generations=100, episodes=4,
                 max_steps=2200, start="random"),
        PYTHON_QUICK,
    ),
    # Trained on varied starts and validated on others, which the benchmark's own setup (one
    # episode from the standard start, examples/double_pole.py --set ...) does not do: with it,
    # dnnevo's GA solved the task without velocities in 0 of 10 seeds (docs/classic.md).
    "double-pole": Preset(
        "double-pole balancing without velocities (docs/classic.md): 5 neurons, population 100, "
        "4 episodes from random starts, champions validated on 20 others",
        dataclasses.replace(
            _classic("double_pole.DoublePole", size=5, n_inputs=3, generations=250, episodes=4,
                     max_steps=1000, start="random", validation_episodes=20),
            integrator=IntegratorConfig(), validation_candidates=10),
        PYTHON_QUICK,
    ),
    # Paper §3.2, whose details are Yamauchi (1993)'s: our choices are dnnevo.robots.pursuit's
    # (docs/paper.md, "Predator avoidance"). The paper's landmark GA (crossover 0.5, mutation
    # 0.025), with rank selection and 5 elites as for the classic tasks; the champion is chosen
    # among the 5 best of each generation on 20 validation episodes.
    "predator-avoidance": Preset(
        "paper §3.2: a robot escapes two pursuers while avoiding static obstacles (docs/robots.md); "
        "6 neurons, 100 x 200, 6 random starts, champions validated on 20 others",
        EvolutionConfig(task=f"{PYTHON_TASK}dnnevo.robots.pursuit.Pursuit", population=100, generations=200,
                        crossover_rate=0.5, mutation_rate=0.025, selection="rank", elitism=5,
                        validation_candidates=5, size=6, n_inputs=12,
                        task_params={"episodes": 6, "max_steps": 450, "validation_episodes": 20}),
        PYTHON_QUICK,
    ),
    # Paper §3.2 used a hand-designed network here (dnnevo.robots.navigation.navigator) and
    # evolved none: this is dnnevo's comparison only (docs/reactive-navigation.md), evolved in
    # the U-trap without detectors with the landmark GA, rank selection and 3 elites.
    "reactive-navigation": Preset(
        "paper §3.2 (the paper did not evolve it; docs/reactive-navigation.md): reach a goal past "
        "a U-shaped trap; 6 neurons, 60 x 40, 4 random starts, champions validated on 10 others",
        EvolutionConfig(task=f"{PYTHON_TASK}dnnevo.robots.navigation.Navigate", population=60, generations=40,
                        crossover_rate=0.5, mutation_rate=0.025, selection="rank", elitism=3,
                        validation_candidates=3, size=6, n_inputs=11,
                        task_params={"episodes": 4, "max_steps": 600, "validation_episodes": 10,
                                     "world": "u-trap", "steps": 600}),
        PYTHON_QUICK,
    ),
    "categorical-perception": Preset(
        "Beer's categorical perception: catch circles, avoid diamonds (docs/classic.md); "
        "7 neurons, 100 x 300, 16 falls",
        _classic("categorical.CategoricalPerception", size=7, n_inputs=7, generations=300,
                 episodes=16, max_steps=917),
        PYTHON_QUICK,
    ),
}


ALIASES = {"sequence-2bit-incremental16": "sequence-2bit"}
"""Presets that are another name for one above, by the name they stand for."""


def names() -> list[str]:
    """The preset names, sorted."""
    return sorted(PRESETS)


def unseeded_warning(name: str, seeded: bool) -> str | None:
    """A warning when preset ``name`` is meant to start from earlier runs (:attr:`Preset.seeded_by`)
    and the run is not ``seeded``; None otherwise.

    >>> unseeded_warning("sequence-1bit", seeded=False) is None
    True
    >>> unseeded_warning("sequence-2bit", seeded=True) is None
    True
    >>> print(unseeded_warning("nav1d-single-incremental", seeded=False))
    nav1d-single-incremental is meant to start from earlier runs (--seed-from a chained nav1d-near run --spare-neurons 3); without --seed-from this run starts from random networks
    """
    preset = PRESETS.get(name)
    if seeded or preset is None or not preset.seeded_by:
        return None
    return (f"{name} is meant to start from earlier runs ({preset.seeded_by}); without "
            "--seed-from this run starts from random networks")


def get(name: str, *, quick: bool = False, overrides: list[str] | None = None) -> EvolutionConfig:
    """The config of preset ``name``, optionally its quick variant, with ``key=value`` overrides.
    A task written in Python (``"python:module.Class"``) starts from the defaults, with the
    class's own ``preset`` (:func:`~dnnevo.closedloop.named.class_preset`) over them and then
    the quick variant's population and generations; its ``n_inputs`` is the environment's
    ``observation_size`` (which imports the class's module and makes one with the final
    ``task_params``) unless the class's preset or an override sets it."""
    if name.startswith(PYTHON_TASK):
        own = named.class_preset(name)  # checked: a config of its own
        quick_sets = [f"{k}={v}" for k, v in PYTHON_QUICK.items()] if quick else []
        try:  # the quick settings and the overrides together, so that an override can fit them
            config = apply_overrides(EvolutionConfig.from_dict({**own, "task": name}), [*quick_sets, *(overrides or [])])
        except ConfigError as e:
            if not (quick and own and any(k in str(e) for k in PYTHON_QUICK)):
                raise
            raise ConfigError(f"{e}: --quick's {', '.join(f'{k} {v}' for k, v in PYTHON_QUICK.items())} "
                              f"go over {name.rpartition('.')[2]}.preset; --set the setting to fit") from None
        if "n_inputs" in own or any(o.partition("=")[0].strip() == "n_inputs" for o in overrides or []):
            return config
        size = named.observation_size(name, config.task_params)
        if size is None:  # the run's own check names what is wrong with the task
            return config
        return EvolutionConfig.from_dict({**config.to_dict(), "n_inputs": size})
    try:
        preset = PRESETS[name]
    except KeyError:
        hint = did_you_mean(name, names())
        if not hint and "." in name:  # module.Class: a task written in Python
            hint = f" (a task written in Python is named {PYTHON_TASK}{name})"
        raise ConfigError(f"unknown preset {name!r}{hint}; presets: {', '.join(names())}") from None
    config = preset.config
    if quick:
        config = EvolutionConfig.from_dict({**config.to_dict(), **preset.quick})
    return apply_overrides(config, overrides or [])
