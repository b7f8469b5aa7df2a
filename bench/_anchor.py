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


F32_SOURCE = Path(__file__).resolve().parent / "anchor_f32"
"""The anchor in float: ctrnn_simd_f32.c, adapted from the double anchor (its header says how)."""


class FloatAnchor:
    """The float C anchor (bench/anchor_f32), built into `folder`: `run_simd_omp(params, T)`
    integrates the population of `params` (the double anchor's dict) in float32 on 2 threads,
    with the double anchor's dt and inputs, and returns the final states (P, N) as float32."""

    def __init__(self, folder: Path, dt: float):
        import ctypes

        lib = ctypes.CDLL(str(folder / "libctrnn_simd_f32.so"))
        fp = ctypes.POINTER(ctypes.c_float)
        lib.run_popsimd_omp_f32.argtypes = [ctypes.c_int64] * 3 + [fp] * 6 + [ctypes.c_int64]
        lib.block_size_f32.restype = ctypes.c_int64
        self.BLOCK = lib.block_size_f32()
        self._lib, self._fp, self._dt = lib, fp, dt

    def run_simd_omp(self, params: dict, steps: int):
        import numpy as np

        arrays = [np.ascontiguousarray(a, dtype=np.float32) for a in
                  (params["W"], params["theta"], self._dt / params["tau"], params["S"], params["v0"])]
        out = np.empty(arrays[-1].shape, dtype=np.float32)
        pointers = [a.ctypes.data_as(self._fp) for a in (*arrays, out)]
        self._lib.run_popsimd_omp_f32(params["P"], params["N"], steps, *pointers, 2)
        return out


def load_f32(dt: float, env: dict | None = None) -> FloatAnchor:
    """Builds the float anchor (`bash anchor_f32/build.sh`, a second; `env` as for `load`) into a
    temporary folder and loads it."""
    import tempfile

    folder = Path(tempfile.mkdtemp(prefix="dnnevo-anchor-f32-"))
    built = subprocess.run(["bash", str(F32_SOURCE / "build.sh"), str(folder)], capture_output=True,
                           text=True, env=env)
    if built.returncode != 0:
        raise SystemExit(f"error: building the float C anchor failed:\n{built.stderr.strip()}")
    return FloatAnchor(folder, dt)
