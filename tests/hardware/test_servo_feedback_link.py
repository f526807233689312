"""The pen servo's feedback over the link: the C firmware's STATUS carries it, the PC reads it, the Safety
chart trips on a stuck servo over the firmware emulator (docs/hardware.md, "The pen servo's feedback").

The firmware reports the ADC's counts as the board read them (``ttt_sensors.servo_adc``, the last two
bytes of ``STATUS``, protocol 2); the PC turns them into an angle with the ``[servo]`` calibration.
"""

from __future__ import annotations

import dataclasses

import pytest

from ttt_sm.app.robot import Robot
from ttt_sm.hardware import link as L
from ttt_sm.hardware.emulator import ArmEmulator, FirmwareOnPlant
from ttt_sm.hardware.serial_arm import SerialArm, SerialArmError
from ttt_sm.twin import layout
from ttt_sm.twin.cascade import CascadeController
from ttt_sm.twin.plant import REST_POSE
from ttt_sm.twin.tuning import design_gains
from ttt_sm.twin.workspace import load_arm

P = load_arm(None)


def test_the_status_carries_the_adc_counts_the_board_read_of_the_servo(firmware_libs):
    bench = FirmwareOnPlant(P, firmware_libs["float"], seed=2)
    tx, rx = L.Sender(), L.Receiver()
    pc = CascadeController(P, design_gains(P), servo_angle=REST_POSE[3])
    messages = [L.Hello(), *[L.Gains(d, tuple(pc.cp[d, :layout.N_CP])) for d in range(3)],
                L.Gains(3, tuple(pc.cg[:layout.N_CG])), L.Start()]
    bench.sense()
    bench.firmware.rx(b"".join(tx.frame(m) for m in messages))
    assert bench.firmware.state == 1
    read: list[int] = []  # what the board read before each control step
    statuses: list[L.Status] = []
    for k in range(400):
        if k % P.control.chart_divider == 0:
            q4 = 0.6 if k >= 100 else REST_POSE[3]  # the servo swings at 0.1 s
            bench.firmware.rx(tx.frame(L.Setpoints(bench.firmware.steps, (0.0, 0.0, 0.0, q4), False)))
        read.append(bench.plant.feedback_counts)
        bench.step()
        statuses += [m for m in rx.feed(bench.firmware.tx()) if isinstance(m, L.Status)]
    assert len(statuses) >= 200 and rx.rejected == 0
    for st in statuses[1:]:  # (the first answers START, before any step)
        assert st.servo_adc == read[st.step - 1], st.step
    counts = [st.servo_adc for st in statuses]
    # at rest, then the swing to 0.6 rad: the counts follow the calibration
    assert abs(P.servo.feedback_angle(counts[10]) - REST_POSE[3]) < 0.01
    assert abs(P.servo.feedback_angle(counts[-1]) - 0.6) < 0.01


class _OldFirmware:
    """A tap that makes the emulator's firmware say it speaks protocol 1 (the one before the servo's feedback)."""

    def __init__(self) -> None:
        self._pending = b""

    def to_firmware(self, data: bytes, now: float) -> bytes:
        return data

    def to_pc(self, data: bytes, now: float) -> bytes:
        self._pending += data
        *frames, self._pending = self._pending.split(b"\x00")
        out = b""
        for raw in frames:
            frame = L.cobs_decode(raw)
            kind, seq, body = frame[0], int.from_bytes(frame[1:3], "little"), frame[3:-2]
            if kind == L.Msg.HANDSHAKE:
                body = bytes([1]) + body[1:]
            out += L.encode_frame(kind, seq, body)
        return out


def test_a_firmware_of_another_protocol_is_refused_at_the_handshake(tmp_path, firmware_libs):
    assert L.PROTOCOL_VERSION == 2
    with ArmEmulator(P, pace="gated", link=tmp_path / "arm", cache=firmware_libs["float"].path.parent) as emu:
        emu.tap = _OldFirmware()
        with pytest.raises(SerialArmError, match="the firmware speaks protocol 1, this PC 2"):
            SerialArm(emu.port, P)


def test_a_servo_stuck_while_initialising_trips_the_safety_chart_over_the_emulator_at_its_next_move(
        tmp_path, firmware_libs):
    """The C firmware on a real pty; the emulated servo sticks 0.5 s after power-on, while the drives
    initialise (the servo is not commanded to move: nothing trips).  Then the Control chart turns the pen:
    the feedback stays where the servo stuck, and the Safety chart lifts the pen with the drives."""
    with ArmEmulator(P, pace="gated", link=tmp_path / "arm", truth=True,
                     cache=firmware_libs["float"].path.parent) as emu:
        arm = SerialArm(emu.port, P, servo_angle=REST_POSE[3], link_timeout_s=5.0)
        try:
            robot = Robot(P, arm=arm, truth=arm.truth)
            moved: list[float] = []
            robot.safety_stage.listeners.append(lambda kind, data: moved.append(arm.servo_setpoint))
            robot.run_for(0.5)  # the servo turns to the angle the init charts hold it at
            emu.plant.pg[layout.PG_SV_RATE] = 0.0  # the servo's gears stuck (the twin's servo_stuck)
            stuck = float(emu.plant.pgs[layout.PGS_SV_Q])
            t_stuck = robot.t
            assert robot.run_until(lambda: robot.tripped, 120.0)
            # no trip while the servo was held still (the drives initialising, 10 s and more): a stuck servo
            # is harmless until its next commanded move, and found there
            assert robot.t > t_stuck + 5.0
            assert robot.initialised and arm.link_ok, (robot.t, robot.safety.reason, moved)
            assert robot.safety.reason.startswith("servo stuck: pen servo at ")
            assert robot.active("Safety") == {"safe", "lift"}
            # what the PC read is where the servo stuck; the setpoint had moved on by more than the limit
            assert abs(arm.sensors().servo_rad - stuck) < 0.005
            assert abs(moved[0] - stuck) > P.safety.max_servo_error_rad
            assert emu.firmware.rejections()[L.Reason.CRC] == 0
        finally:
            arm.close()


def test_the_serial_arm_reads_the_servo_through_its_own_calibration(tmp_path, firmware_libs):
    """The PC turns the counts into an angle with the calibration of its parameter file, not the plant's."""
    quiet = dataclasses.replace(P, servo=dataclasses.replace(P.servo, feedback_noise_lsb=0.0))
    pc_servo = dataclasses.replace(P.servo, feedback_cal_a_counts=P.servo.feedback_cal_a_counts + 100.0)
    pc = dataclasses.replace(P, servo=pc_servo)  # a calibration 100 counts off at -90 deg
    with ArmEmulator(quiet, pace="gated", link=tmp_path / "arm", cache=firmware_libs["float"].path.parent) as emu:
        arm = SerialArm(emu.port, pc, servo_angle=REST_POSE[3], link_timeout_s=5.0)
        try:
            arm.step(2)
            counts = emu.plant.feedback_counts  # at rest and without noise: what every status carried
            assert arm.sensors().servo_rad == pytest.approx(pc_servo.feedback_angle(counts), abs=1e-12)
            assert abs(arm.sensors().servo_rad - P.servo.feedback_angle(counts)) > 0.05
        finally:
            arm.close()
