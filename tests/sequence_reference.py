"""An independent, plain NumPy reference for one trial of the sequence-learning task (paper §5).

Written from the task's description (docs/paper.md, "The network" and "Sequence learning"), not
from the Rust code, so that tests and benchmarks can check dnnevo against a second
implementation. It does not import dnnevo.

The protocol of one trial, for a target pattern ``p`` (e.g. ``"01"``, repeated forever) and one
``(delay, gap)`` pair per trigger:

* the state starts at 0 (unless a ``state`` is given);
* for each trigger ``k``:

  1. trigger window: ``trigger_steps`` time steps with input 0 (the trigger) = 1; the output
     ``f(v_0 - theta_0)`` is recorded after each time step;
  2. delay: ``delay_k`` time steps with no input;
  3. reinforcement: ``reinforcement_steps`` time steps with input 1 =
     ``R_k = 1 - mean over the window of |p_k - output|``, where ``p_k = p[k mod len(p)]``;
  4. gap: ``gap_k`` time steps with no input.

One time step holds the input for ``substeps`` forward-Euler steps of ``dt``::

    v <- v + dt / tau * (-v + W f(v - theta) + S I),        f(x) = 1 / (1 + exp(-x))

with ``W[i, j]`` the weight from neuron j to neuron i and ``S[i, k]`` from sensor k to neuron i.

A trial's performance is ``max(0, (mean_k R_k - base) / (1 - base))``, and a network's fitness
the mean performance over its trials.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "TRIGGER",
    "DELAY",
    "REINFORCE",
    "GAP",
    "decode_genomes",
    "fitness",
    "performance",
    "phases",
    "run_chain",
    "run_trial",
    "run_trials",
    "stack_networks",
]

TRIGGER, DELAY, REINFORCE, GAP = "trigger", "delay", "reinforce", "gap"


def _rate(x):
    """The logistic firing rate; 0 (not a warning) where exp overflows."""
    with np.errstate(over="ignore"):
        return 1.0 / (1.0 + np.exp(-x))


def _bits(pattern):
    if not pattern or set(pattern) - {"0", "1"}:
        raise ValueError(f"pattern is {pattern!r}; expected a non-empty string of '0' and '1'")
    return [float(c) for c in pattern]


def phases(timing, trigger_steps=10, reinforcement_steps=10):
    """The trial as a list of ``(phase, k, steps)``: trigger, delay, reinforce and gap of each
    trigger ``k`` in turn (phases of 0 steps included)."""
    out = []
    for k, (delay, gap) in enumerate(timing):
        out += [(TRIGGER, k, trigger_steps), (DELAY, k, int(delay)),
                (REINFORCE, k, reinforcement_steps), (GAP, k, int(gap))]
    return out


def run_trial(tau, theta, weights, sensor_weights, pattern, timing, **kw):
    """One trial of one network, written as plainly as possible.

    ``tau``, ``theta`` (N,), ``weights`` (N, N), ``sensor_weights`` (N, 2). Returns
    ``(r, output)``: R of each trigger (K,) and the output after every time step of the whole
    trial (T,), the last gap included. Keywords: ``trigger_steps``, ``reinforcement_steps``,
    ``dt``, ``substeps`` and the starting ``state``.
    """
    r, output, _ = _trial(tau, theta, weights, sensor_weights, pattern, timing, **kw)
    return r, output


def run_chain(tau, theta, weights, sensor_weights, links, **kw):
    """Trials run one after another without a reset, each ``(pattern, timing)`` of ``links``
    starting from the state the one before ended in (after its last gap); the first starts
    from rest. Returns the R of each link's triggers."""
    state, rs = None, []
    for pattern, timing in links:
        r, _, state = _trial(tau, theta, weights, sensor_weights, pattern, timing, state=state, **kw)
        rs.append(r)
    return rs


def _trial(tau, theta, weights, sensor_weights, pattern, timing, *, trigger_steps=10,
           reinforcement_steps=10, dt=0.1, substeps=10, state=None):
    """``run_trial``'s work; also returns the state at the end."""
    tau = np.asarray(tau, dtype=np.float64)
    theta = np.asarray(theta, dtype=np.float64)
    w = np.asarray(weights, dtype=np.float64)
    s = np.asarray(sensor_weights, dtype=np.float64)
    bits = _bits(pattern)
    v = np.zeros_like(tau) if state is None else np.array(state, dtype=np.float64)
    r = np.zeros(len(timing))
    output = []

    def time_step(inputs):
        nonlocal v
        for _ in range(substeps):
            v = v + dt / tau * (-v + w @ _rate(v - theta) + s @ inputs)
        out = _rate(v[0] - theta[0])
        output.append(out)
        return out

    for phase, k, steps in phases(timing, trigger_steps, reinforcement_steps):
        if phase == TRIGGER:
            target = bits[k % len(bits)]
            errors = [abs(target - time_step(np.array([1.0, 0.0]))) for _ in range(steps)]
            r[k] = 1.0 - sum(errors) / steps
        elif phase == REINFORCE:
            for _ in range(steps):
                time_step(np.array([0.0, r[k]]))
        else:
            for _ in range(steps):
                time_step(np.array([0.0, 0.0]))
    return r, np.array(output), v


def run_trials(params, pattern, timing, *, trigger_steps=10, reinforcement_steps=10, dt=0.1,
               substeps=10, full=False):
    """One trial of P networks at once, all with the same timing (common random numbers).

    ``params`` is ``(tau (P, N), theta (P, N), weights (P, N, N), sensor_weights (P, N, 2))``.
    Returns R (P, K). Unless ``full``, the trial stops after the last trigger window: the delay,
    reinforcement and gap after it cannot change any R.
    """
    tau, theta, w, s = (np.asarray(x, dtype=np.float64) for x in params)
    bits = _bits(pattern)
    p = tau.shape[0]
    h = dt / tau
    s_trigger = np.ascontiguousarray(s[:, :, 0])
    s_reinf = np.ascontiguousarray(s[:, :, 1])
    zero = np.zeros_like(tau)
    v = np.zeros_like(tau)
    r = np.zeros((p, len(timing)))
    plan = phases(timing, trigger_steps, reinforcement_steps)
    if not full:
        plan = plan[: 4 * (len(timing) - 1) + 1]

    def integrate(ext, steps, record=None):
        nonlocal v
        for _ in range(steps):
            for _ in range(substeps):
                drive = np.einsum("pij,pj->pi", w, _rate(v - theta))
                drive += ext
                drive -= v
                drive *= h
                v += drive
            if record is not None:
                record(_rate(v[:, 0] - theta[:, 0]))

    with np.errstate(over="ignore"):
        for phase, k, steps in plan:
            if steps == 0:
                continue
            if phase == TRIGGER:
                target = bits[k % len(bits)]
                err = np.zeros(p)

                def record(out, err=err, target=target):
                    err += np.abs(target - out)

                integrate(s_trigger, steps, record)
                r[:, k] = 1.0 - err / steps
            elif phase == REINFORCE:
                integrate(s_reinf * r[:, k, None], steps)
            else:
                integrate(zero, steps)
    return r


def performance(r, base):
    """``max(0, (mean_k R_k - base) / (1 - base))`` over the last axis of ``r``."""
    return np.maximum(0.0, (np.mean(r, axis=-1) - base) / (1.0 - base))


def fitness(params, targets, trial_timings, trials_per_target, *, perf_base=0.5, **kw):
    """Fitness (P,) and R (P, trials, K) of P networks: trial ``t`` (target-major, so
    ``targets[t // trials_per_target]``) with ``trial_timings[t]``; fitness is the mean
    performance over the trials. ``perf_base`` is a number or ``"generation-mean"``."""
    if len(trial_timings) != len(targets) * trials_per_target:
        raise ValueError("need one timing per trial: len(targets) * trials_per_target")
    r = np.stack([run_trials(params, targets[t // trials_per_target], timing, **kw)
                  for t, timing in enumerate(trial_timings)], axis=1)
    base = float(np.mean(r)) if perf_base == "generation-mean" else float(perf_base)
    if base >= 1.0:
        return np.zeros(r.shape[0]), r
    return performance(r, base).mean(axis=1), r


def stack_networks(nets):
    """``(tau, theta, weights, sensor_weights)`` of objects with those attributes, stacked
    along a leading axis P."""
    return (np.stack([np.asarray(n.tau) for n in nets]),
            np.stack([np.asarray(n.theta) for n in nets]),
            np.stack([np.asarray(n.weights) for n in nets]),
            np.stack([np.asarray(n.sensor_weights) for n in nets]))


def decode_genomes(genomes, size, n_inputs):
    """``(tau, theta, weights, sensor_weights)`` from genomes (P, G) of the modular layout: for
    each neuron in turn its tau, its theta, its M sensor weights and its N incoming weights."""
    g = np.asarray(genomes, dtype=np.float64)
    blocks = g.reshape(g.shape[0], size, 2 + n_inputs + size)
    return (np.ascontiguousarray(blocks[:, :, 0]),
            np.ascontiguousarray(blocks[:, :, 1]),
            np.ascontiguousarray(blocks[:, :, 2 + n_inputs:]),
            np.ascontiguousarray(blocks[:, :, 2:2 + n_inputs]))
