"""The firmware for the link faults, built once per test session with the system compiler."""

from __future__ import annotations

from pathlib import Path

import pytest

from ttt_sm.hardware.firmware import build


@pytest.fixture(scope="session")
def firmware_cache(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A folder holding the float firmware (the reference board's), for ``ArmEmulator(cache=...)``."""
    out = tmp_path_factory.mktemp("firmware")
    build("float", out)
    return out
