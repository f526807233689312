"""Photos that must not be read silently or at any cost: huge, not images, turned, mirrored.

An image's size is read from its header before anything is decoded; a photo
whose orientation the perspective (or the robot's own marks) contradicts is
refused naming the photo; docs/reliability.md lists the limits.
"""

from __future__ import annotations

import re
import struct
import subprocess
import sys
import textwrap
import zlib
from pathlib import Path

import cv2
import numpy as np
import pytest

from ttt_sm.vision import VisionError, detect
from ttt_sm.vision.camera import MAX_FILE_BYTES, MAX_SIZE, read_image
from ttt_sm.vision.errors import ImageError, OrientationError
from ttt_sm.vision.orientation import check_orientation, check_robot_marks, image_text
from ttt_sm.vision.scenes import scene_from_text
from ttt_sm.vision.simulated import SimulatedCamera

MEMORY_LIMIT_MB = 500
BOARD = "X...O" ".O..." "..X.." "....." "O...X"  # the robot plays X
ROBOT_MARKS = "".join(ch if ch == "X" else "." for ch in BOARD)


def png_of_size(path: Path, width: int, height: int) -> Path:
    """A valid grey PNG of any size, written row by row: the file is small, its pixels are not."""
    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
    z = zlib.compressobj(9)
    row = b"\0" + b"\xff" * width
    body = b"".join(z.compress(row) for _ in range(height)) + z.flush()
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0))
                     + chunk(b"IDAT", body) + chunk(b"IEND", b""))
    return path


def jpeg_header_of_size(path: Path, width: int, height: int) -> Path:
    """The start of a baseline JPEG whose frame header claims `width` x `height` (no scan follows)."""
    sof = struct.pack(">BBHBHHB", 0xFF, 0xC0, 11, 8, height, width, 1) + b"\x01\x11\x00"
    path.write_bytes(b"\xff\xd8" + b"\xff\xe0" + struct.pack(">H", 16) + b"JFIF\0\x01\x01\0\0\x01\0\x01\0\0" + sof)
    return path


def peak_mb_reading(path: Path) -> tuple[str, float]:
    """read_image(path) in a fresh process whose address space is capped; its message and peak RSS."""
    code = textwrap.dedent(f"""
        import resource, sys
        cap = {3 * MEMORY_LIMIT_MB} * 2**20  # a safety net: decoding 20000 x 20000 pixels takes 1.2 GB
        resource.setrlimit(resource.RLIMIT_AS, (cap, cap))
        from ttt_sm.vision.camera import read_image
        from ttt_sm.vision.errors import ImageError
        try:
            read_image({str(path)!r})
            print("read")
        except ImageError as exc:
            print(exc)
        hwm = next(line for line in open("/proc/self/status") if line.startswith("VmHWM:"))
        print(int(hwm.split()[1]) / 1024)
    """)
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    lines = proc.stdout.strip().splitlines()
    assert proc.returncode == 0 and len(lines) == 2, proc.stderr[-1500:]
    return lines[0], float(lines[1])


def test_a_20000_pixel_square_image_is_refused_from_its_header_in_bounded_memory(tmp_path):
    big = png_of_size(tmp_path / "big.png", 20_000, 20_000)
    assert big.stat().st_size < MAX_FILE_BYTES
    message, peak_mb = peak_mb_reading(big)
    assert message == (f"{big}: 20000 x 20000 pixels is the wrong size: width and height must lie within 320 x 240"
                       f" .. {MAX_SIZE[0]} x {MAX_SIZE[1]} (640 x 480 expected)")
    assert peak_mb < MEMORY_LIMIT_MB


def test_a_jpeg_header_claiming_a_huge_frame_is_refused_before_decoding(tmp_path):
    with pytest.raises(ImageError, match=r"60000 x 50000 pixels is the wrong size"):
        read_image(jpeg_header_of_size(tmp_path / "big.jpg", 60_000, 50_000))


@pytest.mark.parametrize("content, message", [
    (b"", "not an image: the file is empty"),
    (b"hello", "not an image this program reads (PNG, JPEG, BMP"),
    (b"\x89PNG\r\n\x1a\n\0\0", "a PNG file cut short before its size"),
    (b"\xff\xd8\xff\xe0\0\x10JFIF", "a JPEG file cut short before its size"),
])
def test_files_that_are_not_images_get_one_line_naming_the_file(tmp_path, content, message):
    f = tmp_path / "x.png"
    f.write_bytes(content)
    with pytest.raises(ImageError) as info:
        read_image(f)
    assert str(info.value).startswith(f"{f}: ") and message in str(info.value)


def test_a_folder_or_a_device_is_not_read(tmp_path):
    with pytest.raises(ImageError, match=rf"^{tmp_path}: not a file"):
        read_image(tmp_path)
    with pytest.raises(ImageError, match=r"^/dev/zero: not a file"):
        read_image("/dev/zero")


def test_a_truncated_photo_is_an_image_error(tmp_path):
    photo = tmp_path / "p.png"
    cv2.imwrite(str(photo), np.full((480, 640, 3), 200, np.uint8))
    photo.write_bytes(photo.read_bytes()[:200])
    with pytest.raises(ImageError, match=rf"^{photo}: "):
        read_image(photo)


# --------------------------------------------------------------------------- orientation

@pytest.fixture(scope="module")
def photo(params) -> np.ndarray:
    scene = scene_from_text(params, BOARD, "X", seed=3)
    return SimulatedCamera(scene.board, params, seed=3).frame()


def test_an_upright_photo_from_beyond_the_far_edge_passes(photo):
    det = detect(photo)
    note = check_orientation(det.grid, "far_edge", "p.png")
    assert note.startswith("orientation checked: the field's near side is at the bottom, 1")
    check_robot_marks(det.cells, "far_edge", ROBOT_MARKS, "p.png")


@pytest.mark.parametrize("turn, side, fix", [
    (cv2.ROTATE_90_CLOCKWISE, "left", "turn it 90 deg counter-clockwise"),
    (cv2.ROTATE_90_COUNTERCLOCKWISE, "right", "turn it 90 deg clockwise"),
    (cv2.ROTATE_180, "top", "turn it 180 deg"),
])
def test_a_turned_photo_is_refused_by_its_perspective(photo, turn, side, fix):
    det = detect(cv2.rotate(photo, turn))
    with pytest.raises(OrientationError) as info:
        check_orientation(det.grid, "far_edge", "p.png")
    message = str(info.value)
    assert re.match(rf"p.png: the photo is turned: the field's near side \(the widest, 1\.\d\d times its far side\)"
                    rf" is at the {side} of the picture", message), message
    assert fix in message


def test_a_mirrored_photo_is_refused_by_the_robot_s_marks(photo):
    det = detect(cv2.flip(photo, 1))
    check_orientation(det.grid, "far_edge", "p.png")  # the perspective cannot see a mirror
    with pytest.raises(OrientationError, match=r"^p.png: the robot's marks show the photo mirrored left-right"):
        check_robot_marks(det.cells, "far_edge", ROBOT_MARKS, "p.png")


def test_a_view_without_perspective_says_it_did_not_check(photo):
    note = check_orientation(detect(photo).grid, "above", "p.png")
    assert note.startswith("orientation not checked")


def test_robot_marks_that_are_not_there_are_named(photo):
    det = detect(photo)
    marks = "X" + "." * 24
    other = image_text(marks, "far_edge")
    assert det.cells != other
    with pytest.raises(VisionError, match=r"the robot's marks are not all seen"):
        check_robot_marks(det.cells, "far_edge", "...X." + "." * 20, "p.png")


def test_in_a_game_marks_seen_where_a_mirror_puts_them_blame_the_camera_not_the_person():
    from ttt_sm.vision import PictureTurnedError, SymbolVanishedError, percent_process

    robot, person = [(1, 1), (3, 2)], [(2, 4)]
    seen = [0.0] * 25
    for r, c in robot + person:  # every mark where a left-right mirror of the picture shows it
        seen[(r - 1) * 5 + (5 - c)] = 25.0
    with pytest.raises(PictureTurnedError) as info:
        percent_process(seen, robot, person)
    assert "fix the camera" in info.value.message_for_person
    assert isinstance(info.value, OrientationError)
    seen[(1 - 1) * 5 + (5 - 1)] = 0.0  # one of them wiped as well: nothing explains it, a symbol vanished
    with pytest.raises(SymbolVanishedError):
        percent_process(seen, robot, person)


def run_cli(argv: list[str]) -> int:
    from ttt_sm.cli import main
    return main(argv)


def test_vision_detect_refuses_a_turned_and_a_mirrored_photo_naming_it(photo, tmp_path, capsys):
    turned = tmp_path / "turned.png"
    cv2.imwrite(str(turned), cv2.rotate(photo, cv2.ROTATE_90_CLOCKWISE))
    assert run_cli(["vision", "detect", str(turned)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"ttt-sm vision: error: {turned}: the photo is turned") and err.count("\n") == 1
    mirrored = tmp_path / "mirrored.png"
    cv2.imwrite(str(mirrored), cv2.flip(photo, 1))
    assert run_cli(["vision", "detect", str(mirrored), "--robot-marks", ROBOT_MARKS]) == 2
    assert f"{mirrored}: the robot's marks show the photo mirrored left-right" in capsys.readouterr().err
    upright = tmp_path / "upright.png"
    cv2.imwrite(str(upright), photo)
    assert run_cli(["vision", "detect", str(upright), "--robot-marks", ROBOT_MARKS, "--json"]) == 0
    out = capsys.readouterr().out
    assert '"orientation": "orientation checked: the field\'s near side is at the bottom' in out
    assert "the robot's marks ((1, 1), (3, 3), (5, 5)) are where it drew them" in out


@pytest.mark.parametrize("argv, message", [
    (["vision", "render", "{tmp}/photo"], "OUT '{tmp}/photo': cannot write a picture with the extension '(none)'"),
    (["vision", "render", "{tmp}/photo.xyz"], "OUT '{tmp}/photo.xyz': cannot write a picture with the extension"),
    (["vision", "render", "{tmp}/no/such/photo.png"], "OUT '{tmp}/no/such/photo.png': could not write the picture"),
    (["vision", "detect", "{tmp}/upright.png", "--overlay", "{tmp}/o"], "--overlay '{tmp}/o': cannot write a picture"),
    (["vision", "bench", "--photos", "1000000000"], "--photos must lie in 1..10000, got 1000000000"),
])
def test_output_paths_and_counts_are_checked_before_the_work(photo, tmp_path, capsys, argv, message):
    cv2.imwrite(str(tmp_path / "upright.png"), photo)
    assert run_cli([a.replace("{tmp}", str(tmp_path)) for a in argv]) == 2
    err = capsys.readouterr().err
    assert message.replace("{tmp}", str(tmp_path)) in err and err.count("\n") == 1, err
