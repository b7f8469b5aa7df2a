"""The field's classic benchmarks, written with the closed-loop protocol
(:mod:`dnnevo.closedloop`) as a user would write a task: :class:`DoublePole`, double-pole
balancing with or without velocities."""

from dnnevo.classic.double_pole import DoublePole

__all__ = ["DoublePole"]
