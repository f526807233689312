"""``ttt-sm gui --camera``: a camera outside the simulation shown in the Tic-tac-toe page.

The image folder is real PNG files (photos of a whiteboard with symbols
drawn by hand, taken by the simulated camera and written by OpenCV); the
serial smart camera is the camera emulator on a real pseudo-terminal. An
OpenCV capture device cannot be tested on this machine (it has no camera):
only its refusal is.
"""

from __future__ import annotations

import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import cv2
import pytest
from starlette.testclient import TestClient

from ttt_sm.debug.debugger import Debugger
from ttt_sm.params import load_params
from ttt_sm.smartcam import CameraEmulator
from ttt_sm.smartcam.sources import board_source
from ttt_sm.twin.whiteboard import Whiteboard
from ttt_sm.vision import board_text, detect
from ttt_sm.vision.scenes import draw_field
from ttt_sm.vision.simulated import SimulatedCamera
from ttt_sm.web.camera_feed import CameraFeedError, open_feed
from ttt_sm.web.server import create_app
from ttt_sm.web.session import Session

from .conftest import Cockpit, served
from .test_protocol import Page

#: The boards the folder's two pictures show, by file name (board order, row 1 first).
PICTURES = {"01_first.png": {(2, 3): "X"}, "02_second.png": {(2, 3): "X", (4, 1): "O", (5, 5): "X"}}


@pytest.fixture(scope="module")
def picture_folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Two photos of boards drawn by hand, as PNG files, and a file that is no picture."""
    params = load_params()
    folder = tmp_path_factory.mktemp("camera")
    for name, cells in PICTURES.items():
        board = Whiteboard(params, seed=3)
        draw_field(board)
        for (row, column), symbol in cells.items():
            board.draw_symbol(symbol, row, column)
        assert cv2.imwrite(str(folder / name), SimulatedCamera(board, params, seed=3).frame())
    (folder / "notes.txt").write_text("not a picture\n")
    return folder


def expected_board(cells: dict[tuple[int, int], str]) -> str:
    return "".join(cells.get((r, c), ".") for r in range(1, 6) for c in range(1, 6))


def test_an_image_folder_is_shown_in_name_order_with_what_the_detector_reads(picture_folder: Path) -> None:
    feed = open_feed(str(picture_folder))
    seen = [feed.grab_now() for _ in range(3)]
    assert [f.source for f in seen] == ["picture 1 of 2: 01_first.png", "picture 2 of 2: 02_second.png",
                                        "picture 1 of 2: 01_first.png"]
    for frame, cells in zip(seen, [*PICTURES.values(), PICTURES["01_first.png"]], strict=True):
        assert frame.error is None and frame.image is not None
        assert frame.read == expected_board(cells)
        assert frame.percentages is not None
        assert all((p > 5.0) == ((i // 5 + 1, i % 5 + 1) in cells) for i, p in enumerate(frame.percentages))
    # What the feed read is what the detector reads in the file itself.
    again = detect(cv2.imread(str(picture_folder / "02_second.png")))
    assert board_text(again.cells, "far_edge") == seen[1].read


def test_the_serial_smart_camera_on_a_pseudo_terminal_shows_its_percentages() -> None:
    # In image order, as the camera sends it: the far edge's view turns it into board order.
    image_order = "X..../...../...../...../....O"
    with CameraEmulator(board_source(image_order, seed=1), rate_hz=20.0).start() as camera:
        feed = open_feed(f"serial:{camera.port}")
        try:
            deadline = time.monotonic() + 30
            frame = feed.grab_now()
            while frame.percentages is None:
                assert time.monotonic() < deadline, frame.error
                time.sleep(0.1)
                frame = feed.grab_now()
            assert frame.image is None and frame.source.startswith(f"serial camera on {camera.port}, frame ")
            assert frame.read == board_text(image_order.replace("/", "").replace("X", "#").replace("O", "#"),
                                            "far_edge")
        finally:
            feed.stop()


@pytest.mark.parametrize("spec, error", [
    ("7", "--camera 7: OpenCV cannot open capture device 7 (on Linux /dev/video7): is a camera plugged in,"
          " and may this user read it?"),
    ("no/such/thing", "--camera no/such/thing: not a capture device index (0, 1, ...), a folder of pictures or a"
                      " serial port (serial:PORT or a device path such as /dev/ttyUSB0)"),
])
def test_a_camera_that_is_not_there_is_refused_by_name(spec: str, error: str) -> None:
    with pytest.raises(CameraFeedError) as exc:
        open_feed(spec)
    assert str(exc.value) == error


def test_an_empty_folder_is_refused(tmp_path: Path) -> None:
    with pytest.raises(CameraFeedError, match="no pictures in that folder"):
        open_feed(str(tmp_path))


def test_ttt_sm_gui_refuses_a_missing_capture_device_in_one_line() -> None:
    proc = subprocess.run([sys.executable, "-m", "ttt_sm.cli", "gui", "--port", "0", "--camera", "7"],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.strip().splitlines()[-1] == (
        "ttt-sm gui: error: --camera 7: OpenCV cannot open capture device 7 (on Linux /dev/video7): is a camera"
        " plugged in, and may this user read it?")
    assert "Traceback" not in proc.stderr


def test_the_frames_carry_the_cameras_reading_and_its_picture(picture_folder: Path) -> None:
    session = Session(Debugger.build(load_params(), seed=0), speed=None, running=False,
                      camera_feed=open_feed(str(picture_folder), rate_hz=20.0))
    session.start()
    try:
        with TestClient(create_app(session, manage_session=False)) as c, c.websocket_connect("/ws") as ws:
            page = Page(ws)
            page.join()
            frame = page.frame()
            while not (frame.get("camera") or {}).get("n"):
                frame = page.frame()
            camera = frame["camera"]
            name = camera["source"].split(": ")[1]
            assert camera["kind"] == "folder" and camera["read"] == expected_board(PICTURES[name])
            png = c.get("/api/camera/frame.png")
            assert png.status_code == 200 and png.headers["content-type"] == "image/png"
    finally:
        session.stop()


@pytest.fixture
def feed_cockpit(picture_folder: Path) -> Iterator[Cockpit]:
    session = Session(Debugger.build(load_params(), seed=0, game=True, person="page"), speed=None, running=False,
                      camera_feed=open_feed(str(picture_folder), rate_hz=4.0))
    with served(session) as cockpit:
        yield cockpit


def test_the_game_page_shows_the_folders_pictures_and_what_was_read(browser: Any, feed_cockpit: Cockpit) -> None:
    page = browser.new_page()
    try:
        page.goto(feed_cockpit.page_url("/game"))
        for name, cells in PICTURES.items():
            # The picture shown is that file, loaded, and the table beside it says what was read in it.
            page.wait_for_function(
                "(name) => { const img = document.querySelector('[data-role=feed-photo]');"
                " return !img.hidden && img.complete && img.naturalWidth > 0 && img.dataset.source.endsWith(name)"
                " && document.querySelector('[data-role=feed-source]').textContent.endsWith(name); }",
                arg=name, timeout=30_000)
            read = page.evaluate("Array.from(document.querySelectorAll('[data-role=feed-reading] [role=cell]'))"
                                 ".map((c) => c.dataset.read).join('')")
            if read == expected_board(cells):
                continue
            # The next grab may have come between the two reads: wait for this file's again.
            page.wait_for_function(
                "([name, board]) => document.querySelector('[data-role=feed-source]').textContent.endsWith(name)"
                " && Array.from(document.querySelectorAll('[data-role=feed-reading] [role=cell]'))"
                ".map((c) => c.dataset.read).join('') === board", arg=[name, expected_board(cells)], timeout=30_000)
        assert page.locator('[data-role="feed-panel"]').is_visible()
    finally:
        page.close()
