"""The thesis' Erase_flag (section 3.6.1): a full board erases, as the end of a game does (section 3.6)."""

from ttt_sm.app.game import GameSession
from ttt_sm.params import load_params

P = load_params()


def _session():
    return GameSession(P, seed=1, robot_symbol="O", engine="thesis", camera="direct", record_trace=False)


def test_the_manipulators_symbols_and_the_cameras_reaching_25_set_the_erase_flag():
    session = _session()
    try:
        robot = session.robot
        assert robot.run_until(lambda: bool(robot.control.ready), 300.0)  # the field is drawn, wait_1
        flag = robot.control_stage
        # 12 drawn by the manipulator, 12 detected by the camera: one cell is still free
        robot.control.ctr = 12
        session.o_pos = (1 << 12) - 1
        for _ in range(3):
            robot.chart_step()
        assert not flag.erase_requested and not session.erase_started and session.erase_cause is None
        assert "wait_1" in robot.active("Control")
        # the camera detects a 13th symbol of the person's: 25, the flag turns on and the chart erases
        session.o_pos |= 1 << 24
        robot.chart_step()
        assert session.erase_started and session.erase_cause == "full board"
        assert robot.run_until(lambda: bool(robot.control.erasing), 1.0)
        # the result, once the flow knows it, ends the game though the arm erases already (not waiting)
        session.result_code = 3
        assert robot.run_until(lambda: "game_over" in robot.active("Game"), 1.0)
    finally:
        session.close()

