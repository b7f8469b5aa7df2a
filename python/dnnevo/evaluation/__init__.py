"""Judging networks, below any one task: success rates with their intervals and verdicts
(:mod:`.stats`, :mod:`.assessment`) and the time-step check (:mod:`.stepcheck`)."""
