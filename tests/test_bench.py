"""What the benchmark scripts under bench/ rely on still holds (they are not run here: they time
things, and need the C anchor)."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
# bench/ only while importing: left on the path, its distributed.py would hide Dask's package
# from every later test in this process.
sys.path.insert(0, str(ROOT / "bench"))
try:
    import sigmoid_ceiling
finally:
    sys.path.remove(str(ROOT / "bench"))


def test_the_free_sigmoid_patch_applies_to_the_sigmoid_of_today() -> None:
    """bench/sigmoid_ceiling.py replaces the sigmoid's one-line body in math.rs; if that line
    changes, the script must say so instead of timing the exact sigmoid twice."""
    source = (ROOT / sigmoid_ceiling.MATH).read_text()
    patched = sigmoid_ceiling.free_sigmoid(source)
    assert sigmoid_ceiling.EXACT_SIGMOID not in patched
    assert patched.count(sigmoid_ceiling.FREE_SIGMOID) == 1
    with pytest.raises(SystemExit, match="no longer holds the sigmoid body"):
        sigmoid_ceiling.free_sigmoid(patched)


@pytest.mark.parametrize("name", [c for c in sigmoid_ceiling.COPIES if c != "free sigmoid"])
def test_the_cheaper_exponentials_still_apply_to_the_source_of_today(tmp_path: Path, name: str) -> None:
    """Each patch of bench/patches/ applies to a copy of today's crates/ctrnn/src, so the script
    times the exponential it says, not a build that failed to change."""
    import shutil

    source = tmp_path / "src"
    shutil.copytree(ROOT / "crates" / "ctrnn" / "src", source / "crates" / "ctrnn" / "src")
    sigmoid_ceiling.change_source(name, source)
    math = (source / sigmoid_ceiling.MATH).read_text()
    assert "EXP2_" in math and math != (ROOT / sigmoid_ceiling.MATH).read_text()
