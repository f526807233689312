"""The camera emulator: a real pty behind a stable link, a thread at a rate, faults, clean stops."""

from __future__ import annotations

import os
import threading

import pytest

from ttt_sm.smartcam import (
    CameraEmulator,
    EmulatorError,
    Fault,
    Level,
    Status,
    apply_fault,
    board_source,
    decode_line,
    detection_source,
    encode_frame,
    parse_board,
)


def test_the_link_points_at_a_real_pty_and_follows_replugs(tmp_path):
    cam = CameraEmulator(link=tmp_path / "camera")
    try:
        first = cam.plug()
        assert first.startswith("/dev/pts/") and os.readlink(cam.port) == first and os.isatty(cam._pty._slave)
        cam.unplug()
        assert cam.device is None and not os.path.lexists(cam.port)
        assert cam.send_raw(b"lost") is False and cam.stats.bytes_dropped == 4
        second = cam.plug()
        assert os.readlink(cam.port) == second
    finally:
        cam.stop()
    assert not os.path.lexists(cam.port)


def test_the_default_link_lives_in_a_temporary_folder_removed_on_stop(values):
    with CameraEmulator(lambda: values(0), rate_hz=50) as cam:
        folder = os.path.dirname(cam.port)
        assert os.path.islink(cam.port) and cam.running
    assert not cam.running and not os.path.exists(folder)


def test_it_refuses_to_replace_what_is_not_its_link(tmp_path):
    real = tmp_path / "important.txt"
    real.write_text("keep me")
    with pytest.raises(EmulatorError, match="not a symlink"):
        CameraEmulator(link=real)
    assert real.read_text() == "keep me"
    with pytest.raises(EmulatorError, match="does not exist"):
        CameraEmulator(link=tmp_path / "no" / "such" / "camera")


def test_streaming_sends_consecutive_frames_from_the_source(tmp_path, open_reader, values, read_until):
    calls = []

    def source():
        calls.append(threading.current_thread().name)
        return values(len(calls))

    with CameraEmulator(source, rate_hz=100, link=tmp_path / "cam", first_seq=65530) as cam:
        reader = open_reader(cam.port)
        frames = read_until(reader, lambda: reader.stats.frames_ok >= 12)
    seqs = [f.seq for f in frames]
    assert all((b - a) % 65536 == 1 for a, b in zip(seqs, seqs[1:], strict=False))  # wraps past 65535
    assert reader.stats.gaps == 0 and reader.stats.rejected == {}
    assert calls[0].startswith("camera-emulator")
    assert not cam.running


def test_injected_faults_are_applied_in_order_to_the_stream(tmp_path, open_reader, values, read_until):
    with CameraEmulator(lambda: values(0), rate_hz=100, link=tmp_path / "cam") as cam:
        reader = open_reader(cam.port)
        read_until(reader, lambda: reader.stats.frames_ok >= 2)
        cam.inject(Fault.corrupt_checksum(), Fault.out_of_range(), Fault.garbage(), Fault.skip(7))
        read_until(reader, lambda: cam.faults_pending == 0 and reader.stats.gaps >= 2)
        n = reader.stats.frames_ok
        read_until(reader, lambda: reader.stats.frames_ok >= n + 3)  # good frames keep coming
    stats = reader.stats
    assert stats.rejected["checksum_mismatch"] >= 1 and stats.rejected["out_of_range"] >= 1
    assert stats.rejected["garbage"] >= 1 and stats.frames_missed >= 2 + 7
    assert cam.stats.faults_applied == 4


def test_a_pause_is_silence_without_a_gap(tmp_path, open_reader, values, read_until):
    with CameraEmulator(lambda: values(0), rate_hz=100, link=tmp_path / "cam") as cam:
        reader = open_reader(cam.port, silence_s=0.2)
        read_until(reader, lambda: reader.stats.frames_ok >= 2)
        cam.inject(Fault.pause(0.8))
        read_until(reader, lambda: reader.stats.silences >= 1)
        n = reader.stats.frames_ok
        read_until(reader, lambda: reader.stats.frames_ok >= n + 3)
    assert reader.stats.frames_missed == 0 and reader.stats.disconnects == 0


def test_a_failing_source_becomes_an_error_status_and_the_camera_goes_on(tmp_path, open_reader, values,
                                                                         read_until):
    calls = [0]

    def flaky():
        calls[0] += 1
        if calls[0] % 3 == 0:
            raise RuntimeError("sensor timeout")
        return values(0) if calls[0] % 5 else [float("nan")] * 25

    with CameraEmulator(flaky, rate_hz=100, link=tmp_path / "cam") as cam:
        reader = open_reader(cam.port)
        read_until(reader, lambda: reader.stats.statuses >= 2 and reader.stats.frames_ok >= 3)
    assert reader.last_status.level is Level.ERROR
    assert reader.last_status.text in ("no frame: RuntimeError: sensor timeout",
                                       "bad frame from the detector: cell 1: percentage nan is not finite")
    assert cam.stats.source_errors >= 2 and reader.stats.rejected == {}


def test_writes_never_block_when_nobody_reads(camera, values):
    # The pty holds about 20 KB; past that a UART would overrun, and so does the emulator: it drops.
    results = [camera.send_frame(values(0), wait_s=0.0) for _ in range(400)]
    assert all(results)  # every frame was made (bytes returned)
    stats = camera.stats
    assert stats.frames_sent + stats.frames_dropped == 400 and stats.frames_dropped > 0
    assert stats.bytes_dropped > 0


def test_stop_is_clean_even_while_paused(tmp_path, values):
    cam = CameraEmulator(lambda: values(0), rate_hz=100, link=tmp_path / "cam").start()
    cam.inject(Fault.pause(60.0))
    cam.stop()
    assert not cam.running and not os.path.lexists(cam.port)


def test_line_faults_make_the_bad_lines_they_name(values):
    line = encode_frame(3, values(0))
    assert apply_fault(line, None) == line
    assert apply_fault(line, Fault.truncate(0.25)) == line[:len(line) // 4]
    oor = apply_fault(line, Fault.out_of_range(cell=25, value=101.0))
    assert oor.split(b"*")[0].endswith(b",101.0")
    assert apply_fault(line, Fault.garbage(b"xx")) == b"xx" + line
    with pytest.raises(ValueError, match="cell"):
        apply_fault(line, Fault.non_numeric(cell=26))


def test_the_emulator_sends_status_lines(camera, open_reader, values):
    reader = open_reader(camera.port)
    camera.send_status("INFO", "ready")
    camera.send_frame(values(0))
    assert reader.read_frame().seq == 0 and reader.last_status == Status(Level.INFO, "ready")


def test_start_needs_a_source(camera):
    with pytest.raises(EmulatorError, match="frame_source"):
        camera.start()
    with pytest.raises(EmulatorError, match="frame_source"):
        camera.send_frame()


def test_board_source_is_seeded_and_in_range():
    board = "X...O/...../..X../...../....."
    a, b = board_source(board, seed=3), board_source(board, seed=3)
    first = a()
    assert first == b() and len(first) == 25 and all(0.0 <= p <= 100.0 for p in first)
    assert first[0] > 10 and first[4] > 10 and first[12] > 10 and max(first[1:4]) < 10
    decode_line(encode_frame(0, first))  # what it makes can be sent


@pytest.mark.parametrize("board", ["X" * 24, "X" * 26, "X...Q" * 5])
def test_a_bad_board_says_what_a_board_is(board):
    with pytest.raises(ValueError, match="25 cells"):
        parse_board(board)


def test_detection_source_photographs_then_detects():
    class Camera:
        shots = 0

        def frame(self):
            Camera.shots += 1
            return f"image {Camera.shots}"

    class Detection:
        def __init__(self, image):
            self.percentages = [float(len(image))] * 25

    source = detection_source(Camera(), Detection)
    assert source() == [7.0] * 25 and Camera.shots == 1
