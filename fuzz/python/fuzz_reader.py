#!/usr/bin/env python3
"""The Atheris harness of one Python file reader (see ``readers.py``): coverage-guided fuzzing of
dnnevo's own Python code, libFuzzer's options and corpus folders after the reader's name.

    python fuzz/python/fuzz_reader.py READER [LIBFUZZER OPTIONS] [CORPUS FOLDERS]
    python fuzz/python/fuzz_reader.py log -max_total_time=60 /tmp/work-log fuzz/corpus/log

Any exception but :data:`readers.ALLOWED` is a finding: it propagates, and libFuzzer saves the
input as ``crash-*`` (``-artifact_prefix=`` says where). ``fuzz/run`` runs every reader.

libFuzzer runs this file again for ``-merge=1`` and ``-minimize_crash=1`` (hence its mode and
its first line), with its own options only: the reader's name goes to those runs in the
environment, as ``DNNEVO_FUZZ_READER``.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import atheris

sys.path.insert(0, str(Path(__file__).resolve().parent))

with atheris.instrument_imports(include=["dnnevo", "readers"]):
    import readers


def main() -> None:
    args = sys.argv[1:]
    if args and args[0] in readers.READERS:
        os.environ["DNNEVO_FUZZ_READER"] = args.pop(0)
    name = os.environ.get("DNNEVO_FUZZ_READER", "")
    if name not in readers.READERS:
        sys.exit(f"usage: {sys.argv[0]} READER [libFuzzer options] [corpus folders]; "
                 f"READER is one of {', '.join(readers.READERS)}")
    reader = readers.READERS[name]

    def one_input(data: bytes) -> None:
        try:
            readers.read(reader, data)
        except readers.ALLOWED:
            pass

    atheris.Setup([sys.argv[0], *args], one_input)
    atheris.Fuzz()


if __name__ == "__main__":
    main()
