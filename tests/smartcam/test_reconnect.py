"""Disconnects over real pseudo-terminals: the port goes away, the reader reports it, reopens it by its
stable name with bounded backoff, and resumes; or gives up within its bounds.  Nothing here may hang."""

from __future__ import annotations

import logging
import os

import pytest
import serial

from ttt_sm.smartcam import (
    CameraEmulator,
    Fault,
    LinkLost,
    PortUnavailable,
    ReconnectPolicy,
    SerialCameraReader,
)

LOGGER = "ttt_sm.smartcam.reader"
TIGHT = ReconnectPolicy(first_delay_s=0.01, max_delay_s=0.05, max_attempts=5, max_duration_s=30.0)


def send_until_read(camera, reader, values, read_until) -> list:
    """Send frames until the reader gets one (it may still be reopening, and drops stale bytes on open)."""
    got: list = []

    def done() -> bool:
        camera.send_frame(values(len(got)))
        frame = reader.read_frame(0.1)
        if frame is not None:
            got.append(frame)
        return bool(got)
    read_until(reader, done)
    return got


def test_unplug_is_reported_and_the_reader_resumes_on_the_new_pty(camera, open_reader, values, read_until, caplog):
    caplog.set_level(logging.INFO, logger=LOGGER)
    reader = open_reader(camera.port)
    first_device = camera.device
    camera.send_frame(values(0))
    assert reader.read_frame().seq == 0

    camera.unplug()
    assert not os.path.lexists(camera.port)
    assert reader.read_frame(0.3) is None  # notices, keeps trying, returns at the deadline
    assert reader.stats.disconnects == 1 and not reader.connected

    camera.plug()
    assert os.readlink(camera.port) == camera.device
    got = send_until_read(camera, reader, values, read_until)
    assert got[0].seq >= 1
    stats = reader.stats
    assert (stats.disconnects, stats.reconnects) == (1, 1)
    assert reader.device == camera.device
    messages = [r.getMessage() for r in caplog.records]
    assert any("link lost" in m and "reopening" in m for m in messages)
    assert any(f"link back on {camera.device}" in m for m in messages)
    assert first_device.startswith("/dev/pts/")


def test_a_line_cut_by_the_disconnect_is_counted_as_truncated(camera, open_reader, values, read_until):
    reader = open_reader(camera.port)
    camera.send_frame(values(0), fault=Fault.truncate(0.5))
    assert reader.read_frame(0.2) is None  # half a line waits for its end
    camera.unplug()
    read_until(reader, lambda: reader.stats.disconnects == 1)
    assert reader.stats.rejected == {"truncated": 1}


def test_a_streaming_camera_that_drops_off_for_a_while_is_picked_up_again(tmp_path, open_reader, values,
                                                                         read_until):
    with CameraEmulator(lambda: values(0), rate_hz=100, link=tmp_path / "cam") as cam:
        reader = open_reader(cam.port)
        read_until(reader, lambda: reader.stats.frames_ok >= 5)
        cam.inject(Fault.disconnect(0.3))
        read_until(reader, lambda: reader.stats.reconnects == 1)
        after = reader.stats.frames_ok
        frames = read_until(reader, lambda: reader.stats.frames_ok >= after + 5)
        assert frames and cam.stats.unplugs == 1 and cam.stats.plugs == 2
        stats = reader.stats
        # frames made while unplugged were lost: the sequence numbers show it
        assert stats.gaps >= 1 and stats.frames_missed >= 1 and stats.disconnects == 1


def test_a_port_that_never_comes_back_ends_in_link_lost(camera, open_reader, values, caplog):
    reader = open_reader(camera.port, reconnect=TIGHT)
    camera.send_frame(values(0))
    assert reader.read_frame().seq == 0
    camera.unplug()
    with pytest.raises(LinkLost, match=r"never came back: 5 attempts .* No such file"):
        for _ in range(10_000):  # each call is bounded; the policy ends it after 5 attempts
            reader.read_frame(0.05)
    with pytest.raises(LinkLost):  # and it stays lost
        reader.read_frame(0.05)
    with pytest.raises(LinkLost):
        reader.latest()


def test_the_time_bound_ends_retries_too(camera, open_reader, values):
    reader = open_reader(camera.port, reconnect=ReconnectPolicy(first_delay_s=0.01, max_delay_s=0.02,
                                                                max_attempts=10**9, max_duration_s=0.3))
    camera.unplug()
    with pytest.raises(LinkLost, match="never came back"):
        reader.read_frame(60.0)  # the policy's 0.3 s, not the 60 s asked, ends the wait


def test_latest_never_waits_for_a_reconnect(camera, open_reader, values, read_until):
    reader = open_reader(camera.port)
    camera.send_frame(values(0))
    read_until(reader, lambda: reader.latest() is not None)
    camera.unplug()
    for _ in range(20):  # polls while the link is down: the last frame, stale, and no wait
        assert reader.latest().seq == 0
    assert reader.stats.disconnects == 1
    camera.plug()
    read_until(reader, lambda: (camera.send_frame(values(1)), reader.latest())[1].seq != 0)
    assert reader.stats.reconnects == 1


def test_a_missing_port_at_start_is_port_unavailable(tmp_path):
    reader = SerialCameraReader(str(tmp_path / "no-camera"), 1.0, reconnect=TIGHT)
    with pytest.raises(PortUnavailable, match="could not be opened: 5 attempts"):
        reader.open()


def test_a_camera_that_starts_after_the_reader_is_found(tmp_path, values, read_until):
    link = tmp_path / "late"
    reader = SerialCameraReader(str(link), 1.0, reconnect=ReconnectPolicy(first_delay_s=0.01, max_delay_s=0.05,
                                                                          max_duration_s=30.0))
    try:
        assert reader.read_frame(0.2) is None and not reader.connected  # nothing there yet: tries, returns
        with CameraEmulator(lambda: values(0), rate_hz=100, link=link):
            frames = read_until(reader, lambda: reader.stats.frames_ok >= 3)
        assert frames[0].percentages == tuple(values(0)) and reader.stats.reconnects == 0
    finally:
        reader.close()


def test_a_malformed_url_is_refused_at_once():
    reader = SerialCameraReader("nosuchscheme://camera", 1.0, reconnect=TIGHT)
    with pytest.raises(PortUnavailable, match="nosuchscheme"):
        reader.read_frame(0.1)


def test_a_given_serial_instance_is_reopened_by_its_name(camera, open_reader, values, read_until):
    reader = open_reader(serial.Serial(camera.port, timeout=1))
    camera.send_frame(values(0))
    assert reader.read_frame().seq == 0
    camera.unplug()
    read_until(reader, lambda: reader.stats.disconnects == 1)
    camera.plug()
    send_until_read(camera, reader, values, read_until)
    assert reader.stats.reconnects == 1 and reader.device == camera.device


def test_backoff_grows_and_is_capped():
    policy = ReconnectPolicy(first_delay_s=0.05, max_delay_s=1.0, factor=2.0)
    assert [policy.delay_s(k) for k in range(7)] == [0.05, 0.1, 0.2, 0.4, 0.8, 1.0, 1.0]
    assert policy.delay_s(10_000) == 1.0
    with pytest.raises(ValueError):
        ReconnectPolicy(max_attempts=0)
    with pytest.raises(ValueError):
        ReconnectPolicy(first_delay_s=2.0, max_delay_s=1.0)
