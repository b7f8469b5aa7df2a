"""2-D robots in closed loop: :class:`RobotWorld` puts one robot per row in a world from a file
(a differential drive that never enters a wall, a ring of sonars, pursuers that chase it),
stepped together in Rust; a task subclasses it with its reward in NumPy. :class:`Avoid` is one,
obstacle avoidance, and :class:`Pursuit` another, the paper's predator avoidance
(docs/robots.md)."""

from dnnevo.robots.avoid import Avoid
from dnnevo.robots.navigation import Navigate
from dnnevo.robots.pursuit import Pursuit
from dnnevo.robots.world import RobotWorld

__all__ = ["Avoid", "Navigate", "Pursuit", "RobotWorld"]
