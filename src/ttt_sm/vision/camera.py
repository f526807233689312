"""Cameras: where frames come from (a simulated board, a real device, image files).

Every source gives BGR ``uint8`` frames of shape ``(height, width, 3)``,
640 x 480 by default, through one :class:`Camera` protocol, so the game and
the detector do not care which one runs.  :func:`check_image` is the one
place that decides whether an array is a usable frame.
"""

from __future__ import annotations

import struct
from collections.abc import Iterable
from pathlib import Path
from typing import Any, Protocol, runtime_checkable

import cv2
import numpy as np

from ..params import shown_path
from .errors import CameraError, ImageError

#: Default frame size (width, height), pixels.
DEFAULT_SIZE = (640, 480)
#: Smallest and largest frames :func:`check_image` accepts (width, height), pixels.
MIN_SIZE = (320, 240)
MAX_SIZE = (4096, 3072)
#: Largest image file read, bytes: an uncompressed BMP of MAX_SIZE is 38 MB.
MAX_FILE_BYTES = 64 * 2**20
#: The formats :func:`read_image` reads: their headers give the size before anything is decoded.
IMAGE_FORMATS = "PNG, JPEG, BMP, WebP, PPM/PGM"


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
    """Read an image file as BGR uint8, or :class:`ImageError` naming the file and the problem.

    The size is read from the file's header (:func:`image_size`) and checked
    before anything is decoded: a 20000 x 20000 PNG of a few hundred kB would
    take 1.2 GB as pixels.  Files over :data:`MAX_FILE_BYTES` are not read.
    """
    p = Path(path)
    name = shown_path(p)
    try:
        if not p.is_file():
            raise ImageError(f"{name}: no such file" if not p.exists() else f"{name}: not a file")
    except OSError as exc:  # a name too long, a folder without search permission, ...
        raise ImageError(f"{name}: cannot read the file ({exc.strerror or exc})") from None
    try:
        with p.open("rb") as f:
            data = f.read(MAX_FILE_BYTES + 1)
    except OSError as exc:
        raise ImageError(f"{name}: cannot read the file ({exc.strerror or exc})") from None
    if len(data) > MAX_FILE_BYTES:
        raise ImageError(f"{name}: more than {MAX_FILE_BYTES // 2**20} MB: not a camera photo")
    if not data:
        raise ImageError(f"{name}: not an image: the file is empty")
    width, height = image_size(data, name)
    _check_size(width, height, name)
    try:
        image = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_COLOR)
    except cv2.error as exc:
        raise ImageError(f"{name}: OpenCV cannot decode it ({str(exc).strip().splitlines()[-1][:80]})") from None
    if image is None:
        raise ImageError(f"{name}: not an image OpenCV can decode (damaged or cut short?)")
    return check_image(image, name)


def _check_size(width: int, height: int, what: str) -> None:
    if not (MIN_SIZE[0] <= width <= MAX_SIZE[0] and MIN_SIZE[1] <= height <= MAX_SIZE[1]):
        raise ImageError(f"{what}: {width} x {height} pixels is the wrong size: width and height must lie within "
                         f"{MIN_SIZE[0]} x {MIN_SIZE[1]} .. {MAX_SIZE[0]} x {MAX_SIZE[1]} (640 x 480 expected)")


def image_size(data: bytes, what: str = "image") -> tuple[int, int]:
    """(width, height) of an image from its header alone; :class:`ImageError` if the format is not one of
    :data:`IMAGE_FORMATS` or the header is cut short."""
    try:
        if data.startswith(b"\x89PNG\r\n\x1a\n"):
            if data[12:16] != b"IHDR":
                raise struct.error
            width, height = struct.unpack(">II", data[16:24])
            return width, height
        if data.startswith(b"\xff\xd8"):
            return _jpeg_size(data)
        if data.startswith(b"BM"):
            width, height = struct.unpack("<ii", data[18:26])
            return abs(width), abs(height)
        if data.startswith(b"RIFF") and data[8:12] == b"WEBP":
            return _webp_size(data)
        if data[:1] == b"P" and data[1:2] in b"123456" and len(data) > 2:
            return _pnm_size(data)
    except (struct.error, IndexError, ValueError):
        kind = {b"\x89P": "PNG", b"\xff\xd8": "JPEG", b"BM": "BMP", b"RI": "WebP"}.get(data[:2], "PPM/PGM")
        raise ImageError(f"{what}: a {kind} file cut short before its size, or damaged") from None
    raise ImageError(f"{what}: not an image this program reads ({IMAGE_FORMATS})")


def _jpeg_size(data: bytes) -> tuple[int, int]:
    i = 2
    while True:
        i = data.index(b"\xff", i)  # ValueError at the end of the data: cut short
        while data[i] == 0xFF:
            i += 1
        marker = data[i]
        i += 1
        if marker in (0xD8, 0x01) or 0xD0 <= marker <= 0xD7:  # markers without a length
            continue
        length = struct.unpack(">H", data[i:i + 2])[0]
        if 0xC0 <= marker <= 0xCF and marker not in (0xC4, 0xC8, 0xCC):  # a frame header (SOFn)
            height, width = struct.unpack(">HH", data[i + 3:i + 7])
            return width, height
        if marker == 0xD9 or length < 2:
            raise ValueError("no frame header")
        i += length


def _webp_size(data: bytes) -> tuple[int, int]:
    kind = data[12:16]
    if kind == b"VP8 ":
        width, height = struct.unpack("<HH", data[26:30])
        return width & 0x3FFF, height & 0x3FFF
    if kind == b"VP8L":
        bits = int.from_bytes(data[21:25], "little")
        return (bits & 0x3FFF) + 1, ((bits >> 14) & 0x3FFF) + 1
    if kind == b"VP8X":
        return int.from_bytes(data[24:27], "little") + 1, int.from_bytes(data[27:30], "little") + 1
    raise ValueError("unknown WebP chunk")


def _pnm_size(data: bytes) -> tuple[int, int]:
    words: list[bytes] = []
    for line in data[2:256].split(b"\n"):
        words += line.split(b"#")[0].split()
        if len(words) >= 2:
            return int(words[0]), int(words[1])
    raise ValueError("no size")


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
