"""An independent, plain NumPy reference for a chain of one-dimensional navigation trials (paper §4).

Written from the task's description (docs/paper.md, "The network" and "One-dimensional
navigation"), not from the Rust code, so that tests can check dnnevo against a second
implementation. It does not import dnnevo.

The world: a point agent on the line [-H, H] (``half_length``). A condition is ``(environment,
goal, start, landmark)``; the landmark sensor (input 0) reads 1 while ``|x - landmark| <=
landmark_width / 2``. A network with two sensors also gets the reinforcement as input 1.

The world is updated once per *tick*. In the continuous world (``world = "continuous"``, the
default) a tick is one forward-Euler step of ``dt``, ``substeps`` of them to a time step: the
agent's ``dx/dt = f(v_R - theta_R) - f(v_L - theta_L)`` is integrated with the network. In the
stepped world (``world = "stepped"``) a tick is a whole time step of ``substeps`` Euler steps with
the inputs held, and the agent moves once at its end.

One trial, from ``x = start`` and the state left by the previous trial (0 for the first one unless
a ``state`` is given):

1. moving: each tick reads the inputs at the current ``x`` (landmark; reinforcement 0),
   integrates the network for the tick, then moves
   ``x += tick_time * (f(v_R - theta_R) - f(v_L - theta_L))`` with the rates after the tick
   (``tick_time`` is ``dt``, or ``dt * substeps`` in the stepped world). The trial's moving phase
   ends when ``x >= H`` (the right end), ``x <= -H`` (the left end) or after ``max_steps`` time
   steps. The goal is reached iff the end reached is the goal's side;
2. reinforcement: ``reinforcement_steps`` more time steps with landmark input 0 and reinforcement
   1 if the goal was reached, else 0; ``x`` stays where it is. The classifier's rate
   ``f(v_C - theta_C)`` at the end is the trial's classification.

One Euler step, with the tick's inputs ``I`` held::

    v <- v + dt / tau * (-v + W f(v - theta) + S I),        f(x) = 1 / (1 + exp(-x))

with ``W[i, j]`` the weight from neuron j to neuron i and ``S[i, k]`` from sensor k to neuron i.

The chain is logged once per time step of each phase, counted from the phase's start: after every
``substeps``-th tick of the moving phase and of the reinforcement period, and after the moving
phase's last tick, which may end a partial time step. Each entry holds ``x`` and the rates after
its last tick, and the mean of its ticks' landmark inputs.
"""

from __future__ import annotations

import numpy as np

__all__ = ["DEFAULTS", "goal_score", "classify_score", "rate", "run_chain", "trial_scores"]

DEFAULTS = {
    "half_length": 20.0,
    "landmark_width": 4.0,
    "max_steps": 1000,
    "reinforcement_steps": 50,
    "left_motor": 0,
    "right_motor": 1,
    "classifier": 2,
}
"""The task's defaults (docs/paper.md), used for any key ``params`` leaves out."""


def rate(x):
    """The logistic firing rate ``1 / (1 + exp(-x))``; 0 (not a warning) where exp overflows."""
    with np.errstate(over="ignore"):
        return 1.0 / (1.0 + np.exp(-x))


def _field(condition, name):
    """A condition's field, from an object with attributes or from a dict."""
    return condition[name] if isinstance(condition, dict) else getattr(condition, name)


def run_chain(params, tau, theta, weights, sensor_weights, conditions, state=None):
    """Runs one network through a chain of trials, written as plainly as possible.

    ``params`` is the task's parameter dict (``nav1d.params(config)``: ``integrator`` with ``dt``
    and ``substeps``, and optionally the keys of :data:`DEFAULTS`). ``tau``, ``theta`` (N,),
    ``weights`` (N, N), ``sensor_weights`` (N, M) with M = 1 (landmark) or 2 (landmark,
    reinforcement). ``conditions`` are objects or dicts with ``goal``, ``start`` and
    ``landmark``.

    Returns a dict of ``x``, ``landmark``, ``reinforcement`` (T,), ``outputs`` (T, N): the
    position, the inputs the network got (the landmark input as the fraction of the time step's
    ticks that read 1; the reinforcement is 0 throughout for M = 1) and the firing rates of every
    logged time step of the chain (position and rates after the step); ``trial`` (T,) the trial
    of each step; ``moving`` (T,) whether the step was in a moving phase; ``reached`` and
    ``classification`` per trial; ``final_state`` (N,).
    """
    p = {**DEFAULTS, **params}
    integrator = params.get("integrator", {})
    if integrator.get("method", "euler") != "euler":
        raise ValueError("the reference integrates with forward Euler only")
    dt = float(integrator.get("dt", 0.1))
    substeps = int(integrator.get("substeps", 10))
    world = params.get("world", "continuous")
    if world == "continuous":
        euler_per_tick, ticks_per_step = 1, substeps
    elif world == "stepped":
        euler_per_tick, ticks_per_step = substeps, 1
    else:
        raise ValueError(f"world {world!r}; expected 'continuous' or 'stepped'")
    tick_time = dt * euler_per_tick
    h = float(p["half_length"])
    half_width = float(p["landmark_width"]) / 2.0
    left, right, classifier = int(p["left_motor"]), int(p["right_motor"]), int(p["classifier"])

    tau = np.asarray(tau, dtype=np.float64)
    theta = np.asarray(theta, dtype=np.float64)
    w = np.asarray(weights, dtype=np.float64)
    s = np.asarray(sensor_weights, dtype=np.float64)
    m = s.shape[1]
    if m not in (1, 2):
        raise ValueError(f"the network has {m} sensors; expected 1 or 2")
    v = np.zeros_like(tau) if state is None else np.array(state, dtype=np.float64)

    out = {"x": [], "landmark": [], "reinforcement": [], "outputs": [], "trial": [],
           "moving": [], "reached": [], "classification": []}

    def tick(landmark_input, reinforcement_input):
        nonlocal v
        inputs = np.array([landmark_input, reinforcement_input][:m])
        for _ in range(euler_per_tick):
            v = v + dt / tau * (-v + w @ rate(v - theta) + s @ inputs)
        return rate(v - theta)

    def log(k, x, landmark_input, reinforcement_input, rates, moving):
        out["x"].append(x)
        out["landmark"].append(landmark_input)
        out["reinforcement"].append(reinforcement_input)
        out["outputs"].append(rates)
        out["trial"].append(k)
        out["moving"].append(moving)

    for k, condition in enumerate(conditions):
        x = float(_field(condition, "start"))
        landmark = float(_field(condition, "landmark"))
        goal = _field(condition, "goal")
        end = None
        ticks = 0
        sensed_in_step = []  # the landmark inputs of the time step's ticks so far
        while end is None and ticks < int(p["max_steps"]) * ticks_per_step:
            sensed = 1.0 if abs(x - landmark) <= half_width else 0.0
            rates = tick(sensed, 0.0)
            x = x + tick_time * (rates[right] - rates[left])
            ticks += 1
            if x >= h:
                end = "right"
            elif x <= -h:
                end = "left"
            sensed_in_step.append(sensed)
            if ticks % ticks_per_step == 0 or end is not None:
                log(k, x, sum(sensed_in_step) / len(sensed_in_step), 0.0, rates, True)
                sensed_in_step = []
        reached = end == goal
        r = 1.0 if reached else 0.0
        for i in range(int(p["reinforcement_steps"]) * ticks_per_step):
            rates = tick(0.0, r)
            if (i + 1) % ticks_per_step == 0:
                log(k, x, 0.0, r if m == 2 else 0.0, rates, False)
        out["reached"].append(reached)
        out["classification"].append(float(rate(v[classifier] - theta[classifier])))

    result = {key: np.array(val) for key, val in out.items()
              if key not in ("reached", "classification")}
    result["outputs"] = result["outputs"].reshape(len(result["x"]), len(tau))
    result["reached"] = out["reached"]
    result["classification"] = out["classification"]
    result["final_state"] = v
    return result


def goal_score(reached):
    """A goal-seeking trial's score: 1 if the goal was reached, else 0."""
    return 1.0 if reached else 0.0


def classify_score(environment, classification):
    """A classifying trial's score: ``f(v_C)`` on a landmark-near trial, ``1 - f(v_C)`` on a
    landmark-far one."""
    return classification if environment == "near" else 1.0 - classification


def trial_scores(objective, conditions, chain):
    """The score of every trial of a chain run by :func:`run_chain`, for objective ``"goal"`` or
    ``"classify"``."""
    if objective == "goal":
        return [goal_score(r) for r in chain["reached"]]
    if objective == "classify":
        return [classify_score(_field(c, "environment"), f)
                for c, f in zip(conditions, chain["classification"], strict=True)]
    raise ValueError(f"objective {objective!r}; expected 'goal' or 'classify'")
