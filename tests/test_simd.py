"""The integrator's kernel is chosen when the program runs; every kernel the CPU has gives the same
bits, and a bad choice is a clear error."""

from __future__ import annotations

import dataclasses
import hashlib
import os
import subprocess
import sys
from collections.abc import Iterator

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_fingerprints import numbers_only

import dnnevo
from dnnevo import presets

KERNELS = dnnevo.build_info()["kernels"]


@pytest.fixture(autouse=True)
def _restore_kernel() -> Iterator[None]:
    before = dnnevo.build_info()["kernel"]
    yield
    dnnevo.use_kernel(before)


def bits(x: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(x, dtype=np.float64).view(np.uint64)


def test_build_info_names_the_cpu_and_the_kernel_in_use() -> None:
    info = dnnevo.build_info()
    assert info["version"] == dnnevo.__version__
    assert info["kernel"] in info["kernels"] and "portable" in info["kernels"]
    assert set(info["kernels"]) <= {"portable", "avx2", "avx512", "neon"}
    assert all(isinstance(v, bool) for v in info["cpu_features"].values())
    if info["arch"] == "x86_64":
        assert ("avx2" in info["kernels"]) == (info["cpu_features"]["avx2"] and info["cpu_features"]["fma"])
        assert ("avx512" in info["kernels"]) == info["cpu_features"]["avx512f"]
    assert ("neon" in info["kernels"]) == (info["arch"] == "aarch64")
    for name in info["kernels"]:
        dnnevo.use_kernel(name)
        assert dnnevo.build_info()["kernel"] == name


def test_unknown_and_unsupported_kernels_are_errors() -> None:
    with pytest.raises(dnnevo.InvalidArgumentError, match="avx513.*portable, avx2, avx512, neon"):
        dnnevo.use_kernel("avx513")
    for name in {"avx2", "avx512", "neon"} - set(KERNELS):
        with pytest.raises(dnnevo.InvalidArgumentError, match=f"cannot run the {name} kernel"):
            dnnevo.use_kernel(name)


@settings(max_examples=40, deadline=None)
@given(
    p=st.integers(1, 40),
    n=st.integers(1, 12),
    m=st.integers(0, 3),
    steps=st.integers(1, 30),
    method=st.sampled_from(["euler", "rk4"]),
    substeps=st.integers(1, 3),
    seed=st.integers(0, 2**32 - 1),
)
def test_every_kernel_gives_the_same_states(
    p: int, n: int, m: int, steps: int, method: str, substeps: int, seed: int
) -> None:
    inputs = np.random.default_rng(seed).uniform(-3, 3, size=(steps, m))
    runs = {}
    for name in KERNELS:
        dnnevo.use_kernel(name)
        nets = [dnnevo.Network.random(n, m, seed=seed + k) for k in range(p)]  # run() moves a network on
        states = dnnevo.run_population(nets, inputs, dt=0.05, substeps=substeps, method=method)
        single = nets[0].run(inputs, dt=0.05, substeps=substeps, method=method)
        runs[name] = (bits(states), bits(single.states), bits(single.outputs))
    first = runs[KERNELS[0]]
    for name, run in runs.items():
        for a, b in zip(run, first, strict=True):
            assert np.array_equal(a, b), f"{name} differs from {KERNELS[0]}"


@settings(max_examples=20, deadline=None)
@given(
    p=st.integers(1, 40),
    n=st.integers(1, 12),
    m=st.integers(0, 3),
    steps=st.integers(1, 30),
    method=st.sampled_from(["euler", "rk4"]),
    seed=st.integers(0, 2**32 - 1),
)
def test_every_kernel_gives_the_same_states_in_f32(
    p: int, n: int, m: int, steps: int, method: str, seed: int
) -> None:
    inputs = np.random.default_rng(seed).uniform(-3, 3, size=(steps, m))
    nets = [dnnevo.Network.random(n, m, seed=seed + k) for k in range(p)]
    runs = {}
    for name in KERNELS:
        dnnevo.use_kernel(name)
        runs[name] = dnnevo.run_population(nets, inputs, dt=0.05, substeps=2, method=method,
                                           precision="f32")
    first = runs[KERNELS[0]]
    assert first.dtype == np.float64
    assert np.array_equal(first.astype(np.float32).astype(np.float64), first)  # f32 values
    for name, run in runs.items():
        assert np.array_equal(bits(run), bits(first)), f"{name} differs from {KERNELS[0]}"


@settings(max_examples=10, deadline=None)
@given(n=st.integers(1, 8), m=st.integers(0, 3), steps=st.integers(1, 30),
       method=st.sampled_from(["euler", "rk4"]), seed=st.integers(0, 2**32 - 1))
def test_a_network_run_alone_in_f32_has_its_population_s_bits(n: int, m: int, steps: int, method: str,
                                                               seed: int) -> None:
    inputs = np.random.default_rng(seed).uniform(-3, 3, size=(steps, m))
    nets = [dnnevo.Network.random(n, m, seed=seed + k) for k in range(3)]
    for name in KERNELS:
        dnnevo.use_kernel(name)
        population = dnnevo.run_population(nets, inputs, dt=0.05, substeps=2, method=method,
                                           precision="f32")
        for net, states in zip(nets, population, strict=True):
            alone = dnnevo.Network.from_json(net.to_json())
            trace = alone.run(inputs, dt=0.05, substeps=2, method=method, precision="f32")
            assert np.array_equal(bits(trace.states), bits(states)), name
            assert np.array_equal(bits(alone.state), bits(states[-1]))  # the state kept
            # The outputs are f32's own sigmoid of the f32 states, widened.
            assert np.array_equal(trace.outputs.astype(np.float32).astype(np.float64), trace.outputs)
            exact = 1.0 / (1.0 + np.exp(net.theta - trace.states))
            assert np.allclose(trace.outputs, exact, rtol=1e-6, atol=1e-7)


def test_a_batch_in_f32_steps_each_row_as_network_run_in_f32() -> None:
    nets = [dnnevo.Network.random(4, 2, seed=k) for k in range(9)]
    inputs = np.random.default_rng(3).uniform(-2, 2, size=(12, len(nets) * 2, 2))
    for name in KERNELS:
        dnnevo.use_kernel(name)
        batch = dnnevo.Batch(nets, replicas=2, substeps=3, method="rk4", precision="f32")
        assert batch.precision == "f32" and "precision='f32'" in repr(batch)
        rates = np.empty((batch.rows, batch.size))
        for row in inputs:
            batch.step(row, out=rates)
        for r in range(batch.rows):
            alone = dnnevo.Network.from_json(nets[r // 2].to_json())
            trace = alone.run(inputs[:, r], substeps=3, method="rk4", precision="f32")
            assert np.array_equal(bits(batch.states[r]), bits(trace.states[-1])), (name, r)
            assert np.array_equal(bits(rates[r]), bits(trace.outputs[-1])), (name, r)
    assert dnnevo.Batch(nets).precision == "f64"


def test_f32_is_close_to_f64_and_a_bad_precision_is_refused() -> None:
    nets = [dnnevo.Network.random(5, 2, seed=k) for k in range(20)]
    inputs = np.random.default_rng(1).uniform(-1, 1, size=(50, 2))
    f64 = dnnevo.run_population(nets, inputs)
    assert np.array_equal(bits(dnnevo.run_population(nets, inputs, precision="f64")), bits(f64))
    f32 = dnnevo.run_population(nets, inputs, precision="f32")
    assert f32.shape == f64.shape and not np.array_equal(f32, f64)
    assert np.abs(f32 - f64).max() < 1e-3  # 50 steps: rounding, not divergence
    with pytest.raises(ValueError, match='precision is "f16"; expected "f64" or "f32"'):
        dnnevo.run_population(nets, inputs, precision="f16")
    with pytest.raises(ValueError, match='precision is "f16"; expected "f64" or "f32"'):
        nets[0].run(inputs, precision="f16")
    with pytest.raises(ValueError, match='precision is "f16"; expected "f64" or "f32"'):
        dnnevo.Batch(nets, precision="f16")


TIMINGS = {"evals_per_s", "elapsed_s"}  # the log's columns that are wall times


def test_an_evolution_run_is_the_same_on_every_kernel() -> None:
    config = dataclasses.replace(presets.get("sequence-1bit"), population=40, generations=3)
    results = {}
    for name in KERNELS:
        dnnevo.use_kernel(name)
        result = dnnevo.evolve("sequence-1bit", config, seed=3, progress=False, threads=2)
        history = {k: bits(np.asarray(v)) for k, v in result.history.items() if k not in TIMINGS}
        results[name] = (history, numbers_only(result.best))
    first_history, first_best = results[KERNELS[0]]
    for name, (history, best) in results.items():
        assert best == first_best, f"{name} differs from {KERNELS[0]}"
        assert history.keys() == first_history.keys()
        for key, column in history.items():
            assert np.array_equal(column, first_history[key]), f"{name}: {key} differs from {KERNELS[0]}"


#: The kernels dnnevo has for each architecture; a CPU runs those its features allow.
ARCH_KERNELS = {"x86_64": ("portable", "avx2", "avx512"), "aarch64": ("portable", "neon")}

#: The evolution run below, pinned: its whole history (wall times aside) and champion, hashed.
#: Every kernel must give it; a change here changes every published result (CHANGELOG.md).
EVOLUTION_FINGERPRINT = "30226182fd8b36e1"


def evolution_fingerprint() -> str:
    config = dataclasses.replace(presets.get("sequence-1bit"), population=40, generations=3)
    result = dnnevo.evolve("sequence-1bit", config, seed=3, progress=False, threads=2)
    digest = hashlib.sha256()
    for key in sorted(result.history):
        if key not in TIMINGS:
            digest.update(key.encode() + bits(np.asarray(result.history[key])).tobytes())
    digest.update(numbers_only(result.best).encode())
    return digest.hexdigest()[:16]


@pytest.mark.parametrize("name", ARCH_KERNELS.get(dnnevo.build_info()["arch"], ("portable",)))
def test_every_kernel_gives_the_pinned_evolution(name: str) -> None:
    """A kernel this CPU lacks is a skip that says so in the test summary, not a silent pass."""
    if name not in KERNELS:
        pytest.skip(f"this CPU cannot run the {name} kernel, so its bits were not proven here")
    dnnevo.use_kernel(name)
    assert evolution_fingerprint() == EVOLUTION_FINGERPRINT


def run_with_simd(value: str, code: str) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "DNNEVO_SIMD": value}
    return subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120)


@pytest.mark.parametrize("name", KERNELS)
def test_the_environment_variable_forces_a_kernel(name: str) -> None:
    done = run_with_simd(name, "import dnnevo; print(dnnevo.build_info()['kernel'])")
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == name


def test_a_bad_environment_variable_fails_the_import_and_the_command_in_one_line() -> None:
    done = run_with_simd("avx513", "import dnnevo")
    assert done.returncode != 0
    assert "InvalidArgumentError" in done.stderr and "DNNEVO_SIMD" in done.stderr
    done = run_with_simd("avx513", "import sys; from dnnevo.cli.command import main; sys.exit(main())")
    assert done.returncode != 0
    env = {**os.environ, "DNNEVO_SIMD": "avx513"}
    command = subprocess.run([sys.executable, "-m", "dnnevo", "--help"], env=env, capture_output=True,
                             text=True, timeout=120)
    assert command.returncode != 0
    assert command.stderr.strip().splitlines() == [
        'dnnevo: error: DNNEVO_SIMD="avx513": unknown SIMD kernel "avx513"; '
        "choose one of portable, avx2, avx512, neon"
    ]
