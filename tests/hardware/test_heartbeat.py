"""The idle link stays watched both ways, and the PC declares it lost within 50 ms of silence.

A chart loop that streams setpoints watches the link itself (a STATUS is due
every chart step).  When the PC has nothing to send (the charts paused, the
debugger at a breakpoint), :class:`SerialArm`'s keeper sends a HEARTBEAT
every 10 ms, the firmware answers each; on its own clock the firmware also
goes on reporting its STATUS.  When nothing valid comes for the link's
timeout, the keeper declares the link lost.  The emulator runs on a real
pseudo-terminal; the times asserted are the ones the PC recorded when it
decided (the last frame, the look that found the silence too long, the
look before it), not the test's own clock.
"""

from __future__ import annotations

import time

import pytest

from ttt_sm.hardware.emulator import ArmEmulator
from ttt_sm.hardware.firmware_link import HEARTBEAT_PERIOD_S, KEEPER_TICK_S, LINK_TIMEOUT_S
from ttt_sm.hardware.serial_arm import SerialArm
from ttt_sm.twin.plant import REST_POSE
from ttt_sm.twin.workspace import load_arm

P = load_arm(None)


def wait_for(condition, limit_s: float = 30.0) -> bool:
    """Wait until `condition()` holds (a loaded machine may take long); whether it did."""
    give_up = time.monotonic() + limit_s
    while not condition():
        if time.monotonic() > give_up:
            return False
        time.sleep(0.005)
    return True


@pytest.fixture
def emulator(tmp_path, firmware_libs):
    with ArmEmulator(P, pace="gated", link=tmp_path / "arm", cache=firmware_libs["float"].path.parent) as emu:
        yield emu


def test_an_idle_pc_sends_heartbeats_and_the_firmware_answers_each(emulator):
    # what is asserted is the heartbeat, not the 50 ms limit (the next test's): a machine loaded by other
    # work can stall a process past 50 ms, so the limit here is one no stall reaches
    arm = SerialArm(emulator.port, P, servo_angle=REST_POSE[3], link_timeout_s=5.0)
    try:
        arm.step(2)
        frames, replies = emulator.firmware.frames_ok, arm.heartbeat_replies
        # the charts do nothing: the link is kept
        assert wait_for(lambda: arm.heartbeat_replies >= replies + 5)
        assert arm.lost is None and arm.losses == []
        # the firmware took them as valid frames (a heartbeat it took before `frames` was read may be one of
        # the replies counted: the firmware's count is waited for, not read at the same instant)
        assert wait_for(lambda: emulator.firmware.frames_ok - frames >= 5)
        assert emulator.firmware.setpoints_ok == 1  # heartbeats are no setpoints: the arm was not moved
        reply = arm.heartbeat()  # and one asked for: the firmware's step and counters
        assert reply.step == emulator.firmware.steps and sum(reply.rejections) == 0
        arm.step(2)  # the chart loop takes over again where it was
        assert arm.steps == 4 and arm.rx.rejected == 0
    finally:
        arm.close()


def test_the_pc_declares_a_silent_idle_link_lost_within_50_ms(emulator):
    arm = SerialArm(emulator.port, P, servo_angle=REST_POSE[3])
    seen = []
    arm.on_link_lost = seen.append
    try:
        arm.step(2)
        assert wait_for(lambda: arm.heartbeat_replies >= 2)
        emulator.hang()  # the firmware stops: bytes still go in, nothing comes out
        assert wait_for(lambda: arm.lost is not None)
        loss = arm.lost
        assert seen == [loss] and arm.losses == [loss]
        assert loss.timeout_s == LINK_TIMEOUT_S == 0.050
        assert "no status from the firmware for 50 ms" in loss.reason
        # declared once the silence passed 50 ms, at the first look after: the look before saw less
        assert loss.silence_s > LINK_TIMEOUT_S
        assert loss.checked_before - loss.last_frame_at <= LINK_TIMEOUT_S
        assert loss.checked_before < loss.declared_at
        steps = arm.steps
        arm.step(2)  # no exception: the link stays lost, the arm's time stands, nothing more goes out
        assert not arm.link_ok and arm.link_fault == loss.reason and arm.steps == steps
    finally:
        arm.close()


def test_a_firmware_on_its_own_clock_reports_while_the_pc_is_idle(tmp_path, firmware_libs):
    with ArmEmulator(P, pace="realtime", link=tmp_path / "arm", cache=firmware_libs["float"].path.parent) as emu:
        arm = SerialArm(emu.port, P, servo_angle=REST_POSE[3], link_timeout_s=5.0)
        try:
            step0 = arm.status_step
            # no setpoints: the firmware's watchdog stops the arm, and it says so, STATUS after STATUS
            assert wait_for(lambda: arm.heartbeat_replies >= 3 and arm._status is not None
                            and arm._status.state == 2 and arm.status_step > step0 + 100)
            assert arm.lost is None  # the link itself is fine: the firmware answers and reports
        finally:
            arm.close()


def test_the_keeper_looks_often_enough_to_declare_within_the_limit():
    # a heartbeat is due well inside the timeout, and the keeper's look is finer still
    assert KEEPER_TICK_S < HEARTBEAT_PERIOD_S < LINK_TIMEOUT_S / 4
