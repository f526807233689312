"""Drawing on the real loop (thesis section 3.5): DrawSession, the simulated arm and its whiteboard.

The drawings are measured against the ink the TRUE pen tip left on the
simulated whiteboard, not against what the chart commanded.  One session
(module fixture) draws the field, an X and an O at the GUI's default speed
and erases the board, as `ttt-sm play` does; the other checks are cheap.
"""

from __future__ import annotations

import math
from pathlib import Path

import cv2
import numpy as np
import pytest

from ttt_sm.app.drawing import DrawError, DrawResult, DrawSession
from ttt_sm.params import load_params
from ttt_sm.twin.kinematics import fk

P = load_params()
FIELD = P.board.field_bounds()
X_CELL, O_CELL = (2, 4), (4, 2)


class Drawn:
    """What the module's session drew and measured."""

    def __init__(self, session: DrawSession, results: dict[str, DrawResult], ink_before_erase: dict,
                 png: Path, ink_after_erase_mm2: float) -> None:
        self.session = session
        self.results = results
        self.ink_before_erase = ink_before_erase
        self.png = png
        self.ink_after_erase_mm2 = ink_after_erase_mm2


@pytest.fixture(scope="module")
def drawn(tmp_path_factory: pytest.TempPathFactory) -> Drawn:
    """Field, X and O at the default 20 mm/s, the board saved, then erased (about 150 s simulated)."""
    out = tmp_path_factory.mktemp("drawing")
    session = DrawSession(P, seed=0)
    session.start()
    results = {
        "field": session.draw("field"),
        "X": session.draw("X", *X_CELL),
        "O": session.draw("O", *O_CELL, out_dir=out),
    }
    board = session.robot.board
    ink = {"field": board.ink_area_mm2(FIELD),
           **{cell: board.cell_ink_fraction(*cell) for r in range(1, 6) for cell in [(r, c) for c in range(1, 6)]}}
    robot = session.robot
    robot.control_stage.erase_requested = True
    assert robot.run_until(lambda: "Erase" in robot.active("Control"), 5.0)
    assert robot.run_until(lambda: "wait_1" in robot.active("Control"), 120.0)
    assert results["O"].board_png is not None
    return Drawn(session, results, ink, Path(results["O"].board_png), board.ink_area_mm2(FIELD))


@pytest.mark.parametrize("kind", ["field", "X", "O"])
def test_at_the_default_speed_the_ink_follows_the_desired_path_within_a_third_of_a_millimetre(drawn, kind):
    r = drawn.results[kind]
    assert r.speed_mm_s == 20.0
    assert r.ink_points > 100  # the pen did touch the board
    assert r.rms_error_mm <= 0.3 and r.max_error_mm <= 1.0, r
    # no ink where the pen lands or lifts off the desired path
    assert r.longest_tail_mm <= 1.0, r
    assert math.isfinite(r.fk_vs_true_max_mm)


def test_the_o_closes(drawn):
    r = drawn.results["O"]
    assert r.closure_gap_mm is not None and r.closure_gap_mm <= 0.5, r


def test_the_symbols_are_inked_in_their_cells_and_nowhere_else(drawn):
    ink = drawn.ink_before_erase
    assert ink[X_CELL] > 0.02 and ink[O_CELL] > 0.02
    empty = [cell for cell in ink if cell not in (X_CELL, O_CELL, "field")]
    assert len(empty) == 23 and all(ink[cell] == 0.0 for cell in empty)
    # the field's lines: 8 lines, 15 cm, about 0.8 mm wide
    assert 8 * 150 * 0.6 < ink["field"] < 8 * 150 * 1.6


def test_erasing_leaves_no_ink_on_the_field(drawn):
    assert drawn.ink_before_erase["field"] > 1000
    assert drawn.ink_after_erase_mm2 == 0.0
    contact = drawn.session.robot.board.contact
    assert contact.pen_collision_count == 0 and not contact.sponge_touching


def test_the_board_png_is_written_and_opencv_reads_it(drawn):
    image = cv2.imread(str(drawn.png))
    assert image is not None and image.ndim == 3 and image.shape[2] == 3
    board = drawn.session.robot.board
    assert image.shape[:2] == board.render(grid_mm=True).shape[:2]
    # the robot's dark blue ink is there (the millimetre paper is light)
    assert np.count_nonzero(image.sum(axis=2) < 300) > 1000


def test_the_paths_plot_is_written(drawn):
    plot = drawn.results["O"].plot_png
    assert plot is not None and cv2.imread(plot) is not None


@pytest.mark.parametrize("kind, row, column, speed, size, named", [
    ("X", 0, 3, None, None, "cell (0, 3)"),
    ("O", 3, 6, None, None, "cell (3, 6)"),
    ("X", 3, 3, 0.5, None, "speed 500.0 mm/s"),
    ("O", 3, 3, 0.0005, None, "speed 0.5 mm/s"),
    ("X", 3, 3, None, 0.05, "size 50.0 mm"),
    ("O", 3, 3, None, 0.002, "size 2.0 mm"),
    ("Y", 3, 3, None, None, "'Y'"),
])
def test_a_bad_request_is_rejected_naming_it_before_anything_moves(drawn, kind, row, column, speed, size, named):
    session = drawn.session
    robot = session.robot
    before = (robot.t, robot.steps, sorted(robot.active("Control")), robot.control.speed, robot.control.size,
              robot.control.row, robot.control.column, len(robot.board.strokes), robot.truth.q.copy())
    with pytest.raises(DrawError, match=named.replace("(", r"\(").replace(")", r"\)")):
        session.draw(kind, row, column, speed=speed, size=size)
    after = (robot.t, robot.steps, sorted(robot.active("Control")), robot.control.speed, robot.control.size,
             robot.control.row, robot.control.column, len(robot.board.strokes), robot.truth.q.copy())
    assert after[:-1] == before[:-1] and np.array_equal(after[-1], before[-1])
    assert robot.control.pending_events == []


def test_drawing_is_refused_while_the_arm_is_busy():
    session = DrawSession(P, seed=0)
    with pytest.raises(DrawError, match="busy"):
        session.draw("X", 3, 3)  # still initialising
    assert session.robot.t == 0.0


def test_finish_mid_stroke_lifts_the_pen_off_the_board_and_the_arm_returns_to_its_start_pose():
    session = DrawSession(P, seed=0)
    session.start()
    robot, c, board = session.robot, session.robot.control, session.robot.board
    c.row, c.column, c.symbol = 3, 3, 1
    robot.post("Control", "button")
    assert robot.run_until(lambda: "line_1" in robot.active("Control"), 10.0)
    robot.run_for(0.3)
    assert board.contact.pen_touching  # mid-stroke
    c.finish = True
    robot.chart_step()
    assert "home_lift" in robot.active("Control")
    assert robot.run_until(lambda: not board.contact.pen_touching, 0.5)
    ink_at_lift = board.ink_area_mm2()
    lowest_over_board = math.inf
    while "finished" not in robot.active("Control"):
        robot.chart_step()
        x, y, z, _ = fk(robot.truth.q, P.geometry)
        if P.board.in_zone(x, y, 0.0):
            lowest_over_board = min(lowest_over_board, z)
        assert robot.t < 60.0
    # the tip never came back down onto the board: no ink after the lift, no collision
    assert lowest_over_board > P.board.surface_z
    assert board.ink_area_mm2() == ink_at_lift and board.contact.pen_collision_count == 0
    robot.run_for(1.0)
    tool = fk(robot.truth.q, P.geometry)[:3]
    assert np.linalg.norm(tool - (c.x_start, c.y_start, c.z_start)) < 0.002


@pytest.mark.soak
@pytest.mark.parametrize("speed", [0.01, 0.05])
def test_at_other_speeds_every_symbol_in_the_corner_cells_is_drawn_precisely(speed):
    session = DrawSession(P, seed=1)
    session.start()
    for kind, cell in [("X", (1, 1)), ("O", (1, 5)), ("X", (5, 5)), ("O", (5, 1))]:
        r = session.draw(kind, *cell, speed=speed)
        assert r.rms_error_mm <= 0.3 and r.max_error_mm <= 1.0 and r.longest_tail_mm <= 1.0, r
        if kind == "O":
            assert r.closure_gap_mm is not None and r.closure_gap_mm <= 0.5, r
        assert session.robot.board.cell_ink_fraction(*cell) > 0.02


@pytest.mark.soak
def test_the_sine_wave_is_drawn_precisely():
    session = DrawSession(P, seed=0)
    session.start()
    r = session.draw("sine")
    assert r.rms_error_mm <= 0.3 and r.max_error_mm <= 1.0 and r.longest_tail_mm <= 1.0, r
