"""The example scripts run, and what they claim by construction holds."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

import dnnevo

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "examples"))

import incremental_plateau  # noqa: E402


def test_incremental_plateau(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A composite with zero cross weights answers as its 1-bit part on every trial."""
    alternating = tmp_path / "alt.json"
    dnnevo.Network.random(5, 2, seed=4).save(alternating)
    one_bit = ROOT / "tests" / "data" / "sequence-1bit-seed0-champion.json"
    incremental_plateau.main([str(one_bit), str(alternating), "--trials", "3", "--timings", "3"])
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == "composite output identical to the 1-bit part's on 12 of 12 trials"
    assert len(lines) == 2 + 7 and lines[2].startswith("composite, cross weights 0")
    assert lines[-1].startswith("relay: w[0][5] = -16, theta[0] = -8")
