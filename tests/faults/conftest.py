"""The firmware for the link faults, built once per test session with the system compiler."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from ttt_sm.faults.matrix import DETECT_TARGET_S
from ttt_sm.hardware.firmware import build


@pytest.fixture(scope="session")
def firmware_cache(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A folder holding the float firmware (the reference board's), for ``ArmEmulator(cache=...)``."""
    out = tmp_path_factory.mktemp("firmware")
    build("float", out)
    return out


def _assert_matrix_targets(cells: list[dict[str, Any]]) -> None:
    """The whole matrix's targets, on either arm: every fault found within the target but the servo."""
    for c in cells:
        assert c["limit_violations"] == 0 and c["record_intact"], c
        if c["fault"] == "servo_stuck":  # docs/safety.md, "The pen servo": found once its model leaves it
            if c["phase"] == "initialising":
                assert not c["detected"], c  # not commanded to move within the watch
            else:
                assert c["detected"] and c["reason"].startswith("servo stuck"), c
            assert c["recovered"], c
            continue
        assert c["detected"] and c["detect_ms"] <= DETECT_TARGET_S * 1e3, c
        assert c["recovered"], c


@pytest.fixture(scope="session")
def assert_matrix_targets() -> Callable[[list[dict[str, Any]]], None]:
    """Asserts the targets of docs/safety.md on a whole matrix's cells (the twin's and the emulator's alike)."""
    return _assert_matrix_targets
