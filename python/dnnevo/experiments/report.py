"""The report of ``dnnevo reproduce``: ``report.md`` and a self-contained ``report.html`` (figures
embedded) in the reproduction's folder.

It holds the paper-vs-dnnevo table (success rates over seeds with their Wilson intervals, final
champions passing on fresh conditions, median first-success generations with bootstrap
intervals, step artefacts, wall times), the robot-like test's confusion matrices, the landmark
champions in the held-out worlds beside each world's bounds, the integrated
navigation system's goal rates, the hand-designed reactive navigator's arrivals with and without
its detectors, every run's figures for the first seed of each experiment, a
fitness figure over all seeds, and the machine and settings the runs ran with.

The report is made of :class:`Block` s, rendered to Markdown and to HTML by the same code, so the
two always say the same.
"""

from __future__ import annotations

import base64
import html
import math
import os
import platform
import statistics
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from dnnevo import _core, figures, plot, presets
from dnnevo.experiments import plan
from dnnevo.evaluation import stats
from dnnevo.experiments import sweep
from dnnevo.evaluation.assessment import Assessment
from dnnevo.experiments.jobs import (HAND_CONDITIONS, ROBOT_SEED_BASE, SYSTEM_TRIALS, Settings,
                                     hand_counts, world_counts, world_places)
from dnnevo.robots.navigation import WORLDS
from dnnevo.runs import RunDir, save_figure, write_atomic
from dnnevo.tasks import landmark_transfer, nav1d
from dnnevo.experiments.scheduler import Outcome

__all__ = ["Block", "build", "write", "markdown", "summary_row", "seed_table", "describe", "k_of_n", "done_results", "SUMMARY_HEADER",
           "REPORT_FILES"]

REPORT_FILES = ("report.md", "report.html")
"""The files the report is written to, in the reproduction's folder."""

FIGURES = "figures"
"""The report's own figures (fitness over seeds) go into this subfolder."""


@dataclass(frozen=True)
class Block:
    """One piece of the report: ``kind`` is ``h1``, ``h2``, ``h3``, ``p``, ``table`` (``rows``,
    the first one the header), ``img`` (``text`` the caption, ``path`` relative to the report)."""

    kind: str
    text: str = ""
    rows: tuple[tuple[str, ...], ...] = ()
    path: str = ""


def _pct(x: float) -> str:
    return f"{100 * x:.0f}%" if x in (0.0, 1.0) else f"{100 * x:.1f}%"


def k_of_n(k: int, n: int) -> str:
    """``k/n`` with its 95% Wilson interval, as every table of the report writes a count."""
    lo, hi = stats.wilson(k, n)
    return f"{k}/{n} ({_pct(lo)}-{_pct(hi)})"


def _generation(x: float) -> str:
    return "not reached" if not math.isfinite(x) else f"{x:.0f}"


def _median_wall(values: Sequence[float]) -> str:
    return f"{statistics.median(values):.0f} s" if values else "-"


def done_results(name: str, order: Sequence[plan.Job], outcomes: dict[str, Outcome]) -> dict[int, dict[str, Any]]:
    """The stored result of each seed of experiment ``name`` that is done, by seed."""
    return {j.seed: o.result for j in order if j.experiment == name
            and (o := outcomes[j.id]).status == "done" and o.result is not None}


def _runs(name: str, order: Sequence[plan.Job], outcomes: dict[str, Outcome]) -> list[sweep.SeedResult]:
    return [sweep.SeedResult.from_dict(r["run"]) for r in done_results(name, order, outcomes).values()]


def summary_row(e: plan.Experiment, order: Sequence[plan.Job], outcomes: dict[str, Outcome]) -> tuple[str, ...]:
    """``e``'s row of the paper-vs-dnnevo table (:data:`SUMMARY_HEADER`), from the results in
    ``outcomes`` alone (no run folder is read)."""
    planned = [j for j in order if j.experiment == e.name]
    done = [outcomes[j.id] for j in planned if outcomes[j.id].status == "done"]
    walls = [float(o.result["wall_s"]) for o in done if o.result is not None]
    head = (e.name, e.paper, f"{len(done)}/{len(planned)}")
    if e.kind == plan.EVOLVE:
        runs = _runs(e.name, order, outcomes)
        if not runs:
            return (*head, "-", "-", "-", "-", "-")
        s = sweep.summarize(runs)
        m = s.first_success
        median = (f"{_generation(m.median)} ({_generation(m.lo)}-{_generation(m.hi)})" if m.reached
                  else f"not reached ({m.censored} of {s.seeds} seeds never met the rule)")
        artefacts = f"{s.artefacts}/{s.checked}" if s.checked else "not checked"
        return (*head, k_of_n(s.succeeded, s.seeds), k_of_n(s.passed, s.seeds), median, artefacts,
                _median_wall([r.wall_s for r in runs]))
    if e.kind == plan.ROBOT_LIKE:
        assessments = [Assessment.from_dict(o.result["assessment"]) for o in done if o.result]
        if not assessments:
            return (*head, "-", "-", "-", "-", _median_wall(walls))
        passed = sum(a.verdict == "pass" for a in assessments)
        # The 95% rule is the ideal world's; a transfer test is judged by issue 47's goal too.
        beat = sum(landmark_transfer.meets(a.rates[-1].k, a.rates[-1].n) for a in assessments)
        text = (f"95% rule: {k_of_n(passed, len(assessments))}; right in >85% with the interval's "
                f"lower end >80%: {k_of_n(beat, len(assessments))}")
        return (*head, "-", text, "-", "-", _median_wall(walls))
    if e.kind == plan.HAND_DESIGNED:
        counts = [hand_counts(o.result) for o in done if o.result]
        return (*head, "-", _hand_pooled(counts) if counts else "-", "-", "-", _median_wall(walls))
    if e.kind == plan.HELD_OUT:
        worlds = [world_counts(o.result, e.worlds) for o in done if o.result]
        every = sum(_meets_every(w, e.worlds) for w in worlds)
        text = (f"seeds right in >85% with the interval's lower end >80% in every held-out world: "
                f"{k_of_n(every, len(worlds))}" if worlds else "-")
        return (*head, "-", text, "-", "-", _median_wall(walls))
    rates = [o.result["goal_rate"] for o in done if o.result]
    text = f"goal in {', '.join(_pct(r) for r in rates)} of trials" if rates else "-"
    return (*head, "-", text, "-", "-", _median_wall(walls))


def _meets_every(counts: dict[str, dict[str, int]], world_set: str) -> bool:
    """Whether a champion meets issue 47's goal in every held-out world of ``world_set``."""
    return all(landmark_transfer.meets(counts[w]["right"], counts[w]["n"])
               for w in landmark_transfer.held_out(world_set))


def _hand_pooled(counts: Sequence[dict[str, dict[str, tuple[int, int]]]]) -> str:
    """The hand-designed navigator's arrivals, world by world, with and without its detectors,
    pooled over seeds (each seed draws its own starts)."""
    parts = []
    for world in WORLDS:
        pooled = {c: tuple(sum(x[world][c][i] for x in counts) for i in (0, 1)) for c in HAND_CONDITIONS}
        parts.append(f"{world} {k_of_n(*pooled['with'])} / {k_of_n(*pooled['without'])}")
    return "goal reached with / without detectors: " + "; ".join(parts)


SUMMARY_HEADER = ("experiment", "paper", "runs done", "seeds meeting the rule during the run (95% interval)",
                  "final champions passing on fresh trials (95% interval)",
                  "median first-success generation (95% interval)", "step artefacts", "wall time per run (median)")


def seed_table(e: plan.Experiment, order: Sequence[plan.Job], outcomes: dict[str, Outcome]) -> Block | None:
    """``e``'s table of one row per seed, from the results in ``outcomes`` alone; None when
    ``order`` has no job of ``e``."""
    rows: list[tuple[str, ...]] = []
    for job in (j for j in order if j.experiment == e.name):
        o = outcomes[job.id]
        if o.status != "done" or o.result is None:
            rows.append((str(job.seed), o.status, o.message))
        elif e.kind == plan.EVOLVE:
            r = sweep.SeedResult.from_dict(o.result["run"])
            w = r.final.weakest
            rows.append((str(r.seed), f"{r.best_fitness:.4f} (gen {r.best_generation})",
                         "-" if r.first_success is None else str(r.first_success),
                         f"{w.name}: {w.k}/{w.n} ({_pct(w.interval[0])}-{_pct(w.interval[1])})", r.final.verdict,
                         "-" if r.step is None else f"{100 * r.step.max_change:.1f} points"
                         + (" (artefact)" if r.artefact else ""), f"{r.wall_s:.0f} s"))
        elif e.kind == plan.ROBOT_LIKE:
            a = Assessment.from_dict(o.result["assessment"])
            overall = a.rates[-1]
            (p, q), (s, t) = a.details["confusion"]
            rows.append((str(job.seed), f"{overall.k}/{overall.n} ({_pct(overall.interval[0])}-"
                         f"{_pct(overall.interval[1])})", f"[[{p}, {q}], [{s}, {t}]]",
                         ", ".join(f"{r.name} {_pct(r.rate)}" for r in a.rates[:-1]), a.verdict,
                         f"{o.result['wall_s']:.0f} s"))
        elif e.kind == plan.HELD_OUT:
            res = o.result
            held = world_counts(res, e.worlds)
            bounds = "; ".join(f"{w} " + " / ".join(_pct(held[w][b] / held[w]["n"]) for b in
                                                    ("threshold", "observer", "observer, other worlds") if b in held[w])
                               for w in world_places(e.worlds))
            rows.append((str(job.seed), *(k_of_n(held[w]["right"], held[w]["n"]) for w in world_places(e.worlds)),
                         "yes" if _meets_every(held, e.worlds) else "no", bounds,
                         f"{res['trials']} trials per landmark per world, seed {res['test_seed']}; bounds "
                         f"fitted on {res['fit_trials']} per landmark, seed {res['fit_seed']}",
                         f"{res['wall_s']:.0f} s"))
        elif e.kind == plan.HAND_DESIGNED:
            res = o.result
            counts = hand_counts(res)
            rows.append((str(job.seed), *(f"{k_of_n(*counts[w]['with'])} / {k_of_n(*counts[w]['without'])}"
                                          for w in WORLDS),
                         f"{res['starts']} starts per world, seed {res['seed']}, trials of {res['steps']} steps",
                         f"{res['wall_s']:.0f} s"))
        else:
            res = o.result
            later = res["goal_rate_by_trial"]["all"][1:]
            rows.append((str(job.seed), f"{_pct(res['goal_rate'])} ({_pct(res['goal_interval'][0])}-"
                         f"{_pct(res['goal_interval'][1])})", f"{_pct(res['classification_rate'])}",
                         ", ".join(_pct(x) for x in later), f"{res['environments']} environments x "
                         f"{res['trials']} trials, seed {res['seed']}", f"{res['wall_s']:.0f} s"))
    if not rows:
        return None
    header = {
        plan.EVOLVE: ("seed", "best training fitness", "first success", "weakest judged rate, fresh trials",
                      "verdict", "largest change at a finer step", "wall (the run's, every session)"),
        plan.ROBOT_LIKE: ("seed", "right (95% interval)", "confusion [[1 as 1, 1 as 2], [2 as 1, 2 as 2]]",
                          "per landmark", "verdict (95% rule)", "wall"),
        plan.HELD_OUT: ("seed", *(f"{w}{'' if w == 'training' else ' (held out)'}: right (95% interval)"
                                  for w in world_places(e.worlds)), "goal in every held-out world (>85%, lower end >80%)",
                        "bounds, % right: threshold rule / observer / observer fitted on the other held-out worlds",
                        "conditions", "wall"),
        plan.SYSTEM: ("seed", "goal reached (95% interval, by environment)", "classifier right",
                      "goal rate in trials 2-5", "conditions", "wall"),
        plan.HAND_DESIGNED: ("seed", *(f"{w}: goal reached with / without detectors (95% intervals)" for w in WORLDS),
                             "conditions", "wall"),
    }[e.kind]
    rows = [row + ("",) * (len(header) - len(row)) for row in rows]
    return Block("table", rows=(header, *rows))


def _figures(e: plan.Experiment, order: Sequence[plan.Job], outcomes: dict[str, Outcome], root: Path) -> list[Block]:
    """Draws and returns the experiment's figures: fitness over seeds, and the first finished
    seed's own figures."""
    done = [j for j in order if j.experiment == e.name and outcomes[j.id].status == "done"]
    if not done:
        return []
    blocks = []
    if e.kind == plan.EVOLVE:
        histories = {}
        for job in done:
            run = RunDir(root / job.id)
            rows = run.read_log(run.read_config()[0])
            histories[job.seed] = {k: [r[k] for r in rows] for k in ("generation", "best", "mean")}
        ax = plot.plot_fitness_seeds(histories, title=f"{e.name}: fitness over {len(histories)} seed(s)")
        name = f"{FIGURES}/fitness-{e.name}.png"
        (root / FIGURES).mkdir(exist_ok=True)
        save_figure(ax.figure, root / name)
        plot.close(ax.figure)
        blocks.append(Block("img", f"{e.name}: best (solid) and mean (dotted) fitness per seed", path=name))
        first = done[0]
        # The seeds' fitness is drawn above, together: the run's own fitness.png is not drawn.
        for file in figures.draw_run(root / first.id, seed=0, fitness=False):
            blocks.append(Block("img", f"{e.name}, seed {first.seed}: {file}", path=f"{first.id}/{file}"))
    elif e.kind == plan.SYSTEM:
        first = done[0]
        parts = [nav1d.load_part(root / plan.job_id(n, first.seed)) for n in e.needs]
        (root / first.id).mkdir(parents=True, exist_ok=True)
        nav1d.draw_system(parts, SYSTEM_TRIALS, root / first.id / "fig2-system.png")
        blocks.append(Block("img", f"{e.name}, seed {first.seed}: Fig. 2 of the integrated system",
                            path=f"{first.id}/fig2-system.png"))
    return blocks


def describe(e: plan.Experiment) -> str:
    """What the paper says of ``e`` and how dnnevo runs it, in a sentence or three."""
    what = f"Paper: {e.paper}."
    if e.preset:
        what += f" Preset `{e.preset}`" + (f" with `{' '.join(e.overrides)}`" if e.overrides else "") + "."
    if e.needs:
        what += f" Uses the runs of {', '.join(e.needs)} of the same seed."
    if e.note:
        what += f" {e.note[0].upper()}{e.note[1:]}."
    if e.preset and presets.get(e.preset, overrides=list(e.overrides)).task_params.get("near_first_weight", 0) > 0:
        what += (" Its training fitness can exceed 1: near_first_weight adds a bonus for reaching the goal "
                 "in the first, unscored trial of landmark-near chains; the success rule is unchanged.")
    return what


def build(root: Path, order: Sequence[plan.Job], outcomes: dict[str, Outcome], *, settings: Settings,
          environment: dict[str, str], command: str, draw: bool = True) -> list[Block]:
    """The report of the jobs ``order`` run with ``settings`` and what became of them; ``draw``
    makes the figures."""
    present = [e for e in plan.EXPERIMENTS if any(j.experiment == e.name for j in order)]
    seeds = sorted({j.seed for j in order})
    intro = (f"Made by `{command}` over seeds {', '.join(map(str, seeds))}. Each final champion is judged "
             f"on fresh conditions from seed {settings.eval_seed} + the run's seed, which no run uses; the "
             f"robot-like test draws its trials from seed {ROBOT_SEED_BASE} + the run's seed, the held-out "
             f"worlds theirs from seed {landmark_transfer.TEST_SEED} for every seed. Intervals "
             "are 95%: Wilson for rates, percentile bootstrap for medians.")
    if settings.quick:
        intro += (" **Quick mode**: small populations and few generations. It shows that everything "
                  "runs; its rates say nothing about the paper.")
    if settings.overrides:
        intro += f" Every evolution was changed by `{' '.join(settings.overrides)}`."
    blocks = [
        Block("h1", "dnnevo: Yamauchi & Beer, reproduced"),
        Block("p", intro),
        Block("h2", "Paper and dnnevo"),
        Block("table", rows=(SUMMARY_HEADER, *(summary_row(e, order, outcomes) for e in present))),
    ]
    missing = [o for o in outcomes.values() if o.status != "done"]
    if missing:
        blocks.append(Block("h2", "Not done"))
        blocks.append(Block("table", rows=(("job", "status", "why"),
                                           *((o.task.id, o.status, o.message) for o in missing))))
    blocks.append(Block("h2", "Experiments"))
    for e in present:
        blocks.append(Block("h3", e.name))
        blocks.append(Block("p", describe(e)))
        table = seed_table(e, order, outcomes)
        if table is not None:
            blocks.append(table)
        if draw:
            blocks.extend(_figures(e, order, outcomes, root))
    blocks.append(Block("h2", "Environment"))
    blocks.append(Block("table", rows=(("what", "value"), *environment.items())))
    return blocks


def markdown(blocks: Sequence[Block]) -> str:
    """The report as Markdown; figures are linked by their paths."""
    out = []
    for b in blocks:
        if b.kind in ("h1", "h2", "h3"):
            out.append("#" * int(b.kind[1]) + " " + b.text)
        elif b.kind == "p":
            out.append(b.text)
        elif b.kind == "img":
            out.append(f"![{b.text}]({b.path})")
        else:
            cells = [[c.replace("|", "\\|").replace("\n", " ") for c in row] for row in b.rows]
            lines = ["| " + " | ".join(cells[0]) + " |", "|" + "---|" * len(cells[0])]
            lines += ["| " + " | ".join(row) + " |" for row in cells[1:]]
            out.append("\n".join(lines))
    return "\n\n".join(out) + "\n"


_CSS = ("body{font-family:system-ui,sans-serif;max-width:75em;margin:2em auto;padding:0 1em;color:#222}"
        "table{border-collapse:collapse;margin:1em 0;font-size:90%}td,th{border:1px solid #ccc;"
        "padding:.3em .6em;vertical-align:top}th{background:#f3f3f3}img{max-width:100%;display:block}"
        "figure{margin:1em 0}figcaption{color:#555;font-size:90%}code{background:#f3f3f3;padding:0 .2em}")


def _inline(text: str) -> str:
    """HTML of ``text`` with `code` spans."""
    parts = html.escape(text).split("`")
    return "".join(f"<code>{p}</code>" if i % 2 else p for i, p in enumerate(parts))


def to_html(blocks: Sequence[Block], root: Path) -> str:
    """The report as one self-contained HTML page: figures are embedded as data URIs."""
    body = []
    for b in blocks:
        if b.kind in ("h1", "h2", "h3"):
            body.append(f"<{b.kind}>{_inline(b.text)}</{b.kind}>")
        elif b.kind == "p":
            body.append(f"<p>{_inline(b.text)}</p>")
        elif b.kind == "img":
            data = base64.b64encode((root / b.path).read_bytes()).decode("ascii")
            body.append(f'<figure><img alt="{html.escape(b.text)}" src="data:image/png;base64,{data}">'
                        f"<figcaption>{_inline(b.text)}</figcaption></figure>")
        else:
            head = "".join(f"<th>{_inline(c)}</th>" for c in b.rows[0])
            rows = "".join("<tr>" + "".join(f"<td>{_inline(c)}</td>" for c in row) + "</tr>" for row in b.rows[1:])
            body.append(f"<table><thead><tr>{head}</tr></thead><tbody>{rows}</tbody></table>")
    title = next((b.text for b in blocks if b.kind == "h1"), "dnnevo report")
    return (f'<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8"><title>{html.escape(title)}</title>'
            f"<style>{_CSS}</style></head><body>\n" + "\n".join(body) + "\n</body></html>\n")


def write(root: Path, blocks: Sequence[Block]) -> list[Path]:
    """Writes ``report.md`` and ``report.html`` into ``root``; returns their paths."""
    paths = [root / name for name in REPORT_FILES]
    write_atomic(paths[0], markdown(blocks))
    write_atomic(paths[1], to_html(blocks, root))
    return paths


def environment(*, workers: str, threads: int | None, wall_s: float) -> dict[str, str]:
    """The machine and settings of a reproduction, for its report."""
    info = _core.build_info()
    cpu = platform.processor() or "unknown"
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            cpu = next((line.split(":", 1)[1].strip() for line in f if line.startswith("model name")), cpu)
    except OSError:
        pass
    features = ", ".join(k for k, v in info["cpu_features"].items() if v) or "none"
    return {
        "dnnevo": f"{info['version']} (git {info['commit']})", "Python": platform.python_version(),
        "system": f"{platform.system()} {platform.release()} ({platform.machine()})", "CPU": cpu,
        "CPU features": features, "SIMD kernel": f"{info['kernel']} ({info['lanes']} lanes)",
        "cores": str(os.cpu_count()), "workers": workers,
        "threads per run": "all cores" if threads is None else str(threads),
        "wall time of this session": f"{wall_s:.0f} s",
    }
