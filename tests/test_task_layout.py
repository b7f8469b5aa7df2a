"""A Python task's digest counts its code, not its layout
(:func:`dnnevo.closedloop.source.normalised`): comments, blank lines, line continuations, the
width of spaces and indentation, docstrings and the way a string is written leave it as it was;
any other token changes it; the text is the same on Python 3.11 to 3.13; and runs recorded
before, with the source as written, still open."""

from __future__ import annotations

import dataclasses
import hashlib
import io
import keyword
import re
import tokenize
from pathlib import Path

import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

import dnnevo
from dnnevo import ConfigError
from dnnevo.closedloop import ClosedLoop
from dnnevo.closedloop.source import normalised, task_source
from test_closedloop import dnnevo_command
from test_task_digest import MODULE, load

# What every Python from 3.11 to 3.13 makes of SAMPLE (3.12 on reads f-strings as many tokens,
# 3.11 splits a name with a combining mark): one text, so a run evolved on one opens on another.
SAMPLE = '''\
import numpy as np  # a comment after code

SCALE = {'far': 5.0,   # a comment inside brackets
         "near": 1.5e-3}
cafe\u0301 = 0x1F + 0o17 + 0b1 + 1_000 + 2j


@np.vectorize
def speed(x, *, gain=.5, name=r'\\d+' "tail" u"\\xe9"):
    """A docstring, left out."""
    label = f"{name!r:>{int(gain * 10)}} {x:.3f} {'inner'} \u00e9"
    block = f"""
{label}
    """
    if x > 0 and \\
            x < 10: return gain * x
    elif x == 0:
        pass
    else:
        return [  # a list split over lines
            -x, x ** 2,
        ]
    'a string alone, left out too'
    return b'\\x00bytes' + rb"\\raw"


class Task(object):
    observation_size = 1 ; rows = None

    def step(self, rates, active):
        return np.sign(rates[:, 0] - rates[:, 1])[:, None], lambda: 0, {**SCALE}
'''

EXPECTED = '''\
import numpy as np
SCALE = { "far" : 5.0 , "near" : 1.5e-3 }
cafe\u0301 = 0x1F + 0o17 + 0b1 + 1_000 + 2j
@ np . vectorize
def speed ( x , * , gain = .5 , name = "\\\\d+" "tail" "\\xe9" ) :
    label = f"{name!r:>{int(gain * 10)}} {x:.3f} {'inner'} \u00e9"
    block = f"""
{label}
    """
    if x > 0 and x < 10 : return gain * x
    elif x == 0 :
        pass
    else :
        return [ - x , x ** 2 , ]
    return b'\\x00bytes' + b'\\\\raw'
class Task ( object ) :
    observation_size = 1 ; rows = None
    def step ( self , rates , active ) :
        return np . sign ( rates [ : , 0 ] - rates [ : , 1 ] ) [ : , None ] , lambda : 0 , { ** SCALE }'''


def test_the_text_is_the_same_on_every_python() -> None:
    assert normalised(SAMPLE) == EXPECTED


def test_source_that_does_not_parse_alone_is_kept_as_it_is() -> None:
    cut = "    key=lambda x: x,)\n"  # a lambda's line, as inspect finds it inside a call
    assert normalised(cut) == cut
    # An indented piece parses in a block, and a string's value is kept whatever its lines.
    assert normalised('    class A:\n        x = """\nb"""\n') == '    class A :\n        x = "\\nb"'


# Edits that change nothing Python runs: each keeps the digest of the class, its subclass and
# the fitness function that MODULE holds (test_task_digest.py).
LAYOUT = [
    ("    observation_size = 1\n", "    observation_size = 1\n\n\n"),            # blank lines
    ("    success_rate = 0.9\n", "    success_rate = 0.9  # from the paper\n"),  # a comment
    ("    def step(", "    # moves towards the light\n        # (indented oddly)\n    def step("),
    ("class Seeker:\n", 'class Seeker:\n    """Seeks the light."""\n\n'),      # a docstring
    ("self.x += SPEED * (rates[:, 1] - rates[:, 0])", "self.x+=SPEED*(rates[:,1]-rates[:,0])"),
    ("        return towards(self.light, self.x)\n",                            # split in brackets
     "        return towards(\n            self.light,  # the light\n            self.x)\n"),
    ("distance = np.abs(self.light - self.x)", "distance = \\\n        np.abs(self.light - self.x)"),
    ('LIMITS = {"far": 5.0}', "LIMITS = {\n    'far':  5.0  # metres\n}"),    # a constant's layout
    ("return np.sign(light - x)[:, None]", "return np.sign( light-x )[ :,None ]"),  # a helper's
    ("SPEED = 0.1\n", "SPEED = 0.1\n\n\n# the module's own comment\n"),
]


def reindented(text: str, unit: str) -> str:
    """``text`` with each level of four spaces of indentation made ``unit``."""
    return re.sub(r"^((?:    )+)", lambda m: unit * (len(m.group(1)) // 4), text, flags=re.M)


def digests(module) -> tuple[str | None, ...]:
    return (*(task_source(getattr(module, name)) for name in ("Seeker", "Ruleless", "fitness")),
            ClosedLoop(module.Seeker(), max_steps=50).digest())


@pytest.mark.parametrize("edit", [*LAYOUT, "two spaces", "tabs"])
def test_layout_comments_and_docstrings_keep_the_digest(tmp_path, edit) -> None:
    before = load(tmp_path, "layout_a", MODULE)
    if isinstance(edit, tuple):
        assert edit[0] in MODULE
        edited = MODULE.replace(*edit)
    else:
        edited = reindented(MODULE, "  " if edit == "two spaces" else "\t")
    after = load(tmp_path, "layout_b", edited)
    assert [d.replace("layout_b", "layout_a") for d in digests(after)[:3]] == list(digests(before)[:3])
    assert digests(after)[3] == digests(before)[3]


# Edits that change what Python runs, however small: each changes the class's digest.
BEHAVIOUR = [
    ("SPEED = 0.1", "SPEED = 0.2"),                                  # a constant
    ("SPEED = 0.1", "SPEED = 0.10"),                                 # a number as written counts
    ("self.light - self.x)\n", "self.x - self.light)\n"),            # operands swapped
    ("distance < 0.05", "distance <= 0.05"),                         # an operator
    ('LIMITS["far"], LIMITS["far"]', 'LIMITS["far"], LIMITS["near"]'),  # a string's value
    ("return lengths < 50", "return lengths < 50 if True else 0"),   # tokens added
    ("    def success(", "    @staticmethod\n    def success(_, "),      # a decorator
]


@pytest.mark.parametrize("edit", BEHAVIOUR)
def test_any_other_edit_changes_the_digest(tmp_path, edit) -> None:
    assert edit[0] in MODULE
    before = load(tmp_path, "behaviour_a", MODULE)
    after = load(tmp_path, "behaviour_b", MODULE.replace(*edit))
    assert task_source(after.Seeker) != task_source(before.Seeker).replace("behaviour_a", "behaviour_b")
    loops = (ClosedLoop(m.Seeker(), max_steps=50) for m in (before, after))
    assert next(loops).digest() != next(loops).digest()


def logical_lines(source: str) -> list[tuple[int, list[str]]]:
    """``source``'s logical lines: each one's block depth and its tokens (no f-strings, which
    3.12 on splits into tokens)."""
    lines: list[tuple[int, list[str]]] = []
    depth, words = 0, []
    for token in tokenize.generate_tokens(io.StringIO(source).readline):
        if token.type == tokenize.INDENT:
            depth += 1
        elif token.type == tokenize.DEDENT:
            depth -= 1
        elif token.type == tokenize.NEWLINE:
            lines.append((depth, words))
            words = []
        elif token.type not in (tokenize.NL, tokenize.COMMENT, tokenize.ENDMARKER):
            words.append(token.string)
    return lines


BASE = logical_lines(MODULE)


def written(lines: list[tuple[int, list[str]]], draw=None) -> str:
    """``lines`` as source: plainly (one space between tokens, four a block), or laid out as
    ``draw`` chooses: any indentation, spaces, comments, blank lines, lines split in brackets
    or by a backslash."""
    pick = (lambda options: options[0]) if draw is None else (lambda options: draw(st.sampled_from(options)))
    unit = pick(["    ", "  ", " ", "\t", "        "])
    text = ""
    for depth, words in lines:
        for _ in range(0 if draw is None else draw(st.integers(0, 2))):
            text += pick(["\n", "   \n", "# a comment\n", "          # an indented comment\n"])
        text += unit * depth
        brackets = 0
        for i, word in enumerate(words):
            if i:
                inside = ["\n", "\n  ", "  # a note\n            "] if brackets else [" \\\n   ", " \\\n"]
                text += pick([" ", "  ", "\t", *inside])
            text += word
            brackets += (word in ("(", "[", "{")) - (word in (")", "]", "}"))
        text += pick(["\n", "  # trailing\n", "   \n"])
    return text


@settings(max_examples=100, deadline=None, database=None, derandomize=True)
@given(data=st.data())
def test_any_layout_of_a_module_has_its_text(data) -> None:
    laid_out = written(BASE, data.draw)
    compile(laid_out, "<laid out>", "exec")
    assert normalised(laid_out) == normalised(MODULE)


NAMES = st.from_regex(r"[a-z_][a-z0-9_]{0,5}", fullmatch=True).filter(lambda n: not keyword.iskeyword(n))
TOKENS = st.one_of(NAMES, st.integers(0, 10**6).map(str), st.floats(0, 1e6).map(repr),
                   st.sampled_from(["+", "-", "*", "/", "<", ">", "==", "%"]),
                   st.text(max_size=5).map(lambda s: repr(s)))


@settings(max_examples=200, deadline=None, database=None, derandomize=True,
          suppress_health_check=[HealthCheck.filter_too_much])
@given(place=st.integers(0, 10**6), new=TOKENS)
def test_any_other_token_changes_the_text(place, new) -> None:
    """One token replaced by another of a different value, where the module still compiles."""
    spots = [(i, j) for i, (_, words) in enumerate(BASE) for j, word in enumerate(words)
             if not keyword.iskeyword(word)]
    i, j = spots[place % len(spots)]
    old = BASE[i][1][j]
    assume(new != old and not (old[0] in "'\"" and new[0] in "'\"" and eval(old) == eval(new)))
    changed = [(depth, [new if (k, m) == (i, j) else w for m, w in enumerate(words)])
               for k, (depth, words) in enumerate(BASE)]
    source = written(changed)
    try:
        compile(source, "<changed>", "exec")
    except SyntaxError:
        assume(False)
    assert normalised(source) != normalised(MODULE)


# Runs recorded before comments and layout were left out recorded the source as written.


def recorded_before(loop: ClosedLoop, cls: type) -> tuple[str, str]:
    """The digest, and the source part's, that a run of ``loop`` recorded before."""
    source = task_source(cls, raw=True)
    text = loop.fitness_source.replace(task_source(cls), source, 1)
    return hashlib.sha256(text.encode()).hexdigest(), hashlib.sha256(source.encode()).hexdigest()


def rewrite(folder: Path, old: str, new: str) -> None:
    """``old`` made ``new`` in the run's config.toml and checkpoint."""
    for name in ("config.toml", "checkpoint.json"):
        path = folder / name
        text = path.read_text()
        assert old in text, name
        path.write_text(text.replace(old, new))


CLI = ["--set", "n_inputs=1", "--set", "size=3", "--set", "selection=rank", "--set",
       "task_params.max_steps=50", "--set", "task_params.episodes=2", "--set", "population=12",
       "--set", "generations=2"]


def test_a_run_recorded_before_still_opens_and_a_new_one_survives_a_reformatting(tmp_path) -> None:
    (tmp_path / "layout_cli.py").write_text(MODULE)
    for seed in ("0", "1"):
        run = dnnevo_command(tmp_path, "run", "python:layout_cli.Seeker", "--seed", seed, *CLI)
        assert run.returncode == 0, run.stderr
    old, new = (tmp_path / "runs" / f"layout_cli.Seeker-seed{s}" for s in (0, 1))
    # Seed 0 as a run made before: its digests are those of the source as written.
    module = load(tmp_path, "layout_cli", MODULE)
    loop = ClosedLoop(module.Seeker(), episodes=2, max_steps=50)
    assert loop.digest() in (old / "config.toml").read_text()
    digest, part = recorded_before(loop, module.Seeker)
    rewrite(old, loop.digest(), digest)
    rewrite(old, loop.part_digests()["source"], part)
    for command in (["assess", "runs/layout_cli.Seeker-seed0"],
                    ["resume", "runs/layout_cli.Seeker-seed0", "--generations", "3"]):
        r = dnnevo_command(tmp_path, *command)
        assert r.returncode in (0, 1, 3) and "another version" not in r.stderr, (command, r.stderr)
    # Seed 1, recorded now, keeps its task through a reformatting and a docstring; an edited
    # constant is still another task.
    (tmp_path / "layout_cli.py").write_text(reindented(MODULE, "  ").replace(
        "class Seeker:\n", 'class Seeker:\n  """Seeks the light."""  # documented after the run\n'))
    for command in (["assess", "runs/layout_cli.Seeker-seed1"],
                    ["resume", "runs/layout_cli.Seeker-seed1", "--generations", "3"]):
        r = dnnevo_command(tmp_path, *command)
        assert r.returncode in (0, 1, 3) and "another version" not in r.stderr, (command, r.stderr)
    (tmp_path / "layout_cli.py").write_text(MODULE.replace("SPEED = 0.1", "SPEED = 0.2"))
    r = dnnevo_command(tmp_path, "assess", "runs/layout_cli.Seeker-seed1")
    assert r.returncode == 2 and "another version of python:layout_cli.Seeker" in r.stderr, r.stderr


def test_runs_of_a_fitness_function_or_class_recorded_before_resume(tmp_path) -> None:
    module = load(tmp_path, "layout_api", MODULE)
    config = dnnevo.EvolutionConfig(population=12, generations=2, size=2, n_inputs=1, selection="rank")
    loop = ClosedLoop(module.Seeker(), episodes=2, max_steps=50)
    for task, size in ((module.fitness, 2), (loop, 3)):
        out = tmp_path / f"run-{size}"
        dnnevo.evolve(task, dataclasses.replace(config, size=size), out=out, progress=False)
        if task is loop:
            now, (before, _) = loop.digest(), recorded_before(loop, module.Seeker)
        else:
            now, before = (hashlib.sha256(t.encode()).hexdigest()
                           for t in (task_source(module.fitness), task_source(module.fitness, raw=True)))
        assert now != before
        rewrite(out, now, before)
        result = dnnevo.resume(out, task, generations=3, progress=False)
        assert len(result.history["best"]) == 3
    # A run made now resumes with the function reformatted; not with it edited.
    out = tmp_path / "run-now"
    dnnevo.evolve(module.fitness, config, out=out, progress=False)
    spaced = load(tmp_path, "layout_api", MODULE.replace("return np.full(len(networks), SPEED)",
                                                         "return np.full( len( networks ),SPEED )  # ok"))
    assert len(dnnevo.resume(out, spaced.fitness, generations=3, progress=False).history["best"]) == 3
    edited = load(tmp_path, "layout_api", MODULE.replace("np.full(len(networks), SPEED)",
                                                         "np.full(len(networks), -SPEED)"))
    with pytest.raises(ConfigError, match="not an edited python:layout_api.fitness"):
        dnnevo.resume(out, edited.fitness, generations=4, progress=False)
