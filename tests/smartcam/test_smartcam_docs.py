"""docs/smartcam.md stays true: its example runs and prints what the page says; the numbers it quotes hold."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from ttt_sm.smartcam import MAX_SENTENCE_BYTES, board_source, crc16, decode_line, encode_frame, encode_status
from ttt_sm.smartcam.errors import Reason

DOC = Path(__file__).resolve().parents[2] / "docs" / "smartcam.md"
TEXT = DOC.read_text(encoding="utf-8")


def test_the_game_example_runs_and_prints_what_the_page_says(capsys):
    pytest.importorskip("ttt_sm.vision")
    blocks = re.findall(r"```python\n(.*?)```", TEXT, re.S)
    assert len(blocks) == 1
    exec(compile(blocks[0], f"{DOC.name}[example]", "exec"), {"__name__": "smartcam_docs"})  # noqa: S102
    out = capsys.readouterr().out
    assert "-> /dev/pts/" in out
    assert "the person played (3, 3)" in out
    assert "rejected {'checksum_mismatch': 1} disconnects 1 reconnects 1" in out


def test_the_example_lines_are_valid_and_as_encoded():
    frame_line, status_line = re.findall(r"^(\$TT[TS],.*)$", TEXT, re.M)[:2]
    frame = decode_line(frame_line.encode() + b"\r\n")
    assert encode_frame(frame.seq, frame.percentages) == frame_line.encode() + b"\r\n"
    assert encode_status("INFO", "ready") == status_line.encode() + b"\r\n"


def test_the_quoted_numbers_hold():
    assert f"{crc16(b'123456789'):04X}" == "29B1" and "0x29B1" in TEXT
    assert f"**{MAX_SENTENCE_BYTES} bytes**" in TEXT
    typical = len(encode_frame(1234, board_source("X...O/...../..X../...../...O.", seed=0)()))
    assert 110 <= typical <= 130
    assert int(11520 / MAX_SENTENCE_BYTES) == 68 and int(960 / MAX_SENTENCE_BYTES * 10) == 57
    assert "carries 68 longest frames per second; at 9600 baud, 5.7." in " ".join(TEXT.split())


def test_every_reason_is_in_the_table():
    for reason in Reason:
        assert f"| `{reason.value}` |" in TEXT, reason
