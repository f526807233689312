"""Fixtures of the serial-link tests: a plugged emulator, readers that close themselves, a hang watchdog.

Everything runs through real pseudo-terminals; nothing of pyserial is mocked.
Waits are loops with generous deadlines (a loaded 2-core machine is slow),
and nothing asserts how long something took.
"""

from __future__ import annotations

import faulthandler
import time
from collections.abc import Callable, Iterator

import pytest

from ttt_sm.smartcam import CameraEmulator, Frame, ReconnectPolicy, SerialCameraReader

FAST = ReconnectPolicy(first_delay_s=0.01, max_delay_s=0.1, max_attempts=1000, max_duration_s=20.0)
"""Reconnect quickly in tests, still bounded."""
PATIENCE_S = 15.0
"""Longest a test waits for something that should happen (frames, a reconnect)."""


@pytest.fixture(autouse=True)
def _hang_watchdog() -> Iterator[None]:
    # The reader promises never to hang; if it does, fail loudly with every
    # thread's stack instead of stalling the whole run.
    faulthandler.dump_traceback_later(120, exit=True)
    yield
    faulthandler.cancel_dump_traceback_later()


def _values(k: int = 0) -> list[float]:
    return [round((7.3 * i + 11.1 * k) % 100.0, 1) for i in range(25)]


@pytest.fixture
def values() -> Callable[[int], list[float]]:
    """``values(k)``: 25 distinct percentages for frame ``k`` (one decimal, 0..100)."""
    return _values


@pytest.fixture
def fast_policy() -> ReconnectPolicy:
    return FAST


@pytest.fixture
def camera(tmp_path) -> Iterator[CameraEmulator]:
    """A plugged emulator without a thread: the test sends each line itself."""
    cam = CameraEmulator(link=tmp_path / "camera")
    cam.plug()
    yield cam
    cam.stop()


@pytest.fixture
def open_reader() -> Iterator[Callable[..., SerialCameraReader]]:
    """``open_reader(port, **kw)``: an open reader with fast bounded reconnects, closed after the test."""
    readers: list[SerialCameraReader] = []

    def make(port, **kw) -> SerialCameraReader:
        kw.setdefault("reconnect", FAST)
        reader = SerialCameraReader(port, kw.pop("timeout_s", 5.0), **kw)
        readers.append(reader)
        return reader.open()

    yield make
    for reader in readers:
        reader.close()


def _read_until(reader: SerialCameraReader, done: Callable[[], bool], patience_s: float = PATIENCE_S) -> list[Frame]:
    frames: list[Frame] = []
    give_up = time.monotonic() + patience_s
    while not done() and time.monotonic() < give_up:
        frame = reader.read_frame(0.1)
        if frame is not None:
            frames.append(frame)
    assert done(), f"still waiting after {patience_s} s; stats {reader.stats}"
    return frames


@pytest.fixture
def read_until() -> Callable[..., list[Frame]]:
    """``read_until(reader, done)``: read frames until ``done()`` or patience runs out; the frames read."""
    return _read_until
