"""The reference reproduction's results, kept in ``docs/results/``, and every results table made
from them.

``docs/results/`` holds what ``dnnevo reproduce --seeds 0-9`` wrote that is worth keeping, and
nothing that can be remade:

- ``reproduce.json``: the reproduction's settings and every evolution's config;
- ``EXPERIMENT/seed-N.json``: one job's result, as :mod:`~dnnevo.experiments.jobs` wrote it (no
  run folder, no checkpoint: runs are deterministic, so a lost run folder is remade to the same
  bits by the same command);
- ``provenance.json``: the commit, the machine (CPU, SIMD kernel, cores, workers) and, per
  family, the command and the time it took.

Two commands::

    python -m dnnevo.experiments.results collect /root/dnnevo-reference docs/results --only landmark
    python -m dnnevo.experiments.results render [--check]

``collect`` copies a reproduction's finished results (checked against their run folders) into
``docs/results/``. ``render`` writes the tables between marker lines in ``README.md`` and every
Markdown file under ``docs/``, from ``docs/results/`` alone:

- ``<!-- results:summary:begin -->`` / ``...:end -->``: the paper-vs-dnnevo table, one row per
  experiment of the plan, "not yet run" where no result is stored yet;
- ``<!-- results-table:begin -->`` / ``<!-- results-table:end -->`` (the README): the same
  table for the paper's families alone;
- ``<!-- results:summary:FAMILY:begin -->``: the same table, for one family;
- ``<!-- results:FAMILY:begin -->``: each experiment of the family, with one row per seed;
- ``<!-- results:machine:begin -->``: the machine, and the time per experiment and family.
- ``<!-- results:example:NAME:begin -->``: an example script's table, from ``examples/NAME.json``
  (written by the script's ``--record``; :mod:`~dnnevo.experiments.examples`).

``render --check`` changes nothing and exits with status 1, naming each file whose tables differ
from what ``render`` would write. The rows are :mod:`~dnnevo.experiments.report`'s, so a
reproduction's own report and these tables say the same.
"""

from __future__ import annotations

import argparse
import json
import math
import re
import statistics
import sys
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from dnnevo.errors import DnnevoError
from dnnevo.experiments import examples, jobs, plan, precision, report
from dnnevo.experiments.scheduler import Outcome, Task
from dnnevo.runs import RunFileError, first_difference, manifest_with_later_defaults, short, write_atomic
from dnnevo.runs.files import checked, read_json

__all__ = ["RESULTS_DIR", "SETTINGS_FILE", "PROVENANCE_FILE", "REFERENCE_FAMILIES", "Results", "load", "collect",
           "blocks", "render", "main"]

RESULTS_DIR = Path("docs") / "results"
"""Where the reference reproduction's results live, under the repository's root."""

SETTINGS_FILE = "reproduce.json"
"""The reproduction's settings, as ``dnnevo reproduce`` wrote them."""

PROVENANCE_FILE = "provenance.json"
"""The commit, machine and times of the reference reproduction."""

DEFAULT_SEEDS = tuple(range(10))
"""The reference reproduction's seeds, ``--seeds 0-9``."""

REFERENCE_FAMILIES = (*plan.PAPER_FAMILIES, "ablation")
"""The families the reference reproduction covers: the paper's and the ablation of its 2-bit
route (issue 47). Their experiments have rows in the tables, "not yet run" until collected;
another family's (``classic``) appear once its runs are collected."""

NOT_RUN = "not yet run"
"""The status of a job with no stored result."""

_README_KEY = "results-table"
_PRECISION_KEY = "precision-vs-f64"
_MARKER = re.compile(r"<!-- (results-table|results:([a-z0-9:-]+?)):begin -->")


def _nothing() -> None:
    """Stands for a job's function: rows are made from stored results, nothing is run."""


@dataclass(frozen=True)
class Results:
    """The stored results of one reproduction."""

    folder: Path
    settings: dict[str, Any] | None
    """Its ``reproduce.json``; None when the folder holds no reproduction yet."""
    provenance: dict[str, Any]
    """Its ``provenance.json``."""
    found: dict[str, dict[str, Any]]
    """The result of each finished job, by job id."""

    @property
    def seeds(self) -> list[int]:
        """The seeds the reproduction covers (done or not)."""
        return [int(s) for s in self.provenance.get("seeds", DEFAULT_SEEDS)]

    @property
    def families(self) -> tuple[str, ...]:
        """The families the tables cover: :data:`REFERENCE_FAMILIES`, and any other whose runs were
        collected."""
        collected = self.provenance.get("families", {})
        return tuple(f for f in plan.FAMILIES if f in REFERENCE_FAMILIES or f in collected)

    @property
    def order(self) -> list[plan.Job]:
        """Every job of those families over the seeds, done or not."""
        return plan.jobs(self.seeds, self.families)

    def outcomes(self, order: Sequence[plan.Job] | None = None) -> dict[str, Outcome]:
        """Each job's outcome (of ``order``, default :attr:`order`): ``done`` with its result, or
        :data:`NOT_RUN`."""
        return {j.id: _done(j, self.found[j.id]) if j.id in self.found
                else Outcome(Task(j.id, j.needs, _nothing), NOT_RUN) for j in (self.order if order is None else order)}


def _done(job: plan.Job, result: dict[str, Any]) -> Outcome:
    return Outcome(Task(job.id, job.needs, _nothing), "done", result)


def _is_count(value: Any) -> bool:
    return isinstance(value, int) and not isinstance(value, bool) and value >= 0


def _is_seconds(value: Any) -> bool:
    return (isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)
            and value >= 0)


def _read_settings(path: Path) -> dict[str, Any]:
    """``reproduce.json``: an object whose ``settings`` are an object."""
    settings = read_json(path)
    if not isinstance(settings, dict) or not isinstance(settings.get("settings"), dict):
        raise RunFileError(f"{path}: not a reproduction's settings (an object with an object 'settings')")
    return settings


def _read_provenance(path: Path) -> dict[str, Any]:
    """``provenance.json``, with every field the tables and ``collect`` read of the type they
    read it as; a file without it is no provenance (``{}``)."""
    if not path.exists() and not path.is_symlink():
        return {}
    prov = read_json(path)
    if not isinstance(prov, dict):
        raise RunFileError(f"{path}: is a JSON {type(prov).__name__}; expected an object")
    seeds = prov.get("seeds", [])
    if not isinstance(seeds, list) or not all(_is_count(s) for s in seeds):
        raise RunFileError(f"{path}: seeds is {short(seeds)}; expected a list of integers >= 0")
    if not isinstance(prov.get("environment", {}), dict):
        raise RunFileError(f"{path}: environment is {short(prov['environment'])}; expected an object")
    families = prov.get("families", {})
    if not isinstance(families, dict):
        raise RunFileError(f"{path}: families is {short(families)}; expected an object")
    for family, info in families.items():
        if not (isinstance(info, dict) and isinstance(info.get("command"), str)
                and isinstance(info.get("commit"), str) and _is_count(info.get("runs"))
                and _is_count(info.get("planned")) and _is_seconds(info.get("elapsed_s"))):
            raise RunFileError(f"{path}: families.{family} is {short(info)}; expected an object with "
                               "command and commit (strings), runs and planned (counts) and elapsed_s "
                               "(seconds)")
        machines = info.get("machines", [])
        if not isinstance(machines, list) or not all(isinstance(m, str) for m in machines):
            raise RunFileError(f"{path}: families.{family}.machines is {short(machines)}; expected a "
                               "list of strings")
    return prov


def load(folder: Path) -> Results:
    """The results stored in ``folder`` (e.g. ``docs/results``); no results when it holds no
    ``reproduce.json``. Every result file must belong to a job of the plan and carry the
    folder's settings. Every field the tables read is checked here, so that a damaged file is a
    :class:`~dnnevo.errors.DnnevoError` naming it, never an error of the tables' code."""
    settings_file = folder / SETTINGS_FILE
    if not settings_file.exists() and not settings_file.is_symlink():
        return Results(folder, None, {}, {})
    settings = _read_settings(settings_file)
    provenance = _read_provenance(folder / PROVENANCE_FILE)
    known = {e.name for e in plan.EXPERIMENTS}
    found: dict[str, dict[str, Any]] = {}
    for path in sorted(folder.glob("*/seed-*.json")):
        name, number = path.parent.name, path.stem.removeprefix("seed-")
        if name not in known:
            raise DnnevoError(f"{path}: {name} is no experiment of the plan; delete "
                              f"{path.parent.relative_to(folder)} or collect again")
        if not re.fullmatch(r"[0-9]+", number):
            raise DnnevoError(f"{path}: not a result file (they are EXPERIMENT/seed-N.json)")
        job = next(j for j in plan.jobs([int(number)], plan.FAMILIES) if j.experiment == name)
        result = read_json(path)
        if not isinstance(result, dict) or result.get("job") != job.id:
            raise DnnevoError(f"{path}: not the result of job {job.id}")
        if result.get("settings") != settings["settings"]:
            raise DnnevoError(f"{path}: made with other settings than {settings_file}")
        if not _is_seconds(result.get("wall_s")):
            raise DnnevoError(f"{path}: wall_s is {short(result.get('wall_s'))}; expected seconds (a finite "
                              "number >= 0)")
        one = {job.id: _done(job, result)}
        try:  # every field a table reads is there: the tables' own code reads them
            report.summary_row(job.spec, [job], one)
            report.seed_table(job.spec, [job], one)
        except (KeyError, TypeError, ValueError, IndexError, AttributeError, OverflowError, RecursionError) as e:
            raise DnnevoError(f"{path}: not a valid job result ({type(e).__name__}: {e})") from None
        found[job.id] = result
    return Results(folder, settings, provenance, found)


# -- collect ---------------------------------------------------------------------------------------

def _environment_of(source: Path) -> dict[str, str]:
    """The Environment table of the reproduction's own report (what the reproducing process
    recorded), or this process's machine when it has none yet."""
    table: dict[str, str] = {}
    md = source / report.REPORT_FILES[0]
    if md.exists():
        text = md.read_text(encoding="utf-8")
        env = text.split("## Environment", 1)[1] if "## Environment" in text else ""
        for line in env.strip().splitlines()[2:]:  # after the empty header and its rule
            cells = [c.strip() for c in line.strip().strip("|").split(" | ")]
            if len(cells) != 2 or not line.startswith("|"):
                break
            table[cells[0]] = cells[1]
    if not table:
        # No report yet (the reproduction is running): this machine's facts, without this
        # process's commit, which need not be the reproduction's.
        table = report.environment(workers="unknown", threads=None, wall_s=0.0)
        table["dnnevo"] = re.sub(r"\s*\(git [^)]*\)", "", table["dnnevo"])
        table["workers"] = table["threads per run"] = "unknown until the reproduction writes its report"
    table.pop("wall time of this session", None)
    return table


def _seeds_text(seeds: Sequence[int]) -> str:
    """``0-9`` for a range, ``1,4,7`` otherwise."""
    s = sorted(seeds)
    if len(s) > 1 and s == list(range(s[0], s[-1] + 1)):
        return f"{s[0]}-{s[-1]}"
    return ",".join(map(str, s))


def _command(seeds: Sequence[int], family: str, settings: jobs.Settings) -> str:
    words = ["dnnevo", "reproduce", "--seeds", _seeds_text(seeds), "--only", family]
    words += ["--quick"] if settings.quick else []
    words += ["--eval-trials", str(settings.eval_trials)] if settings.eval_trials is not None else []
    words += [] if settings.dt_check else ["--no-dt-check"]
    words += [w for kv in settings.overrides for w in ("--set", kv)]
    return " ".join(words)


def _joined(held: Any, found: dict[str, Any]) -> dict[str, Any] | None:
    """The settings ``held`` by the results folder with the configs of experiments that only the
    reproduction's settings ``found`` have (experiments added to dnnevo since the first family was
    collected), or None when a setting or a config that both hold differs."""
    mine, theirs = (held.get("configs") if isinstance(held, dict) else None), found.get("configs")
    if not isinstance(mine, dict) or not isinstance(theirs, dict):
        return None
    if {k: v for k, v in held.items() if k != "configs"} != {k: v for k, v in found.items() if k != "configs"}:
        return None
    # Configs compare with the settings added since either was written at their defaults.
    old, new = (manifest_with_later_defaults({"configs": c})["configs"] for c in (mine, theirs))
    if any(old[k] != new[k] for k in mine.keys() & theirs.keys()):
        return None
    return {**held, "configs": {**mine, **{k: v for k, v in theirs.items() if k not in mine}}}


def _comparable(result: Any) -> Any:
    """What two machines that ran the same job must agree on: its result without wall times,
    its config with the settings added since it was written at their defaults (a result
    collected before a setting existed is the same run as one collected after)."""
    if isinstance(result, dict) and isinstance(result.get("config"), dict):
        result = manifest_with_later_defaults(result)
    return _timeless(result)


def _comparable_pair(kept: Any, new: Any) -> tuple[Any, Any]:
    """Both results as :func:`_comparable` makes them, and where only one of them holds a
    held-out-worlds test's digest of its worlds (results collected before it existed lack it),
    both without it."""
    def digests(result: Any) -> set[str]:
        inputs = result.get("inputs") if isinstance(result, dict) else None
        return {k for k in inputs if str(k).startswith(jobs.WORLDS_INPUT)} if isinstance(inputs, dict) else set()

    if bool(digests(kept)) != bool(digests(new)):
        kept, new = ({**r, "inputs": {k: v for k, v in r["inputs"].items() if k not in digests(r)}}
                     if digests(r) else r for r in (kept, new))
    return _comparable(kept), _comparable(new)


def _timeless(result: Any) -> Any:
    """A job's result without its wall times (``wall_s`` at any depth): what two machines that
    ran the same job must agree on."""
    if isinstance(result, dict):
        return {k: _timeless(v) for k, v in result.items() if k != "wall_s"}
    if isinstance(result, list):
        return [_timeless(v) for v in result]
    return result


def _machines(provenance: Mapping[str, Any]) -> list[str]:
    """Every machine a reproduction's collected runs were made on: each family's, or the
    environment's for a family collected before families named theirs."""
    first = _machine_name(provenance.get("environment", {}))
    return list(dict.fromkeys(m for info in provenance.get("families", {}).values()
                              for m in info.get("machines", [first]))) or [first]


def _machine_name(env: Mapping[str, Any]) -> str:
    """The CPU and SIMD kernel of a reproduction's environment table, as a family's
    ``machines`` lists them."""
    return f"{env.get('CPU', 'unknown CPU')}, SIMD kernel {env.get('SIMD kernel', 'unknown')}"


def _commits(before: Any, commit: str) -> str:
    """The commits a family's collected runs were made at: those of its earlier collection and
    ``commit``. A reproduction continued at a later commit (runs are deterministic, so a later
    commit of the same code gives the same bits) keeps the commits of its earlier runs named."""
    earlier = before.get("commit") if isinstance(before, dict) else None
    names = [c.strip() for c in earlier.split(",")] if isinstance(earlier, str) else []
    return ", ".join(dict.fromkeys([*filter(None, names), commit]))


def _own(seeds: Sequence[int], family: str) -> list[plan.Job]:
    """The jobs of ``family``'s own experiments over ``seeds``: not those of another family that
    it needs, which are collected, counted and timed with their own family."""
    return [j for j in plan.jobs(list(seeds), [family]) if j.spec.family == family]


def collect(source: Path, dest: Path, *, families: Sequence[str] | None = None,
            seeds: Sequence[int] = DEFAULT_SEEDS, commit: str | None = None) -> list[str]:
    """Copies the finished results of ``families`` (default the paper's) over ``seeds`` from the
    reproduction folder ``source`` into ``dest``, each checked against its run folder as
    ``dnnevo reproduce`` checks it, with ``reproduce.json`` and ``provenance.json``. Returns the
    ids of the jobs copied. ``dest`` must hold the same reproduction (same settings) or none. A
    family collected again (its reproduction continued, maybe in another session on another
    machine) names the commits and machines of every collection, counts the runs ``dest`` then
    holds and adds the new runs' elapsed time to the earlier; a result ``dest`` already holds is
    kept, and must be the same but for its wall times (else nothing is written)."""
    settings_file = source / SETTINGS_FILE
    if not settings_file.exists():
        raise DnnevoError(f"{source} holds no {SETTINGS_FILE}: not a reproduction's folder")
    manifest = _read_settings(settings_file)
    if (dest / SETTINGS_FILE).exists():
        joined = _joined(read_json(dest / SETTINGS_FILE), manifest)
        if joined is None:
            raise DnnevoError(f"{dest / SETTINGS_FILE} holds another reproduction's settings than {settings_file}; "
                              f"empty {dest} first to replace them")
        manifest = joined
    old = _read_provenance(dest / PROVENANCE_FILE)
    if old and old.get("seeds") != sorted(seeds):
        raise DnnevoError(f"{dest / PROVENANCE_FILE} covers seeds {old.get('seeds')}, not {sorted(seeds)}; "
                          "collect with its --seeds")
    env = _environment_of(source)
    if commit is not None:
        version = re.sub(r"\s*\(git [^)]*\)", "", env.get("dnnevo", ""))
        env["dnnevo"] = f"{version} (git {commit})".strip()
    named = re.search(r"\(git ([0-9a-f]{4,40})\)", env.get("dnnevo", ""))
    if named is None:
        why = ("its report names no commit" if (source / report.REPORT_FILES[0]).exists()
               else "it has no report yet to name its commit")
        raise DnnevoError(f"{source}: {why}; pass --commit, the commit the reproduction ran")
    with checked(settings_file):
        settings = jobs.Settings(**manifest["settings"])
    # Every result is checked before any is written, so a refusal leaves dest as it was.
    chosen = {family: [job for job in _own(seeds, family)
                       if jobs.read_result(source, job, settings) is not None]  # checked against its run
              for family in plan.families(families)}
    # A result collected before (another session's reproduction, maybe another machine) must be
    # the same but for its wall times: runs are deterministic. It is kept as it was.
    for finished in chosen.values():
        for job in list(finished):
            kept = jobs.result_path(dest, job)
            if not kept.exists():
                continue
            diff = first_difference(*_comparable_pair(read_json(kept), read_json(jobs.result_path(source, job))))
            if diff is not None:
                raise DnnevoError(f"{job.id}: the result in {source} differs from the one in {dest} "
                                  f"at {diff[0]} ({short(diff[2])} against {short(diff[1])}); runs "
                                  "are deterministic, so one of them was made by other code")
            finished.remove(job)
    dest.mkdir(parents=True, exist_ok=True)
    old_machine = _machine_name(old.get("environment", {}))
    copied, times = [], {}
    for family, finished in chosen.items():
        done = []
        for job in finished:
            src, out = jobs.result_path(source, job), jobs.result_path(dest, job)
            out.parent.mkdir(parents=True, exist_ok=True)
            write_atomic(out, src.read_text(encoding="utf-8"))
            copied.append(job.id)
            done.append(src)
        before = old.get("families", {}).get(family)
        if done:
            ends = [p.stat().st_mtime for p in done]
            starts = [e - float(read_json(p)["wall_s"]) for p, e in zip(done, ends)]
            earlier = [] if before is None else before.get("machines", [old_machine])
            times[family] = {"command": _command(seeds, family, settings),
                             "commit": _commits(before, named.group(1)),
                             "runs": sum(jobs.result_path(dest, j).exists() for j in _own(seeds, family)),
                             "planned": len(_own(seeds, family)),
                             "elapsed_s": round(max(ends) - min(starts))
                             + (0 if before is None else before["elapsed_s"]),
                             "machines": list(dict.fromkeys([*earlier, _machine_name(env)]))}
        elif before is not None and "machines" not in before:
            times[family] = {**before, "machines": [old_machine]}
    write_atomic(dest / SETTINGS_FILE, json.dumps(manifest, indent=1) + "\n")
    families_done = {**old.get("families", {}), **times}
    commits = [c for f in families_done.values() for c in f["commit"].split(", ")]
    provenance = {
        "seeds": sorted(seeds),
        "commit": ", ".join(dict.fromkeys(commits)) or named.group(1),
        # The machine of the first collection: the one the reproduction began on (each family
        # names its own machines).
        "environment": old.get("environment") or env,
        "families": families_done,
        "elapsed": "per family, from the first job's start to the last job's end, taken from the result "
                   "files' times and wall times; it includes any pause when the reproduction spanned sessions",
    }
    write_atomic(dest / PROVENANCE_FILE, json.dumps(provenance, indent=1) + "\n")
    return copied


# -- render ----------------------------------------------------------------------------------------

def _duration(seconds: float) -> str:
    if seconds < 90:
        return f"{seconds:.0f} s"
    if seconds < 90 * 60:
        return f"{seconds / 60:.0f} min"
    h, m = divmod(round(seconds / 60), 60)
    return f"{h} h {m:02d} min"


def _summary(results: Results, families: tuple[str, ...] | None) -> list[report.Block]:
    """The paper-vs-dnnevo table of ``families`` (every family when None)."""
    order, outcomes = results.order, results.outcomes()
    rows = []
    for e in plan.EXPERIMENTS:
        if e.family not in results.families or (families is not None and e.family not in families):
            continue
        row = report.summary_row(e, order, outcomes)
        if not any(j.experiment == e.name and j.id in results.found for j in order):
            row = (*row[:2], NOT_RUN, *row[3:])
        rows.append(row)
    mine = [j for j in order if families is None or j.spec.family in families]
    done, planned = sum(1 for j in mine if j.id in results.found), len(mine)
    prov = results.provenance
    if results.settings is None:
        text = f"No results yet in {RESULTS_DIR.as_posix()}/: every experiment is {NOT_RUN}."
    else:
        text = (f"From the reference reproduction in {RESULTS_DIR.as_posix()}/ (`dnnevo reproduce --seeds "
                f"{_seeds_text(results.seeds)}`, commit {prov.get('commit', 'unknown')}, "
                f"{' and '.join(_machines(prov))}): "
                f"{done} of {planned} runs done. Intervals are 95%: Wilson for rates, percentile bootstrap "
                "for medians.")
        if results.settings["settings"].get("quick"):
            text += " **Quick mode**: its rates say nothing about the paper."
    return [report.Block("p", text), report.Block("table", rows=(report.SUMMARY_HEADER, *rows))]


def _family(results: Results, family: str) -> list[report.Block]:
    order, outcomes = results.order, results.outcomes()
    out = []
    for e in plan.EXPERIMENTS:
        if e.family != family:
            continue
        out.append(report.Block("h3", e.name))
        out.append(report.Block("p", report.describe(e)))
        if not any(j.experiment == e.name and j.id in results.found for j in order):
            out.append(report.Block("p", f"Not yet run over seeds {_seeds_text(results.seeds)}."))
            continue
        table = report.seed_table(e, order, outcomes)
        if table is not None:
            out.append(table)
    return out


def _precision(results: Results) -> list[report.Block]:
    single = [e for e in plan.EXPERIMENTS if e.family == precision.FAMILY]
    families = dict.fromkeys([precision.FAMILY, *(precision.twin(e).family for e in single)])
    order = plan.jobs(results.seeds, tuple(families))
    found = sum(j.id in results.found for j in order if j.spec.family == precision.FAMILY)
    text = (f"From the results in {RESULTS_DIR.as_posix()}/: each experiment run again with "
            f"precision = \"f32\" beside its f64 runs, on the seeds both have done "
            f"({found} f32 runs collected). Intervals are 95% Wilson intervals; a p-value is the chance "
            f"of counts at least this far apart if f32 and f64 had one success rate.")
    rows = precision.rows(order, results.outcomes(order))
    return [report.Block("p", text), report.Block("table", rows=(precision.HEADER, *rows))]


def _machine(results: Results) -> list[report.Block]:
    if results.settings is None:
        return [report.Block("p", f"No results yet in {RESULTS_DIR.as_posix()}/.")]
    prov = results.provenance
    env = dict(prov.get("environment", {}))
    env["commit"] = str(prov.get("commit", "unknown"))
    out = [report.Block("table", rows=(("machine and build", "value"), *((k, str(v)) for k, v in env.items())))]
    rows: list[tuple[str, ...]] = []
    families = prov.get("families", {})
    total_run = total_elapsed = 0.0
    for family in results.families:
        fam_run, fam_rows = 0.0, []
        for e in (e for e in plan.EXPERIMENTS if e.family == family):
            walls = [float(results.found[j.id]["wall_s"]) for j in results.order
                     if j.experiment == e.name and j.id in results.found]
            fam_run += sum(walls)
            fam_rows.append((family, e.name, str(len(walls)), _duration(sum(walls)),
                             _duration(statistics.median(walls)), _duration(max(walls)), "-") if walls
                            else (family, e.name, NOT_RUN, "-", "-", "-", "-"))
        info = families.get(family)
        if info is None:
            rows.append((family, "(whole family)", NOT_RUN, "-", "-", "-", "-"))
            continue
        total_run += fam_run
        total_elapsed += float(info["elapsed_s"])
        rows += fam_rows
        # Counted from the results and today's plan: a plan that grew since the collection
        # (new experiments not yet run) shows them as not done.
        done = sum(1 for j in results.order if j.spec.family == family and j.id in results.found)
        planned = sum(1 for j in results.order if j.spec.family == family)
        rows.append((family, "(whole family)", f"{done}/{planned}", _duration(fam_run), "-", "-",
                     _duration(info["elapsed_s"])))
    out.append(report.Block("table", rows=(("family", "experiment", "runs", "run time, summed", "median run",
                                            "longest run", "elapsed"),
                                           *rows)))
    if families:
        text = (f"All families: {_duration(total_run)} of run time, {_duration(total_elapsed)} elapsed on "
                f"{env.get('cores', '?')} cores. Elapsed is {prov.get('elapsed', 'per family')}. Commands: "
                + "; ".join(f"`{info['command']}`" for info in families.values()) + ".")
        spread = {f: info["machines"] for f, info in families.items() if len(info.get("machines", [])) > 1}
        if spread:
            text += (" Run times add up runs made on different machines: "
                     + "; ".join(f"{f} on {' and '.join(m)}" for f, m in spread.items()) + ".")
    else:
        text = "No time recorded yet."
    out.append(report.Block("p", text.strip()))
    return out


def blocks(results: Results, key: str) -> list[report.Block]:
    """The blocks a marker ``key`` stands for (``summary``, ``summary:FAMILY``, ``FAMILY``,
    ``machine``, or ``example:NAME``, an example script's table from
    ``examples/NAME.json`` of the results folder); raises :class:`~dnnevo.errors.DnnevoError` for
    an unknown one."""
    if key.startswith("example:"):
        return examples.blocks(examples.read(results.folder / examples.EXAMPLES_DIR / f"{key[len('example:'):]}.json"))
    if key == "summary":
        return _summary(results, None)
    if key == _README_KEY:
        return _summary(results, plan.PAPER_FAMILIES)
    if key.startswith("summary:") and key.split(":", 1)[1] in plan.FAMILIES:
        return _summary(results, (key.split(":", 1)[1],))
    if key in plan.FAMILIES:
        return _family(results, key)
    if key == "machine":
        return _machine(results)
    if key == _PRECISION_KEY:
        return _precision(results)
    raise DnnevoError(f"unknown results marker {key!r}; markers are summary, summary:FAMILY, FAMILY, machine, "
                      f"{_PRECISION_KEY} "
                      f"(FAMILY one of {', '.join(plan.FAMILIES)}), example:NAME, and results-table in the README")


def fill(text: str, results: Results, *, where: str = "") -> str:
    """``text`` with every results marker's content made again from ``results``."""
    out, at = [], 0
    for m in _MARKER.finditer(text):
        if m.start() < at:
            raise DnnevoError(f"{where}: a results marker at offset {m.start()} lies inside another")
        key = m.group(2) or _README_KEY
        end = f"<!-- {m.group(1)}:end -->"
        stop = text.find(end, m.end())
        if stop < 0:
            raise DnnevoError(f"{where}: {m.group(0)} has no {end}")
        out.append(text[at:m.end()])
        out.append("\n\n" + report.markdown(blocks(results, key)) + "\n")
        at = stop
    out.append(text[at:])
    return "".join(out)


def targets(root: Path) -> list[Path]:
    """The Markdown files that may hold results markers: ``README.md`` and ``docs/**/*.md``."""
    found = [root / "README.md"] if (root / "README.md").exists() else []
    return found + sorted((root / "docs").rglob("*.md"))


def render(root: Path, *, results_dir: Path | None = None, check: bool = False,
           files: Sequence[Path] | None = None) -> list[Path]:
    """Makes every results table in ``files`` (default :func:`targets` of ``root``) from
    ``results_dir`` (default ``root/docs/results``). Returns the files that changed (with
    ``check``, that would change; nothing is written)."""
    results = load(results_dir if results_dir is not None else root / RESULTS_DIR)
    changed = []
    for path in targets(root) if files is None else files:
        text = path.read_text(encoding="utf-8")
        if "<!-- results" not in text:
            continue
        new = fill(text, results, where=str(path))
        if new != text:
            changed.append(path)
            if not check:
                write_atomic(path, new)
    return changed


# -- command line ----------------------------------------------------------------------------------

def _seeds(text: str) -> list[int]:
    seeds: list[int] = []
    for part in text.split(","):
        lo, _, hi = part.partition("-")
        try:
            a, b = int(lo), int(hi or lo)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{part!r}: seeds are e.g. 0-9 or 1,4,7") from None
        seeds.extend(range(a, b + 1))
    return seeds


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m dnnevo.experiments.results collect|render``."""
    p = argparse.ArgumentParser(prog="python -m dnnevo.experiments.results",
                                description="Keep the reference reproduction's results in docs/results/ and make "
                                            "every results table from them.")
    sub = p.add_subparsers(dest="command", required=True)
    c = sub.add_parser("collect", help="copy a reproduction's finished results into docs/results",
                       epilog="example: python -m dnnevo.experiments.results collect /root/dnnevo-reference "
                              "docs/results --only landmark --commit ca5f9b8")
    c.add_argument("source", type=Path, help="the reproduction's folder (dnnevo reproduce --out)")
    c.add_argument("dest", type=Path, nargs="?", default=RESULTS_DIR, help=f"default {RESULTS_DIR}")
    c.add_argument("--only", help=f"comma-separated families, from {','.join(plan.FAMILIES)} (default the paper's: {','.join(plan.PAPER_FAMILIES)})")
    c.add_argument("--seeds", type=_seeds, default=list(DEFAULT_SEEDS), help="default 0-9")
    c.add_argument("--commit", help="the commit the reproduction ran (default: what its report names)")
    r = sub.add_parser("render", help="write the results tables into README.md and docs/**/*.md",
                       epilog="example: python -m dnnevo.experiments.results render --check")
    r.add_argument("--root", type=Path, default=Path("."), help="the repository (default .)")
    r.add_argument("--results", type=Path, help=f"the results (default ROOT/{RESULTS_DIR})")
    r.add_argument("--check", action="store_true", help="change nothing; exit 1 if a table is out of date")
    r.add_argument("files", type=Path, nargs="*", help="only these files (default README.md and docs/**/*.md)")
    args = p.parse_args(argv)
    try:
        if args.command == "collect":
            copied = collect(args.source, args.dest, families=args.only.split(",") if args.only else None,
                             seeds=args.seeds, commit=args.commit)
            print(f"collected {len(copied)} results into {args.dest}; next: "
                  "python -m dnnevo.experiments.results render")
            return 0
        changed = render(args.root, results_dir=args.results, check=args.check, files=args.files or None)
    except DnnevoError as e:
        sys.stderr.write(f"dnnevo: {e}\n")
        return 2
    if args.check:
        for path in changed:
            sys.stderr.write(f"{path}: results tables differ from {RESULTS_DIR.as_posix()}; run "
                             "python -m dnnevo.experiments.results render\n")
        return 1 if changed else 0
    for path in changed:
        print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
