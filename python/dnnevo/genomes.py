"""Genomes as arrays: dnnevo's genome layout, for an optimiser of your own.

A genome holds one block per neuron, in order: its ``tau``, its ``theta``, its M sensor weights
and its N incoming weights (``weights[i][:]``), so G = N (2 + M + N), in model units, as the
genetic algorithm evolves them (:meth:`dnnevo.Network.from_genome` makes one network of one).
:func:`stack_genomes` turns a population's genomes into the stacked arrays that
:func:`dnnevo.run_population`, :class:`dnnevo.Batch` and :func:`dnnevo.closedloop.rollout` take,
with no network object per genome.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from dnnevo.errors import InvalidArgumentError

__all__ = ["stack_genomes"]


def stack_genomes(genomes: npt.ArrayLike, *, size: int, n_inputs: int) -> dict[str, npt.NDArray[np.float64]]:
    """The parameters of the networks whose genomes are the rows of ``genomes`` (P, G), as
    stacked arrays: ``tau`` and ``theta`` (P, N), ``weights`` (P, N, N) and ``sensor_weights``
    (P, N, M). The values are checked where they are used (a time constant that is not
    positive, a gene that is not finite), with the network's index.

    >>> import dnnevo
    >>> nets = [dnnevo.Network.random(3, 2, seed=s) for s in range(4)]
    >>> stacked = stack_genomes([n.genome() for n in nets], size=3, n_inputs=2)
    >>> weights = stacked["weights"]
    >>> weights.shape, bool((weights[1] == nets[1].weights).all())
    ((4, 3, 3), True)
    >>> bool((dnnevo.run_population(stacked, np.ones((5, 2))) == dnnevo.run_population(nets, np.ones((5, 2)))).all())
    True
    """
    for name, value, least in (("size", size, 1), ("n_inputs", n_inputs, 0)):
        if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < least:
            raise InvalidArgumentError(f"{name} is {value!r}; expected a whole number >= {least}")
    n, m = int(size), int(n_inputs)
    if genomes is None:
        raise InvalidArgumentError("genomes is None; expected an array (P, G), one genome per row")
    try:
        rows = np.asarray(genomes, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise InvalidArgumentError(f"genomes must be an array (P, G) of numbers, one genome per row: {e}") from None
    block = 2 + m + n
    if rows.ndim != 2 or rows.shape[1] != n * block:
        raise InvalidArgumentError(
            f"genomes has shape {rows.shape}; expected (P, G) with G = N x (2 + M + N) = {n * block} "
            f"for N = {n} neurons and M = {m} sensors")
    neurons = rows.reshape(len(rows), n, block)
    return {"tau": neurons[:, :, 0].copy(), "theta": neurons[:, :, 1].copy(),
            "sensor_weights": neurons[:, :, 2:2 + m].copy(), "weights": neurons[:, :, 2 + m:].copy()}
