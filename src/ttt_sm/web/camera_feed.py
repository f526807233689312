"""A camera outside the simulation, shown in the Tic-tac-toe page (``ttt-sm gui --camera``).

Three kinds of camera, named by ``--camera`` (:func:`open_feed`):

- an OpenCV capture device, by its index (``0`` is ``/dev/video0`` on Linux);
- a folder of images: its pictures in name order, one per grab, from the
  first again after the last (a recorded session, a test);
- the serial smart camera (``serial:PORT``, or a port path such as
  ``/dev/ttyUSB0``): the thesis' camera that sends the 25 cells' ink
  percentages over a serial line (section 3.6.3, :mod:`ttt_sm.smartcam`);
  it sends no picture.

A :class:`CameraFeed` grabs in a thread of its own, ``rate_hz`` times a
second, reads each picture with the project's detector (thesis section
3.6.3: the field found, each cell's ink percentage and the symbol read) and
keeps the newest :class:`FeedFrame`; the session's frames carry what it read
(:func:`feed_view`) and the page asks for the picture (``/api/camera/frame.png``)
when it changes.  The game itself plays with the simulated camera, which
photographs the simulated whiteboard the simulated arm draws on: a real
camera sees a real board, which the simulated arm never touches.
"""

from __future__ import annotations

import os
import stat
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from ..vision import VisionError, board_text, board_values, detect
from ..vision.detection import OCCUPIED_PCT

#: Pictures a folder may hold, by extension (what OpenCV reads).
IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".webp")
#: Grabs a second unless told otherwise.
DEFAULT_RATE_HZ = 2.0
#: How the camera's image lies on the board: beyond the board's far edge, facing the robot,
#: as the simulated camera (docs/vision.md).
DEFAULT_VIEW = "far_edge"


class CameraFeedError(ValueError):
    """A ``--camera`` that names no camera this machine has; the text says which and what to do."""


@dataclass(frozen=True)
class FeedFrame:
    """One grab: what the camera showed and what the detector read from it.

    ``n`` counts grabs from 1; ``source`` says which picture or frame it was;
    ``image`` the picture (BGR, None for the serial camera); ``percentages``
    each cell's ink, percent, and ``read`` the symbols (``X``, ``O``, ``#``
    for ink the serial camera cannot name, ``.``), both in board order (row
    1, column 1 first), None when nothing was read; ``error`` why not.
    """

    n: int
    source: str
    image: np.ndarray | None
    percentages: tuple[float, ...] | None
    read: str | None
    error: str | None = None


#: A grab: (what it was, the picture or None, image-order percentages or None, image-order symbols or None).
Grab = Callable[[], tuple[str, np.ndarray | None, list[float] | None, str | None]]


class CameraFeed:
    """Grabs from one camera in a thread of its own and keeps the newest :class:`FeedFrame`.

    ``grab`` returns one raw grab; ``close`` releases the camera; ``kind`` and
    ``name`` describe it (``"folder"``, ``"device"``, ``"serial"``).
    """

    def __init__(self, kind: str, name: str, grab: Grab, close: Callable[[], None] = lambda: None, *,
                 rate_hz: float = DEFAULT_RATE_HZ, view: str = DEFAULT_VIEW) -> None:
        if not 0 < rate_hz <= 50:
            raise CameraFeedError(f"the camera's rate must lie in (0, 50] grabs a second, got {rate_hz!r}")
        self.kind, self.name = kind, name
        self._grab, self._close = grab, close
        self.period_s = 1.0 / rate_hz
        self.view = view
        self._latest: FeedFrame | None = None
        self._n = 0
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    @property
    def grabs(self) -> int:
        """Grabs so far (a view looks again when it changes)."""
        return self._n

    def latest(self) -> FeedFrame | None:
        """The newest grab (None before the first)."""
        with self._lock:
            return self._latest

    def grab_now(self) -> FeedFrame:
        """Grab once, read it, keep it as the newest; the thread calls this ``rate_hz`` times a second."""
        try:
            source, image, percentages, symbols = self._grab()
            error = None
            if image is not None and percentages is None:
                try:
                    d = detect(image)
                    percentages, symbols = [float(p) for p in d.percentages], d.cells
                except VisionError as exc:
                    error = f"the field was not found in the picture: {exc}"
        except Exception as exc:  # a camera that fails: said in the page, the feed goes on trying
            source, image, percentages, symbols, error = "no picture", None, None, None, f"{type(exc).__name__}: {exc}"
        board = None if percentages is None else board_values(percentages, self.view)
        read = None if symbols is None else board_text(symbols, self.view)
        with self._lock:
            self._n += 1
            frame = FeedFrame(self._n, source, image, board, read, error)
            self._latest = frame
        return frame

    def start(self) -> CameraFeed:
        """Start grabbing in a thread (a daemon: it never holds the process up)."""
        if self._thread is None:
            self._thread = threading.Thread(target=self._main, name=f"ttt-sm-camera-{self.kind}", daemon=True)
            self._thread.start()
        return self

    def stop(self) -> None:
        """Stop grabbing and release the camera."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join(5.0)
        self._close()

    def _main(self) -> None:
        next_at = time.monotonic()
        while not self._stop.is_set():
            self.grab_now()
            next_at += self.period_s
            self._stop.wait(max(0.0, next_at - time.monotonic()))
            next_at = max(next_at, time.monotonic() - self.period_s)  # a slow grab does not queue up others


def folder_feed(folder: Path, rate_hz: float = DEFAULT_RATE_HZ) -> CameraFeed:
    """The pictures of ``folder`` in name order, one per grab, the first again after the last."""
    if not folder.is_dir():
        raise CameraFeedError(f"--camera {folder}: not a folder")
    files = sorted(p for p in folder.iterdir() if p.suffix.lower() in IMAGE_SUFFIXES and p.is_file())
    if not files:
        raise CameraFeedError(f"--camera {folder}: no pictures in that folder (looked for"
                              f" {', '.join(IMAGE_SUFFIXES)})")
    at = 0

    def grab() -> tuple[str, np.ndarray | None, list[float] | None, str | None]:
        nonlocal at
        path = files[at % len(files)]
        at += 1
        image = cv2.imread(str(path), cv2.IMREAD_COLOR)
        if image is None:
            raise CameraFeedError(f"{path.name}: OpenCV cannot read it as a picture")
        return f"picture {(at - 1) % len(files) + 1} of {len(files)}: {path.name}", image, None, None

    return CameraFeed("folder", str(folder), grab, rate_hz=rate_hz)


def device_feed(index: int, rate_hz: float = DEFAULT_RATE_HZ) -> CameraFeed:
    """The OpenCV capture device ``index``; refused at once when it does not open."""
    capture = cv2.VideoCapture(index)
    if not capture.isOpened():
        capture.release()
        raise CameraFeedError(f"--camera {index}: OpenCV cannot open capture device {index}"
                              f" (on Linux /dev/video{index}): is a camera plugged in, and may this user read it?")
    lock = threading.Lock()

    def grab() -> tuple[str, np.ndarray | None, list[float] | None, str | None]:
        with lock:
            ok, image = capture.read()
        if not ok or image is None:
            raise CameraFeedError(f"capture device {index} gave no picture")
        return f"capture device {index}", image, None, None

    def close() -> None:
        with lock:
            capture.release()

    return CameraFeed("device", str(index), grab, close, rate_hz=rate_hz)


def serial_feed(port: str, rate_hz: float = DEFAULT_RATE_HZ) -> CameraFeed:
    """The serial smart camera on ``port``: its newest frame of 25 percentages at each grab."""
    from ..smartcam import SerialCameraReader
    from ..smartcam.errors import SerialLinkError

    reader = SerialCameraReader(port, 1.0)
    try:
        reader.open()
    except SerialLinkError as exc:
        raise CameraFeedError(f"--camera serial:{port}: {exc}") from None
    lock = threading.Lock()

    def grab() -> tuple[str, np.ndarray | None, list[float] | None, str | None]:
        with lock:
            frame = reader.latest()
        if frame is None:
            raise CameraFeedError(f"no frame from the camera on {port} yet")
        pct = [float(p) for p in frame.percentages]
        # The smart camera sends the ink only: a cell with ink is '#' (which symbol, the camera does not say).
        return f"serial camera on {port}, frame {frame.seq}", None, pct, \
            "".join("#" if p >= OCCUPIED_PCT else "." for p in pct)

    def close() -> None:
        with lock:
            reader.close()

    return CameraFeed("serial", port, grab, close, rate_hz=rate_hz)


def open_feed(spec: str, rate_hz: float = DEFAULT_RATE_HZ) -> CameraFeed:
    """The camera ``--camera spec`` names: a device index, an image folder, or ``serial:PORT`` (or a port path)."""
    text = spec.strip()
    if text.isdigit():
        return device_feed(int(text), rate_hz)
    if text.lower().startswith("serial:"):
        return serial_feed(text[len("serial:"):], rate_hz)
    path = Path(text)
    if path.is_dir():
        return folder_feed(path, rate_hz)
    if _is_port(path):
        return serial_feed(text, rate_hz)
    raise CameraFeedError(f"--camera {spec}: not a capture device index (0, 1, ...), a folder of pictures or a"
                          " serial port (serial:PORT or a device path such as /dev/ttyUSB0)")


def _is_port(path: Path) -> bool:
    try:
        return stat.S_ISCHR(os.stat(path).st_mode)
    except OSError:
        return False


def feed_view(feed: CameraFeed | None) -> dict[str, Any] | None:
    """The ``camera`` part of a frame: what the camera outside the simulation showed last (None: no such camera)."""
    if feed is None:
        return None
    frame = feed.latest()
    base = {"kind": feed.kind, "name": feed.name}
    if frame is None:
        return {**base, "n": 0, "source": "no picture yet", "has_image": False, "percentages": None, "read": None,
                "error": None}
    return {**base, "n": frame.n, "source": frame.source, "has_image": frame.image is not None,
            "percentages": None if frame.percentages is None else [round(p, 1) for p in frame.percentages],
            "read": frame.read, "error": frame.error}


def feed_png(feed: CameraFeed | None) -> bytes | None:
    """The camera's newest picture as PNG (None: no camera, no picture yet, or a camera without pictures)."""
    frame = None if feed is None else feed.latest()
    if frame is None or frame.image is None:
        return None
    ok, data = cv2.imencode(".png", frame.image)
    if not ok:
        raise RuntimeError("OpenCV could not encode the camera's picture as PNG")
    return bytes(data)
