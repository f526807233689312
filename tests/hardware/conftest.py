"""The firmware, compiled once per test session in both precisions and loaded with ctypes."""

from __future__ import annotations

import pytest

from ttt_sm.hardware.firmware import PRECISIONS, build
from ttt_sm.hardware.native import FirmwareLibrary


@pytest.fixture(scope="session")
def firmware_libs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, FirmwareLibrary]:
    """``{"float": ..., "double": ...}``: the firmware built with the system compiler, warnings as errors."""
    out = tmp_path_factory.mktemp("firmware")
    return {p: FirmwareLibrary(build(p, out), p) for p in PRECISIONS}
