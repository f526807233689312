"""The game's eyes: the simulated camera, the detector, and (optionally) the serial link.

Two ways to get the 25 per-cell percentages of the board (thesis 3.6.3):

- ``direct``: photograph the simulated whiteboard and detect in-process;
- ``serial``: the smart camera is emulated on a real pseudo-terminal
  (:class:`ttt_sm.smartcam.CameraEmulator`), photographing and detecting
  in its own thread, and the game reads the frames through pyserial
  (:class:`ttt_sm.smartcam.SerialCameraReader`), as the thesis' PC did.

The simulation and the camera thread share the whiteboard: the camera only
photographs while the simulation is paused for a reading (a lock, and an event
that says a reading is wanted), and a reading taken for a decision is always a
frame photographed after the last change.  Between readings the camera waits:
a frame photographed while the game thread takes the board back would only
cost it time.  So the reader's silence watchdog runs only while a reading
waits for its frame: a link idle while the person thinks is not a camera
that stopped.  A camera silent for ``silence_s`` while a reading waits is
:class:`CameraLost` at once (the game's Safety chart lifts the pen and
holds, docs/safety.md), not a reading that waits on.
"""

from __future__ import annotations

import tempfile
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np

from ..params import ArmParams
from ..smartcam.protocol import SEQ_MODULUS
from ..twin.whiteboard import Whiteboard
from ..vision import Detection, board_text, board_values, detect
from ..vision.orientation import check_orientation
from ..vision.simulated import SimulatedCamera

#: A reading asks the camera for another photo when none arrived for this long, s.
REASK_S = 0.5


class CameraLost(RuntimeError):
    """The camera sent no valid frame for the link's ``silence_s`` while a reading waited for a photo."""


class CameraLink:
    """Per-cell percentages of the board, in board order, from a photo taken now."""

    def __init__(self, params: ArmParams, board: Whiteboard, seed: int = 0, mode: str = "serial",
                 rate_hz: float = 50.0, silence_s: float = 2.0) -> None:
        if mode not in ("direct", "serial"):
            raise ValueError(f"camera mode must be 'direct' or 'serial', got {mode!r}")
        self.mode = mode
        self.camera = SimulatedCamera(board, params, seed=seed)
        self.view = self.camera.view()
        self.lock = threading.Lock()
        self.lock.acquire()  # held by the simulation; released only while reading
        self._wanted = threading.Event()  # set while a reading waits for its fresh frame
        self.read_wall_s = 0.0  # wall time spent waiting for photos
        self._closing = False
        self._last_percentages: list[float] = [0.0] * 25
        #: The last photo taken (BGR, as the camera sees the board), None before the first.
        self.last_photo: np.ndarray | None = None
        self._made = 0  # frames photographed so far = the next frame's sequence number
        self._symbols_by_seq: dict[int, str] = {}
        self._emulator: Any = None
        self._reader: Any = None
        self._tmp: tempfile.TemporaryDirectory[str] | None = None
        self.silence_s = silence_s
        if mode == "serial":
            self._start_serial(rate_hz, silence_s)

    def _start_serial(self, rate_hz: float, silence_s: float) -> None:
        from ..smartcam import CameraEmulator, SerialCameraReader

        def source() -> list[float]:
            while True:
                self._wanted.wait()
                with self.lock:  # never photograph a board the simulation is writing
                    if self._closing:
                        return list(self._last_percentages)
                    if not self._wanted.is_set():
                        continue  # the reading got its frame while this one waited for the board
                    self._wanted.clear()  # one photo per request: the reading asks again if it is lost
                    photo = self.camera.frame()
                    d = detect(photo)  # no frame (and no sequence number) if this raises
                    self.last_photo = photo
                    # The emulator numbers frames 0, 1, 2 ... in the order they are made.
                    self._symbols_by_seq[self._made % SEQ_MODULUS] = d.cells
                    self._made += 1
                break
            self._last_percentages = [float(p) for p in d.percentages]
            return self._last_percentages

        self._tmp = tempfile.TemporaryDirectory(prefix="ttt_sm_camera_")
        self._emulator = CameraEmulator(source, rate_hz=rate_hz, link=Path(self._tmp.name) / "camera").start()
        self._reader = SerialCameraReader(self._emulator.port, 5.0, silence_s=silence_s)
        self._reader.expect_frames(False)  # the camera sends only when a reading asks

    @property
    def emulator(self) -> Any:
        """The camera's emulator on its pseudo-terminal (serial mode; None in direct): its faults are injected here."""
        return self._emulator

    @property
    def port(self) -> str | None:
        """The serial port the camera is read from (None in direct mode)."""
        return self._emulator.port if self._emulator is not None else None

    def read(self) -> tuple[tuple[float, ...], str | None]:
        """(percentages in board order, symbols in board order or None) from a photo of the board as it is now."""
        t0 = time.perf_counter()
        try:
            return self._read()
        finally:
            self.read_wall_s += time.perf_counter() - t0

    def _read(self) -> tuple[tuple[float, ...], str | None]:
        if self.mode == "direct":
            self.last_photo = self.camera.frame()
            d: Detection = detect(self.last_photo)
            # a camera turned on its stand would put every symbol in the wrong cell: its perspective says so
            # (OrientationError, never read); a mirror keeps the perspective, the robot's marks tell it
            # (app.game_orientation, in the game)
            check_orientation(d.grid, self.view, "the camera's photo")
            return tuple(board_values(list(d.percentages), self.view)), board_text(d.cells, self.view)
        # Frames photographed before now may still wait in the port: only a
        # frame numbered from `fresh` on shows the board as it is now.
        fresh = self._made
        self._reader.expect_frames(True)
        self._wanted.set()
        self.lock.release()
        try:
            deadline = time.monotonic() + 10.0
            while True:
                left = deadline - time.monotonic()
                frame = self._reader.read_frame(max(0.0, min(left, REASK_S)))
                if frame is None:
                    if self._reader.silent:  # its watchdog: silence while this reading waited for a photo
                        raise CameraLost(f"the camera sent no frame for {self.silence_s:g} s while a photo was"
                                         f" asked ({self._reader.port_name})")
                    if left <= REASK_S:
                        raise TimeoutError("the camera sent no fresh frame for 10 s")
                    self._wanted.set()  # the photo may have been lost on the line: ask again
                    continue
                if (frame.seq - fresh) % SEQ_MODULUS < SEQ_MODULUS // 2:
                    break
        finally:
            self._wanted.clear()
            self._reader.expect_frames(False)
            self.lock.acquire()
        cells = self._symbols_by_seq.pop(frame.seq, None)
        self._symbols_by_seq.clear()
        symbols = board_text(cells, self.view) if cells else None
        return tuple(board_values(list(frame.percentages), self.view)), symbols

    def stats(self) -> dict[str, Any]:
        """The serial link's counters (frames read, rejected, reconnects), or {} in direct mode."""
        if self._reader is None:
            return {}
        from dataclasses import asdict, is_dataclass

        s = self._reader.stats
        return asdict(s) if is_dataclass(s) and not isinstance(s, type) else {}

    def close(self) -> None:
        """Stop the emulator and close the port."""
        if self._reader is not None:
            self._reader.close()
        if self._emulator is not None:
            self._closing = True  # the camera thread stops photographing ...
            self._wanted.set()
            if self.lock.locked():
                self.lock.release()  # ... and may finish the frame it was waiting to take
            self._emulator.stop()
        if self._tmp is not None:
            self._tmp.cleanup()
