"""Your own task, in closed loop: an :class:`Environment` written in NumPy, run by
:func:`rollout` over a whole population at once through :class:`dnnevo.Batch`.

:class:`ClosedLoop` makes an environment a fitness function for :func:`dnnevo.evolve`.
:class:`FarSeeker` is the paper's landmark-far goal seeker written this way, as an example.
"""

from dnnevo.closedloop.environment import Environment, RestartingEnvironment
from dnnevo.closedloop.far_seeker import FarSeeker
from dnnevo.closedloop.fitness import ClosedLoop
from dnnevo.closedloop.loop import Rollout, rollout

__all__ = ["ClosedLoop", "Environment", "FarSeeker", "RestartingEnvironment", "Rollout", "rollout"]
