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
from ttt_sm.app.path_plot import PEN_UP_LABEL, PathData, path_figure, state_spans
from ttt_sm.params import load_params
from ttt_sm.twin.board_picture import FIELD_MARGIN_M, PX_PER_MM
from ttt_sm.twin.kinematics import fk

P = load_params()
FIELD = P.board.field_bounds()
X_CELL, O_CELL = (2, 4), (4, 2)


class Drawn:
    """What the module's session drew and measured."""

    def __init__(self, session: DrawSession, results: dict[str, DrawResult], ink_before_erase: dict,
                 png: Path, ink_after_erase_mm2: float, o_path: PathData) -> None:
        self.session = session
        self.results = results
        self.ink_before_erase = ink_before_erase
        self.png = png
        self.ink_after_erase_mm2 = ink_after_erase_mm2
        self.o_path = o_path


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
    o_path = session.path_data()  # before the sponge cuts the O's stroke
    board = session.robot.board
    ink = {"field": board.ink_area_mm2(FIELD),
           **{cell: board.cell_ink_fraction(*cell) for r in range(1, 6) for cell in [(r, c) for c in range(1, 6)]}}
    robot = session.robot
    robot.control_stage.erase_requested = True
    assert robot.run_until(lambda: "Erase" in robot.active("Control"), 5.0)
    assert robot.run_until(lambda: "wait_1" in robot.active("Control"), 120.0)
    assert results["O"].board_png is not None
    return Drawn(session, results, ink, Path(results["O"].board_png), board.ink_area_mm2(FIELD), o_path)


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


def test_the_board_picture_is_written_and_opencv_reads_it(drawn):
    image = cv2.imread(str(drawn.png))
    assert image is not None and image.ndim == 3 and image.shape[2] == 3
    # cropped to the field (150 mm and its margins at PX_PER_MM), not the whole 300 x 240 mm board
    side_px = (P.board.field_size * 1e3 + 2 * FIELD_MARGIN_M * 1e3) * PX_PER_MM
    assert side_px < image.shape[1] < side_px + 200 and side_px < image.shape[0] < side_px + 250
    # the robot's dark blue ink is there: the field, the X and the O
    blue = (image[:, :, 0] > 80) & (image[:, :, 2] < 60)
    assert np.count_nonzero(blue) > 8 * 150 * PX_PER_MM * 2
    assert Path(drawn.results["O"].board_png).name == f"board_O_r{O_CELL[0]}c{O_CELL[1]}.png"


def test_the_paths_plot_is_written(drawn):
    plot = drawn.results["O"].plot_png
    assert plot is not None and cv2.imread(plot) is not None
    assert Path(plot).stat().st_size < 250_000


def test_the_path_plot_draws_the_numbers_the_drawing_reports(drawn):
    r, d = drawn.results["O"], drawn.o_path
    errors = np.concatenate([err for _, _, err in d.strokes]) * 1e3
    assert round(float(errors.max()), 4) == r.max_error_mm
    assert round(float(np.sqrt(np.mean(errors ** 2))), 4) == r.rms_error_mm
    assert sum(len(pts) for pts, _, _ in d.strokes) == r.ink_points
    assert round(float(np.nanmax(d.tip_vs_encoders_m)) * 1e3, 4) == r.fk_vs_true_max_mm
    fig = path_figure(d, "O")
    xy, strip, height, error = fig.axes
    drawn_err = np.concatenate([ln.get_ydata() for ln in error.lines if ln.get_gid() == "ink_error"])
    assert drawn_err.max() == pytest.approx(r.max_error_mm, abs=1e-4)
    (enc,) = [ln for ln in error.lines if ln.get_gid() == "encoders_vs_true"]
    assert np.nanmax(enc.get_ydata()) == pytest.approx(r.fk_vs_true_max_mm, abs=1e-4)
    # the X-Y view: the desired pen-down path in black, travel dashed and labelled as such
    labels = {ln.get_label(): ln for ln in xy.lines if not ln.get_label().startswith("_")}
    assert labels[PEN_UP_LABEL].get_linestyle() == "--"
    down = [ln for ln in xy.lines if ln.get_color() == "k" and ln.get_linestyle() == "-"]
    assert len(down) == len(d.runs) == 1  # an O is one stroke
    np.testing.assert_allclose(np.column_stack(down[0].get_data()), d.runs[0] * 1e3)
    # the jump of the desired pose (to the waiting pose, smoothed by the filters) is explained
    assert any("jumps to the waiting pose" in a.get_text() for a in height.texts)


def test_the_path_plot_bands_show_the_control_states_that_drew_the_ink(drawn):
    d = drawn.o_path
    spans = state_spans(d.states, float(d.t[-1]))
    labels = [label for _, _, label in spans]
    assert labels[0] == "Drawing_O.o_to_start" and labels[-1] == "start_stop.go_wait"
    assert d.states[-1][1] == "start_stop.wait_1"  # where the drawing ended: entered at the last sample
    assert [lb for lb in labels if ".arc_" in lb] == [f"Drawing_O.arc_{k}" for k in (1, 2, 3, 4)]
    assert "start_stop.go_wait" in labels
    # every point of ink was laid while the O's sub-chart was active, lowering, drawing or lifting
    for _, times, _ in d.strokes:
        for t in times:
            (label,) = [lb for a, b, lb in spans if a <= t < b]
            assert label.startswith("Drawing_O.o_pen") or label.startswith("Drawing_O.arc_"), (t, label)
    # the strip draws exactly those spans
    strip = path_figure(d, "O").axes[1]
    bands = [p.get_gid() for p in strip.patches]
    assert bands == [f"state:{lb}" for lb in labels]


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
        x, y, z, _ = fk(robot.truth.q, P.true_geometry)
        if P.board.in_zone(x, y, 0.0):
            lowest_over_board = min(lowest_over_board, z)
        assert robot.t < 60.0
    # the tip never came back down onto the board: no ink after the lift, no collision
    assert lowest_over_board > P.board.surface_z
    assert board.ink_area_mm2() == ink_at_lift and board.contact.pen_collision_count == 0
    robot.run_for(1.0)
    tool = fk(robot.truth.q, P.true_geometry)[:3]
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
