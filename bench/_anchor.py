"""The hand-written C population integrator that bench/integrate.py holds dnnevo against.

It is not part of dnnevo: it lives in the workplace's `shared/anchors/` folder next to the
repository (`../shared/anchors` from the repository root), or wherever `--anchor DIR` or the
environment variable DNNEVO_ANCHOR points. `bash c/build.sh` there builds it with gcc for this
CPU (SIMD across networks, libmvec's vector exp, -ffast-math, OpenMP on 2 threads).
"""

from __future__ import annotations

import importlib
import os
import subprocess
import sys
from pathlib import Path

ENV = "DNNEVO_ANCHOR"
DEFAULT = Path(__file__).resolve().parent.parent.parent / "shared" / "anchors"


def locate(path: str | None) -> Path | None:
    """The anchor folder: `path`, else $DNNEVO_ANCHOR, else ../shared/anchors; None if the
    default is missing. A folder given explicitly must exist."""
    chosen = path or os.environ.get(ENV)
    if chosen:
        folder = Path(chosen)
        if not (folder / "impl_c.py").is_file():
            raise SystemExit(f"error: {folder} holds no C anchor (impl_c.py is missing)")
        return folder
    return DEFAULT if (DEFAULT / "impl_c.py").is_file() else None


def load(folder: Path, build: bool = True, env: dict | None = None):
    """Builds the anchor (`bash c/build.sh`, a few seconds; with `env` as its environment, for
    example ANCHOR_MARCH) unless `build` is false, and returns its `impl_c` module, whose
    `run_simd_omp(params, T)` integrates a population on 2 threads."""
    if build:
        built = subprocess.run(["bash", str(folder / "c" / "build.sh")], capture_output=True,
                               text=True, env=env)
        if built.returncode != 0:
            raise SystemExit(f"error: building the C anchor failed:\n{built.stderr.strip()}")
    sys.path.insert(0, str(folder))
    try:
        return importlib.import_module("impl_c")
    finally:
        sys.path.remove(str(folder))


def params(tau, theta, weights, sensor_weights, state) -> dict:
    """The anchor's parameter dict for stacked arrays (P, N), (P, N), (P, N, N), (P, N, 2),
    (P, N)."""
    return dict(W=weights, theta=theta, tau=tau, S=sensor_weights, v0=state,
                N=tau.shape[1], P=tau.shape[0])
