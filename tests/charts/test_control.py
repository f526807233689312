"""The Control chart on its own (thesis section 3.6.1, figs. 3.24-3.27), with no arm.

A bare chart is ticked by hand.  Where a test needs the whole sequence from
power-on, an *ideal arm* closes the loop: before each tick the tool pose the
chart reads (`X_now`, `Y_now`, `Z_now`) is the pose it commanded.  What is
checked is what the chart commands: the geometry of eqs. 3.36-3.51, the
order of the strokes, the pen heights, the flags and counters.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pytest

from ttt_sm.app.control_wiring import make_control_chart
from ttt_sm.charts.control import Control
from ttt_sm.params import load_params

P = load_params()
L = P.board.cell_size
X_MIN, X_MAX, Y_MIN, Y_MAX = P.board.field_bounds()
START_POSE = (0.13, -0.05, -0.066)  # where the arm stands once initialised (beside the board)
COMPOUNDS = ("start_stop", "Drawing_playing_field", "Drawing_X", "Drawing_O", "Drawing_sine", "Erase",
             "finishing")


@dataclass
class Log:
    """Per tick: the leaf state and the commanded pose."""

    state: list[str] = field(default_factory=list)
    pose: list[tuple[float, float, float, float]] = field(default_factory=list)

    def points(self, state: str) -> list[np.ndarray]:
        """The (x, y, z, phi) of every visit of `state`, one array per visit."""
        runs: list[np.ndarray] = []
        current: list[tuple[float, float, float, float]] = []
        for s, p in zip(self.state, self.pose, strict=True):
            if s == state:
                current.append(p)
            elif current:
                runs.append(np.array(current))
                current = []
        if current:
            runs.append(np.array(current))
        return runs


def leaf(c: Control) -> str:
    compounds = set(COMPOUNDS)
    (state,) = [s for s in c.configuration_values if s not in compounds]
    return state


def ideal_tick(c: Control, log: Log | None = None) -> None:
    """One chart tick with an arm that is wherever the chart commanded it."""
    if math.isfinite(c.X_out):
        c.X_now, c.Y_now, c.Z_now = c.X_out, c.Y_out, c.Z_out
    c.tick()
    if log is not None:
        log.state.append(leaf(c))
        log.pose.append((c.X_out, c.Y_out, c.Z_out, c.phi))


def run_until(c: Control, predicate, log: Log | None = None, max_s: float = 200.0) -> None:
    for _ in range(int(max_s / P.control.chart_dt)):
        if predicate():
            return
        ideal_tick(c, log)
    raise AssertionError(f"not reached within {max_s} s; Control is in {sorted(c.configuration_values)}")


def waiting(c: Control) -> bool:
    return "wait_1" in c.configuration_values


def powered(speed: float = 0.02) -> Control:
    """The application's Control chart, initialised drives, the arm at its start pose."""
    c = make_control_chart(P)
    c.X_now, c.Y_now, c.Z_now = START_POSE
    c.initialised = True
    c.speed = speed
    return c


def with_field(speed: float = 0.1) -> Control:
    """Waiting in wait_1 with the field drawn: started there (``start_value``), inputs set by hand."""
    app = make_control_chart(P)
    local = {d.name: getattr(app, d.name) for d in Control.declarations() if d.kind == "local"}
    c = Control(tick_period_s=P.control.chart_dt, data=local, start_value="wait_1")
    c.x_start, c.y_start, c.z_start = START_POSE
    c.X_out, c.Y_out, c.Z_out = c.X_now, c.Y_now, c.Z_now = c.x_wait, c.y_wait, c.z_wait
    c.Pl_fld = c.initialised = True
    c.speed = speed
    return c


def draw(c: Control, event: str, log: Log, **inputs) -> None:
    """Post `event` from wait_1 with `inputs` set, and run until the chart waits again."""
    assert waiting(c)
    for name, value in inputs.items():
        setattr(c, name, value)
    c.post(event)
    ideal_tick(c, log)
    run_until(c, lambda: waiting(c), log)


# --------------------------------------------------------------------- start_stop


def test_from_power_on_the_chart_rises_goes_over_and_steps_to_the_waiting_pose():
    c = powered()
    c.initialised = False
    log = Log()
    for _ in range(50):
        ideal_tick(c, log)
    assert log.state == ["wait_ini"] * 50 and math.isnan(c.X_out)  # no command before initialisation
    c.initialised, c.Pl_fld = True, True
    run_until(c, lambda: waiting(c), log)
    states = [s for k, s in enumerate(log.state) if k == 0 or s != log.state[k - 1]]
    assert states == ["wait_ini", "rise", "go_over", "go_wait", "wait_1"]
    (rise,) = log.points("rise")
    # straight up from the start pose to z_safe
    assert np.allclose(rise[:, :2], START_POSE[:2]) and np.all(np.diff(rise[:, 2]) > 0)
    assert rise[-1, 2] == c.z_safe
    (over,) = log.points("go_over")
    assert np.all(over[:, 2] == c.z_safe)
    # go_wait is one step with the slow filters (the thesis' wait_1 "step")
    (step,) = log.points("go_wait")
    assert np.allclose(step[:, :3], (c.x_wait, c.y_wait, c.z_wait))
    assert (c.X_out, c.Y_out, c.Z_out) == (c.x_wait, c.y_wait, c.z_wait) and not c.fr_sw
    assert (c.x_start, c.y_start, c.z_start) == START_POSE


def test_go_wait_sets_fr_sw_and_waits_for_the_arm_itself():
    c = powered()
    c.Pl_fld = True
    run_until(c, lambda: "go_wait" in c.configuration_values)
    assert c.fr_sw
    c.X_now, c.Y_now, c.Z_now = c.x_wait + 0.01, c.y_wait, c.z_wait  # the arm lags behind the step
    for _ in range(100):
        c.tick()
    assert "go_wait" in c.configuration_values and c.fr_sw
    c.X_now = c.x_wait + 0.5 * c.wait_tol
    c.tick()
    assert waiting(c) and not c.fr_sw


# --------------------------------------------------------------- the playing field


def test_the_field_is_4_lines_parallel_to_x_and_4_parallel_to_y_15_cm_long_3_cm_apart():
    c = powered(speed=0.02)
    log = Log()
    run_until(c, lambda: waiting(c) and c.Pl_fld, log)
    lines = log.points("line")
    assert len(lines) == 8
    along_x, along_y = lines[:4], lines[4:]
    ends = []
    for run in lines:
        # the pen is pressed on the board along the whole line
        assert np.all(run[:, 2] == c.z_draw) and np.all(run[:, 3] == 0.0)
        ends.append((run[0], run[-1]))  # the tick that enters the line still stands at its start
    for (a, b), run in zip(ends[:4], along_x, strict=True):
        assert np.all(run[:, 1] == run[0, 1])  # y constant
        assert abs(a[0] - b[0]) == pytest.approx(0.15, abs=1e-9)
        assert {round(min(a[0], b[0]), 9), round(max(a[0], b[0]), 9)} == {round(X_MIN, 9), round(X_MAX, 9)}
    for (a, b), run in zip(ends[4:], along_y, strict=True):
        assert np.all(run[:, 0] == run[0, 0])  # x constant
        assert abs(a[1] - b[1]) == pytest.approx(0.15, abs=1e-9)
        assert min(a[1], b[1]) == pytest.approx(Y_MIN, abs=1e-9)
    ys = sorted(run[0, 1] for run in along_x)
    xs = sorted(run[0, 0] for run in along_y)
    assert np.allclose(np.diff(ys), 0.03) and np.allclose(np.diff(xs), 0.03)
    assert ys[0] == pytest.approx(Y_MIN + L) and xs[0] == pytest.approx(X_MIN + L)
    # eq. 3.36: one coordinate changes by inc = speed * dt per tick, the other stays
    for run in lines:
        steps = np.hypot(*np.diff(run[:, :2], axis=0).T)
        assert np.allclose(steps[:-1], c.speed * P.control.chart_dt)
    # between lines the pen is lifted to z_up, and lowered again before the next
    assert len(log.points("field_pen_up")) == 8 and len(log.points("field_pen_down")) == 8
    for run in log.points("field_pen_up"):
        assert run[-1, 2] == c.z_up
    for run in log.points("to_line"):
        assert np.all(run[:, 2] > P.board.surface_z)
    assert c.Pl_fld and c.ctr == 0


# ------------------------------------------------------------------------- the X


def cell_box(row: int, column: int) -> tuple[float, float, float, float]:
    return X_MAX - column * L, X_MAX - (column - 1) * L, Y_MAX - row * L, Y_MAX - (row - 1) * L


@pytest.mark.parametrize("row, column", [(1, 1), (2, 4), (5, 5), (3, 1)])
def test_an_x_is_two_lines_at_45_and_135_degrees_in_the_right_cell(row, column):
    c = with_field()
    log = Log()
    draw(c, "button", log, row=row, column=column, symbol=1)
    size = c.size
    assert size == pytest.approx(3 * L / 5)  # the thesis' X: L/5 margins in an L cell
    # eqs. 3.37-3.38: the first line starts L/5 inside the cell's upper right corner
    assert c.x_ini == pytest.approx(c.x11 - (column - 1) * L - L / 5, abs=1e-12)
    assert c.y_ini == pytest.approx(c.y11 - (row - 1) * L - L / 5, abs=1e-12)
    assert c.h1 == pytest.approx(c.y_ini - c.x_ini)  # eq. 3.39
    (l1,), (l2,) = log.points("line_1"), log.points("line_2")
    # eqs. 3.40-3.41: X decreases, Y = X + h1 (45 deg)
    assert np.all(np.diff(l1[:, 0]) < 0)
    assert np.allclose(l1[:, 1] - l1[:, 0], c.h1, atol=1e-12)
    assert l1[-1, 0] == pytest.approx(c.x_ini - size) and c.Y_end == pytest.approx(c.y_ini - size)
    # eq. 3.42: the second line starts at (x_ini, Y_end); eq. 3.44: Y = -X + h2 (135 deg)
    (to2,) = log.points("x_pen_down_2")
    assert to2[0, 0] == c.x_ini and to2[0, 1] == c.Y_end
    assert c.h2 == pytest.approx(c.Y_end + c.x_ini)
    assert np.allclose(l2[:, 1] + l2[:, 0], c.h2, atol=1e-12)
    # eq. 3.43 is printed with X increasing: from x_ini that would leave the cell
    # (x_ini + size is past the cell's right edge); the chart decreases X instead
    x0, x1, y0, y1 = cell_box(row, column)
    assert c.x_ini + size > x1
    assert np.all(np.diff(l2[:, 0]) < 0)
    assert l2[-1, 0] == pytest.approx(c.x_ini - size) and l2[-1, 1] == pytest.approx(c.y_ini)
    # both lines lie in the cell, with the pen down, and cross at its centre
    for run in (l1, l2):
        assert np.all((x0 < run[:, 0]) & (run[:, 0] < x1) & (y0 < run[:, 1]) & (run[:, 1] < y1))
        assert np.all(run[:, 2] == c.z_draw)
        # the pen moves at the drawing speed along the line
        assert np.allclose(np.hypot(*np.diff(run[:, :2], axis=0).T)[:-1], c.speed * P.control.chart_dt)
    cross_x = (c.h2 - c.h1) / 2
    assert cross_x == pytest.approx((x0 + x1) / 2) and cross_x + c.h1 == pytest.approx((y0 + y1) / 2)
    # the pen is lifted between the two lines
    (up,) = log.points("x_pen_up")
    assert up[-1, 2] == c.z_up
    assert c.ctr == 1


# ------------------------------------------------------------------------- the O


def angles(run: np.ndarray, x0: float, y0: float) -> np.ndarray:
    return np.unwrap(np.arctan2(run[:, 1] - y0, run[:, 0] - x0))


@pytest.mark.parametrize("row, column", [(1, 1), (4, 2), (5, 5)])
def test_an_o_is_four_arcs_each_a_bit_over_a_quarter_that_close_the_circle(row, column):
    c = with_field()
    log = Log()
    draw(c, "button", log, row=row, column=column, symbol=0)
    # eqs. 3.45-3.47: the centre of the cell; R is half the symbol size
    x0, x1, y0, y1 = cell_box(row, column)
    assert c.x0 == pytest.approx((x0 + x1) / 2, abs=1e-12) and c.y0 == pytest.approx((y0 + y1) / 2, abs=1e-12)
    assert c.R == c.size / 2
    (start,) = log.points("o_pen_down")
    arcs = [log.points(f"arc_{k}")[0] for k in range(1, 5)]
    quarter = math.pi / 2
    prev_end = start[-1]
    spans = []
    for k, arc in enumerate(arcs, start=1):
        # every point on the circle (X - x0)^2 + (Y - y0)^2 = R^2, the pen down
        r = np.hypot(arc[:, 0] - c.x0, arc[:, 1] - c.y0)
        assert np.allclose(r, c.R, atol=1e-9), k
        assert np.all(arc[:, 2] == c.z_draw)
        # one coordinate is decreased or incremented (eqs. 3.48, 3.50: X down along the lower half, then Y up
        # along the left half; parts 3 and 4 the other way), the other follows the circle: clockwise
        moving = arc[:, 0] if k in (1, 3) else arc[:, 1]
        assert np.all(np.diff(moving) < 0) if k in (1, 4) else np.all(np.diff(moving) > 0)
        # each arc goes on from where the last ended: no jump
        assert np.hypot(*(arc[0, :2] - prev_end[:2])) < 1.01 * c.speed * P.control.chart_dt
        a = angles(np.vstack([prev_end[None, :], arc]), c.x0, c.y0)
        spans.append(a[0] - a[-1])
        prev_end = arc[-1]
    # a bit more than a quarter each
    assert c.arc_overlap > 0
    assert spans == pytest.approx([quarter + c.arc_overlap] * 4, abs=1e-9)
    assert all(span < quarter * 1.1 for span in spans)
    # the whole circle, and the end past the beginning: it closes
    circle = np.vstack([start[-1:], *arcs])
    a = angles(circle, c.x0, c.y0)
    assert np.all(np.diff(a) <= 0)  # once round, clockwise (an arc's first tick repeats the last one's end)
    assert a[0] - a[-1] == pytest.approx(2 * math.pi + 4 * c.arc_overlap, abs=1e-6)
    # the arcs lie inside the cell
    assert np.all((x0 < circle[:, 0]) & (circle[:, 0] < x1) & (y0 < circle[:, 1]) & (circle[:, 1] < y1))
    (up,) = log.points("o_pen_up")
    assert up[-1, 2] == c.z_up
    assert c.ctr == 1


def test_each_symbol_counts_and_the_button_draws_the_symbol_asked_for():
    c = with_field()
    log = Log()
    draw(c, "button", log, row=1, column=1, symbol=1)
    draw(c, "button", log, row=1, column=2, symbol=0)
    draw(c, "button", log, row=1, column=3, symbol=1)
    assert c.ctr == 3 and c.ignored_buttons == 0
    order = [s for k, s in enumerate(log.state) if s in ("x_to_start", "o_to_start")
             and log.state[k - 1] != s]
    assert order == ["x_to_start", "o_to_start", "x_to_start"]


# ----------------------------------------------------------------------- erasing


def test_erasing_turns_the_sponge_down_and_wipes_the_field_in_passes_3_cm_apart():
    c = with_field()
    draw(c, "button", Log(), row=3, column=3, symbol=1)
    assert c.ctr == 1 and c.Pl_fld
    log = Log()
    c.erase = True
    ideal_tick(c, log)
    assert "Erase" in c.configuration_values
    c.erase = False  # the wiring clears the game's request once erased; here at once
    run_until(c, lambda: waiting(c), log)
    passes = log.points("wipe")
    assert len(passes) == 5
    # the sponge faces the board (phi = 90 deg) before it comes down, and all along the passes
    (turn,) = log.points("turn_sponge")
    assert turn[-1, 3] == pytest.approx(math.pi / 2)
    for down in log.points("sponge_down"):
        assert np.all(down[:, 3] == pytest.approx(math.pi / 2))
    xs = []
    for run in passes:
        assert np.all(run[:, 3] == pytest.approx(math.pi / 2)) and np.all(run[:, 2] == c.z_sponge)
        assert np.all(run[:, 0] == run[0, 0])  # along Y
        xs.append(run[0, 0])
        ys = run[:, 1]
        assert min(ys) <= Y_MIN and max(ys) >= Y_MAX - c.wipe_speed * P.control.chart_dt  # the whole field's depth
    assert np.allclose(np.diff(xs), -0.03)
    # the strips the sponge wipes cover the field's width
    half = P.sponge.width / 2
    assert xs[0] + half >= X_MAX and xs[-1] - half <= X_MIN
    assert all(a - half <= b + half for a, b in zip(xs[1:], xs[:-1], strict=True))
    # flag and counter reset, phi back to 0; the field is drawn again next
    assert not c.Pl_fld and c.ctr == 0 and c.phi == 0.0
    ideal_tick(c)
    assert "Drawing_playing_field" in c.configuration_values


def test_erase_comes_before_the_field_and_the_field_before_the_persons_button():
    # wait_1's transitions in the order written: [erase], [not Pl_fld], then the button's.  The button's
    # wake-up is the one that leaves for Erase (or the field): it draws nothing and, as no state stayed
    # to run its `on button` action, is not counted; the next button, while erasing, is.
    c = Control(tick_period_s=P.control.chart_dt, start_value="wait_1")
    c.X_out, c.Y_out, c.Z_out = c.x_wait, c.y_wait, c.z_wait
    c.erase = True
    c.symbol = 1
    c.post("button")
    c.tick()
    assert "Erase" in c.configuration_values and c.ignored_buttons == 0 and c.ctr == 0
    c.post("button")
    c.tick()
    assert "Erase" in c.configuration_values and c.ignored_buttons == 1 and c.ctr == 0
    c = Control(tick_period_s=P.control.chart_dt, start_value="wait_1")
    c.X_out, c.Y_out, c.Z_out = c.x_wait, c.y_wait, c.z_wait
    c.post("button")
    c.post("draw_sine")
    c.tick()  # the button's wake-up leaves for the field; draw_sine's finds the field being drawn
    assert "Drawing_playing_field" in c.configuration_values and c.ignored_buttons == 0 and c.ctr == 0


# -------------------------------------------------------------- busy: buttons ignored


def reach(state: str) -> Control:
    """A powered chart (ideal arm, fast drawing) driven into `state`."""
    start = {"Drawing_X": ("button", {"symbol": 1}), "Drawing_O": ("button", {"symbol": 0}),
             "Drawing_sine": ("draw_sine", {}), "Erase": (None, {"erase": True})}
    parent = next((p for p in start if state in {s.id for s in getattr(Control, p).states}), None)
    c = powered(speed=0.1) if parent is None else with_field(speed=0.1)
    if parent is not None:
        event, inputs = start[parent]
        for name, value in inputs.items():
            setattr(c, name, value)
        if event:
            c.post(event)
    run_until(c, lambda: state in c.configuration_values)
    return c


BUSY = ["wait_ini", "rise", "go_over", "go_wait", "to_line", "line", "field_pen_up", "line_1", "to_line_2",
        "line_2", "arc_1", "arc_3", "o_pen_up", "wave", "turn_sponge", "wipe", "sponge_up", "turn_pen",
        "home_lift", "go_home", "finished"]


def busy_in(state: str) -> Control:
    if state == "wait_ini":
        c = powered()
        c.initialised = False
        return c
    if state in {s.id for s in Control.finishing.states}:
        c = reach("line")
        c.finish = True
        run_until(c, lambda: state in c.configuration_values)
        return c
    return reach(state)


@pytest.mark.parametrize("state", BUSY)
def test_a_button_while_busy_is_ignored_and_counted_and_leaves_the_chart_where_it_was(state):
    c = busy_in(state)
    before = set(c.configuration_values)
    ctr = c.ctr
    for symbol in (1, 0):
        c.symbol = symbol
        c.post("button")
    c.post("draw_sine")  # dropped: only wait_1 handles it
    c.tick()
    assert c.ignored_buttons == 2 and c.ctr == ctr
    # no sub-chart left or entered (the leaf may move on by its own tick transition)
    after = set(c.configuration_values)
    assert {s for s in before if s in COMPOUNDS} == {s for s in after if s in COMPOUNDS}


def test_a_drawing_is_never_started_over_another():
    c = with_field()
    log = Log()
    c.symbol = 0
    c.post("button")
    ideal_tick(c, log)
    pressed = 0
    while not waiting(c):
        if len(log.state) % 10 == 0:
            c.symbol = 1 - c.symbol
            c.post("button")  # the person keeps pressing, for X and O in turn
            pressed += 1
        ideal_tick(c, log)
    entered = [s for k, s in enumerate(log.state) if k and s != log.state[k - 1]]
    assert "x_to_start" not in entered and log.state[0] == "o_to_start"
    assert c.ctr == 1 and c.ignored_buttons == pressed > 50


# ----------------------------------------------------------------------- finishing


@pytest.mark.parametrize("state", ["go_over", "wait_1", "line", "field_pen_down", "line_1", "line_2",
                                   "arc_2", "arc_4", "wave", "to_pass", "wipe", "turn_pen"])
def test_finish_from_any_sub_chart_lifts_first_then_returns_to_the_start_pose(state):
    c = reach(state)
    if state == "wait_1":
        run_until(c, lambda: waiting(c) and c.Pl_fld)
    z_at_finish = c.Z_out
    c.finish = True
    log = Log()
    ideal_tick(c, log)
    assert {"finishing", "home_lift"} <= set(c.configuration_values)
    run_until(c, lambda: "finished" in c.configuration_values, log)
    (lift,) = log.points("home_lift")
    # straight up from where the pen was, never down, phi turned back to 0 before moving on
    assert np.all(lift[:, :2] == lift[0, :2])
    assert np.all(np.diff(lift[:, 2]) >= 0) and lift[0, 2] >= z_at_finish
    # (phi reaches 0 in finishing's during action, which runs before home_lift's transition is tried:
    # the tick that turns phi to 0 is the tick that leaves home_lift)
    assert lift[-1, 2] == max(z_at_finish, c.z_safe)
    (over,) = log.points("go_home_over")
    assert np.all(over[:, 2] == lift[-1, 2]) and np.all(over[:, 3] == 0.0)
    assert (c.X_out, c.Y_out, c.Z_out, c.phi) == (*START_POSE, 0.0)
    assert not c.fr_sw
    # finished is final
    for _ in range(100):
        ideal_tick(c)
    assert set(c.configuration_values) == {"finishing", "finished"}


def test_finish_before_initialisation_waits_for_it_then_ends_where_the_arm_stands():
    c = make_control_chart(P)
    c.X_now, c.Y_now, c.Z_now = START_POSE
    c.finish = True
    for _ in range(100):
        c.tick()
    assert set(c.configuration_values) == {"start_stop", "wait_ini"} and math.isnan(c.X_out)
    c.initialised = True
    for _ in range(4):  # into finishing, then one tick per state: the targets are already reached
        c.tick()
    # nothing was commanded yet: the arm is already at its start pose
    assert set(c.configuration_values) == {"finishing", "finished"}
    assert (c.X_out, c.Y_out, c.Z_out, c.phi) == (*START_POSE, 0.0)


# ---------------------------------------------------- what others read: outputs, not states


def test_ready_busy_erasing_and_at_start_follow_the_states_at_every_tick():
    """The outputs the game and the application read (never the states) say what the states say."""
    c = powered(speed=0.1)
    seen: set[tuple[bool, bool, bool, bool]] = set()

    def tick_and_check() -> None:
        ideal_tick(c)
        active = c.configuration_values
        assert c.busy == ("wait_1" not in active), active
        assert c.ready == ("wait_1" in active and c.Pl_fld), active
        assert c.erasing == ("Erase" in active), active
        assert c.at_start == ("finished" in active), active
        seen.add((c.ready, c.busy, c.erasing, c.at_start))

    def until(predicate, max_s: float = 200.0) -> None:
        for _ in range(int(max_s / P.control.chart_dt)):
            if predicate():
                return
            tick_and_check()
        raise AssertionError(f"not reached; Control is in {sorted(c.configuration_values)}")

    assert (c.ready, c.busy, c.erasing, c.at_start) == (False, True, False, False)  # before the first tick
    until(lambda: c.ready)  # the field is drawn, the arm waits
    c.symbol = 1
    c.post("button")
    until(lambda: c.busy)
    until(lambda: c.ready)  # the X is drawn
    c.erase = True
    until(lambda: c.erasing)
    c.erase = False
    until(lambda: not c.erasing)
    until(lambda: c.ready)  # erased, and the field drawn again
    c.finish = True
    until(lambda: c.at_start)
    # ready, busy, erasing, at_start: moving; waiting; waiting with the field still to draw (one tick);
    # erasing; back at the start pose
    assert seen == {(False, True, False, False), (True, False, False, False), (False, False, False, False),
                    (False, True, True, False), (False, True, False, True)}
