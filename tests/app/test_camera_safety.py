"""The game's camera link feeds the Safety chart's Camera block (docs/safety.md).

The camera is the game's own: its emulator on a real pseudo-terminal,
photographing the simulated whiteboard when a reading asks, read through
pyserial.  The camera is cut by pausing its emulator (the port stays open,
nothing comes): the reader's silence watchdog, which runs only while a
reading waits for its photo, says so, the reading gives up, and the Safety
chart lifts the pen off the board and holds.
"""

from __future__ import annotations

import time

from ttt_sm.app.camera_link import CameraLink, CameraLost
from ttt_sm.app.game import GameSession
from ttt_sm.app.game_outcome import GameError
from ttt_sm.params import load_params
from ttt_sm.smartcam import Fault
from ttt_sm.twin.whiteboard import Whiteboard
from ttt_sm.vision.scenes import draw_field

P = load_params()


def _read_until_lost(read, tries: int = 3) -> Exception:
    """Read until the cut shows (the emulator may answer the one reading it was already making)."""
    for _ in range(tries):
        try:
            read()
        except (CameraLost, GameError) as exc:
            return exc
    raise AssertionError(f"the camera still answered after {tries} readings")


def test_a_camera_silent_while_a_photo_is_asked_is_lost_after_its_silence_limit_not_ten_seconds():
    board = Whiteboard(P, seed=2)
    draw_field(board)
    link = CameraLink(P, board, seed=2, mode="serial", silence_s=0.5)
    try:
        link.read()
        link.emulator.inject(Fault.pause(60.0))  # the camera stops answering; its port stays open
        t0 = time.monotonic()
        exc = _read_until_lost(link.read)
        waited = time.monotonic() - t0
        stats = link.stats()
    finally:
        link.close()
    assert isinstance(exc, CameraLost) and "no frame for 0.5 s while a photo was asked" in str(exc)
    assert stats["silences"] == 1
    assert waited < 10.0  # the reading's own limit is 10 s: the watchdog ended it first


def test_a_camera_lost_while_the_game_waits_for_a_photo_lifts_the_pen_and_holds():
    session = GameSession(P, seed=4, robot_symbol="O", engine="strong", camera="serial")
    try:
        robot = session.robot
        assert robot.run_until(lambda: robot.initialised, 40.0)
        z0 = robot.truth.tool_pose()[2]
        session.camera.emulator.inject(Fault.pause(60.0))
        exc = _read_until_lost(session._look)
        assert isinstance(exc, GameError)
        assert str(exc) == "safety stop: camera lost: no frame from the camera"
        assert robot.camera_status.ok is False
        assert robot.active("Safety") == {"safe", "hold"}  # through lift: the pen went up first
        assert robot.truth.tool_pose()[2] - z0 >= P.safety.lift_height_m - 0.002
        events = [e["event"] for e in session.record.events]
        assert events[-2:] == ["camera_lost", "safety_trip"] or events[-3:-1] == ["camera_lost", "safety_trip"]
        trip = [e for e in session.record.events if e["event"] == "safety_trip"][-1]
        assert trip["reason"] == "camera lost: no frame from the camera"
    finally:
        session.close()
