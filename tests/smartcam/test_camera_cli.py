"""``ttt-sm camera serve`` and ``ttt-sm camera read`` through the parser that ``register`` builds."""

from __future__ import annotations

import argparse
import json
import os
import re
import threading
import time

import pytest

from ttt_sm.cli.camera import register
from ttt_sm.smartcam import CameraEmulator, board_source


def run(*argv: str) -> int:
    parser = argparse.ArgumentParser(prog="ttt-sm")
    register(parser.add_subparsers(dest="command", required=True))
    args = parser.parse_args(list(argv))
    return int(args.func(args))


def test_serve_then_read_as_json(tmp_path, capsys):
    link = str(tmp_path / "cam")
    rc: list[int] = []
    server = threading.Thread(target=lambda: rc.append(run("camera", "serve", "--link", link, "--rate", "50",
                                                           "--duration", "1.5", "--json")))
    server.start()
    try:
        give_up = time.monotonic() + 15
        while not os.path.islink(link) and time.monotonic() < give_up:
            time.sleep(0.01)
        assert run("camera", "read", "--port", link, "--count", "3", "--json") == 0
    finally:
        server.join(30)
    assert rc == [0] and not os.path.lexists(link)
    out = capsys.readouterr().out
    read_doc = json.loads(out[:out.index("\n}\n") + 2])
    serve_doc = json.loads(out[out.index("\n}\n") + 3:])
    frames = read_doc["frames"]
    assert len(frames) == 3 and all(len(f["percentages"]) == 25 for f in frames)
    assert frames[0]["percentages"][0] > 10 and frames[0]["percentages"][1] < 10  # the demo board: X at 1,1
    # frames_ok counts every valid frame received: a busy machine may deliver a 4th in the chunk holding the 3rd
    assert read_doc["stats"]["frames_ok"] >= 3 and read_doc["stats"]["rejected_total"] == 0
    assert serve_doc["stats"]["frames_sent"] >= 3 and serve_doc["link"] == link


def test_read_prints_grids_and_a_summary(tmp_path, capsys):
    with CameraEmulator(board_source("...../...../..O../...../....."), rate_hz=50, link=tmp_path / "cam") as cam:
        assert run("camera", "read", "--port", cam.port, "--count", "2") == 0
    captured = capsys.readouterr()
    assert captured.out.count("(percent of dark pixels per field)") == 2
    # the summary counts every valid frame received: a busy machine may deliver a 3rd in the chunk holding the 2nd
    summary = re.search(r"(\d+) frames, rejected 0,", captured.err)
    assert summary is not None and int(summary.group(1)) >= 2, captured.err


def test_read_shows_rejections_on_stderr(tmp_path, capsys):
    done = threading.Event()

    def noisy_camera(cam: CameraEmulator) -> None:
        while not done.wait(0.05):  # the reader opens whenever it opens: keep sending noise and frames
            cam.send_raw(b"noise\r\n")
            cam.send_frame([1.0] * 25)

    with CameraEmulator(link=tmp_path / "cam") as cam:
        sender = threading.Thread(target=noisy_camera, args=(cam,))
        sender.start()
        try:
            assert run("camera", "read", "--port", cam.port, "--count", "3") == 0
        finally:
            done.set()
            sender.join(30)
    err = capsys.readouterr().err
    assert "WARNING camera" in err and "rejected garbage: 7 bytes outside any sentence" in err
    assert "(garbage " in err.splitlines()[-1]


def test_read_from_a_missing_port_is_one_error_line(tmp_path, capsys):
    assert run("camera", "read", "--port", str(tmp_path / "none"), "--give-up", "0.2") == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1].startswith("ttt-sm camera read: error: camera port") and "could not be opened" in err[-1]


def test_read_from_a_silent_port_stops_at_the_timeout(tmp_path, capsys):
    with CameraEmulator(link=tmp_path / "cam") as cam:
        assert run("camera", "read", "--port", cam.port, "--timeout", "0.3") == 2
    assert "no valid frame" in capsys.readouterr().err


@pytest.mark.parametrize("argv, message", [
    (["serve", "--board", "XX"], "25 cells"),
    (["serve", "--rate", "0"], "--rate"),
    (["serve", "--duration", "-1"], "--duration"),
    (["read", "--count", "0"], "--count"),
    (["read", "--timeout", "0"], "--timeout"),
])
def test_bad_options_are_one_error_line(argv, message, tmp_path, capsys):
    assert run("camera", *argv) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"ttt-sm camera {argv[0]}: error:") and message in err


def test_serve_refuses_to_replace_a_real_file(tmp_path, capsys):
    real = tmp_path / "notes.txt"
    real.write_text("mine")
    assert run("camera", "serve", "--link", str(real), "--duration", "0") == 2
    assert "not a symlink" in capsys.readouterr().err and real.read_text() == "mine"


def test_read_json_that_loses_its_link_still_prints_the_frames_it_read(tmp_path, capsys):
    from ttt_sm.smartcam import Fault

    with CameraEmulator(board_source("...../...../..O../...../....."), rate_hz=50, link=tmp_path / "cam") as cam:
        def pull_the_cable() -> None:
            give_up = time.monotonic() + 15
            while cam.stats.frames_sent < 20 and time.monotonic() < give_up:
                time.sleep(0.02)
            cam.inject(Fault.disconnect(60.0))  # gone for longer than the reader tries to reopen it

        puller = threading.Thread(target=pull_the_cable)
        puller.start()
        try:
            status = run("camera", "read", "--port", cam.port, "--count", "100000", "--give-up", "0.5", "--json")
        finally:
            puller.join(30)
    captured = capsys.readouterr()
    assert status == 2
    doc = json.loads(captured.out)  # one strict JSON document, though the link was lost
    assert doc["complete"] is False and "never came back" in doc["error"]
    assert len(doc["frames"]) == doc["stats"]["frames_ok"] >= 1 and doc["stats"]["disconnects"] == 1
    last = captured.err.strip().splitlines()[-1]
    assert last.startswith("ttt-sm camera read: error: camera port") and f"{len(doc['frames'])} of 100000" in last
