"""A lost link trips the Safety chart, a game ends with its reason, and reset re-arms the firmware.

The robot runs over :class:`SerialArm` against the firmware emulator on a
real pseudo-terminal (gated: the PC's setpoints set its pace, so a loaded
machine cannot trip anything), with a :class:`~ttt_sm.faults.link.LinkTap`
on the emulator's wire to cut the link and plug it in again.  A gated
emulator keeps no deadline: the PC gives it :attr:`SerialArm.gated_timeout_s`
before it declares the link lost, shortened here.
"""

from __future__ import annotations

import json
import threading
import time

import pytest

from ttt_sm.app.robot import Robot
from ttt_sm.cli import main
from ttt_sm.faults.link import LinkTap
from ttt_sm.hardware import firmware_link as FL
from ttt_sm.hardware.emulator import ArmEmulator
from ttt_sm.hardware.serial_arm import SerialArm
from ttt_sm.twin.plant import REST_POSE
from ttt_sm.twin.workspace import load_arm

P = load_arm(None)
#: How long the PC waits for a silent gated emulator here (5 s by default): wall time, so not so short that a
#: loaded machine's first status is taken for a lost link (1 s was: the game ended at tick 1, t = 0).
GATED_S = 3.0


@pytest.fixture
def tapped(tmp_path, firmware_libs):
    with ArmEmulator(P, pace="gated", link=tmp_path / "arm", truth=True,
                     cache=firmware_libs["float"].path.parent) as emu:
        emu.tap = LinkTap()
        yield emu


def test_a_cut_link_stops_the_robot_with_its_reason_and_reset_rearms_the_firmware_once_it_answers(tapped):
    arm = SerialArm(tapped.port, P, servo_angle=REST_POSE[3])
    arm.gated_timeout_s = GATED_S
    try:
        robot = Robot(P, arm=arm, truth=arm.truth)
        events: list[tuple[str, dict]] = []
        robot.safety_stage.listeners.append(lambda kind, data: events.append((kind, data)))
        robot.run_for(0.5)  # the drives search their index switches
        assert arm.link_ok and not robot.tripped and robot.active("Safety") == {"monitoring"}
        steps = tapped.firmware.steps
        tapped.tap.inject("link_cut")
        assert robot.run_until(lambda: robot.tripped, 2.0)  # no exception out of a chart step
        assert robot.active("Safety") == {"safe", "stopped"}
        assert robot.safety.reason.startswith("link lost")
        assert not arm.link_ok and arm.lost is not None and arm.lost.silence_s > GATED_S
        (kind, data), = events
        assert kind == "safety_trip" and data["drive"] == 0 and data["reason"] == robot.safety.reason
        assert data["link"].startswith(f"no status from the firmware for {GATED_S * 1000:.0f} ms")
        # the firmware saw nothing more: the cut held every setpoint back, and no step ran past them
        assert tapped.firmware.steps - steps <= P.control.chart_divider
        t_lost = robot.t
        robot.run_for(0.1)  # the charts tick on; the arm's time (the firmware's) stands
        assert robot.t == t_lost and robot.tripped

        # reset while the link is still cut: nothing to re-arm, the chart stops again on the link
        robot.post("Safety", "reset")
        robot.run_for(0.05)
        assert arm.rearms == 0 and robot.active("Safety") == {"safe", "stopped"}

        tapped.tap.clear()  # the cable back: the keeper's heartbeats are answered again
        assert robot.run_until(lambda: arm.last_frame_at > arm.lost.declared_at, 2.0)
        assert not arm.link_ok  # a loss is never forgotten on its own
        setpoints = tapped.firmware.setpoints_ok
        robot.post("Safety", "reset")
        robot.run_for(0.2)
        assert arm.rearms == 1 and arm.link_ok, arm.link_fault
        assert arm.lost is None and tapped.firmware.state == 1
        assert robot.active("Safety") == {"reinitialising"}, robot.safety.reason  # the drives initialise again
        assert tapped.firmware.setpoints_ok - setpoints >= 90 and robot.t > t_lost + 0.15
        # the reset on a cut link restarted the init charts and tripped on the link again
        assert [k for k, _ in events] == ["safety_trip", "safety_reset", "safety_trip", "safety_reset"]
        assert events[2][1]["reason"].startswith("link lost")
    finally:
        arm.close()


def test_a_game_whose_link_is_cut_ends_with_one_error_line_and_the_reason_in_its_record(tapped, tmp_path, capsys,
                                                                                          monkeypatch):
    monkeypatch.setattr(FL, "GATED_TIMEOUT_S", GATED_S)
    arms: list[SerialArm] = []  # the PC's side of the link, as `play` builds it
    init = SerialArm.__init__

    def kept(self: SerialArm, *args: object, **kwargs: object) -> None:
        init(self, *args, **kwargs)  # type: ignore[arg-type]
        arms.append(self)

    monkeypatch.setattr(SerialArm, "__init__", kept)

    def cut_after_a_second() -> None:  # of simulated time: the drives are initialising
        # the PC's time, from the statuses it has read: on a loaded machine the firmware's step count runs
        # ahead of it, and a cut then could come before the PC has seen a second (the record would end at 0 s)
        give_up = time.monotonic() + 120
        while (tapped.firmware.steps < 1000 or not arms or arms[-1].t < 1.0) and time.monotonic() < give_up:
            time.sleep(0.01)
        tapped.tap.inject("link_cut")

    cutter = threading.Thread(target=cut_after_a_second, daemon=True)
    cutter.start()
    status = main(["play", "--arm", f"serial:{tapped.port}", "--opponent", "simulated", "--camera", "direct",
                   "--time-limit", "60", "--out", str(tmp_path / "play")])
    cutter.join(5)
    err = capsys.readouterr().err
    assert status == 2
    last = err.strip().splitlines()[-1]
    assert "safety stop: link lost" in last and "Traceback" not in err
    records = [json.loads(line) for line in (tmp_path / "play" / "game.jsonl").read_text().splitlines()]
    trips = [r for r in records if r.get("event") == "safety_trip"]
    assert len(trips) == 1 and trips[0]["reason"].startswith("link lost")
    assert trips[0]["link"].startswith(f"no status from the firmware for {GATED_S * 1000:.0f} ms")
    assert 1.0 <= records[-1]["t"] < 60, (records[-1], len(arms))
