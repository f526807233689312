"""A game's record survives: written as it happens, ended however the game ends, replayable to its last tick.

The interrupted games run `ttt-sm play` in a subprocess and send it SIGINT or
SIGTERM at a random moment (after a random number of the record's lines);
every line of the record must parse, the last must say how the game ended,
and replaying the record's seed to that line's chart tick must reach the
same state (docs/reliability.md, "Records that survive").  The default run
interrupts three games; the soak run (`make soak`) fifty, two at a time (a
game's replay in this process overlaps the next game's run).
"""

from __future__ import annotations

import io
import random
import signal
import subprocess
import sys
import time
from collections import Counter
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pytest

from ttt_sm.app.game import GameSession
from ttt_sm.app.game_outcome import winning_cells
from ttt_sm.app.game_record import ENDINGS, read_record
from ttt_sm.app.game_replay import replay_record
from ttt_sm.app.person import SimulatedPerson, TerminalPerson
from ttt_sm.charts.game import RESULT_MESSAGES
from ttt_sm.params import load_params
from ttt_sm.twin.board_picture import save_board_picture

P = load_params()
TTT = Path(sys.executable).with_name("ttt-sm")
needs_script = pytest.mark.skipif(not TTT.exists(), reason="the ttt-sm console script is not installed beside python")


def _game_events(path: Path) -> list[dict]:
    return [e for e in read_record(path) if e["event"] != "transition"]


def test_giving_up_ends_the_game_as_given_up_with_a_message_that_says_so(tmp_path):
    shown = io.StringIO()
    person = TerminalPerson(stdin=io.StringIO("3 3\nq\n"), stdout=shown)
    session = GameSession(P, seed=2, person=person, camera="direct", out_dir=tmp_path)
    try:
        report = session.play()
    finally:
        session.close()
    text = shown.getvalue()
    assert report["outcome"] == "given_up" and report["winner"] == "robot"
    assert RESULT_MESSAGES[4] in text and "Draw" not in text
    events = _game_events(tmp_path / "game.jsonl")
    kinds = [e["event"] for e in events]
    assert "given_up" in kinds and kinds[-1] == "finished" and events[-1]["outcome"] == "given_up"
    assert {"event": "result", "outcome": "given_up"}.items() <= next(e for e in events
                                                                      if e["event"] == "result").items()


def _dark_pixels(png: str) -> int:
    image = cv2.imread(png, cv2.IMREAD_GRAYSCALE)
    assert image is not None
    return int(np.count_nonzero(image < 80))


def test_the_final_board_picture_is_taken_before_the_erase_and_the_erased_one_has_its_own_name(
        tmp_path, monkeypatch):
    import ttt_sm.app.game_report as game_module

    titles: list[str] = []

    def save_and_note_the_title(board, path, title, subtitle=""):
        titles.append(title)
        return save_board_picture(board, path, title, subtitle)

    monkeypatch.setattr(game_module, "save_board_picture", save_and_note_the_title)
    said: list[str] = []
    session = GameSession(P, seed=4, camera="direct", out_dir=tmp_path, progress=said.append)
    try:
        report = session.play()
        files = session.save()
    finally:
        session.close()
    # the picture's title and the terminal's line say who won in words, not a bare symbol
    words = {"O": "the robot (O) won", "X": "the person (X) won"}[report["outcome"]]
    assert titles[0].startswith(f"The whiteboard at the end of the game: {words},"), titles
    assert any(line.startswith(f"result: {words}; erasing and turning off; the board as the game ended:\n")
               for line in said), said
    # ... and under the board, the four in a row it was won with
    four = " ".join(f"({r}, {c})" for r, c in winning_cells(session.board) or [])
    assert four and any(line.startswith("result: ") and line.endswith(f"\n  the four in a row: {four}")
                        for line in said), said
    assert Path(files["board_png"]).name == "board_final.png"
    assert Path(files["board_erased_png"]).name == "board_erased.png"
    # the person's black ink and the robot's dark blue are on the final board, not on the erased one
    assert _dark_pixels(files["board_png"]) > 2 * _dark_pixels(files["board_erased_png"])
    events = _game_events(tmp_path / "game.jsonl")
    assert events[-1]["pictures"] == {"final": files["board_png"], "erased": files["board_erased_png"]}


@pytest.mark.parametrize("strength", ["random", "greedy", "thesis", "perfect"])
def test_the_simulated_person_plays_free_cells_at_each_strength(strength):
    person = SimulatedPerson(seed=1, strength=strength)
    board = "XX.X." + "OO.O." + "." * 15
    cell = person.choose(board, "X")
    assert cell is not None and board[(cell[0] - 1) * 5 + cell[1] - 1] == "."
    if strength != "random":
        assert cell == (1, 3)  # four in a row: X X _ X -> the gap wins


def test_a_perfect_person_is_not_beaten_quickly(tmp_path):
    session = GameSession(P, seed=1, camera="direct", person=SimulatedPerson(1, strength="perfect"),
                          record_trace=False)
    try:
        report = session.play()
    finally:
        session.close()
    assert report["outcome"] == "draw" and len(report["moves"]) == 25  # the board full: nobody could force a win


def test_every_game_is_bounded_in_simulated_time():
    from ttt_sm.app.game_outcome import GameError

    session = GameSession(P, seed=0, camera="direct", record_trace=False, time_limit_s=20.0)
    try:
        with pytest.raises(GameError, match=r"did not end within 20 s of simulated time \(its time limit\)"):
            session.play()
        assert session.record.ended == "error" and session.robot.t <= 20.0 + 1e-9
    finally:
        session.close()


def _interrupt_game(tmp_path: Path, seed: int) -> dict[str, Any]:
    """Run one game in a subprocess, signal it after a random number of record lines; what its record shows.

    Returns ``ending`` (``finished``, ``SIGINT``, ``SIGTERM``) and ``problems``:
    every way the record or the run fell short (a lost record is one of them).
    """
    rng = random.Random(seed)
    out = tmp_path / f"game{seed}"
    sig = rng.choice([signal.SIGINT, signal.SIGTERM])
    camera = "serial" if seed % 2 else "direct"
    person = rng.choice(["random", "greedy"])
    proc = subprocess.Popen([str(TTT), "play", "--opponent", "simulated", "--seed", str(seed), "--camera", camera,
                             "--person", person, "--out", str(out)],
                            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                            cwd=tmp_path)
    record = out / "game.jsonl"
    after_lines = rng.randint(1, 150)  # game events and transitions: a whole game writes about 170
    give_up = time.monotonic() + 600
    try:
        while proc.poll() is None and time.monotonic() < give_up:
            try:
                with record.open("rb") as f:
                    if sum(1 for _ in f) >= after_lines:
                        break
            except FileNotFoundError:
                pass
            time.sleep(0.02)
        time.sleep(rng.uniform(0.0, 1.0))
        proc.send_signal(sig)
        _, err = proc.communicate(timeout=300)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    status = proc.returncode
    problems: list[str] = []
    result: dict[str, Any] = {"seed": seed, "ending": "lost", "problems": problems, "lines": 0}
    if "Traceback" in err:
        problems.append(f"a traceback: {err[-2000:]}")
    try:
        lines = read_record(record)  # every line parses
    except (OSError, ValueError) as exc:
        problems.append(f"record lost: {exc}")
        return result
    result["lines"] = len(lines)
    if not lines or lines[0].get("event") != "game" or lines[0].get("seed") != seed:
        problems.append(f"record lost: its first line is not the game's: {lines[:1]}")
        return result
    if (lines[0].get("person"), lines[0].get("camera")) != (f"simulated {person}", camera):
        problems.append(f"the game line does not say who played and how it saw: {lines[0]}")
    last = lines[-1]
    if last.get("event") not in ENDINGS:
        problems.append(f"record lost: its last line says nothing of how the game ended: {last}")
        return result
    if last["event"] == "finished":  # the game ended before the signal came
        result["ending"] = "finished"
        if status != 0:
            problems.append(f"finished, but status {status}: {err[-500:]}")
    else:
        result["ending"] = sig.name
        if not (last["event"] == "interrupted" and last["signal"] == sig.name and last["boundary"] is True):
            problems.append(f"the last line is not this {sig.name}'s: {last}")
        if status != 128 + sig:
            problems.append(f"status {status}, not {128 + sig}: {err[-500:]}")
        if f"interrupted ({sig.name})" not in (err.strip().splitlines() or [""])[-1]:
            problems.append(f"standard error does not end saying so: {err[-500:]}")
        if not (last.get("waiting_for") and last.get("pictures")) or not all(
                Path(p).is_file() for p in last["pictures"].values()):
            problems.append(f"where it stood or its pictures missing: {last}")
    check = replay_record(record, P)
    if not check.identical:
        problems.append(check.describe())
    return result


def _interrupt_games(tmp_path: Path, seeds: list[int], workers: int = 1) -> tuple[dict[str, int], list[str]]:
    """Interrupt a game per seed (``workers`` at a time: a game's replay overlaps another game's run).

    Returns the counts (games, how they ended, records lost, lines) and every problem found.
    """
    with ThreadPoolExecutor(max_workers=workers) as pool:
        results = list(pool.map(lambda s: _interrupt_game(tmp_path, s), seeds))
    endings = Counter(str(r["ending"]) for r in results)
    problems = [f"seed {r['seed']}: {p}" for r in results for p in r["problems"]]
    counts = {"games": len(results), "SIGINT": endings["SIGINT"], "SIGTERM": endings["SIGTERM"],
              "finished_first": endings["finished"],
              "records_lost": sum(any(p.startswith("record lost") for p in r["problems"]) for r in results),
              "lines": sum(r["lines"] for r in results)}
    return counts, problems


@needs_script
def test_interrupted_games_keep_a_record_that_replays_to_its_last_tick(tmp_path):
    counts, problems = _interrupt_games(tmp_path, [11, 12, 13])
    assert not problems, "\n\n".join(problems)
    assert counts["records_lost"] == 0 and counts["SIGINT"] + counts["SIGTERM"] >= 2


@pytest.mark.soak
@needs_script
def test_fifty_interrupted_games_lose_no_record(tmp_path):
    counts, problems = _interrupt_games(tmp_path, list(range(100, 150)), workers=2)
    print(f"interrupted games: {counts}")
    assert not problems, "\n\n".join(problems)
    assert counts["games"] == 50 and counts["records_lost"] == 0 and counts["SIGINT"] + counts["SIGTERM"] >= 45


def _signal_after_the_end(tmp_path: Path, seed: int, sig: signal.Signals) -> tuple[int, int, str, list[dict]]:
    """Play a game; from the moment its record says ``finished``, send ``sig`` every millisecond until it exits.

    Returns the exit status, how many signals were sent to the running process, its standard error and
    its record.
    """
    out = tmp_path / f"late{seed}"
    proc = subprocess.Popen([str(TTT), "play", "--opponent", "simulated", "--seed", str(seed), "--camera", "direct",
                             "--out", str(out)], stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True, cwd=tmp_path)
    record, sent = out / "game.jsonl", 0
    give_up = time.monotonic() + 600
    try:
        while proc.poll() is None and time.monotonic() < give_up:
            try:
                ended = b'"event": "finished"' in record.read_bytes()[-2000:]
            except FileNotFoundError:
                ended = False
            if ended:
                proc.send_signal(sig)
                sent += 1
            time.sleep(0.001)
        _, err = proc.communicate(timeout=300)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    return proc.returncode, sent, err, read_record(record)


@needs_script
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_a_signal_after_the_game_ended_changes_nothing(tmp_path, sig):
    """Ctrl-C or SIGTERM while a finished game saves its pictures and exits: status 0, all files whole.

    The 50-game soak once caught the process killed by such a late signal (status -2, -15) after its
    record said ``finished``: the handlers were put back before the pictures were saved.
    """
    status, sent, err, lines = _signal_after_the_end(tmp_path, 21, sig)
    assert sent >= 1, "the process exited before a signal could be sent after its record ended"
    assert status == 0 and "Traceback" not in err, (status, err[-1500:])
    assert lines[-1]["event"] == "finished"
    assert (tmp_path / "late21" / "board_final.png").is_file(), sorted(p.name for p in (tmp_path / "late21").iterdir())
