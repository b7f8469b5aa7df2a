"""The tasks, one module each and each its only Python home: sequence learning
(:mod:`.sequence`), one-dimensional navigation (:mod:`.nav1d`) and landmark recognition
(:mod:`.landmark`). Every module implements :class:`~dnnevo.tasks.protocol.Task`;
:mod:`.registry` finds one by name and judges a network by its rule. Beside them: the protocol a
task written in Python follows (:mod:`.protocol`, :mod:`.user`), the defaults shared by the tasks
(:mod:`.defaults`) and landmark recognition's held-out test worlds (:mod:`.landmark_worlds`) and
the judging of champions in them beside each world's bounds (:mod:`.landmark_transfer`)."""

from dnnevo.tasks import landmark, nav1d, sequence
from dnnevo.tasks.protocol import Task
from dnnevo.tasks.registry import DEFAULT_TRIALS, THRESHOLDS, UNITS, assess, find, get, names

__all__ = ["DEFAULT_TRIALS", "THRESHOLDS", "UNITS", "Task", "assess", "find", "get", "landmark",
           "nav1d", "names", "sequence"]
