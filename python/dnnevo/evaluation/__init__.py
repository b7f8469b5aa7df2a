"""Judging networks, below any one task: success rates with their intervals and verdicts
(:mod:`.stats`, :mod:`.assessment`), the time-step check (:mod:`.stepcheck`), and the simple
classifiers that bound a task's difficulty from below and above (:mod:`.observer`)."""
