"""A Python task's digest (``fitness_sha256``) covers what the task reads from its module, so an
edited constant is an edited task; an ``analysis`` attribute is not part of it; and the digests
that runs recorded before (the class's or function's source alone) are still accepted."""

from __future__ import annotations

import dataclasses
import hashlib
import importlib
import inspect
import os
import subprocess
import sys

import numpy as np
import pytest

import dnnevo
from dnnevo import ConfigError
from dnnevo.closedloop import ClosedLoop, FarSeeker
from dnnevo.closedloop.source import plain_source, task_source

MODULE = '''
import numpy as np

SPEED = 0.1
LIMITS = {"far": 5.0}
UNUSED = 7


def towards(light, x):
    return np.sign(light - x)[:, None]


def unrelated():
    return UNUSED


class Seeker:
    observation_size = 1
    success_rate = 0.9

    def reset(self, episodes, rng):
        self.light = rng.uniform(-LIMITS["far"], LIMITS["far"], size=len(episodes))
        self.x = np.zeros(len(episodes))
        return towards(self.light, self.x)

    def step(self, rates, active):
        self.x += SPEED * (rates[:, 1] - rates[:, 0])
        distance = np.abs(self.light - self.x)
        return towards(self.light, self.x), -distance, distance < 0.05

    def success(self, returns, lengths):
        return lengths < 50


class Ruleless(Seeker):
    success_rate = None


def fitness(networks):
    return np.full(len(networks), SPEED)
'''

ANALYSIS = '''    analysis = Analysis(input_names=["light"], conditions={"dark": [0.0]},
                        main_input=0, output_neuron=0)
'''


def load(tmp_path, name: str, text: str):
    """Writes ``text`` as module ``name`` in ``tmp_path`` and imports it afresh."""
    (tmp_path / f"{name}.py").write_text(text)
    sys.path.insert(0, str(tmp_path))
    try:
        sys.modules.pop(name, None)
        importlib.invalidate_caches()
        return importlib.import_module(name)
    finally:
        sys.path.remove(str(tmp_path))


def test_the_text_holds_the_constants_and_functions_the_task_reads_and_nothing_else(tmp_path) -> None:
    module = load(tmp_path, "digest_reads", MODULE)
    text = task_source(module.Seeker)
    assert text.startswith("class Seeker :")  # by its tokens (see test_task_layout.py)
    assert "# SPEED\nSPEED = 0.1" in text and '# LIMITS\nLIMITS = { "far" : 5.0 }' in text
    assert "# towards\ndef towards" in text
    assert "UNUSED" not in text and "unrelated" not in text and "import numpy" not in text
    assert "# SPEED\nSPEED = 0.1" in task_source(module.fitness)
    # A subclass is its base class too.
    inherited = task_source(module.Ruleless)
    assert inherited.startswith("class Ruleless ( Seeker ) :") and "# Seeker\nclass Seeker :" in inherited
    assert "# SPEED\nSPEED = 0.1" in inherited


@pytest.mark.parametrize("edit, seeker_changes, fitness_changes", [
    (("SPEED = 0.1", "SPEED = 0.25"), True, True),
    (('LIMITS = {"far": 5.0}', 'LIMITS = {"far": 6.0}'), True, False),
    (("return np.sign(light - x)[:, None]", "return np.sign(x - light)[:, None]"), True, False),
    (("UNUSED = 7", "UNUSED = 8"), False, False),
    (("return UNUSED", "return UNUSED + 1"), False, False),
])
def test_an_edit_of_what_the_task_reads_changes_its_digest_and_no_other_edit_does(
        tmp_path, edit, seeker_changes, fitness_changes) -> None:
    before = load(tmp_path, "digest_edit_a", MODULE)
    after = load(tmp_path, "digest_edit_b", MODULE.replace(*edit))
    for task, changes in (("Seeker", seeker_changes), ("Ruleless", seeker_changes),
                          ("fitness", fitness_changes)):
        old, new = (task_source(getattr(m, task)) for m in (before, after))
        assert (old != new) == changes, (edit, task)


def test_an_analysis_attribute_is_not_part_of_the_task(tmp_path) -> None:
    plain = load(tmp_path, "digest_plain", MODULE)
    declared = MODULE.replace("    success_rate = 0.9\n", "    success_rate = 0.9\n" + ANALYSIS)
    declared = declared.replace("import numpy as np\n",
                                "import numpy as np\nfrom dnnevo.tasks.protocol import Analysis\n", 1)
    with_analysis = load(tmp_path, "digest_analysis", declared)
    assert with_analysis.Seeker.analysis.main_input == 0
    assert task_source(with_analysis.Seeker) == task_source(plain.Seeker)
    assert plain_source(with_analysis.Seeker) != plain_source(plain.Seeker)


def test_a_run_of_a_task_class_refuses_an_edited_constant_and_keeps_an_added_analysis(tmp_path) -> None:
    original = load(tmp_path, "digest_run", MODULE)
    config = dnnevo.EvolutionConfig(population=12, generations=2, size=3, n_inputs=1, selection="rank")
    out = tmp_path / "run"
    dnnevo.evolve(ClosedLoop(original.Seeker(), episodes=2, max_steps=50), config, out=out, progress=False)
    declared = MODULE.replace("    success_rate = 0.9\n", "    success_rate = 0.9\n" + ANALYSIS).replace(
        "import numpy as np\n", "import numpy as np\nfrom dnnevo.tasks.protocol import Analysis\n", 1)
    analysed = load(tmp_path, "digest_run", declared)
    result = dnnevo.resume(out, ClosedLoop(analysed.Seeker(), episodes=2, max_steps=50),
                           generations=3, progress=False)
    assert len(result.history["best"]) == 3
    edited = load(tmp_path, "digest_run", declared.replace("SPEED = 0.1", "SPEED = 0.25"))
    with pytest.raises(ConfigError, match="not an edited python:digest_run.Seeker"):
        dnnevo.resume(out, ClosedLoop(edited.Seeker(), episodes=2, max_steps=50), generations=4,
                      progress=False)


def test_a_run_of_a_fitness_function_refuses_an_edited_constant(tmp_path) -> None:
    original = load(tmp_path, "digest_function", MODULE)
    config = dnnevo.EvolutionConfig(population=12, generations=2, size=2, n_inputs=1, selection="rank")
    out = tmp_path / "run"
    dnnevo.evolve(original.fitness, config, out=out, progress=False)
    edited = load(tmp_path, "digest_function", MODULE.replace("SPEED = 0.1", "SPEED = 0.25"))
    with pytest.raises(ConfigError, match="not an edited python:digest_function.fitness"):
        dnnevo.resume(out, edited.fitness, generations=3, progress=False)


def test_runs_that_recorded_the_source_alone_are_still_accepted(tmp_path) -> None:
    module = load(tmp_path, "digest_legacy", MODULE)
    config = dnnevo.EvolutionConfig(population=12, generations=2, size=2, n_inputs=1, selection="rank")
    for task, target in ((module.fitness, module.fitness),
                         (ClosedLoop(module.Seeker(), episodes=2, max_steps=50), module.Seeker)):
        out = tmp_path / f"run-{target.__name__}"
        size = 3 if target is module.Seeker else 2
        dnnevo.evolve(task, dataclasses.replace(config, size=size), out=out, progress=False)
        toml = out / "config.toml"
        recorded = toml.read_text()
        current = next(line for line in recorded.splitlines() if line.startswith("fitness_sha256"))
        legacy = legacy_digest(task, target)
        assert legacy not in current
        toml.write_text(recorded.replace(current, f'fitness_sha256 = "{legacy}"'))
        checkpoint = out / "checkpoint.json"
        checkpoint.write_text(checkpoint.read_text().replace(current.split('"')[1], legacy))
        result = dnnevo.resume(out, task, generations=3, progress=False)
        assert len(result.history["best"]) == 3


def legacy_digest(task, target) -> str:
    """The digest a run made before recorded: the source alone (and, for a task class, the
    environment's attributes and the rollout's settings, as now)."""
    if isinstance(task, ClosedLoop):
        return task.digests()[1]
    return hashlib.sha256(inspect.getsource(target).encode()).hexdigest()


@pytest.mark.parametrize("setting, message", [
    (dict(max_steps=0), "max_steps is 0; expected a whole number, at least 1"),
    (dict(max_steps=-1), "max_steps is -1; expected a whole number, at least 1"),
    (dict(max_steps=10, episodes=0), "episodes is 0; expected a whole number, at least 1"),
    (dict(max_steps=10, substeps=0), "substeps is 0; it must be >= 1"),
    (dict(max_steps=10, dt=-0.1), "dt is -0.1; it must be finite and > 0"),
    (dict(max_steps=10, method="rk5"), 'method is "rk5"; expected "euler" or "rk4"'),
])
def test_a_closed_loop_with_bad_settings_is_refused_when_made(tmp_path, setting, message) -> None:
    module = load(tmp_path, "digest_settings", MODULE)
    with pytest.raises(dnnevo.DnnevoError, match=message.replace("(", r"\(").replace(")", r"\)")):
        ClosedLoop(module.Seeker(), **setting)
    assert np.isfinite(ClosedLoop(module.Seeker(), max_steps=10)(
        [dnnevo.Network.random(3, 1, seed=0)])).all()


EDGES = '''
import dataclasses
import functools

STEPS = 200
GAIN = 2.0
steps = 50  # a script's variable, named like an attribute the class reads


@dataclasses.dataclass(frozen=True)
class Params:
    speed: float = 0.1


PARAMS = Params(speed=0.1)


def double(x):
    return 2 * x


HANDLERS = {double: "x2"}
TREE = {"leaf": 1}
TREE["self"] = TREE


@functools.lru_cache(maxsize=None)
def cached(x):
    return x * GAIN


def decorate(function):
    @functools.wraps(function)
    def wrapper(*args):
        return function(*args)
    return wrapper


@decorate
def wrapped_fitness(networks):
    return [GAIN] * len(networks)


def fitness(networks, horizon=STEPS):
    return [horizon + cached(1) + PARAMS.speed + len(HANDLERS) + len(TREE)] * len(networks)


class Task:
    horizon = STEPS

    def __init__(self):
        self.steps = 3

    @property
    def level(self):
        return self._level

    @level.setter
    def level(self, value):
        self._level = value * GAIN
'''


@pytest.mark.parametrize("edit, task", [
    (("STEPS = 200", "STEPS = 100"), "fitness"),     # a default argument
    (("STEPS = 200", "STEPS = 100"), "Task"),        # a class's data attribute
    (("return x * GAIN", "return x * GAIN * 2"), "fitness"),  # a helper behind lru_cache
    (("GAIN = 2.0", "GAIN = 3.0"), "wrapped_fitness"),        # a decorated task
    (("GAIN = 2.0", "GAIN = 3.0"), "Task"),          # a property's setter
    (("PARAMS = Params(speed=0.1)", "PARAMS = Params(speed=0.2)"), "fitness"),  # a dataclass
])
def test_what_a_task_reads_besides_its_body_is_covered(tmp_path, edit, task) -> None:
    before = load(tmp_path, "digest_edges_a", EDGES)
    after = load(tmp_path, "digest_edges_b", EDGES.replace(*edit))
    assert task_source(getattr(before, task)) != task_source(getattr(after, task)), edit


def test_an_attribute_is_not_a_global_and_a_container_may_hold_itself(tmp_path) -> None:
    module = load(tmp_path, "digest_edges_c", EDGES)
    text = task_source(module.Task)
    assert "# steps" not in text  # self.steps is an attribute; the module's steps is not read
    assert 'TREE [ "self" ] = TREE' in task_source(module.fitness)  # its statements, no endless walk
    assert task_source(module.Task) == task_source(load(tmp_path, "digest_edges_d",
                                                        EDGES.replace("steps = 50", "steps = 60")).Task)


def test_the_digest_is_the_same_in_every_process(tmp_path) -> None:
    (tmp_path / "digest_edges_e.py").write_text(EDGES)
    code = ("import hashlib, digest_edges_e as m; from dnnevo.closedloop.source import task_source; "
            "print(hashlib.sha256(task_source(m.fitness).encode()).hexdigest())")
    digests = {subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True,
                              env={**os.environ, "PYTHONHASHSEED": seed}, check=True).stdout
               for seed in ("0", "1", "2")}
    assert len(digests) == 1, digests


def test_old_runs_keep_their_task_when_an_analysis_attribute_is_added(tmp_path) -> None:
    plain = load(tmp_path, "digest_old_a", MODULE)
    recorded = ClosedLoop(plain.Seeker(), max_steps=50).digests()[1]  # how a run recorded it before
    declared = MODULE.replace("    success_rate = 0.9\n", "    success_rate = 0.9\n" + ANALYSIS).replace(
        "import numpy as np\n", "import numpy as np\nfrom dnnevo.tasks.protocol import Analysis\n", 1)
    analysed = load(tmp_path, "digest_old_a", declared)
    assert recorded in ClosedLoop(analysed.Seeker(), max_steps=50).digests()
    # And an analysis attribute on a base class leaves its subclasses' tasks as they were.
    assert task_source(analysed.Ruleless).replace("digest_old_a", "") == \
        task_source(plain.Ruleless).replace("digest_old_a", "")


RUNTIME = '''
import enum
import functools

import numpy as np

PENALTY = 1.0
CACHE = {}


class Color(enum.Enum):
    RED = 1
    BLUE = 2


MODE = Color.RED


def scale(x, k):
    return k * x


HALF = functools.partial(scale, k=0.5)


def make(gain):
    def apply(x):
        return gain * x
    return apply


AMPLIFY = make(2.0)
PICK = (scale, make)


class Raising:
    def __getattr__(self, name):
        raise RuntimeError("no attributes here")


ODD = Raising()


def penalised(function):
    @functools.wraps(function)
    def wrapper(networks):
        return [v - PENALTY for v in function(networks)]
    return wrapper


@penalised
def fitness(networks):
    CACHE[len(networks)] = True
    return [HALF(AMPLIFY(1.0)) + (MODE is Color.RED) + len(PICK) + (ODD is not None)] * len(networks)


class Counted:
    made = 0

    def __init__(self):
        type(self).made += 1
'''


@pytest.mark.parametrize("edit", [
    ("PENALTY = 1.0", "PENALTY = 2.0"),        # read by the decorator's wrapper
    ("MODE = Color.RED", "MODE = Color.BLUE"),  # an enum constant
    ("HALF = functools.partial(scale, k=0.5)", "HALF = functools.partial(scale, k=0.25)"),
    ("AMPLIFY = make(2.0)", "AMPLIFY = make(3.0)"),  # a closure
    ("PICK = (scale, make)", "PICK = (make, scale)"),
])
def test_what_a_module_s_statements_make_is_covered(tmp_path, edit) -> None:
    before = load(tmp_path, "digest_runtime_a", RUNTIME)
    after = load(tmp_path, "digest_runtime_b", RUNTIME.replace(*edit))
    assert task_source(before.fitness) != task_source(after.fitness), edit


def test_what_a_task_holds_at_run_time_is_not_an_edit(tmp_path) -> None:
    module = load(tmp_path, "digest_runtime_c", RUNTIME)
    before, counted = task_source(module.fitness), task_source(module.Counted)
    module.fitness([1, 2, 3])  # fills the cache
    module.Counted(), module.Counted()  # counts
    assert task_source(module.fitness) == before and task_source(module.Counted) == counted
    assert "CACHE = { }" in before and "# ODD" in before  # an object that refuses lookups is read safely


def test_an_environment_that_holds_itself_is_wrapped() -> None:
    env = FarSeeker()
    env.graph = {"leaf": 1}
    env.graph["parent"] = env.graph
    assert len(ClosedLoop(env, max_steps=10).digests()) == 4


def test_runs_begun_with_numpy_settings_keep_the_digest_they_recorded() -> None:
    """A NumPy dt is now recorded as the Python number it holds; a run begun with one before
    recorded it by its NumPy form, and is still accepted."""
    from dnnevo.closedloop.far_seeker import FarSeeker
    from dnnevo.closedloop.source import fingerprint

    loop = ClosedLoop(FarSeeker(), max_steps=10, dt=np.float64(0.05))
    assert loop.settings["dt"] == 0.05 and type(loop.settings["dt"]) is float
    head, _, settings = loop.fitness_source.rpartition("\n")
    # (recorded, as every digest then, with the source as written: comments and layout counted)
    head = head.replace(task_source(FarSeeker), task_source(FarSeeker, raw=True), 1)
    before = head + "\n" + settings.replace(fingerprint(0.05), fingerprint(np.float64(0.05)))
    assert before != loop.fitness_source
    assert hashlib.sha256(before.encode()).hexdigest() in loop.digests()
    plain = ClosedLoop(FarSeeker(), max_steps=10, dt=0.05)
    assert plain.digest() == loop.digest() and len(plain.digests()) < len(loop.digests())


def test_a_class_preset_is_not_part_of_the_task_unless_its_code_reads_it(tmp_path) -> None:
    """``preset`` says where a new run starts (config.toml records what a run used), so editing it
    keeps the runs evolved with the class; a class whose own code reads it is another matter."""
    base = MODULE + "\n\nclass Started(Seeker):\n    preset = {'size': 3}\n"
    reader = ("\n\nclass Reader(Seeker):\n    preset = {'size': 3}\n\n"
              "    def reset(self, episodes, rng):\n        self.size = self.preset['size']\n"
              "        return super().reset(episodes, rng)\n")
    # Read from outside the class: by a base class, by getattr, by a helper of the module.
    based = (MODULE + "\n\nclass Base(Seeker):\n    def reset(self, episodes, rng):\n"
             "        self.size = self.preset['size']\n        return super().reset(episodes, rng)\n"
             "\n\nclass Sub(Base):\n    preset = {'size': 3}\n")
    by_name = MODULE + "\n\nclass Named(Seeker):\n    preset = {'size': 3}\n    size = getattr(object, 'preset', 0)\n"
    # Sharing its line with code that counts, it stays: that code must.
    shared = MODULE + "\n\nclass Semi(Seeker):\n    preset = {'size': 3}; goal = 1.0\n"
    for name, text, cls in [("digest_preset", base, "Started"), ("digest_reader", MODULE + reader, "Reader"),
                            ("digest_based", based, "Sub"), ("digest_named", by_name, "Named"),
                            ("digest_semi", shared, "Semi")]:
        before = task_source(getattr(load(tmp_path, name, text), cls))
        after = task_source(getattr(load(tmp_path, name, text.replace("{'size': 3}", "{'size': 5}")), cls))
        assert (before == after) == (cls == "Started"), cls
        assert ("preset" in before) == (cls != "Started"), cls
    semi = task_source(load(tmp_path, "digest_semi", shared.replace("goal = 1.0", "goal = 3.0")).Semi)
    assert semi != before


def test_runs_recorded_while_a_preset_counted_still_open(tmp_path) -> None:
    """For a while a class's preset was part of its digest: a ClosedLoop still accepts the
    digests of that time, the source as written and by its tokens, with the preset in."""
    import hashlib

    module = load(tmp_path, "digest_kept", MODULE + "\n\nclass Started(Seeker):\n    preset = {'size': 3}\n")
    loop = ClosedLoop(module.Started(), episodes=2, max_steps=50)
    rest = [loop._parts["attributes"], loop._parts["settings"]]
    for raw in (True, False):
        text = task_source(module.Started, raw=raw, keep=("preset",))
        assert "preset" in text
        assert hashlib.sha256("\n".join([text, *rest]).encode()).hexdigest() in loop.digests()
    assert "preset" not in task_source(module.Started)


def test_a_digest_recorded_with_the_source_as_written_is_known_without_the_digest_code(tmp_path) -> None:
    """The digest runs recorded before comments and layout were left out, made here from the
    class's source as Python gives it (no dnnevo code makes the text): still accepted."""
    import hashlib
    import inspect

    text = ("import numpy as np\n\n\nclass Plain:  # a comment\n    \"\"\"Its docstring.\"\"\"\n\n"
            "    observation_size = 1\n\n    def reset(self, episodes, rng):\n"
            "        return np.zeros((len(episodes), 1))\n\n    def step(self, rates, active):\n"
            "        n = len(rates)\n        return np.zeros((n, 1)), np.ones(n), np.zeros(n, bool)\n")
    module = load(tmp_path, "digest_written", text)
    loop = ClosedLoop(module.Plain(), episodes=2, max_steps=50)
    written = inspect.getsource(module.Plain)
    assert written.startswith("class Plain:  # a comment\n")
    recorded = hashlib.sha256("\n".join([written, loop._parts["attributes"], loop._parts["settings"]]).encode())
    assert recorded.hexdigest() in loop.digests() and recorded.hexdigest() != loop.digest()
