"""An independent, plain NumPy reference for the CTRNN equation of dnnevo.

Written straight from the model (docs/paper.md, "The network"), not from the Rust code, so
that the tests can check dnnevo against a second implementation. It does not import dnnevo.

The model, for N neurons and M sensors::

    dv/dt = (-v + W f(v - theta) + S I) / tau,        f(x) = 1 / (1 + exp(-x))

* ``v`` (N,) is the state, ``tau`` (N,) the time constants (> 0), ``theta`` (N,) the thresholds;
* ``W`` (N, N) are the connection weights, ``W[i, j]`` from neuron j to neuron i;
* ``S`` (N, M) are the sensor weights, ``S[i, k]`` from sensor k to neuron i;
* ``I`` (M,) is the input, held constant over a row of ``substeps`` integration steps.

Forward Euler: ``v <- v + dt * dv/dt``. RK4: the classical fourth-order Runge-Kutta step of the same
equation with ``I`` held fixed.

Every function works on one network or on a batch of P networks: the parameters then carry a
leading axis P (``tau`` (P, N), ``W`` (P, N, N), ``S`` (P, N, M), ``v`` (P, N)) and ``einsum`` with
``...`` broadcasts over it.
"""

from __future__ import annotations

import numpy as np

__all__ = ["sigmoid", "derivative", "euler_step", "rk4_step", "step", "run"]


def sigmoid(x):
    """The logistic firing rate ``1 / (1 + exp(-x))``; 0 (not a warning) where exp overflows."""
    with np.errstate(over="ignore"):
        return 1.0 / (1.0 + np.exp(-x))


def derivative(v, tau, theta, weights, sensor_weights, inputs):
    """``dv/dt`` for states ``v`` (..., N) and inputs (..., M)."""
    rates = sigmoid(v - theta)
    recurrent = np.einsum("...ij,...j->...i", weights, rates)
    sensory = np.einsum("...ik,...k->...i", sensor_weights, inputs)
    return (-v + recurrent + sensory) / tau


def euler_step(v, dt, params, inputs):
    """One forward-Euler step of size ``dt``; ``params`` is (tau, theta, weights, sensor_weights)."""
    return v + dt * derivative(v, *params, inputs)


def rk4_step(v, dt, params, inputs):
    """One classical RK4 step of size ``dt`` with the input held constant."""
    k1 = derivative(v, *params, inputs)
    k2 = derivative(v + 0.5 * dt * k1, *params, inputs)
    k3 = derivative(v + 0.5 * dt * k2, *params, inputs)
    k4 = derivative(v + dt * k3, *params, inputs)
    return v + (dt / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)


def step(method):
    """The step function named ``method`` ("euler" or "rk4")."""
    try:
        return {"euler": euler_step, "rk4": rk4_step}[method]
    except KeyError:
        raise ValueError(f"method is {method!r}; expected 'euler' or 'rk4'") from None


def run(tau, theta, weights, sensor_weights, inputs, state=None, *, dt=0.1, substeps=1,
        method="euler"):
    """Integrates from ``state`` (default zeros) over the rows of ``inputs``.

    Single network: ``inputs`` is (T, M) and the result is the states (T, N) recorded after each
    row. Batch: the parameters have a leading axis P, ``inputs`` is (T, M), shared by every
    network, or (P, T, M), one sequence per network, and the result is (P, T, N).
    Each input row is held for ``substeps`` steps of size ``dt``.
    """
    tau = np.asarray(tau, dtype=np.float64)
    theta = np.asarray(theta, dtype=np.float64)
    weights = np.asarray(weights, dtype=np.float64)
    sensor_weights = np.asarray(sensor_weights, dtype=np.float64)
    inputs = np.asarray(inputs, dtype=np.float64)
    params = (tau, theta, weights, sensor_weights)
    v = np.zeros_like(tau) if state is None else np.array(state, dtype=np.float64)
    do_step = step(method)

    batched = tau.ndim == 2
    if batched and inputs.ndim == 3:
        rows = np.moveaxis(inputs, 1, 0)  # (T, P, M): row t holds every network's input
    else:
        rows = inputs  # (T, M), broadcast over the batch by einsum

    out = np.empty((len(rows),) + v.shape)
    for t, row in enumerate(rows):
        for _ in range(substeps):
            v = do_step(v, dt, params, row)
        out[t] = v
    return np.moveaxis(out, 0, 1) if batched else out
