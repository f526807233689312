"""Cameras: where frames come from (a simulated board, a real device, image files).

Every source gives BGR ``uint8`` frames of shape ``(height, width, 3)``,
640 x 480 by default, through one :class:`Camera` protocol, so the game and
the detector do not care which one runs.  :func:`check_image` is the one
place that decides whether an array is a usable frame.
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path
from typing import Any, Protocol, runtime_checkable

import cv2
import numpy as np

from .errors import CameraError, ImageError

#: Default frame size (width, height), pixels.
DEFAULT_SIZE = (640, 480)
#: Smallest and largest frames :func:`check_image` accepts (width, height), pixels.
MIN_SIZE = (320, 240)
MAX_SIZE = (4096, 3072)


@runtime_checkable
class Camera(Protocol):
    """A source of frames: BGR uint8, shape (height, width, 3)."""

    def frame(self) -> np.ndarray:
        """The next frame."""
        ...

    def release(self) -> None:
        """Free the device (a no-op for sources that hold none)."""
        ...


def check_image(image: Any, what: str = "image") -> np.ndarray:
    """The image as a BGR or grey uint8 array, or :class:`ImageError` saying what is wrong.

    Parameters
    ----------
    image : np.ndarray
        ``uint8``, shape (H, W) grey or (H, W, 3) BGR (or (H, W, 4) BGRA:
        the alpha channel is dropped), with ``MIN_SIZE <= (W, H) <= MAX_SIZE``.
    what : str
        How to name the image in the message (a file name, "frame").

    Returns
    -------
    np.ndarray
        The same array (a view without alpha for BGRA).
    """
    if not isinstance(image, np.ndarray):
        raise ImageError(f"{what}: expected a numpy array (an image), got {type(image).__name__}")
    if image.dtype != np.uint8:
        raise ImageError(f"{what}: expected 8-bit pixels (uint8), got dtype {image.dtype}; "
                         "convert with np.clip(img, 0, 255).astype(np.uint8)")
    if image.ndim == 3 and image.shape[2] == 4:
        image = image[:, :, :3]
    if not (image.ndim == 2 or (image.ndim == 3 and image.shape[2] in (1, 3))):
        raise ImageError(f"{what}: expected shape (H, W) or (H, W, 3), got {image.shape}")
    if image.ndim == 3 and image.shape[2] == 1:
        image = image[:, :, 0]
    h, w = image.shape[:2]
    if not (MIN_SIZE[0] <= w <= MAX_SIZE[0] and MIN_SIZE[1] <= h <= MAX_SIZE[1]):
        raise ImageError(f"{what}: {w} x {h} pixels is the wrong size: width and height must lie within "
                         f"{MIN_SIZE[0]} x {MIN_SIZE[1]} .. {MAX_SIZE[0]} x {MAX_SIZE[1]} (640 x 480 expected)")
    return image


def read_image(path: str | Path) -> np.ndarray:
    """Read an image file as BGR uint8, or :class:`ImageError` naming the file and the problem."""
    p = Path(path)
    if not p.is_file():
        raise ImageError(f"{p}: no such file")
    data = np.fromfile(str(p), np.uint8)
    image = cv2.imdecode(data, cv2.IMREAD_COLOR) if data.size else None
    if image is None:
        raise ImageError(f"{p}: not an image OpenCV can read (PNG, JPEG, BMP, ...)")
    return check_image(image, str(p))


class ImageFileCamera:
    """Frames from image files, in order (the last one repeats); for tests, replays and photos.

    Parameters
    ----------
    paths : iterable of str or Path
        Image files; each is read and checked when its turn comes.
    loop : bool
        Start again at the first file after the last (default: keep the last).
    """

    def __init__(self, paths: Iterable[str | Path], *, loop: bool = False) -> None:
        self.paths = tuple(Path(p) for p in paths)
        if not self.paths:
            raise CameraError("ImageFileCamera: give at least one image file")
        self.loop = loop
        self._next = 0

    def frame(self) -> np.ndarray:
        """The next file's image (BGR uint8)."""
        i = self._next
        if i >= len(self.paths):
            i = 0 if self.loop else len(self.paths) - 1
        self._next = i + 1
        return read_image(self.paths[i])

    def release(self) -> None:
        """Nothing to release."""


class OpenCVCamera:
    """A real camera through ``cv2.VideoCapture`` (a USB webcam over the board).

    Parameters
    ----------
    index : int or str
        Device index (0 the first camera) or a device path / stream URL.
    size : (width, height)
        Resolution to ask the driver for, pixels (640 x 480 default).

    Raises
    ------
    CameraError
        The device does not exist or cannot be opened.
    """

    def __init__(self, index: int | str = 0, size: tuple[int, int] = DEFAULT_SIZE) -> None:
        self.index = index
        self._cap = cv2.VideoCapture(index)
        if not self._cap.isOpened():
            self._cap.release()
            raise CameraError(f"camera {index!r}: cannot open the device (is it connected, and not in use"
                              " by another program? on Linux, see `ls /dev/video*`)")
        self._cap.set(cv2.CAP_PROP_FRAME_WIDTH, size[0])
        self._cap.set(cv2.CAP_PROP_FRAME_HEIGHT, size[1])

    def frame(self) -> np.ndarray:
        """Grab one frame (BGR uint8)."""
        ok, image = self._cap.read()
        if not ok or image is None:
            raise CameraError(f"camera {self.index!r}: no frame (unplugged, or the driver stopped)")
        return check_image(image, f"camera {self.index!r}")

    def release(self) -> None:
        """Close the device."""
        self._cap.release()

    def __enter__(self) -> OpenCVCamera:
        return self

    def __exit__(self, *exc: object) -> None:
        self.release()
