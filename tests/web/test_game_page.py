"""The Tic-tac-toe page (/game) in Chromium: a person plays the robot by clicking, through the camera.

Each test has a session of its own (a game is played once): the robot with
the Game and AlgorithmActivator charts, the person at the page
(``Debugger.build(game=True, person="page")``), paused at power-on, as fast as
it goes once Run is clicked.  What the tests assert on is the game's own
state read in the simulation thread (moves, detections, the whiteboard's
ink), beside what the page shows.

The screenshot of docs/gui.md's ``/game`` section is taken mid-game; ``make
screenshots`` (``TTT_SM_SCREENSHOTS=docs/img``) writes it into docs/img.
"""

from __future__ import annotations

import os
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from ttt_sm.app.game_outcome import outcome_in_words
from ttt_sm.app.game_record import read_record
from ttt_sm.charts.game import MSG_ERASING, MSG_TURNING_OFF, MSG_YOUR_TURN, RESULT_MESSAGES
from ttt_sm.debug.debugger import Debugger
from ttt_sm.params import load_params
from ttt_sm.web.session import Session

from .conftest import Cockpit, served, text_of

SHOT = "gui_game.png"
WON_SHOT = "gui_game_won.png"
#: Waits in the page, ms: the simulation runs as fast as it goes but the machine may be busy.
LONG = 240_000


@pytest.fixture
def game_cockpit(tmp_path: Path) -> Iterator[Cockpit]:
    """A game with the person at the page, paused at power-on, as fast as it goes when run."""
    dbg = Debugger.build(load_params(), seed=0, game=True, person="page", record_root=tmp_path / "gui")
    session = Session(dbg, speed=None, running=False, trace_path=tmp_path / "trace.jsonl")
    with served(session) as cockpit:
        yield cockpit


def wait_text(page: Any, role: str, text: str, timeout: int = LONG) -> None:
    page.wait_for_function("([role, text]) => document.querySelector(`[data-role=\"${role}\"]`)"
                           ".textContent.trim() === text", arg=[role, text], timeout=timeout)


def cell(page: Any, row: int, column: int) -> Any:
    return page.get_by_role("gridcell", name=f"row {row}, column {column}", exact=True)


#: Some cell of the board can be clicked: the person's turn to draw (occupied cells never can).
CELL_OFFERED = "Array.from(document.querySelectorAll('[data-role=board] button')).some(b => !b.disabled)"


def game_state(cockpit: Cockpit) -> dict[str, Any]:
    def read(dbg: Debugger) -> dict[str, Any]:
        game = dbg.game
        assert game is not None
        return {"moves": [dict(m) for m in game.moves], "board": game.board, "truth": game.truth,
                "robot": game.robot_symbol, "person": game.person_symbol, "outcome": game.outcome,
                "correct": game.detections_correct, "wrong": game.detections_wrong, "photos": game.photos,
                "ink_mm2": dbg.robot.board.ink_area_mm2(), "ended": bool(game.game.ended),
                "active": sorted(dbg.robot.active("Game")), "activations": game.activator.activations}
    result: dict[str, Any] = cockpit.session.call(read)
    return result


def open_game(page: Any, cockpit: Cockpit) -> None:
    page.goto(cockpit.page_url("/game"))
    wait_text(page, "text-box2", "Wait for the model to be compiled.", timeout=30_000)


def run_to_first_turn(page: Any) -> None:
    page.get_by_role("button", name="Run", exact=True).click()
    wait_text(page, "text-box2", MSG_YOUR_TURN)
    page.wait_for_function(CELL_OFFERED, timeout=LONG)


def wait_board(page: Any, board: str) -> None:
    """Until the page's clean board shows ``board`` (25 characters, '.' for an empty cell)."""
    page.wait_for_function(
        "(board) => Array.from(document.querySelectorAll('[data-role=board] button'))"
        ".map((b) => b.textContent || '.').join('') === board", arg=board, timeout=30_000)


def test_a_whole_game_played_by_clicking(browser: Any, game_cockpit: Cockpit, tmp_path: Path) -> None:
    page = browser.new_page(viewport={"width": 1400, "height": 1000})
    try:
        open_game(page, game_cockpit)
        assert page.get_by_role("status").filter(has_text="Wait for the model to be compiled.").count() == 1
        # Every message Text box2 shows, in order: at full speed the result is on show for a moment only.
        page.evaluate("() => { const box = document.querySelector('[data-role=\"text-box2\"]'); window.box2 = [];"
                      " new MutationObserver(() => { const t = box.textContent.trim();"
                      " if (window.box2[window.box2.length - 1] !== t) window.box2.push(t); })"
                      ".observe(box, { childList: true, characterData: true, subtree: true }); }")
        # And every tool the arm's views showed in use and on the board (the erase is seen live).
        page.evaluate("() => { const arm = document.querySelector('[data-role=\"arm\"]'); window.tools = new Set();"
                      " new MutationObserver(() => window.tools.add(`${arm.dataset.tool}/${arm.dataset.touching}`))"
                      ".observe(arm, { attributes: true }); }")
        run_to_first_turn(page)
        # The engine: the thesis' (section 3.6.2), chosen before the first move.
        page.get_by_role("combobox", name="Engine").select_option("thesis")
        page.wait_for_function("document.querySelector('[data-role=reply]').textContent.includes('thesis')",
                               timeout=30_000)
        assert game_cockpit.session.call(lambda d: d.game.engine_name) == "thesis"
        symbol = page.get_by_role("button", name="Symbol", exact=True)
        # Before the first move the symbol may change, and Text box1 says so.
        assert text_of(page, "text-box1").startswith("You can change the manipulator's symbol: it plays O")
        symbol.click()
        wait_text(page, "robot-symbol", "X", timeout=30_000)
        assert game_state(game_cockpit)["robot"] == "X"
        symbol.click()
        wait_text(page, "robot-symbol", "O", timeout=30_000)
        assert game_state(game_cockpit)["robot"] == "O"

        person_moves = 0
        photos_seen: list[str] = []
        while True:
            state = game_state(game_cockpit)
            if state["outcome"] is not None:
                break
            free = [i for i, v in enumerate(state["truth"]) if v == "."]
            row, column = divmod(free[0], 5)
            cell(page, row + 1, column + 1).click()
            # The hand has drawn: the page shows it drawn, not yet read by the camera.
            page.wait_for_function(
                "([r, c]) => document.querySelector(`[data-role=board] button[data-row=\"${r}\"]"
                "[data-column=\"${c}\"]`).dataset.by === 'drawn'", arg=[row + 1, column + 1], timeout=30_000)
            page.get_by_role("button", name="Play", exact=True).click()
            person_moves += 1
            if person_moves == 1:
                page.wait_for_function("document.querySelector('[data-cmd=symbol]').disabled", timeout=LONG)
                assert "cannot change after the first move" in text_of(page, "text-box1")
            # The camera read the person's cell; the manipulator answers (or the game ends).
            page.wait_for_function(
                "([r, c]) => document.querySelector(`[data-role=board] button[data-row=\"${r}\"]"
                "[data-column=\"${c}\"]`).dataset.by === 'person'", arg=[row + 1, column + 1], timeout=LONG)
            page.wait_for_function(
                "() => { const m = document.querySelector('[data-role=\"text-box2\"]').textContent;"
                " const b = document.querySelector('[data-role=board] button');"
                " return !m.startsWith('If it is') || !b.disabled; }", timeout=LONG)
            page.wait_for_function(
                "() => { const m = document.querySelector('[data-role=\"text-box2\"]').textContent;"
                " return m !== 'The manipulator is drawing.'; }", timeout=LONG)
            state = game_state(game_cockpit)
            if state["outcome"] is None:
                page.wait_for_function(CELL_OFFERED,
                                       timeout=LONG)
            photo = page.locator('[data-role="photo"]')
            photos_seen.append(str(photo.get_attribute("data-photo")))
            if state["outcome"] is None:
                # The clean board is the board the game believes: the robot's moves and the moves read.
                assert state["board"] == state["truth"]
                wait_board(page, state["board"])
            if person_moves == 2:
                shot = Path(os.environ.get("TTT_SM_SCREENSHOTS") or tmp_path) / SHOT
                page.screenshot(path=str(shot), full_page=True)
                assert shot.stat().st_size > 20_000
        state = game_state(game_cockpit)
        result = {state["robot"]: 1, state["person"]: 2, "draw": 3}[state["outcome"]]
        page.wait_for_function("document.querySelector('[data-cmd=stop]').disabled", timeout=LONG)
        wait_text(page, "text-box2", MSG_TURNING_OFF)
        # The result, then erasing, then turning off: the thesis' order, as the Game chart output them.
        assert page.evaluate("window.box2")[-3:] == [RESULT_MESSAGES[result], MSG_ERASING, MSG_TURNING_OFF]
        # ... and who won stays said after Text box2 has moved on
        words = outcome_in_words(state["outcome"], state["robot"], state["person"])
        assert text_of(page, "result") == f"Result: {words}."
        if state["outcome"] in (state["robot"], state["person"]):  # a win: its four in a row marked on the board
            marked = page.locator('[data-role=board] button[data-win="true"]')
            assert marked.count() == 4 and set(marked.all_inner_texts()) == {state["outcome"]}
            shots = os.environ.get("TTT_SM_SCREENSHOTS")
            if shots:
                page.screenshot(path=str(Path(shots) / WON_SHOT), full_page=False)
        state = game_state(game_cockpit)
        person = [m for m in state["moves"] if m["by"] == "person"]
        assert len(person) == person_moves
        assert page.locator('[data-role="engine"]').is_disabled()  # locked since the first move
        # The erase was shown as it happened: the sponge in use, and on the board.
        tools = page.evaluate("Array.from(window.tools)")
        assert "sponge/sponge" in tools and "pen/pen" in tools, tools
        # The record, as `ttt-sm play` writes it, in the gui's folder; the page says where.
        record = tmp_path / "gui" / "game-1" / "game.jsonl"
        page.get_by_role("status", name="the game's record").filter(has_text=f"{record} (ended: finished)").wait_for(
            timeout=LONG)
        lines = read_record(record)
        assert lines[0]["event"] == "game" and lines[-1]["event"] == "finished"
        assert lines[-1]["outcome"] == state["outcome"]
        assert [e["engine"] for e in lines if e["event"] == "engine"] == ["thesis"]
        assert sum(e["event"] == "person_drew" for e in lines) == person_moves
        # Every cell the person clicked was read through the camera, and read right.
        assert all(m["detected"] == [m["row"], m["column"]] for m in person)
        assert state["correct"] == person_moves and state["wrong"] == 0
        assert len(set(photos_seen)) == len(photos_seen)  # a new photo after every move
        assert state["ended"] and state["ink_mm2"] == 0.0  # erased, turned off
        # A new game: a new robot from power-on, the engine kept; Run starts it.
        page.get_by_role("button", name="New game", exact=True).click()
        wait_text(page, "text-box2", "Wait for the model to be compiled.", timeout=60_000)
        wait_board(page, "." * 25)
        assert text_of(page, "result") == ""
        assert game_cockpit.session.call(lambda d: (d.robot.t, d.game.engine_name, d.game.moves)) == (0.0, "thesis", [])
        assert text_of(page, "record").startswith(f"The game's record: {tmp_path / 'gui' / 'game-2' / 'game.jsonl'}")
    finally:
        page.close()


def test_an_occupied_cell_cannot_be_clicked_and_a_click_sent_anyway_is_refused_in_words(
        browser: Any, game_cockpit: Cockpit) -> None:
    """The page's hand cannot wipe a mark off: an occupied cell is not offered, and the session refuses one
    without drawing, the game going on (it used to draw, then end the game asking to "wipe your mark")."""
    page = browser.new_page()
    try:
        open_game(page, game_cockpit)
        run_to_first_turn(page)
        # Play before drawing anything is refused: it is the person's turn (in the page's words).
        page.get_by_role("button", name="Play", exact=True).click()
        page.wait_for_function("document.querySelector('[data-role=reply]').dataset.error === 'true'",
                               timeout=30_000)
        assert text_of(page, "reply").startswith("it is your turn: draw your move (click a cell), then click Play")
        cell(page, 3, 3).click()
        page.get_by_role("button", name="Play", exact=True).click()
        page.wait_for_function("document.querySelector('[data-role=board] button[data-row=\"3\"][data-column=\"3\"]')"
                               ".dataset.by === 'person'", timeout=LONG)
        page.wait_for_function(CELL_OFFERED, timeout=LONG)
        state = game_state(game_cockpit)
        robot = next(m for m in state["moves"] if m["by"] == "robot")
        assert cell(page, robot["row"], robot["column"]).is_disabled() and cell(page, 3, 3).is_disabled()
        # the symbols in the legend are this game's
        assert page.locator('[data-role="legend-robot"]').text_content() == state["robot"]
        assert page.locator('[data-role="legend-person"]').text_content() == state["person"]
        # a click on the manipulator's cell sent anyway (another page, a script): refused, nothing drawn
        page.evaluate("([r, c]) => { const b = document.querySelector("
                      "`[data-role=board] button[data-row=\"${r}\"][data-column=\"${c}\"]`);"
                      " b.disabled = false; b.click(); }", [robot["row"], robot["column"]])
        page.wait_for_function("document.querySelector('[data-role=reply]').textContent.startsWith('cell (')",
                               timeout=30_000)
        assert text_of(page, "reply") == (f"cell ({robot['row']}, {robot['column']}) holds the manipulator's"
                                          f" {state['robot']} already: click an empty cell")
        after = game_state(game_cockpit)
        assert after["truth"] == state["truth"] and after["wrong"] == 0 and not after["ended"]
        # the game goes on: an empty cell is taken
        free = next((r, c) for r in range(1, 6) for c in range(1, 6) if after["truth"][5 * (r - 1) + c - 1] == ".")
        cell(page, *free).click()
        page.wait_for_function("([r, c]) => document.querySelector(`[data-role=board] button[data-row=\"${r}\"]"
                               "[data-column=\"${c}\"]`).dataset.by === 'drawn'", arg=list(free), timeout=30_000)
    finally:
        page.close()


def test_stop_in_the_middle_of_a_stroke_lifts_the_pen_and_returns_the_arm(browser: Any,
                                                                         game_cockpit: Cockpit) -> None:
    page = browser.new_page()
    session = game_cockpit.session
    try:
        open_game(page, game_cockpit)
        session.call(lambda d: d.add_breakpoint("enter Control.field_pen_down"))
        page.get_by_role("button", name="Run", exact=True).click()
        deadline = time.monotonic() + LONG / 1e3
        while not (session.mode == "paused" and session.call(lambda d: d.breakpoints[0].hits) >= 1):
            assert time.monotonic() < deadline, "the breakpoint on the field's first pen-down was not hit"
            time.sleep(0.05)
        page.wait_for_function("!document.querySelector('[data-cmd=run]').disabled", timeout=30_000)

        def into_the_stroke(d: Debugger) -> tuple[bool, float]:
            d.delete(None)
            while not d.robot.board.contact.pen_touching:
                d.step(10)
            d.step(200)  # 0.2 s into the line
            return d.robot.board.contact.pen_touching, d.robot.board.ink_area_mm2()

        touching, ink = session.call(into_the_stroke)
        assert touching and ink > 0.0
        page.get_by_role("button", name="Stop", exact=True).click()
        page.wait_for_function("document.querySelector('[data-role=reply]').textContent.startsWith('Stop:')",
                               timeout=30_000)
        page.get_by_role("button", name="Run", exact=True).click()
        wait_text(page, "text-box2", MSG_TURNING_OFF)
        page.wait_for_function("document.querySelector('[data-cmd=stop]').disabled", timeout=LONG)
        state = game_state(game_cockpit)
        control = session.call(lambda d: (bool(d.robot.control.at_start), d.robot.board.contact.pen_touching,
                                          sorted(d.robot.active("Control"))))
        assert state["ended"] and state["moves"] == []
        assert control[0] and not control[1], control  # back at the start pose, the pen off the board
        assert any("finished" in s for s in control[2]), control
        assert state["ink_mm2"] < ink + 5.0  # the stroke was not finished after Stop
        assert state["outcome"] == "halted"
    finally:
        page.close()


def test_a_blocked_drive_mid_stroke_shows_the_safety_stop_and_its_reason(browser: Any, game_cockpit: Cockpit) -> None:
    """docs/safety.md: the Safety chart trips on a real fault of the twin, and the page says why."""
    page = browser.new_page()
    session = game_cockpit.session
    try:
        open_game(page, game_cockpit)
        assert page.locator('[data-role="safety"]').is_hidden()
        session.call(lambda d: d.add_breakpoint("enter Control.field_pen_down"))
        page.get_by_role("button", name="Run", exact=True).click()
        deadline = time.monotonic() + LONG / 1e3
        while not (session.mode == "paused" and session.call(lambda d: d.breakpoints[0].hits) >= 1):
            assert time.monotonic() < deadline, "the breakpoint on the field's first pen-down was not hit"
            time.sleep(0.05)
        page.wait_for_function("!document.querySelector('[data-cmd=run]').disabled", timeout=30_000)

        def block_drive_2_mid_stroke(d: Debugger) -> None:
            from ttt_sm.twin import layout

            d.delete(None)
            while not d.robot.board.contact.pen_touching:
                d.step(10)
            d.step(200)
            sim = d.robot.sim
            assert sim is not None
            sim.plant.pp[1, layout.PP_QMIN] = sim.plant.pp[1, layout.PP_QMAX] = float(sim.plant.ps[1, layout.PS_Q])

        session.call(block_drive_2_mid_stroke)
        page.get_by_role("button", name="Run", exact=True).click()
        page.wait_for_function("!document.querySelector('[data-role=safety]').hidden", timeout=LONG)
        reason = session.call(lambda d: (bool(d.robot.tripped), str(d.robot.safety.reason)))
        assert reason[0] and "drive 2" in reason[1]
        assert text_of(page, "safety") == f"Safety stop: {reason[1]}"
        assert page.locator('[data-role="safety"]').get_attribute("data-error") == "true"
        # the game cannot go on, and says so where the page says what the game told
        page.wait_for_function("document.querySelector('[data-role=told]').textContent.includes('safety stop')",
                               timeout=30_000)
    finally:
        page.close()


def test_stop_before_run_says_so_and_the_next_run_starts_a_real_game(browser: Any, game_cockpit: Cockpit) -> None:
    page = browser.new_page(viewport={"width": 1280, "height": 720})
    try:
        open_game(page, game_cockpit)
        page.get_by_role("button", name="Stop", exact=True).click()
        # What happened is said, in the page's words: nothing was stopped.
        page.wait_for_function("document.querySelector('[data-role=reply]').textContent.includes('not been started')",
                               timeout=30_000)
        assert text_of(page, "reply") == ("the robot has not been started, so there is nothing to stop;"
                                          " click Run to start the game")
        assert page.locator('[data-role="reply"]').get_attribute("data-error") == "true"
        # No stop waits for Run: once the robot runs, the Game chart initialises instead of turning the arm off.
        active, message, ended = game_cockpit.session.call(
            lambda d: (d.tick(50), sorted(d.robot.active("Game")), str(d.game.game.message), d.game.game.ended)[1:])
        assert (active, ended) == (["initialising"], False), message
    finally:
        page.close()


#: A game the manipulator (O) won on the diagonal from (1, 1) to (4, 4); X moved first.
WON_ON_THE_DIAGONAL = "OXXX." "XO..." "..O.." "...O." "....."


def test_the_winning_four_in_a_row_is_marked_on_the_board(browser: Any, game_cockpit: Cockpit) -> None:
    def won(d: Debugger) -> None:  # the game's state at its end, as the game's flow leaves it
        d.game.board = d.game.truth = WON_ON_THE_DIAGONAL
        d.game.outcome = "O"
    game_cockpit.session.call(won)
    page = browser.new_page(viewport={"width": 1280, "height": 720})
    try:
        open_game(page, game_cockpit)
        wait_board(page, WON_ON_THE_DIAGONAL)
        marked = page.eval_on_selector_all('[data-role=board] button[data-win="true"]',
                                           "bs => bs.map(b => [Number(b.dataset.row), Number(b.dataset.column)])")
        assert marked == [[1, 1], [2, 2], [3, 3], [4, 4]]
        # ... and a line drawn through them, from the first cell's centre to the last's
        ends = page.eval_on_selector("[data-role=board] svg.win-line line",
                                     "l => ['x1', 'y1', 'x2', 'y2'].map(a => Number(l.getAttribute(a)))")
        assert ends == [0.5, 0.5, 3.5, 3.5]
        assert text_of(page, "result") == "Result: the robot (O) won."
    finally:
        page.close()
