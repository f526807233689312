"""The kept gains (twin/gains_cache.py) are the design's to the last bit, and a bad cache only costs a redesign."""

from __future__ import annotations

import dataclasses
import os
import subprocess
import sys
from pathlib import Path

import pytest

from ttt_sm.params import load_params
from ttt_sm.twin.gains_cache import cache_key, kept_gains
from ttt_sm.twin.tuning import design_gains

P = load_params()


def test_kept_gains_are_the_designed_ones_cold_and_warm(tmp_path: Path) -> None:
    designed = design_gains(P)
    cold = kept_gains(P, cache=tmp_path)
    files = list(tmp_path.glob("*.json"))
    assert [f.name for f in files] == [f"ours-{cache_key(P)}.json"]
    warm = kept_gains(P, cache=tmp_path)
    # equal as frozen dataclasses of floats: every field bit for bit (NaN margins would break ==: none here)
    assert cold == designed and warm == designed
    assert list(tmp_path.glob(".tmp-*")) == []  # written whole, then renamed


def test_another_parameter_is_another_key() -> None:
    drive = dataclasses.replace(P.drives[0], gear_ratio=P.drives[0].gear_ratio * 1.01)
    other = dataclasses.replace(P, drives=(drive, *P.drives[1:]))
    assert cache_key(other) != cache_key(P)


@pytest.mark.parametrize("content", ["", '{"drives": [', '{"drives": [{"kp_pos": 1}]}', "not json at all"])
def test_a_broken_cache_file_is_designed_again_and_replaced(tmp_path: Path, content: str) -> None:
    path = tmp_path / f"ours-{cache_key(P)}.json"
    path.write_text(content)
    assert kept_gains(P, cache=tmp_path) == design_gains(P)
    assert kept_gains(P, cache=tmp_path) == design_gains(P) and path.read_text() != content


def test_a_cache_that_cannot_be_written_still_gives_the_gains() -> None:
    # sysfs refuses new entries even to root: the write fails, the gains are designed in the process
    assert kept_gains(P, cache=Path("/sys/ttt-sm-no-cache")) == design_gains(P)


def test_a_process_with_the_gains_kept_builds_a_robot_without_python_control(tmp_path: Path) -> None:
    """What the cache is for: a process that builds a robot does not import (nor run) python-control."""
    env = {**os.environ, "XDG_CACHE_HOME": str(tmp_path)}
    script = ("import sys; from ttt_sm.params import load_params; from ttt_sm.debug.debugger import Debugger;"
              " Debugger.build(load_params(), seed=0); print('control' in sys.modules)")
    runs = [subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True, timeout=300)
            for _ in range(2)]
    assert [r.returncode for r in runs] == [0, 0], [r.stderr[-800:] for r in runs]
    assert [r.stdout.strip() for r in runs] == ["True", "False"]  # designed once, then read
    assert len(list((tmp_path / "ttt_sm" / "gains").glob("*.json"))) == 1
