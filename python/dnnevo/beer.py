"""Networks written in the conventions of Beer's C++ CTRNN code.

There a neuron's state ``y`` obeys ``tau_i dy_i/dt = -y_i + sum_j w[j][i] sigma(g_j (y_j +
bias_j)) + I_i``: a bias where dnnevo has a threshold, a gain dnnevo has not, the weight matrix
indexed from source to target, and one external input per neuron. :func:`from_beer` makes the
dnnevo network with the same firing rates (docs/network-format.md gives the conversion): with
``v = g y``, ``theta_i = -g_i bias_i``, ``weights[i][j] = g_i w[j][i]``, and the external inputs
as N sensors, ``sensor_weights = diag(g)``. Its states are ``g y``; its outputs are Beer's.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from dnnevo import _core
from dnnevo.errors import InvalidNetworkError

__all__ = ["from_beer"]


def from_beer(taus: npt.ArrayLike, biases: npt.ArrayLike, gains: npt.ArrayLike, weights: npt.ArrayLike,
              *, states: npt.ArrayLike | None = None) -> _core.Network:
    """The network of Beer's CTRNN with these ``taus``, ``biases`` and ``gains`` (N each),
    ``weights`` (N, N) with ``weights[j][i]`` from neuron ``j`` to neuron ``i``, as Beer's code
    indexes them, and ``states`` ``y`` (zeros when None). Its N sensors are Beer's external
    inputs, one per neuron: ``net.run(I)`` with ``I`` (T, N) gives Beer's firing rates as its
    outputs (to about 1e-14: dnnevo's exponential is its own, the same bits on every machine).

    >>> net = from_beer([1.0, 1.0], [-2.75, -1.75], [1.0, 1.0], [[4.5, 1.0], [-1.0, 4.5]])
    >>> net.theta.tolist(), net.weights.tolist()
    ([2.75, 1.75], [[4.5, -1.0], [1.0, 4.5]])
    """
    tau, bias, gain, w = (_numbers(name, value) for name, value in
                          (("taus", taus), ("biases", biases), ("gains", gains), ("weights", weights)))
    n = tau.shape[0] if tau.ndim == 1 else -1
    for name, value in (("taus", tau), ("biases", bias), ("gains", gain)):
        if value.shape != (max(n, 0),) or n < 1:
            raise InvalidNetworkError(f"{name} has shape {value.shape}; expected (N,), N = len(taus)"
                                      f"{f' = {n}' if n >= 1 else ' >= 1'}")
    if w.shape != (n, n):
        raise InvalidNetworkError(f"weights has shape {w.shape}; expected (N, N) = ({n}, {n}), "
                                  "weights[j][i] from neuron j to neuron i")
    y = np.zeros(n) if states is None else _numbers("states", states)
    if y.shape != (n,):
        raise InvalidNetworkError(f"states has shape {y.shape}; expected (N,) = ({n},)")
    return _core.Network(tau=tau, theta=-gain * bias, weights=gain[:, None] * w.T,
                         sensor_weights=np.diag(gain), state=gain * y)


def _numbers(name: str, value: npt.ArrayLike) -> npt.NDArray[np.float64]:
    """``value`` as finite float64 numbers, or an :class:`~dnnevo.InvalidNetworkError` naming
    ``name`` (Beer's argument) and the index of the first that is not one."""
    if value is None:
        raise InvalidNetworkError(f"{name} is None; expected numbers")
    try:
        given = np.asarray(value)
    except ValueError as e:  # ragged rows
        raise InvalidNetworkError(f"{name} is not an array of numbers: {e}") from None
    if given.dtype.kind not in "iuf":
        raise InvalidNetworkError(f"{name} is an array of dtype {given.dtype}; expected numbers "
                                  "(a bool or a string is not one)")
    x = given.astype(np.float64)
    if not np.isfinite(x).all():
        at = tuple(int(i) for i in np.argwhere(~np.isfinite(x))[0])
        raise InvalidNetworkError(f"{name}{''.join(f'[{i}]' for i in at)} is {x[at]}; every value must be finite")
    return x
