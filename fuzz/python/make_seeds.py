"""Makes the seed files of ``fuzz/corpus/``: small valid files written by dnnevo itself.

    python fuzz/python/make_seeds.py            # rewrites the seeds (named seed-*), nothing else

The seeds are one tiny run (``dnnevo run sequence-1bit --quick``, 4 individuals, 3 generations),
one tiny sweep, each preset's quick config as the JSON the core reads, the two shipped landmark
worlds and four job results of the reference reproduction (``docs/results``). Files the fuzzers
found (named after what they found) are left alone.
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
CORPUS = ROOT / "fuzz" / "corpus"
TINY = ["--set", "population=4", "--set", "generations=3", "--set", "size=2"]
RESULTS = ("landmark-robot", "nav1d-system", "landmark", "nav1d-near", "reactive-navigation-hand")


def dnnevo(*args: object) -> None:
    subprocess.run([sys.executable, "-m", "dnnevo", *map(str, args)], check=True,
                   capture_output=True, text=True)


def put(reader: str, name: str, data: bytes | str) -> None:
    folder = CORPUS / reader
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / name
    path.write_bytes(data.encode() if isinstance(data, str) else data)
    print(f"{path.relative_to(ROOT)}: {path.stat().st_size} bytes")


def main() -> None:
    from dnnevo import presets

    with tempfile.TemporaryDirectory() as tmp:
        run = Path(tmp) / "run"
        dnnevo("run", "sequence-1bit", "--quick", *TINY, "--seed", "3", "--out", run)
        put("network", "seed-best.json", (run / "best.json").read_bytes())
        put("checkpoint", "seed-checkpoint.json", (run / "checkpoint.json").read_bytes())
        put("config", "seed-config.toml", (run / "config.toml").read_bytes())
        put("log", "seed-log.csv", (run / "log.csv").read_bytes())
        state = json.loads((run / "checkpoint.json").read_text())["state"]
        put("ga_state", "seed-ga-state.json", state["evolution"])
        put("run_config", "seed-run.json", json.dumps(state["config"]))
        sweep = Path(tmp) / "sweep"
        dnnevo("sweep", "sequence-1bit", "--quick", *TINY, "--seeds", "0", "--eval-trials", "4",
               "--no-dt-check", "--out", sweep)
        put("sweep", "seed-sweep.json", (sweep / "sweep.json").read_bytes())
    for name in ("sequence-1bit", "nav1d-near", "landmark"):
        config = presets.get(name, quick=True)
        put("run_config", f"seed-{name}.json", config.to_json())
    for n in (1, 2):
        shutil.copy(ROOT / "crates" / "sim2d" / "worlds" / f"landmark{n}.toml",
                    CORPUS / "world" / f"seed-landmark{n}.toml")
    results = ROOT / "docs" / "results"
    put("reproduce", "seed-reproduce.json", (results / "reproduce.json").read_bytes())
    put("provenance", "seed-provenance.json", (results / "provenance.json").read_bytes())
    for name in RESULTS:
        put("results", f"seed-{name}-0.json", (results / name / "seed-0.json").read_bytes())


if __name__ == "__main__":
    main()
