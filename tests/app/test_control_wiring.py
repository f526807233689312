"""The Control chart's wiring: inputs it feeds every chart step, and forcing them."""

from ttt_sm.app.robot import Robot
from ttt_sm.params import load_params

P = load_params()


def test_the_erase_input_follows_the_games_request_unless_forced():
    robot = Robot(P, seed=0)
    robot.chart_step()
    assert robot.value("Control", "erase") is False
    # without force, the wiring overwrites the input at the next chart step
    robot.set_input("Control", "erase", True)
    robot.chart_step()
    assert robot.value("Control", "erase") is False
    # the game's request (the thesis' Erase_flag) is what the wiring feeds
    robot.control_stage.erase_requested = True
    robot.chart_step()
    assert robot.value("Control", "erase") is True
    robot.control_stage.erase_requested = False
    # forced, the value holds until released
    robot.set_input("Control", "erase", True, force=True)
    for _ in range(3):
        robot.chart_step()
        assert robot.value("Control", "erase") is True
    robot.release("Control", "erase")
    robot.chart_step()
    assert robot.value("Control", "erase") is False
    assert robot.control_stage.overrides == {}


def test_forcing_control_leaves_the_init_charts_overrides_alone():
    robot = Robot(P, seed=0)
    robot.set_input("DriveInit1", "index", True, force=True)
    robot.set_input("Control", "initialised", False, force=True)
    assert robot.init_stage.overrides == {(0, "index"): True}
    assert robot.control_stage.overrides == {"initialised": False}
    robot.release("DriveInit1", "index")
    robot.release("Control", "initialised")
    robot.release("Control", "initialised")  # releasing twice is harmless
    assert robot.init_stage.overrides == {} and robot.control_stage.overrides == {}


def test_a_forced_initialised_flag_holds_the_control_chart_back():
    robot = Robot(P, seed=0)
    robot.set_input("Control", "initialised", False, force=True)
    assert robot.run_until(lambda: robot.initialised, 20)
    robot.run_for(1.0)
    assert robot.active("Control") == {"start_stop", "wait_ini"}
    robot.release("Control", "initialised")
    robot.chart_step()
    robot.chart_step()
    assert "rise" in robot.active("Control")
