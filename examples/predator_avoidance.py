"""Predator avoidance (paper §3.2): do evolved CTRNNs escape two pursuers while avoiding static
obstacles, better than a random network and a hand-written escape rule, in the world they
trained in and in one they never saw?

Each seed runs the ``predator-avoidance`` preset (``dnnevo presets``; change it with ``--set
key=value``) on :class:`dnnevo.robots.Pursuit`: its champion is the network that did best on the
run's validation set. Every champion is then judged on ``--fresh`` fresh episodes drawn from a
seed that no run used (``FRESH_SEED``, ``purpose="evaluate"``), on the same episodes as two
baselines, all over the same sensors:

- **random networks**: ``--random`` networks drawn as a first generation is, pooled;
- **the escape rule** (:func:`dnnevo.robots.pursuit.escape`): away from the pursuers, away from
  near obstacles.

Each champion is also judged, on fresh episodes again,

- **in transfer** (:data:`dnnevo.robots.pursuit.TRANSFER`): another room and boxes, faster and
  sharper-turning pursuers, noise on both sensors; the baselines too;
- **with lost echoes** (``LOST_ECHOES``): the training world with a sonar whose oblique echoes
  are lost, as a real sonar's are; the baselines too;
- **at half the step**: the world's step and the network's Euler step both halved (twice the
  steps, the same starts), so that a behaviour that lives in the step's error shows itself::

    python examples/predator_avoidance.py --seeds 10 --workers 2 \\
        --figure docs/img/predator-avoidance.png --animation docs/img/predator-avoidance.gif

prints one row per seed (escapes of the fresh episodes with their 95% Wilson interval, mean
return, whether the champion meets the task's success rule, escapes in the transfer world, with
lost echoes and at half the step, seconds), then the summary: seeds whose champions meet the rule, pooled rates
of the champions and of the baselines, and seeds whose champion beats each baseline with
intervals apart. ``--figure`` and ``--animation`` draw the best seed's champion in the first
fresh episode it escapes (``--episode E`` for another), and ``--champions DIR`` saves every
champion; ``--draw NETWORK`` draws a saved champion without evolving anything.

Which of the transfer world's changes costs the champions their escapes? ``--ablation DIR``
evolves nothing: it judges the champions saved in ``DIR`` (``seed-0.json`` ..., one per
``--seeds``) and the two baselines on the same fresh episodes in worlds that each make part of
the transfer world's changes (:data:`dnnevo.robots.pursuit.TRANSFER_FACTORS`: the room, the
pursuers, the sensors' noise), one alone or all but one, beside the training and the transfer
world::

    python examples/predator_avoidance.py --ablation runs/predator-avoidance-champions

prints each seed's escapes world by world, then one row per world: the champions' escapes
pooled and seed by seed, the baselines', and how many champions beat each baseline.
"""

from __future__ import annotations

import argparse
import shlex
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

import dnnevo
from dnnevo import plot, presets
from dnnevo.closedloop import ClosedLoop, named, rollout
from dnnevo.config import EvolutionConfig
from dnnevo.evaluation.stats import wilson
from dnnevo.experiments import examples
from dnnevo.robots import Pursuit
from dnnevo.robots.pursuit import TRANSFER, TRANSFER_FACTORS, drive, escape, transfer_part
from dnnevo.runs import save_figure

PRESET = "predator-avoidance"
FRESH_SEED = 1_000_003
"""The seed of the fresh episodes: far above any seed a run here uses."""

LOST_ECHOES = {"specular_max_incidence_deg": 70.0}
"""A harsher sonar, alone in the training world: a ray that meets a surface more than 70
degrees from its normal is lost (reads nothing), as a real sonar's specular reflections are."""


def _loop(env: Pursuit, cfg: EvolutionConfig, *, finer: int = 1) -> ClosedLoop:
    """``env`` as the run integrates it; with ``finer`` > 1, the network's step ``finer`` times
    shorter for a world stepped as many times more often (``env`` made so)."""
    i = cfg.integrator
    return ClosedLoop(env, episodes=1, max_steps=env.steps, dt=i.dt / finer, substeps=i.substeps,
                      method=i.method)


def worlds(cfg: EvolutionConfig) -> dict[str, ClosedLoop]:
    """The judged worlds: the run's (``trained``), the transfer world and the run's at half the
    step, and the training world with :data:`LOST_ECHOES`; each a closed loop integrated as the
    run was."""
    steps = int(cfg.task_params["max_steps"])
    dt = Pursuit().settings["dt"]
    return {"trained": _loop(Pursuit(steps=steps), cfg),
            "transfer": _loop(Pursuit(**TRANSFER, steps=steps), cfg),
            "lost echoes": _loop(Pursuit(sonar=LOST_ECHOES, steps=steps), cfg),
            "half step": _loop(Pursuit(steps=2 * steps, dt=dt / 2), cfg, finer=2)}


def _factors(factors: Sequence[str]) -> str:
    """What ``factors`` of the transfer world change, in words, from :data:`TRANSFER`."""
    t = TRANSFER
    said = {"room": f"room ({t['world']['room'][0]:g} m x {t['world']['room'][1]:g} m, "
                    f"{len(t['world']['boxes'])} boxes)",
            "pursuers": f"pursuers ({t['pursuers']['speed']:g} m/s, {t['pursuers']['max_turn_rate']:g} rad/s)",
            "noise": f"noise (sonar {100 * t['sonar']['noise_sd']:g} cm, pursuer sensor "
                     f"{100 * t['sector_noise_sd']:g} cm)"}
    return " + ".join(said[f] for f in factors) if factors else "nothing"


def ablation_worlds(cfg: EvolutionConfig) -> dict[str, tuple[str, ClosedLoop]]:
    """The worlds of ``--ablation``, each with what it changes of the training world: the
    training world, each of :data:`TRANSFER_FACTORS` alone, the transfer world without each
    one, and the transfer world; each a closed loop integrated as the run was."""
    steps = int(cfg.task_params["max_steps"])
    names = list(TRANSFER_FACTORS)
    parts = {"training world": [], **{f"{f} only": [f] for f in names},
             **{f"all but the {f}": [g for g in names if g != f] for f in names}, "transfer world": names}
    return {world: (_factors(factors), _loop(Pursuit(**transfer_part(*factors), steps=steps), cfg))
            for world, factors in parts.items()}


def judge(network: dnnevo.Network, loops: dict[str, ClosedLoop], fresh: int) -> dict[str, dict[str, Any]]:
    """``network``'s escapes of ``fresh`` fresh episodes in each world of ``loops``."""
    out: dict[str, dict[str, Any]] = {}
    for name, loop in loops.items():
        ok, threshold, judged = loop.judged(network, fresh, FRESH_SEED, "evaluate")
        out[name] = {"successes": int(ok.sum()), "episodes": len(ok), "meets": bool(ok.mean() >= threshold),
                     "return": float(judged.returns.mean())}
    return out


def one_seed(seed: int, overrides: Sequence[str], fresh: int) -> dict[str, Any]:
    """Evolves one seed and judges its champion on fresh episodes in every world."""
    started = time.perf_counter()
    cfg = presets.get(PRESET, overrides=list(overrides))
    fitness = named.closed_loop(cfg)
    result = dnnevo.evolve(fitness, cfg, seed=seed, progress=False)
    if result.interrupted:  # Ctrl-C or SIGTERM stops evolve after a generation; stop here too
        raise KeyboardInterrupt
    out: dict[str, Any] = {"seed": seed, "network": result.best, **judge(result.best, worlds(cfg), fresh)}
    out["seconds"] = time.perf_counter() - started
    return out


def saved_seed(seed: int, directory: Path, overrides: Sequence[str], fresh: int) -> dict[str, Any]:
    """Judges the champion saved as ``directory/seed-N.json`` in every world of the ablation."""
    cfg = presets.get(PRESET, overrides=list(overrides))
    loops = {name: loop for name, (_, loop) in ablation_worlds(cfg).items()}
    return {"seed": seed, **judge(dnnevo.Network.load(directory / f"seed-{seed}.json"), loops, fresh)}


def baselines(cfg: EvolutionConfig, fresh: int, randoms: int, loops: dict[str, ClosedLoop] | None = None
              ) -> dict[str, dict[str, dict[str, int]]]:
    """The escape rule's and ``randoms`` random networks' (pooled) escapes on the fresh
    episodes of each world (of ``loops``, by default :func:`worlds`)."""
    nets = [dnnevo.Network.random(cfg.size, cfg.n_inputs, seed=FRESH_SEED + k) for k in range(randoms)]
    out: dict[str, dict[str, dict[str, int]]] = {"escape rule": {}, "random networks": {}}
    for name, loop in (worlds(cfg) if loops is None else loops).items():
        env = loop.env
        assert isinstance(env, Pursuit)
        r = drive(escape(env), env, episodes=fresh, max_steps=env.steps, seed=FRESH_SEED, purpose="evaluate")
        ok = env.success(r.returns.ravel(), r.lengths.ravel())
        out["escape rule"][name] = {"successes": int(ok.sum()), "episodes": len(ok)}
        i = cfg.integrator
        finer = 2 if name == "half step" else 1
        r = rollout(nets, env, episodes=fresh, max_steps=env.steps, dt=i.dt / finer, substeps=i.substeps,
                    method=i.method, seed=FRESH_SEED, purpose="evaluate")
        ok = env.success(r.returns.ravel(), r.lengths.ravel())
        out["random networks"][name] = {"successes": int(ok.sum()), "episodes": len(ok)}
    return out


def pct(x: float) -> str:
    """A percentage, whole unless that would hide a fraction of a percent from 0 or 100."""
    return f"{x:.1%}" if 0 < x < 0.01 or 0.99 < x < 1 else f"{x:.0%}"


def rate(k: int, n: int) -> str:
    """``k/n (rate, lo-hi)`` with the 95% Wilson interval."""
    lo, hi = wilson(k, n)
    return f"{k}/{n} ({pct(k / n)}, {pct(lo)}-{pct(hi)})"


def beats(a: dict[str, int], b: dict[str, int]) -> bool:
    """Whether ``a``'s escape rate is above ``b``'s with their 95% intervals apart."""
    return wilson(a["successes"], a["episodes"])[0] > wilson(b["successes"], b["episodes"])[1]


def kept(row: dict[str, Any]) -> bool:
    """Whether the champion's escapes at half the step lie within the 95% interval of its
    escapes at the run's step (on the same starts)."""
    lo, hi = wilson(row["trained"]["successes"], row["trained"]["episodes"])
    half = row["half step"]
    return lo <= half["successes"] / half["episodes"] <= hi


def summarize(rows: list[dict[str, Any]], base: dict[str, dict[str, dict[str, int]]]) -> list[str]:
    """The summary lines: counts with their intervals."""
    n = len(rows)
    lines = []
    meets = sum(r["trained"]["meets"] for r in rows)
    lo, hi = wilson(meets, n)
    lines.append(f"champions that meet the success rule ({Pursuit.success_rate:.0%} of fresh episodes "
                 f"escaped): {meets} of {n} seeds (95% interval {lo:.0%}-{hi:.0%})")
    for world, where in (("trained", "in the training world"), ("transfer", "in the transfer world"),
                         ("lost echoes", "with lost echoes")):
        pooled = {k: sum(r[world][k] for r in rows) for k in ("successes", "episodes")}
        parts = [f"champions {rate(pooled['successes'], pooled['episodes'])}"]
        parts += [f"{name} {rate(b[world]['successes'], b[world]['episodes'])}" for name, b in base.items()]
        lines.append(f"fresh episodes escaped {where}, pooled: " + "; ".join(parts))
        for name, b in base.items():
            k = sum(beats(r[world], b[world]) for r in rows)
            lo, hi = wilson(k, n)
            lines.append(f"seeds whose champion beats the {name} {where} (95% intervals apart): "
                         f"{k} of {n} ({lo:.0%}-{hi:.0%})")
    k = sum(kept(r) for r in rows)
    lo, hi = wilson(k, n)
    lines.append(f"seeds whose champion keeps its escape rate at half the step (within its 95% "
                 f"interval at the run's step): {k} of {n} ({lo:.0%}-{hi:.0%})")
    return lines


def _seeds(seeds: list[int]) -> str:
    """``seed 0``, ``seeds 0-9`` or ``seeds 0, 2, 5``."""
    if len(seeds) == 1:
        return f"seed {seeds[0]}"
    run = seeds == list(range(seeds[0], seeds[0] + len(seeds)))
    return f"seeds {seeds[0]}-{seeds[-1]}" if run else "seeds " + ", ".join(map(str, seeds))


def ablation_table(rows: list[dict[str, Any]], base: dict[str, dict[str, dict[str, int]]],
                   changes: dict[str, str]) -> tuple[list[str], list[list[str]], list[str]]:
    """``--ablation``'s columns, one row per world of ``changes`` (what each changes) and the
    summary lines."""
    n = len(rows)

    def count(k: int) -> str:
        lo, hi = wilson(k, n)
        return f"{k} of {n} ({lo:.0%}-{hi:.0%})"

    table, pooled = [], {}
    for world, change in changes.items():
        pooled[world] = {k: sum(r[world][k] for r in rows) for k in ("successes", "episodes")}
        table.append([world, change, rate(pooled[world]["successes"], pooled[world]["episodes"]),
                      " ".join(str(r[world]["successes"]) for r in rows),
                      *(rate(b[world]["successes"], b[world]["episodes"]) for b in base.values()),
                      *(count(sum(beats(r[world], b[world]) for r in rows)) for b in base.values())])
    fresh = rows[0]["training world"]["episodes"]
    columns = ["world", "changed from the training world", "champions, pooled (95% interval)",
               f"champions, seed by seed ({_seeds([r['seed'] for r in rows])}, of {fresh} each)",
               *(f"{name}{', pooled' if name == 'random networks' else ''}" for name in base),
               *(f"champions that beat the {name}" for name in base)]
    home = pooled["training world"]
    lo_home = wilson(home["successes"], home["episodes"])[0]
    others = [w for w in changes if w != "training world"]
    lines = [f"pooled escapes the champions gain (+) or lose (-) against the training world's "
             f"{home['successes']}/{home['episodes']}: "
             + "; ".join(f"{w} {pooled[w]['successes'] - home['successes']:+d}" for w in others),
             "worlds where the champions' pooled rate is below the training world's (95% intervals apart): "
             + (", ".join(w for w in others if wilson(pooled[w]["successes"], pooled[w]["episodes"])[1] < lo_home)
                or "none")]
    return columns, table, lines


class Traced(Pursuit):
    """:class:`Pursuit` keeping every step's robot and pursuer poses, row by row."""

    def reset(self, episodes: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        obs = super().reset(episodes, rng)
        self.trace = [(self.fleet.poses, self.fleet.pursuers)]
        return obs

    def step(self, rates: np.ndarray, active: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        out = super().step(rates, active)
        self.trace.append((self.fleet.poses, self.fleet.pursuers))
        return out


@dataclass
class Shown:
    """One fresh episode of a champion, to draw."""

    label: str
    """Whose champion, for the title."""
    episode: int
    robot: np.ndarray
    """The robot's poses, (T + 1, 3)."""
    chasers: np.ndarray
    """The pursuers' poses, (T + 1, K, 3)."""
    caught: bool
    contact_steps: int
    env: Pursuit

    @property
    def title(self) -> str:
        dt = self.env.settings["dt"]
        seconds = (len(self.robot) - 1) * dt
        if self.caught:
            end = f"caught after {seconds:.1f} s"
        else:
            end = f"not caught in {seconds:.0f} s, touching a wall or box for {self.contact_steps * dt:.1f} s"
        return f"{self.label}, fresh episode {self.episode}: {end}"


def trace(network: dnnevo.Network, cfg: EvolutionConfig, label: str, *, episodes: int,
          episode: int | None = None) -> Shown:
    """The champion in fresh episode ``episode`` or, when None, in the first of ``episodes``
    fresh episodes that it escapes by the success rule (episode 0 if none)."""
    steps = int(cfg.task_params["max_steps"])
    env = Traced(steps=steps)
    i = cfg.integrator
    run = episodes if episode is None else episode + 1
    r = rollout([network], env, episodes=run, max_steps=steps, dt=i.dt, substeps=i.substeps, method=i.method,
                seed=FRESH_SEED, purpose="evaluate")
    if episode is None:
        ok = env.success(r.returns[0], r.lengths[0])
        episode = int(np.flatnonzero(ok)[0]) if ok.any() else 0
    t = int(r.lengths[0, episode])
    return Shown(label, episode, np.array([p[episode] for p, _ in env.trace[:t + 1]]),
                 np.array([q[episode] for _, q in env.trace[:t + 1]]), bool(env.caught[episode]),
                 int(env.contact_steps[episode]), env)


def _room(ax: Any, env: Pursuit) -> None:
    plot.plot_room(env.world, ax)
    ax.set_xticks([])
    ax.set_yticks([])


def draw_paths(path: Path, shown: Shown) -> None:
    """The top-down view: the room, the robot's and the pursuers' paths."""
    fig, ax = plot.subplots(figsize=(7, 5.6), layout="constrained")
    plot.plot_paths(shown.env.world, shown.robot, ax, pursuers=shown.chasers,
                    title=shown.title + "\n(circle: start, square: end)")
    ax.set_xticks([])
    ax.set_yticks([])
    ax.legend(loc="upper left", fontsize=8, framealpha=0.9)
    save_figure(fig, path)
    plot.close(fig)


def animate(path: Path, shown: Shown, *, every: int = 3) -> None:
    """An animated GIF of the episode (every ``every``-th step, at its own pace)."""
    from matplotlib.animation import FuncAnimation, PillowWriter
    from matplotlib.patches import Circle

    robot, chasers, env = shown.robot, shown.chasers, shown.env
    fig, ax = plot.subplots(figsize=(4.4, 3.8), layout="constrained")
    _room(ax, env)
    ax.set_title(shown.title.replace(": ", ":\n", 1), fontsize=7)
    r, pr = env.settings["robot"]["radius"], env.settings["pursuers"]["radius"]
    (trail,) = ax.plot([], [], color="tab:blue", lw=0.8, alpha=0.6)
    body = ax.add_patch(Circle(tuple(robot[0, :2]), r, color="tab:blue"))
    (nose,) = ax.plot([], [], color="w", lw=1.5)
    chaser_bodies = [ax.add_patch(Circle(tuple(chasers[0, k, :2]), pr, color="tab:red"))
                     for k in range(chasers.shape[1])]
    clock = ax.text(0.02, 0.97, "", transform=ax.transAxes, va="top", fontsize=7)
    frames = list(range(0, len(robot), every))
    if frames[-1] != len(robot) - 1:
        frames.append(len(robot) - 1)

    def update(t: int) -> list[Any]:
        x, y, h = robot[t]
        trail.set_data(robot[:t + 1, 0], robot[:t + 1, 1])
        body.center = (x, y)
        nose.set_data([x, x + r * np.cos(h)], [y, y + r * np.sin(h)])
        for k, c in enumerate(chaser_bodies):
            c.center = tuple(chasers[t, k, :2])
        clock.set_text(f"{t * env.settings['dt']:.1f} s")
        return [trail, body, nose, *chaser_bodies, clock]

    anim = FuncAnimation(fig, update, frames=frames, blit=False)
    step = env.settings["dt"] * every
    path.parent.mkdir(parents=True, exist_ok=True)
    anim.save(path, writer=PillowWriter(fps=round(1 / step)), dpi=70)
    plot.close(fig)


def _positive(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number >= 1")
    return value


def _episode(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = -1
    if value < 0:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number >= 0")
    return value


def main(argv: Sequence[str] | None = None) -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--seeds", type=_positive, default=10, help="seeds 0 .. N-1 (default 10)")
    p.add_argument("--workers", type=_positive, default=1,
                   help="run this many seeds at once, each in a process of its own (default 1)")
    p.add_argument("--fresh", type=_positive, default=200, help="fresh episodes per world (default 200)")
    p.add_argument("--random", type=_positive, default=10, help="random networks in the baseline (default 10)")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="override a setting of the preset (repeatable), as for dnnevo run")
    p.add_argument("--figure", type=Path, help="draw the best seed's paths here (PNG)")
    p.add_argument("--animation", type=Path, help="animate the best seed's episode here (GIF)")
    p.add_argument("--episode", type=_episode, metavar="E",
                   help="draw fresh episode E (default: the first the champion escapes)")
    p.add_argument("--draw", type=Path, metavar="NETWORK",
                   help="evolve nothing: draw this saved champion's episode (--figure, --animation)")
    p.add_argument("--champions", type=Path, metavar="DIR",
                   help="save each seed's champion here, as seed-N.json")
    p.add_argument("--ablation", type=Path, metavar="DIR",
                   help="evolve nothing: judge the champions saved in DIR (seed-N.json for each of --seeds) "
                        "in worlds with part of the transfer world's changes "
                        "(docs/results/examples/predator-avoidance-ablation.json)")
    p.add_argument("--record", type=Path, metavar="JSON",
                   help="also write the table here, for the docs "
                        "(docs/results/examples/predator-avoidance.json)")
    args = p.parse_args(argv)
    cfg = presets.get(PRESET, overrides=args.set)  # a bad --set fails here, before any run
    if args.draw:
        if not (args.figure or args.animation):
            p.error("--draw needs --figure or --animation")
        network = dnnevo.Network.load(args.draw)
        draw(trace(network, cfg, f"champion {args.draw.stem}", episodes=args.fresh, episode=args.episode),
             args.figure, args.animation)
        return
    if args.ablation:
        if args.figure or args.animation or args.champions:
            p.error("--ablation judges saved champions; it draws and saves nothing")
        missing = [f"seed-{s}.json" for s in range(args.seeds) if not (args.ablation / f"seed-{s}.json").is_file()]
        if missing:
            p.error(f"--ablation: {args.ablation} has no {missing[0]} (save champions with --champions DIR)")
        ablation(cfg, args, argv)
        return
    rows = []
    print("seed  fresh episodes escaped    mean return  rule  transfer world            "
          "lost echoes               half step                 seconds")
    for r in examples.seeds_run(one_seed, args.seeds, args.workers, args.set, args.fresh):
        rows.append(r)
        if args.champions:
            args.champions.mkdir(parents=True, exist_ok=True)
            r["network"].save(args.champions / f"seed-{r['seed']}.json")
        cells = [rate(r[w]["successes"], r[w]["episodes"]) for w in ("transfer", "lost echoes", "half step")]
        print(f"{r['seed']:4d}  {rate(r['trained']['successes'], r['trained']['episodes']):24}  "
              f"{r['trained']['return']:11.3f}  {'met' if r['trained']['meets'] else 'no':4}  "
              + "".join(f"{c:26}" for c in cells) + f"{r['seconds']:7.0f}", flush=True)
    base = baselines(cfg, args.fresh, args.random)
    summary = summarize(rows, base)
    print("\n".join(summary))
    if args.record:
        given = list(sys.argv[1:] if argv is None else argv)
        if "--record" in given:  # the command that makes the table, without where it was written
            del given[given.index("--record"):given.index("--record") + 2]
        given = [a for a in given if not a.startswith("--record=")]
        table = [[r["seed"], rate(r["trained"]["successes"], r["trained"]["episodes"]),
                  f"{r['trained']['return']:.3f}", "yes" if r["trained"]["meets"] else "no",
                  *(rate(r[w]["successes"], r[w]["episodes"]) for w in ("transfer", "lost echoes", "half step"))]
                 for r in rows]
        examples.write(args.record, command=shlex.join(["python", "examples/predator_avoidance.py", *given]),
                       columns=["seed", "fresh episodes escaped (95% interval)", "mean return",
                                f"meets the rule ({Pursuit.success_rate:.0%})", "transfer world",
                                "lost echoes", "half step"], rows=table, summary=summary)
    if args.figure or args.animation:
        best = max(rows, key=lambda r: (r["trained"]["successes"], r["trained"]["return"]))
        draw(trace(best["network"], cfg, f"seed {best['seed']}'s champion", episodes=args.fresh,
                   episode=args.episode), args.figure, args.animation)


def ablation(cfg: EvolutionConfig, args: argparse.Namespace, argv: Sequence[str] | None) -> None:
    """``--ablation``: each saved champion's escapes world by world as it comes, then the table
    with the baselines and, with ``--record``, the record."""
    changes = {world: change for world, (change, _) in ablation_worlds(cfg).items()}
    rows = []
    print("seed  " + "  ".join(changes))
    for r in examples.seeds_run(saved_seed, args.seeds, args.workers, args.ablation, args.set, args.fresh):
        rows.append(r)
        print(f"{r['seed']:4d}  " + "  ".join(f"{r[w]['successes']}/{r[w]['episodes']}".ljust(len(w))
                                              for w in changes), flush=True)
    loops = {world: loop for world, (_, loop) in ablation_worlds(cfg).items()}
    columns, table, summary = ablation_table(rows, baselines(cfg, args.fresh, args.random, loops), changes)
    print()
    for row in table:
        print(" | ".join(f"{c}: {v}" for c, v in zip(columns, row) if c != columns[1]))
    print("\n".join(summary))
    if args.record:
        examples.write(args.record, command=examples.command("examples/predator_avoidance.py", argv),
                       columns=columns, rows=table, summary=summary)


def draw(shown: Shown, figure: Path | None, animation: Path | None) -> None:
    """The figure and the animation of one episode, each when asked."""
    if figure:
        draw_paths(figure, shown)
    if animation:
        animate(animation, shown)


if __name__ == "__main__":
    main()
