"""The reduced fuzzing pass of the Python file readers (issue 48), which CI runs.

Every reader of ``fuzz/python/readers.py`` (network file, checkpoint, config.toml, log.csv,
sweep.json, a reproduction's results) reads:

- every file of its corpus, ``fuzz/corpus/READER/``: the seeds dnnevo wrote, which it must
  accept, and the inputs the fuzzers found, which pin what they found;
- the damage every reader must refuse alike (no bytes, bytes that are not UTF-8, nesting deeper
  than Python's recursion limit, ...);
- a short Hypothesis pass of its seeds with bytes cut, changed, inserted (tokens of the format,
  from ``fuzz/dicts/``) and repeated; derandomized, so that CI runs the same cases every time
  (the long run explores).

Any input may be refused, but only with a :class:`~dnnevo.errors.DnnevoError`; any other
exception fails, and so does a read that takes more than :data:`TIME_LIMIT`. The long,
coverage-guided run is ``fuzz/run`` (Atheris and cargo-fuzz; see fuzz/README.md).
"""

from __future__ import annotations

import codecs
import contextlib
import json
import signal
import sys
from collections.abc import Iterator
from pathlib import Path
from types import FrameType

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from dnnevo.errors import DnnevoError
from dnnevo.experiments import results
from dnnevo.runs import RunFileError
from dnnevo.runs.files import checked

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "fuzz" / "python"))

import readers  # noqa: E402  (fuzz/python, put on the path above)

TIME_LIMIT = 20.0
"""Seconds one read may take before it counts as a hang (a read takes milliseconds)."""

SLOW = {"results", "reproduce", "provenance"}
"""Readers that render every results table on each read (tens of milliseconds): fewer examples."""


class Hang(Exception):
    """A read took longer than :data:`TIME_LIMIT`."""


@contextlib.contextmanager
def time_limit(seconds: float) -> Iterator[None]:
    """Raises :class:`Hang` inside the block after ``seconds`` (SIGALRM; main thread only)."""
    def alarm(signum: int, frame: FrameType | None) -> None:
        raise Hang(f"a read took longer than {seconds} s")

    previous = signal.signal(signal.SIGALRM, alarm)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def read_or_refuse(name: str, data: bytes) -> bool:
    """Reads ``data`` with reader ``name``: True when it is accepted, False when it is refused
    with an allowed error; anything else, a hang included, propagates and fails the test."""
    with time_limit(TIME_LIMIT):
        try:
            readers.read(readers.READERS[name], data)
        except readers.ALLOWED:
            return False
    return True


CORPUS = [(name, path) for name, reader in readers.READERS.items() for path in sorted(reader.corpus.iterdir())]


@pytest.mark.parametrize(("name", "path"), CORPUS, ids=[f"{n}/{p.name}" for n, p in CORPUS])
def test_corpus_file_is_read_or_refused(name: str, path: Path) -> None:
    accepted = read_or_refuse(name, path.read_bytes())
    if path.name.startswith("seed-"):
        assert accepted, f"{path}: a file dnnevo wrote is refused"


#: Damage every reader must refuse with a typed error. Deep nesting and non-finite numbers
#: escaped untyped from the sweep.json and results readers before the fuzzers' findings were fixed.
DAMAGE = {
    "empty": b"",
    "not UTF-8": b"\xff\xfe{}",
    "NUL": b"\x00",
    "deep JSON array": b"[" * 100_000 + b"]" * 100_000,
    "deep JSON object": b'{"a":' * 50_000 + b"1" + b"}" * 50_000,
    "deep TOML array": b"a = " + b"[" * 100_000 + b"]" * 100_000,
    "JSON number": b"6",
    "JSON list": b"[]",
    "JSON null": b"null",
    "non-finite JSON": b'{"wall_s": 1e999, "seeds": [NaN], "tau": [Infinity]}',
}


@pytest.mark.parametrize("damage", DAMAGE)
@pytest.mark.parametrize("name", readers.READERS)
def test_damage_is_refused_with_a_typed_error(name: str, damage: str) -> None:
    assert not read_or_refuse(name, DAMAGE[damage])


def test_a_number_no_float_holds_is_refused_naming_it() -> None:
    # An integer of 400 digits in a checkpoint's history made float() raise OverflowError.
    doc = json.loads((readers.CORPUS / "checkpoint" / "seed-checkpoint.json").read_text())
    doc["history"][1]["best"] = 10**400
    with pytest.raises(RunFileError, match=r"checkpoint.json: history\[1\].best is 1000.*; expected a number a float can hold"):
        readers.read(readers.READERS["checkpoint"], json.dumps(doc).encode())


def test_a_stray_exception_of_a_reader_names_its_file(tmp_path: Path) -> None:
    # The net under every reader: a check a reader lacks still ends in a RunFileError naming the file.
    row: dict[str, float] = {}
    with pytest.raises(RunFileError, match=r"log.csv: damaged \(KeyError: 'x'\)"):
        with checked(tmp_path / "log.csv"):
            row["x"]


def test_a_result_file_whose_number_int_cannot_read_is_refused(tmp_path: Path) -> None:
    # "²".isdigit() is true, but int("²") raises ValueError.
    (tmp_path / "reproduce.json").write_bytes((readers.CORPUS / "reproduce" / "seed-reproduce.json").read_bytes())
    (tmp_path / "landmark").mkdir()
    (tmp_path / "landmark" / "seed-\u00b2.json").write_text("{}")
    with pytest.raises(DnnevoError, match="not a result file"):
        results.load(tmp_path)


def _tokens() -> list[bytes]:
    """The tokens of every format, from the fuzzers' dictionaries."""
    out = []
    for path in sorted((ROOT / "fuzz" / "dicts").glob("*.dict")):
        for line in path.read_text().splitlines():
            if line.startswith('"') and line.endswith('"'):
                out.append(codecs.escape_decode(line[1:-1].encode())[0])
    return out


TOKENS = _tokens()


@st.composite
def mutated(draw: st.DrawFn, seeds: tuple[bytes, ...]) -> bytes:
    """A seed with one to four cuts, changed bytes, inserted tokens or repeated stretches."""
    data = bytearray(draw(st.sampled_from(seeds)))
    for _ in range(draw(st.integers(1, 4))):
        kind = draw(st.sampled_from(["cut", "byte", "token", "delete", "repeat"]))
        at = draw(st.integers(0, len(data)))
        if kind == "cut":
            del data[at:]
        elif kind == "byte" and at < len(data):
            data[at] = draw(st.integers(0, 255))
        elif kind == "token":
            data[at:at] = draw(st.sampled_from(TOKENS))
        elif kind == "delete":
            del data[at:at + draw(st.integers(1, 16))]
        elif kind == "repeat":
            stretch = data[at:at + draw(st.integers(1, 64))]
            data[at:at] = stretch * draw(st.integers(1, 8))
    return bytes(data)


def _seeds(name: str) -> tuple[bytes, ...]:
    return tuple(p.read_bytes() for p in sorted(readers.READERS[name].corpus.glob("seed-*")))


@pytest.mark.parametrize("name", readers.READERS)
def test_mutated_seeds_are_read_or_refused(name: str) -> None:
    @settings(max_examples=40 if name in SLOW else 200, deadline=None, database=None, derandomize=True,
              suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
    @given(data=mutated(_seeds(name)))
    def read(data: bytes) -> None:
        read_or_refuse(name, data)

    read()


def test_a_deep_job_result_is_a_run_file_error(tmp_path: Path) -> None:
    # json.loads raised RecursionError past read_result's except clause.
    from dnnevo.experiments import jobs, plan

    job = plan.jobs([0], only=["landmark"])[0]
    path = jobs.result_path(tmp_path, job)
    path.parent.mkdir(parents=True)
    path.write_bytes(DAMAGE["deep JSON array"])
    with pytest.raises(RunFileError, match="seed-0.json"):
        jobs.read_result(tmp_path, job, jobs.Settings())


def test_a_sweep_continued_on_a_deep_manifest_is_one_line(tmp_path: Path) -> None:
    # The check for a sweep to extend read sweep.json with json.loads and let RecursionError out.
    from cli_helpers import assert_one_line_error, run_cli

    out = tmp_path / "sweep"
    out.mkdir()
    (out / "sweep.json").write_bytes(DAMAGE["deep JSON object"])
    r = run_cli("sweep", "sequence-1bit", "--quick", "--seeds", "0", "--out", out)
    assert_one_line_error(r, "sweep.json")


def test_a_lone_surrogate_escape_is_refused_naming_the_file() -> None:
    # "\ud800" in the GA state made json.loads give a str the Rust core cannot take
    # (UnicodeEncodeError on resume); a pair of surrogate escapes is a character and stays fine.
    text = (readers.CORPUS / "checkpoint" / "seed-checkpoint.json").read_text()
    doc = json.loads(text)
    doc["state"]["evolution"] = "\\ud800" + doc["state"]["evolution"]
    damaged = json.dumps(doc).replace("\\\\ud800", "\\ud800")
    assert "\\ud800{" in damaged
    with pytest.raises(RunFileError, match=r"checkpoint.json: holds a \\u escape of a lone surrogate"):
        readers.read(readers.READERS["checkpoint"], damaged.encode())


@pytest.mark.parametrize(("kind", "seed"), [("checkpoint", "seed-checkpoint.json"), ("network", "seed-best.json"),
                                            ("results", "seed-landmark-0.json")])
def test_a_key_given_twice_is_refused_naming_the_file(kind: str, seed: str) -> None:
    # json.loads, and serde_json's Value, keep the last of two equal keys: a file edited by hand
    # could hold two values of one setting, and the one read would be a guess.
    text = (readers.CORPUS / kind / seed).read_text()
    first = next(iter(json.loads(text)))  # the document's first key, given again before it
    damaged = text.replace("{", f'{{"{first}": "twice", ', 1)
    with pytest.raises(DnnevoError, match=rf'the key "{first}" appears twice in one object'):
        readers.read(readers.READERS[kind], damaged.encode())
