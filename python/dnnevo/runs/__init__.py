"""Run folders on disk: what a run writes, atomically, and how every file is checked when read.

- :mod:`.files`: one file written atomically and read with its checks;
- :mod:`.settings`: a run's settings compared (digests, the first difference, manifests);
- :mod:`.history`: ``log.csv``, one row per generation;
- :mod:`.checkpoint`: the GA state that continues a run bit for bit;
- :mod:`.rundir`: a run folder as a whole, with its lock.
"""

from dnnevo.runs.checkpoint import Checkpoint
from dnnevo.runs.files import RunFileError, save_figure, short, write_atomic, write_atomic_with
from dnnevo.runs.history import LOG_COLUMNS
from dnnevo.runs.rundir import LOCK_NAME, RunDir
from dnnevo.runs.settings import check_settings, config_digest, first_difference, manifest_with_later_defaults

__all__ = ["LOCK_NAME", "LOG_COLUMNS", "Checkpoint", "RunDir", "RunFileError", "check_settings",
           "config_digest", "first_difference", "manifest_with_later_defaults", "save_figure", "short", "write_atomic",
           "write_atomic_with"]
