"""The paper's landmark-far goal seeker (§4.2, the ``nav1d-far`` preset) written again in NumPy
against the :class:`~dnnevo.closedloop.Environment` protocol, as a user would write a task.

It reproduces the built-in task's world exactly, so it proves that the protocol loses nothing: on
the same networks, ``rollout(nets, FarSeeker(), episodes=2, max_steps=10_000, dt=0.1,
substeps=1)`` (one world step per integration step, as nav1d's) gives the fitness of
``dnnevo.evaluate("nav1d-far", nets, ...)`` bit for bit (tests/test_closedloop.py),
and ``bench/closed_loop.py`` times the two.

The world: an agent on the line ``[-20, 20]`` starts at 0; the goal is one end, and a landmark
of width 4 lies at distance 10 on the other side (the landmark is far from the goal). Its one
sensor reads 1 on the landmark. Its velocity is ``f(v_1) - f(v_0)``, the right motor's firing
rate minus the left's, and it moves once per integration step. An episode ends at either end;
reaching the goal's end scores 1. Episode 0 has its goal on the left, episode 1 on the right
(even and odd episodes likewise).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

__all__ = ["FarSeeker"]


class FarSeeker:
    """The landmark-far goal seeker on a line; see the module docs."""

    observation_size = 1

    def __init__(self, *, half_length: float = 20.0, landmark_offset: float = 10.0,
                 landmark_width: float = 4.0, dt: float = 0.1, left_motor: int = 0,
                 right_motor: int = 1) -> None:
        self.half_length = half_length
        self.landmark_offset = landmark_offset
        self.half_width = 0.5 * landmark_width
        self.dt = dt
        self.left_motor, self.right_motor = left_motor, right_motor

    def reset(self, episodes: npt.NDArray[np.int64], rng: np.random.Generator) -> npt.NDArray[np.float64]:
        """Even episodes seek the left end, odd ones the right; the landmark is on the other side.
        The conditions are fixed, so ``rng`` is not used."""
        rows = len(episodes)
        self.goal_right, self.landmark = np.empty(rows, dtype=bool), np.empty(rows)
        self.x = np.empty(rows)
        # The goal's end as a signed limit: seeking the right end, x >= 20 reaches it; seeking the
        # left one, -x >= 20. Steps then work in place on these buffers.
        self.sign = np.empty(rows)
        self._a, self._b = np.empty(rows), np.empty(rows)
        self._on = np.empty((rows, 1))
        return self._start(np.ones(rows, dtype=bool), episodes)

    def restart(self, rows: npt.NDArray[np.bool_], episodes: npt.NDArray[np.int64]
                ) -> npt.NDArray[np.float64]:
        """Starts episode ``episodes[r]`` at 0 in each row ``r`` where ``rows`` is True, after
        the row's last episode ended (a rollout with fewer rows than episodes)."""
        return self._start(rows, episodes)

    def _start(self, rows: npt.NDArray[np.bool_], episodes: npt.NDArray[np.int64]
               ) -> npt.NDArray[np.float64]:
        goal_right = episodes[rows] % 2 == 1
        self.goal_right[rows] = goal_right
        self.landmark[rows] = np.where(goal_right, -self.landmark_offset, self.landmark_offset)
        self.x[rows] = 0.0
        self.sign[rows] = np.where(goal_right, 1.0, -1.0)
        return self._sense()

    def step(self, rates: npt.NDArray[np.float64], active: npt.NDArray[np.bool_]
             ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.bool_], npt.NDArray[np.bool_]]:
        """Moves every agent by ``dt * (f(v_R) - f(v_L))``; an end ends the episode. Agents whose
        episode has ended move too: nothing reads them any more."""
        a, b = self._a, self._b
        np.subtract(rates[:, self.right_motor], rates[:, self.left_motor], out=a)
        a *= self.dt
        self.x += a
        np.multiply(self.x, self.sign, out=b)  # how far towards the goal's end
        reached = b >= self.half_length
        done = np.abs(self.x, out=a) >= self.half_length
        return self._sense(), reached, done

    def _sense(self) -> npt.NDArray[np.float64]:
        a = np.subtract(self.x, self.landmark, out=self._a)
        np.less_equal(np.abs(a, out=a), self.half_width, out=self._on[:, 0])
        return self._on
