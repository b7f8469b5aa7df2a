"""What ``dnnevo reproduce`` runs: every experiment of the paper, over seeds, as a graph of jobs.

An :class:`Experiment` is one row of the paper-vs-dnnevo table: an evolution of a preset (with
its overrides, and seeded from other experiments' runs of the same seed where the paper does
that), a test of other experiments' champions (the landmark robot-like test and held-out
worlds, the integrated navigation system), or a test of a network designed by hand (reactive navigation's, with and
without its detectors). A :class:`Job` is one experiment at one seed; it needs the jobs of the same
seed that its experiment needs, and nothing else, so seeds never wait for each other.

>>> [job.id for job in jobs([0], only=["sequence"])][:3]
['sequence-1bit/seed-0', 'sequence-2bit-alternating/seed-0', 'sequence-2bit-paper/seed-0']
>>> job = next(j for j in jobs([3]) if j.experiment == "nav1d-system")
>>> job.needs
('nav1d-classifier/seed-3', 'nav1d-far/seed-3', 'nav1d-near/seed-3')

A family's experiments may need another family's: the ablation of the 2-bit route composes the
sequence family's 1-bit and alternating runs. Those jobs are then planned with it, so that a
reproduction runs them, or finds them done in its folder and uses them:

>>> [job.id for job in jobs([0], only=["ablation"])][:3]
['sequence-1bit/seed-0', 'sequence-2bit-alternating/seed-0', 'ablation-2bit-no-spare/seed-0']
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

from dnnevo.errors import ConfigError, did_you_mean

__all__ = ["FAMILIES", "PAPER_FAMILIES", "EXPERIMENTS", "EVOLVE", "ROBOT_LIKE", "HELD_OUT", "SYSTEM", "HAND_DESIGNED",
           "Experiment", "Job", "jobs", "picked", "experiment"]

PAPER_FAMILIES = ("landmark", "robots", "nav1d", "sequence")
"""The paper's experiment families, in the paper's order (``robots`` is §3.2's other robot
tasks): what ``dnnevo reproduce`` runs unless ``--only`` says otherwise."""

PRECISION_FAMILY = "precision"
"""The family of the experiments repeated in single precision."""

F32_SUFFIX = "-f32"
"""What an f32 experiment's name adds to the name of the f64 experiment it repeats."""

FAMILIES = (*PAPER_FAMILIES, "ablation", PRECISION_FAMILY, "classic")
"""Every family; ``--only`` picks among them. ``ablation`` is the working incremental 2-bit route
(``sequence-2bit``) with one of its departures from the paper removed at a time (issue 47);
``precision`` is the 1-bit, 3-bit, landmark and navigation experiments again in single precision
(``precision = "f32"``), whose success counts are compared with the f64 ones (issue 49);
``classic`` is the field's benchmarks written as Python tasks (:mod:`dnnevo.classic`), which the
paper does not have."""

EVOLVE, ROBOT_LIKE, HELD_OUT, SYSTEM, HAND_DESIGNED = ("evolve", "robot-like", "held-out-worlds", "nav1d-system",
                                                      "hand-designed")
"""The kinds of job: an evolution run, the landmark robot-like test, the landmark held-out worlds
(with each world's bounds), the integrated system, the hand-designed reactive navigator on fresh
starts (nothing evolved)."""

_WORLDS_PAPER = ("§3: the real robot right in 17 of 20 trials (10/10 and 7/10); the held-out worlds are not "
                 "in the paper")
_WORLDS_NOTE = ("judged in the training world and in the first set of held-out worlds of "
                "dnnevo.tasks.landmark_worlds (another wall follower, another sonar, a bigger room with the "
                "landmark off-centre; issue 47), which no run trains or selects on, on the trials "
                "examples/landmark_transfer.py draws, beside each world's bounds: a threshold rule and a "
                "logistic-regression observer fitted on that world, and the observer fitted on the other "
                "two held-out worlds (docs/landmark.md)")
_SECOND_NOTE = ("judged in the training world and in the second set of held-out worlds of "
                "dnnevo.tasks.landmark_worlds (a weaving wall follower, a lobed sonar that loses readings, "
                "other boxes; issue 47), fixed before any landmark-wide run was judged, beside each world's "
                "bounds (docs/landmark.md)")


@dataclass(frozen=True)
class Experiment:
    """One experiment of the paper."""

    name: str
    family: str
    kind: str
    paper: str
    """What the paper reports for it."""
    preset: str | None = None
    """For an evolution: the preset it runs."""
    overrides: tuple[str, ...] = ()
    """For an evolution: ``key=value`` overrides of the preset."""
    generations: int | None = None
    """For an evolution: generations other than the preset's (not in a quick reproduction)."""
    needs: tuple[str, ...] = ()
    """The experiments whose run of the same seed this one uses: for an evolution, the runs whose
    champions seed its first population (composed, the first one's output neuron staying the
    output); for a test, the runs it tests."""
    seed_populations: bool = False
    """For an evolution with needs: compose the needed runs' last populations member by member,
    not their champions (``--seed-populations``)."""
    spare_neurons: int = 0
    """For an evolution with needs: unconnected random neurons composed into every seed
    (``--spare-neurons``)."""
    worlds: str = "first"
    """For a held-out-worlds test: the set of held-out worlds it judges in
    (``dnnevo.tasks.landmark_worlds.SETS``)."""
    note: str = ""
    """How dnnevo reads the paper here, for the report."""


_CHAINED = ("task_params.chained=true", "task_params.reinforcement_input=true", "n_inputs=2")

# The working incremental 2-bit route (sequence-2bit: member-by-member composites of the two
# runs' last populations and 6 spare neurons, 16 neurons, the score clamped once per evaluation,
# rank selection, 20 elites, 128 validation trials per target) with one departure from the paper
# removed, and last with the two that mattered least removed together: (name, overrides of the
# preset, --seed-populations, --spare-neurons, what is removed).
_ABLATION: tuple[tuple[str, tuple[str, ...], bool, int, str], ...] = (
    ("no-spare", ("size=10",), True, 0,
     "its 6 spare neurons: the composites alone, 10 neurons as in the paper"),
    ("clamp-trial", ("task_params.clamp=trial",), True, 6,
     "the score clamped once per evaluation: it is clamped per trial, the paper's formula"),
    ("proportional", ("selection=proportional",), True, 6,
     "rank selection: selection is proportional to fitness, the paper's"),
    ("no-elites", ("elitism=0",), True, 6,
     "its 20 elites: no network is kept unchanged, as in the paper"),
    ("validation-32", ("task_params.validation_trials=32",), True, 6,
     "its 128 validation trials per target: champions are chosen on the task's default 32"),
    ("champions", (), False, 6,
     "composing the two runs' last populations member by member: their champions are composed (with "
     "6 spare neurons) and the first population is that composite and its mutants, as in the paper"),
    ("smallest", ("selection=proportional", "task_params.validation_trials=32"), True, 6,
     "rank selection and its 128 validation trials together, the two departures whose removal lost "
     "least: the smallest departure from the paper that the ablation points to"),
)

# The experiments run again in single precision, with the seeds and the fresh trials of their f64
# runs, so that their success counts can be compared (issue 49).
_F32 = ("landmark", "nav1d-classifier", "nav1d-far", "nav1d-near", "sequence-1bit", "sequence-3bit")


def _f32(name: str) -> str:
    return f"{name}{F32_SUFFIX}"


EXPERIMENTS: tuple[Experiment, ...] = (
    Experiment("landmark", "landmark", EVOLVE, "§3: solved by generation 15 in simulation",
               preset="landmark"),
    Experiment("landmark-robot", "landmark", ROBOT_LIKE,
               "§3: the real robot right in 17 of 20 trials (10/10 and 7/10)", needs=("landmark",),
               note="a simulated stand-in for the real robot: sonar noise, specular misses and a "
                    "jittered room, none of which training saw"),
    Experiment("landmark-worlds", "landmark", HELD_OUT, _WORLDS_PAPER, needs=("landmark",),
               note=f"the champion of landmark {_WORLDS_NOTE}"),
    Experiment("landmark-robust", "landmark", EVOLVE, "not in the paper", preset="landmark-robust",
               note="trained on varied trials (robot speed, landmark pose and size, sonar), so that "
                    "the champion transfers to the robot-like test"),
    Experiment("landmark-robust-robot", "landmark", ROBOT_LIKE,
               "§3: the real robot right in 17 of 20 trials (10/10 and 7/10)",
               needs=("landmark-robust",),
               note="landmark-robust's champion on the same robot-like stand-in as landmark-robot"),
    Experiment("landmark-robust-worlds", "landmark", HELD_OUT, _WORLDS_PAPER, needs=("landmark-robust",),
               note=f"the champion of landmark-robust {_WORLDS_NOTE}"),
    Experiment("landmark-robust-second-worlds", "landmark", HELD_OUT, _WORLDS_PAPER,
               needs=("landmark-robust",), worlds="second",
               note=f"the champion of landmark-robust {_SECOND_NOTE}; the baseline for landmark-wide"),
    Experiment("landmark-wide", "landmark", EVOLVE, "not in the paper", preset="landmark-wide",
               note="trained on a wide envelope (robot speed and wall distance, sonar cone and axis, room "
                    "size, landmark pose and size), as far as a real robot may differ, so that the champion "
                    "transfers to worlds that differ in kind"),
    Experiment("landmark-wide-worlds", "landmark", HELD_OUT, _WORLDS_PAPER, needs=("landmark-wide",),
               worlds="second", note=f"the champion of landmark-wide {_SECOND_NOTE}"),
    Experiment("landmark-wide-first-worlds", "landmark", HELD_OUT, _WORLDS_PAPER, needs=("landmark-wide",),
               note="the champion of landmark-wide in the first set of held-out worlds, part of which its "
                    "training envelope now reaches (the sonar's cone and axis, part of the follower's speed and "
                    "distance and of the room's size): a weaker transfer test there than landmark-robust's"),
    Experiment("predator-avoidance", "robots", EVOLVE,
               "§3.2: evolved to escape moving pursuers while avoiding static obstacles (not "
               "quantified)", preset="predator-avoidance",
               note="the task's arena, pursuers, sensors, fitness and success rule are dnnevo's "
                    "(docs/paper.md); a task written in Python (dnnevo.robots.pursuit)"),
    Experiment("reactive-navigation-hand", "robots", HAND_DESIGNED,
               "§3.2: a hand-designed network with static and cyclic detectors reaches a goal "
               "(not quantified; not evolved)",
               note="the paper's own experiment: nothing is evolved; dnnevo's hand-designed network "
                    "(dnnevo/robots/data/navigator.json) in an open room, a U-shaped trap and a "
                    "cul-de-sac, from the same fresh starts with and without the detectors "
                    "(docs/reactive-navigation.md)"),
    Experiment("reactive-navigation", "robots", EVOLVE,
               "not in the paper (§3.2's network is hand-designed)", preset="reactive-navigation",
               note="dnnevo's evolved comparison, which the paper does not make: networks evolved "
                    "to reach a goal past a U-shaped trap, without detectors; the paper's own "
                    "experiment is reactive-navigation-hand"),
    Experiment("nav1d-classifier", "nav1d", EVOLVE, "§4.2: solved at generation 5",
               preset="nav1d-classifier"),
    Experiment("nav1d-far", "nav1d", EVOLVE, "§4.2: solved at generation 0", preset="nav1d-far"),
    Experiment("nav1d-near", "nav1d", EVOLVE, "§4.2: solved at generation 2", preset="nav1d-near"),
    Experiment("nav1d-system", "nav1d", SYSTEM, "§4.2: works in all four environments",
               needs=("nav1d-classifier", "nav1d-far", "nav1d-near"),
               note="the classifier drives trial 1, its answer picks the far or near network for "
                    "trials 2-5, states persist"),
    Experiment("nav1d-far-chained", "nav1d", EVOLVE, "not in the paper", preset="nav1d-far",
               overrides=_CHAINED, generations=100,
               note="the far goal seeker evolved on chains of trials without a reset, with the "
                    "reinforcement sensor, so that it keeps working with persisting states"),
    Experiment("nav1d-near-chained", "nav1d", EVOLVE, "not in the paper", preset="nav1d-near",
               overrides=_CHAINED, generations=100,
               note="the near goal seeker, as nav1d-far-chained"),
    Experiment("nav1d-system-chained", "nav1d", SYSTEM, "not in the paper",
               needs=("nav1d-classifier", "nav1d-far-chained", "nav1d-near-chained"),
               note="the integrated system with the chained goal seekers"),
    Experiment("nav1d-single", "nav1d", EVOLVE, "§4.2: failed (not quantified)",
               preset="nav1d-single"),
    Experiment("nav1d-single-incremental", "nav1d", EVOLVE, "not in the paper",
               preset="nav1d-single-incremental", needs=("nav1d-near-chained",), spare_neurons=3,
               note="one network for the whole task, seeded from the chained near seeker and 3 "
                    "unconnected random neurons, paid for reaching the goal in landmark-near first "
                    "trials (near_first_weight 0.5)"),
    Experiment("sequence-1bit", "sequence", EVOLVE, "§5.2: success in 2 of 2 runs",
               preset="sequence-1bit"),
    Experiment("sequence-2bit-alternating", "sequence", EVOLVE, "§5.3: success (not quantified)",
               preset="sequence-2bit-alternating"),
    Experiment("sequence-2bit-paper", "sequence", EVOLVE, "§5.3: success in 2 of 2 runs",
               preset="sequence-2bit-paper", needs=("sequence-1bit", "sequence-2bit-alternating"),
               note="the paper's incremental route read literally: the first population is the "
                    "composite of the two champions (no cross weights) and its mutants"),
    Experiment("sequence-2bit-direct", "sequence", EVOLVE, "§5.3: failed (not quantified)",
               preset="sequence-2bit-direct"),
    Experiment("sequence-2bit-direct16", "sequence", EVOLVE, "not in the paper",
               preset="sequence-2bit-direct16",
               note="the direct route with 16 neurons, rank selection and 20 elites"),
    Experiment("sequence-2bit-direct16-clamp-eval", "sequence", EVOLVE, "not in the paper",
               preset="sequence-2bit-direct16-clamp-eval",
               note="sequence-2bit-direct16 with the score clamped once per evaluation, not per "
                    "trial"),
    Experiment("sequence-2bit", "sequence", EVOLVE, "§5.3: success in 2 of 2 runs",
               preset="sequence-2bit", needs=("sequence-1bit", "sequence-2bit-alternating"),
               seed_populations=True, spare_neurons=6,
               note="the paper's incremental route as it works here, with "
                    "sequence-2bit-direct16-clamp-eval's GA (not the paper's): member i of "
                    "the first population composes member i of the two runs' last populations and "
                    "6 unconnected random neurons; champions validated on 128 trials per target "
                    "and at dt/10"),
    Experiment("sequence-3bit", "sequence", EVOLVE, "§5.4: 1 success, at generation 700",
               preset="sequence-3bit"),
    *(Experiment(f"ablation-2bit-{name}", "ablation", EVOLVE, "not in the paper", preset="sequence-2bit",
                 overrides=overrides, needs=("sequence-1bit", "sequence-2bit-alternating"),
                 seed_populations=populations, spare_neurons=spare,
                 note=f"the working route, sequence-2bit, without {removed}")
      for name, overrides, populations, spare, removed in _ABLATION),
    *(Experiment(_f32(name), PRECISION_FAMILY, EVOLVE, "not in the paper", preset=name, overrides=("precision=f32",),
                 note=f"{name} computed in single precision (precision = \"f32\"); its counts are compared "
                      f"with {name}'s, which has the same seeds and fresh trials")
      for name in _F32),
    Experiment(_f32("nav1d-system"), PRECISION_FAMILY, SYSTEM, "not in the paper",
               needs=tuple(_f32(n) for n in ("nav1d-classifier", "nav1d-far", "nav1d-near")),
               note="nav1d-system with the parts evolved in single precision, which compute in it"),
    Experiment("legged-walker", "classic", EVOLVE, "not in the paper", preset="legged-walker",
               note="Beer and Gallagher's one-legged walker, a task written in Python "
                    "(dnnevo.classic.walker)"),
    Experiment("categorical-perception", "classic", EVOLVE, "not in the paper",
               preset="categorical-perception",
               note="Beer's categorical perception, a task written in Python "
                    "(dnnevo.classic.categorical)"),
    Experiment("double-pole", "classic", EVOLVE, "not in the paper", preset="double-pole",
               note="double-pole balancing without velocities, trained on random starts, for the "
                    "preset's generations; the benchmark's own test of episodes to solve is "
                    "examples/double_pole.py"),
)
"""Every experiment, in the report's order; each one's needs come before it."""


def experiment(name: str) -> Experiment:
    """The experiment called ``name``."""
    for e in EXPERIMENTS:
        if e.name == name:
            return e
    known = [e.name for e in EXPERIMENTS]
    raise ConfigError(f"unknown experiment {name!r}{did_you_mean(name, known)}; experiments: {', '.join(known)}")


@dataclass(frozen=True)
class Job:
    """One experiment at one seed. Its folder is ``EXPERIMENT/seed-N`` under the reproduction's
    folder."""

    experiment: str
    seed: int
    needs: tuple[str, ...]
    """The ids of the jobs it needs."""

    @property
    def id(self) -> str:
        """``EXPERIMENT/seed-N``, also its folder."""
        return job_id(self.experiment, self.seed)

    @property
    def spec(self) -> Experiment:
        """Its experiment."""
        return experiment(self.experiment)


def job_id(name: str, seed: int) -> str:
    """The id (and folder) of experiment ``name`` at ``seed``."""
    return f"{name}/seed-{seed}"


def families(only: Iterable[str] | None) -> tuple[str, ...]:
    """The families ``--only`` names (the paper's when None), checked."""
    if only is None:
        return PAPER_FAMILIES
    picked = tuple(dict.fromkeys(only))
    unknown = [f for f in picked if f not in FAMILIES]
    if unknown or not picked:
        raise ConfigError(f"--only {','.join(picked) or '(empty)'}: families are {', '.join(FAMILIES)}")
    return picked


def picked(only: Iterable[str] | None) -> tuple[str, ...]:
    """The families and experiments ``--only`` names (the paper's families when None), checked:
    a name is a family's or an experiment's (one that is both, as ``landmark``, is the family)."""
    if only is None:
        return PAPER_FAMILIES
    names = tuple(dict.fromkeys(only))
    known = (*FAMILIES, *(e.name for e in EXPERIMENTS))
    unknown = [n for n in names if n not in known]
    if unknown or not names:
        hint = did_you_mean(unknown[0], known) if unknown else ""
        raise ConfigError(f"--only {','.join(names) or '(empty)'}{hint}: families are {', '.join(FAMILIES)}; "
                          "an experiment's name picks that experiment alone (with what it needs)")
    return names


def jobs(seeds: Sequence[int], only: Iterable[str] | None = None) -> list[Job]:
    """The jobs of the families and experiments ``only`` names (default the paper's families) over
    ``seeds``, each after the jobs it needs, with the jobs of other families that they need.

    >>> [job.id for job in jobs([4], only=["sequence-2bit"])]
    ['sequence-1bit/seed-4', 'sequence-2bit-alternating/seed-4', 'sequence-2bit/seed-4']
    """
    chosen = picked(only)
    if not seeds or any(s < 0 for s in seeds) or len(set(seeds)) != len(seeds):
        raise ConfigError(f"seeds must be distinct and >= 0, at least one; got {list(seeds)[:10]}"
                          + (" ..." if len(seeds) > 10 else ""))
    wanted = {e.name for e in EXPERIMENTS if e.family in chosen or e.name in chosen}
    for e in reversed(EXPERIMENTS):  # needs come first, so this takes needs of needs too
        if e.name in wanted:
            wanted.update(e.needs)
    return [Job(e.name, s, tuple(job_id(n, s) for n in e.needs))
            for e in EXPERIMENTS if e.name in wanted for s in seeds]
