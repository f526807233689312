"""The pty helper both emulators stand on: a raw pseudo-terminal behind a stable symlink."""

from __future__ import annotations

import os

import pytest
import serial

from ttt_sm.ptylink import PtyLink, PtyLinkError


def test_bytes_pass_both_ways_unchanged_through_the_link(tmp_path):
    link = PtyLink(tmp_path / "dev", "thing")
    device = link.open()
    assert os.path.realpath(link.port) == device and link.is_open
    with serial.serial_for_url(link.port, timeout=1.0) as pc:
        every_byte = bytes(range(256))  # raw: no echo, no CR/LF translation, no XON/XOFF
        pc.write(every_byte)
        pc.flush()
        got = b""
        while len(got) < 256:
            try:
                got += os.read(link.master, 4096)  # type: ignore[arg-type]
            except BlockingIOError:
                pass
        assert got == every_byte
        os.write(link.master, every_byte)  # type: ignore[arg-type]
        assert pc.read(256) == every_byte
    link.close()
    assert not os.path.lexists(link.port) and link.master is None and link.device is None


def test_reopening_points_the_same_link_at_a_new_pty(tmp_path):
    link = PtyLink(tmp_path / "dev", "thing")
    first = link.open()
    assert link.open() == first  # open twice: the same pty
    link.close()
    second = link.open()
    assert os.path.realpath(link.port) == second
    link.remove()
    assert not os.path.lexists(link.port)


def test_a_link_of_its_own_lives_in_a_temporary_folder_it_removes():
    link = PtyLink(None, "camera")
    link.open()
    folder = os.path.dirname(link.port)
    assert os.path.basename(link.port) == "camera" and os.path.basename(folder).startswith("ttt-camera-")
    link.remove()
    assert not os.path.exists(folder)


def test_a_missing_folder_or_a_file_in_the_way_is_refused_by_name(tmp_path):
    with pytest.raises(PtyLinkError, match=f"the folder of the link {tmp_path}/no/dev does not exist"):
        PtyLink(tmp_path / "no" / "dev", "arm")
    (tmp_path / "file").write_text("mine")
    with pytest.raises(PtyLinkError, match="exists and is not a symlink"):
        PtyLink(tmp_path / "file", "arm")
    assert (tmp_path / "file").read_text() == "mine"
