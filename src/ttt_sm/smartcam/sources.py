"""Frame sources for the emulator: what the camera "sees" each frame.

The game plugs the simulated camera and the vision detector in with
:func:`detection_source`; :func:`board_source` makes frames from a board
written as text, for the CLI and for tests.  Neither imports the vision
package: they take what they need as arguments, so the link depends on
nothing above it.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any, Protocol

import numpy as np

from .emulator import FrameSource
from .protocol import CELLS


class _Camera(Protocol):
    def frame(self) -> Any: ...


class _Detection(Protocol):
    @property
    def percentages(self) -> Sequence[float]: ...


def detection_source(camera: _Camera, detect: Callable[[Any], _Detection]) -> FrameSource:
    """``frame_source`` that photographs with ``camera.frame()`` and returns ``detect(image).percentages``.

    This is the thesis' camera program (section 3.6.3): take a picture, count
    the dark pixels in each of the 25 fields, send the percentages (in the
    detector's image order, as the camera would).  If the detector raises
    (no field found), the emulator sends an ERROR status line instead.
    """
    def source() -> list[float]:
        return [float(p) for p in detect(camera.frame()).percentages]
    return source


def parse_board(board: str) -> str:
    """25 cells from text like ``"X...O/...../..X../...../....."``: '.' or '-' empty, 'X' or 'O' drawn.

    Row separators ('/', spaces, new lines) are ignored.  Returns the 25
    characters, row-major, upper case.
    """
    cells = "".join(ch for ch in board.upper() if ch not in "/ \t\r\n").replace("-", ".")
    bad = sorted(set(cells) - set(".XO"))
    if len(cells) != CELLS or bad:
        raise ValueError(f"a board is {CELLS} cells of '.', 'X' or 'O' (rows may be split by '/'),"
                         f" got {len(cells)} cells{' with ' + repr(''.join(bad)) if bad else ''} in {board!r}")
    return cells


def board_source(board: str, *, seed: int = 0, symbol_pct: float = 20.0, empty_pct: float = 0.5,
                 noise_pct: float = 1.0) -> FrameSource:
    """``frame_source`` for a fixed board: about ``symbol_pct`` dark pixels in drawn cells, ``empty_pct`` in empty.

    Each value gets Gaussian noise of ``noise_pct`` (standard deviation,
    percent points) from a generator seeded with ``seed``, clipped to 0..100.
    """
    cells = parse_board(board)
    base = np.array([symbol_pct if c in "XO" else empty_pct for c in cells], dtype=float)
    rng = np.random.default_rng(seed)

    def source() -> list[float]:
        values = np.clip(base + rng.normal(0.0, noise_pct, CELLS), 0.0, 100.0)
        return [float(v) for v in values]
    return source
