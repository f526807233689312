"""`ttt-sm play` at a real terminal (a pseudo-terminal): the person types moves, a whole game is played."""

import os
import re
import select
import subprocess
import sys
import time
from pathlib import Path

import pytest

pty = pytest.importorskip("pty")

TTT = Path(sys.executable).with_name("ttt-sm")


def _read_until(fd: int, pattern: re.Pattern[str], buffer: list[str], timeout_s: float) -> re.Match[str] | None:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        text = "".join(buffer)
        found = pattern.search(text)
        if found:
            return found
        ready, _, _ = select.select([fd], [], [], 0.5)
        if ready:
            try:
                chunk = os.read(fd, 4096)
            except OSError:  # the child closed the terminal
                return pattern.search("".join(buffer))
            if not chunk:
                return pattern.search("".join(buffer))
            buffer.append(chunk.decode(errors="replace"))
    return None


def _free_cell(picture: str) -> tuple[int, int]:
    rows = [line.split()[1:] for line in picture.splitlines()[1:]]
    for r, row in enumerate(rows, 1):
        for c, mark in enumerate(row, 1):
            if mark == ".":
                return r, c
    raise AssertionError(f"no free cell in\n{picture}")


@pytest.mark.skipif(not TTT.exists(), reason="the ttt-sm console script is not installed beside python")
def test_make_play_s_command_plays_a_whole_game_with_the_person_typing(tmp_path):
    main_fd, child_fd = pty.openpty()
    proc = subprocess.Popen([str(TTT), "play", "--out", str(tmp_path)], stdin=child_fd, stdout=child_fd,
                            stderr=child_fd, close_fds=True, cwd=tmp_path)
    os.close(child_fd)
    buffer: list[str] = []
    seen: list[str] = []  # the whole transcript (the buffer is cleared at each prompt)
    prompt = re.compile(r"(    1 2 3 4 5\r?\n(?:  \d [.XO ]+\r?\n){5})Your move \(X\): [^\n]*$")
    moves = 0
    try:
        while moves < 13:
            found = _read_until(main_fd, prompt, buffer, 120.0)
            if found is None:
                break
            picture = found.group(1).replace("\r", "")
            row, column = _free_cell(picture)
            seen.extend(buffer)
            buffer.clear()
            os.write(main_fd, f"{row} {column}\n".encode())
            moves += 1
        assert proc.wait(timeout=180) == 0
        _read_until(main_fd, re.compile(r"board_png"), buffer, 5.0)
    finally:
        if proc.poll() is None:
            proc.kill()
        os.close(main_fd)
    text = "".join(buffer)
    seen.extend(buffer)
    # every message starts on a line of its own: the status line is taken off first (it ran into them before)
    for told in re.finditer(r"If it is your turn|Your move \(X\)", transcript := "".join(seen)):
        assert transcript[:told.start()].endswith(("\n", "\x1b[K")), transcript[max(0, told.start() - 80):told.end()]
    assert moves >= 4  # four in a row takes at least four moves of the winner
    assert "The manipulator wins." in text or "You win." in text or "Draw" in text
    assert "erased: True" in text and (tmp_path / "game.jsonl").exists()


def test_at_a_terminal_no_message_runs_into_the_status_line(tmp_path):
    """The status line (rewritten with \\r) is ended with a new line before the next message is written."""
    import ttt_sm
    env = dict(os.environ, PYTHONPATH=str(Path(ttt_sm.__file__).parents[1]))  # this checkout's ttt_sm
    main_fd, child_fd = pty.openpty()
    proc = subprocess.Popen([sys.executable, "-m", "ttt_sm.cli", "play", "--camera", "direct", "--out",
                             str(tmp_path)], stdin=child_fd, stdout=child_fd, stderr=child_fd, close_fds=True,
                            cwd=tmp_path, env=env)
    os.close(child_fd)
    buffer: list[str] = []
    try:
        found = _read_until(main_fd, re.compile(r"Your move \(X\): "), buffer, 120.0)
    finally:
        proc.terminate()
        proc.wait(timeout=60)
        os.close(main_fd)
    text = "".join(buffer)
    assert found is not None, text[-2000:]
    status = re.findall(r"\r\x1b\[K  (t = \d+ s simulated: [^\r\n]*)", text)
    assert status, text[-2000:]  # the status line was on show while the field was drawn
    # After an erase only a status text comes, and the last one is ended by a new line, not by the message.
    after_erase = re.findall(r"\x1b\[K(.{0,12})", text)
    assert all(a.startswith("  t = ") for a in after_erase), after_erase
    assert re.search(r"  t = \d+ s simulated: [^\r\n]*field\r?\nIf it is your turn", text), text[-600:]
