"""Images for `vision detect` under fuzz: any bytes, damaged photos, lying headers and odd arrays give
a VisionError (naming the file) or a detection; the size is checked before pixels are decoded."""

from __future__ import annotations

import struct
import tempfile
import zlib
from pathlib import Path

import cv2
import numpy as np
from hypothesis import strategies as st

from fuzzing import fuzz, one_line
from ttt_sm.params import load_params
from ttt_sm.vision import VisionError, detect
from ttt_sm.vision.camera import read_image
from ttt_sm.vision.scenes import scene_from_text
from ttt_sm.vision.simulated import SimulatedCamera

_PHOTO = SimulatedCamera(scene_from_text(load_params(), "X...O.O.X........X....O..", "X", seed=1).board,
                         load_params(), seed=1).frame()
ENCODED = {ext: cv2.imencode(ext, _PHOTO)[1].tobytes() for ext in (".png", ".jpg", ".bmp", ".webp", ".ppm")}


def read_and_detect(data: bytes) -> None:
    with tempfile.TemporaryDirectory() as d:
        f = Path(d) / "photo"
        f.write_bytes(data)
        try:
            detect(read_image(f))
        except VisionError as exc:
            one_line(str(exc), "")


def damaged(case: tuple[str, list[tuple[int, int, bytes]]]) -> None:
    ext, edits = case
    data = ENCODED[ext]
    for at, cut, piece in edits:
        at = at % (len(data) + 1)
        data = data[:at] + piece + data[at + cut:]
    read_and_detect(data)


def png(width: int, height: int, body: bytes) -> bytes:
    def chunk(kind: bytes, payload: bytes) -> bytes:
        return struct.pack(">I", len(payload)) + kind + payload + struct.pack(">I", zlib.crc32(kind + payload))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(body)) + chunk(b"IEND", b""))


def lying_header(case: tuple[int, int, bytes]) -> None:
    width, height, body = case
    read_and_detect(png(width, height, body))


def odd_array(case: tuple[tuple[int, ...], str, int]) -> None:
    shape, dtype, fill = case
    try:
        detect(np.full(shape, fill, dtype=dtype))
    except VisionError as exc:
        one_line(str(exc), "")


_SIZES = st.one_of(st.integers(0, 2**32 - 1), st.sampled_from([0, 1, 239, 240, 320, 480, 640, 3072, 4096, 4097,
                                                               20_000, 2**31, 2**32 - 1]))
test_any_bytes_give_an_image_error, test_any_bytes_give_an_image_error_soak = fuzz(
    st.binary(max_size=2000), quick=300, soak=20000)(read_and_detect)
test_damaged_photos_give_a_vision_error_or_a_detection, test_damaged_photos_give_a_vision_error_or_a_detection_soak = \
    fuzz(st.tuples(st.sampled_from(sorted(ENCODED)),
                   st.lists(st.tuples(st.integers(0, 10**6), st.integers(0, 64), st.binary(max_size=8)), min_size=1,
                            max_size=4)), quick=100, soak=3000)(damaged)
test_a_lying_header_is_refused_before_decoding, test_a_lying_header_is_refused_before_decoding_soak = fuzz(
    st.tuples(_SIZES, _SIZES, st.binary(max_size=200)), quick=150, soak=5000)(lying_header)
test_odd_arrays_give_an_image_error, test_odd_arrays_give_an_image_error_soak = fuzz(
    st.tuples(st.one_of(st.tuples(st.integers(0, 700), st.integers(0, 700)),
                        st.tuples(st.integers(0, 700), st.integers(0, 700), st.integers(0, 5)),
                        st.tuples(st.integers(0, 3)), st.tuples(st.integers(0, 3), st.integers(0, 3),
                                                                st.integers(0, 3), st.integers(0, 3))),
              st.sampled_from(["uint8", "uint16", "float32", "float64", "int8", "bool"]), st.integers(0, 1)),
    quick=100, soak=3000)(odd_array)
