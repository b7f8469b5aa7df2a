"""Run folders on disk: what a run writes, atomically, and how every file is checked when read."""
