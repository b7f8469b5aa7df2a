"""The field's classic benchmarks, written with the closed-loop protocol
(:mod:`dnnevo.closedloop`) as a user would write a task: :class:`DoublePole`, double-pole
balancing with or without velocities; :class:`CategoricalPerception`, Beer's agent that
catches circles and avoids diamonds; and :class:`LeggedWalker`, Beer and Gallagher's walker with
one leg."""

from dnnevo.classic.categorical import CategoricalPerception
from dnnevo.classic.double_pole import DoublePole
from dnnevo.classic.walker import LeggedWalker

__all__ = ["CategoricalPerception", "DoublePole", "LeggedWalker"]
