"""The Safety chart: it watches the drives, the link and the camera, and takes the arm to a safe state.

The thesis' arm had "securing electronics" beside the MF624 card and no
chart for what to do when something breaks (section 3.1); this chart is the
PC's part of that.  Every chart step it reads, per DC drive, what a real arm
reports and what the PC commanded (docs/safety.md, "What trips it"):

- the **following error** `err_k`: the drive's filtered setpoint (the PC
  runs the same setpoint filter the controller runs, followed no faster than
  the controller's speed clamp) minus its encoder angle; while a drive runs
  at its speed clamp (`fast_k`) it lags as it accelerates, and a looser
  limit applies;
- the **encoder speed** `speed_k`, from the counts of the last chart step: a
  jump of the counter shows as a speed no drive can reach;
- the **motor current** `current_k`;
- how long the encoder has **lagged while commanded to move**
  (`cmd_speed_k` above `moving_speed`, the encoder slower than
  `stall_ratio` of it, or not counting at all while the drives initialise:
  a frozen encoder, a blocked motor): `still_k`;
- the **joint angle** `q_k` against the joint limits (once initialised);
- the **link** to the arm, where the backend reports one, and the **camera**;
- the **pen servo** `servo_err`: a model of the servo following its
  setpoints (its lag and slew rate) minus the angle its feedback wire reads;
  off by more than `max_servo_error` for `servo_error_s`, the servo is stuck.

A fault takes it out of `monitoring`:

- a fault of a drive or of the link goes to `stopped`: every drive holds
  where its encoder says it stands (setpoint = encoder angle: even a drive
  whose encoder jumped stays where it is, its controller seeing no error),
  and a drive that lags its command (a frozen encoder would let its
  controller run away) or draws too much current is switched off (its
  bridge off);
- the camera lost, while the drives are sound, goes to `lift`: the pen is
  lifted (`lift_z`, the tool's height plus `lift_height`), then `hold`
  keeps the arm there; a drive fault while lifting or holding still stops;
- the pen servo stuck, while the drives are sound, goes to `lift` too: the
  servo cannot lift the pen, the drives can (before the drives are
  initialised there is no inverse kinematics to lift with: `hold`).

`reason` says why, in one line; `tripped` is the one output the rest of the
application needs.  The `reset` event (a person's, after the cause is
removed) goes to `reinit`: the application restarts the drive-initialisation
charts (`reinit` output), and once every drive passes its position through
again the chart is back in `monitoring`.

Thresholds are data (``[safety]`` of the parameter file, docs/parameters.md);
while the drives initialise, the following error and the current have
looser limits of their own, because the searches of thesis section 3.1.2
push drive 1 into a hard stop on purpose.  The chart imports only the
runtime; ``ttt_sm.app.safety_wiring`` computes its inputs and carries out
what it outputs.
"""

from __future__ import annotations

import math

from statemachine import State

from ..runtime import Data, TickChart, after, after_s, does


def _per_drive(name: str, unit: str, default: object, doc: str) -> tuple[Data, Data, Data]:
    """Data `name_1`, `name_2`, `name_3`: one per DC drive."""
    return tuple(Data(f"{name}_{k}", unit, default, doc.format(k=k)) for k in (1, 2, 3))  # type: ignore


#: What a drive's check found, by kind: the first words of the reason, whether the drive is switched off.
_KINDS = {
    "jump": ("encoder jumped", False),
    "current": ("overcurrent", True),
    "silent": ("encoder stalled while commanded to move", True),
    "following": ("following error", False),
    "limit": ("joint limit", False),
}


class Safety(TickChart):
    """Watch following error, current, encoders, limits, link and camera; stop, lift, hold; reset re-initialises."""

    timed = True  # still_k counts seconds: the tick period per quiet tick
    # its numbers in one buffer: the Safety stage's compiled Monitor block writes the inputs there, and
    # computes the quiet tick in `monitoring` in place (docs/safety.md, "Cost")
    buffered = True
    tick_period_s: float
    trips: int

    inputs = (
        Data("initialised", "bool", False, "every drive passes its position through (the init charts)"),
        Data("init_failed", "bool", False, "a drive-initialisation chart gave up (a switch not found)"),
        *_per_drive("err", "rad", 0.0, "following error of drive {k}: filtered setpoint minus encoder angle"),
        *_per_drive("speed", "rad/s", 0.0, "encoder speed of drive {k} over the last chart step, from its counts"),
        *_per_drive("cmd_speed", "rad/s", 0.0, "commanded speed of drive {k}: the setpoint filter's rate"),
        *_per_drive("current", "A", 0.0, "measured motor current of drive {k}, magnitude"),
        *_per_drive("q", "rad", 0.0, "encoder angle of drive {k} (a joint angle once initialised)"),
        *_per_drive("fast", "bool", False, "drive {k} is commanded at its speed clamp: it lags as it accelerates"),
        Data("Z_now", "m", 0.0, "tool z by forward kinematics of the encoders"),
        Data("link_ok", "bool", True, "the arm's link is alive (always true for an arm without one)"),
        Data("camera_ok", "bool", True, "the camera answers (always true without a camera)"),
        Data("servo_err", "rad", 0.0, "pen servo: the model of the servo following its setpoints minus its feedback"),
        Data("servo_q", "rad", 0.0, "pen servo: the angle its feedback wire reads"),
    )
    outputs = (
        Data("tripped", "bool", False, "in the safe state: the setpoints are the Safety chart's"),
        Data("holding", "bool", False, "every drive keeps the pose it had when the chart tripped (or the lift's)"),
        Data("lift_z", "m", math.nan, "tool height to lift the pen to (NaN: no lift)"),
        *_per_drive("off", "bool", False, "drive {k}'s bridge is switched off: its sensors cannot be trusted"),
        Data("reinit", "bool", False, "re-initialising: the drive-initialisation charts restart as it rises"),
        Data("reason", "text", "", "why the chart tripped last, in one line (empty while it never did)"),
        Data("fault_drive", "1", 0, "the drive whose check tripped it, 1..3 (0: none or not a drive)"),
        Data("trips", "1", 0, "times the chart tripped since power-on"),
    )
    local = (
        Data("max_following_error", "rad", 0.025, "following error limit once initialised"),
        Data("max_following_error_init", "rad", 0.04, "following error limit while initialising"),
        Data("max_following_error_fast", "rad", 0.1, "following error limit of a drive at its speed clamp"),
        Data("max_current", "A", 6.5, "motor current limit once initialised"),
        Data("max_current_init", "A", 7.0, "motor current limit while initialising (a hard stop is pushed)"),
        Data("max_speed", "rad/s", 8.0, "encoder speed beyond which the counter jumped"),
        Data("moving_speed", "rad/s", 0.05, "commanded speed above which the encoder must keep up"),
        Data("stall_ratio", "1", 0.5, "an encoder slower than this part of the commanded speed lags"),
        Data("silent_s", "s", 0.03, "longest an encoder may lag so while commanded to move"),
        Data("limit_margin", "rad", 0.02, "how far past a joint limit the encoder may read"),
        # the joint limits of the parameter file's arm (the application sets those of its own)
        Data("q_min_1", "rad", math.radians(-170.0), "lower joint limit of drive 1"),
        Data("q_min_2", "rad", math.radians(-45.0), "lower joint limit of drive 2"),
        Data("q_min_3", "rad", math.radians(-150.0), "lower joint limit of drive 3"),
        Data("q_max_1", "rad", math.radians(170.0), "upper joint limit of drive 1"),
        Data("q_max_2", "rad", math.radians(135.0), "upper joint limit of drive 2"),
        Data("q_max_3", "rad", math.radians(30.0), "upper joint limit of drive 3"),
        *_per_drive("still", "s", 0.0, "how long drive {k}'s encoder has lagged its commanded speed"),
        Data("lift_height", "m", 0.015, "how far the pen is lifted when the arm can still move"),
        Data("lift_tol", "m", 0.001, "the lift is done within this distance"),
        Data("max_servo_error", "rad", 0.015, "the pen servo's feedback may be this far off its model ..."),
        Data("servo_error_s", "s", 0.02, "... for at most this long"),
        Data("servo_off", "s", 0.0, "how long the pen servo's feedback has been off its model by more than that"),
    )

    #: What the action texts on the diagrams name besides the chart's data (docs/runtime.md, "What an action does").
    action_helpers = {
        "first_fault()": "(reason, drive) of the first failed check: the link, then drives 1-3 (encoder jump,"
                         " overcurrent, stalled encoder, following error, joint limit), then the initialisation",
        "switch_off(k)": "off_k = True when drive k's fault is an overcurrent or a stalled encoder: its own"
                         " sensors are in doubt",
        "count_still(1, 2, 3)": "for each drive k: still_k = still_k + dt while |cmd_speed_k| > moving_speed and"
                                " speed_k <= stall_ratio*|cmd_speed_k| (ratio 0 while initialising), else 0",
    }

    monitoring = State(initial=True)

    class safe(State.Compound):
        lift = State(initial=True)
        hold = State()
        stopped = State()

        lift.to(stopped, cond="arm_fault", on="note_arm_fault")
        lift.to(hold, cond="lifted")
        lift.to(hold, cond=after_s(2.0))  # out of reach: hold where the lift got to
        hold.to(stopped, cond="arm_fault", on="note_arm_fault")

    reinitialising = State()

    monitoring.to(safe.stopped, cond="arm_fault", on="note_arm_fault")
    monitoring.to(safe.lift, cond="not camera_ok and initialised", on="note_camera_lost")
    monitoring.to(safe.hold, cond="not camera_ok", on="note_camera_lost")
    monitoring.to(safe.lift, cond="servo_stuck and initialised", on="note_servo_stuck")
    monitoring.to(safe.hold, cond="servo_stuck", on="note_servo_stuck")
    reset = safe.to(reinitialising)
    # after(1): the init charts restart after the tick that entered; `initialised` is theirs from the next
    reinitialising.to(monitoring, cond=[after(1), "initialised"])
    reinitialising.to(safe.stopped, cond=[after(1), "arm_fault"], on="note_arm_fault")

    # -- guards: pure functions of inputs and data ------------------------------

    def arm_fault(self) -> bool:
        """A drive's check failed, an initialisation gave up, or the link is lost.

        Written out drive by drive: it runs on every chart step of a game
        (:meth:`_arm_fault` says which check failed, once it has).
        """
        d = self.data_mapping()
        if not d["link_ok"] or d["init_failed"]:
            return True
        ini = d["initialised"]
        cur_max = d["max_current"] if ini else d["max_current_init"]
        speed_max, silent = d["max_speed"], d["silent_s"]
        if (d["speed_1"] > speed_max or d["speed_2"] > speed_max or d["speed_3"] > speed_max
                or d["current_1"] > cur_max or d["current_2"] > cur_max or d["current_3"] > cur_max
                or d["still_1"] >= silent or d["still_2"] >= silent or d["still_3"] >= silent):
            return True
        err_max = d["max_following_error"] if ini else d["max_following_error_init"]
        fast = d["max_following_error_fast"]
        if (abs(d["err_1"]) > (fast if d["fast_1"] and fast > err_max else err_max)
                or abs(d["err_2"]) > (fast if d["fast_2"] and fast > err_max else err_max)
                or abs(d["err_3"]) > (fast if d["fast_3"] and fast > err_max else err_max)):
            return True
        if ini:
            m = d["limit_margin"]
            return not (d["q_min_1"] - m <= d["q_1"] <= d["q_max_1"] + m
                        and d["q_min_2"] - m <= d["q_2"] <= d["q_max_2"] + m
                        and d["q_min_3"] - m <= d["q_3"] <= d["q_max_3"] + m)
        return False

    def servo_stuck(self) -> bool:
        """The pen servo's feedback has been off its model too long."""
        return self.servo_off >= self.servo_error_s

    def lifted(self) -> bool:
        """The tool is up at `lift_z`."""
        return self.Z_now >= self.lift_z - self.lift_tol

    def _arm_fault(self) -> tuple[str, int] | None:
        """The first failed check as (reason, drive), drive 0 for one not of a drive; None if all hold."""
        if not self.link_ok:
            return "link lost: no valid status from the arm", 0
        d = self.data_mapping()
        ini = d["initialised"]
        err_max = d["max_following_error"] if ini else d["max_following_error_init"]
        cur_max = d["max_current"] if ini else d["max_current_init"]
        for k in (1, 2, 3):
            found = self._drive_check(k, ini, err_max, cur_max)
            if found is not None:
                return found, k
        if d["init_failed"]:
            return "initialisation gave up: an index switch was not found", 0
        return None

    def _drive_check(self, k: int, ini: bool, err_max: float, cur_max: float) -> str | None:
        d = self.data_mapping()
        speed, current, still, err = d[f"speed_{k}"], d[f"current_{k}"], d[f"still_{k}"], d[f"err_{k}"]
        if speed > d["max_speed"]:
            return f"{_KINDS['jump'][0]} on drive {k}: {speed:.3g} rad/s > {d['max_speed']:g} rad/s"
        if current > cur_max:
            return f"{_KINDS['current'][0]} on drive {k}: {current:.3g} A > {cur_max:g} A"
        if still >= d["silent_s"]:
            return (f"{_KINDS['silent'][0]} on drive {k}: {speed:.3g} rad/s for {still * 1e3:.0f} ms at"
                    f" {abs(d[f'cmd_speed_{k}']):.3g} rad/s commanded")
        if d[f"fast_{k}"]:
            err_max = max(err_max, d["max_following_error_fast"])
        if abs(err) > err_max:
            # four digits: an error just past its limit must not read as the limit ("0.025 rad > 0.025 rad")
            return f"{_KINDS['following'][0]} on drive {k}: {abs(err):.4g} rad > {err_max:g} rad"
        if ini:
            q, lo, hi, m = d[f"q_{k}"], d[f"q_min_{k}"], d[f"q_max_{k}"], d["limit_margin"]
            if q < lo - m or q > hi + m:
                return f"{_KINDS['limit'][0]} on drive {k}: {math.degrees(q):.1f} deg outside" \
                       f" {math.degrees(lo):.0f}..{math.degrees(hi):.0f} deg"
        return None

    # -- actions -------------------------------------------------------------------

    @does("reason, fault_drive = first_fault(); switch_off(fault_drive)")
    def note_arm_fault(self) -> None:
        """Record why, and switch off the drive whose own sensors are in doubt."""
        found = self._arm_fault()
        assert found is not None  # the guard held a moment ago
        reason, k = found
        self.reason = reason
        self.fault_drive = k
        if k and any(reason.startswith(text) for text, off in _KINDS.values() if off):
            setattr(self, f"off_{k}", True)

    @does("reason = 'servo stuck: pen servo at ... rad, commanded ... rad'; fault_drive = 0",
          summary="reason = 'servo stuck: ...'; fault_drive = 0")
    def note_servo_stuck(self) -> None:
        q = self.servo_q
        self.reason = f"servo stuck: pen servo at {q:.3f} rad, commanded {q + self.servo_err:.3f} rad"
        self.fault_drive = 0

    @does("reason = 'camera lost: no frame from the camera'; fault_drive = 0",
          summary="reason = 'camera lost: ...'; fault_drive = 0")
    def note_camera_lost(self) -> None:
        self.reason = "camera lost: no frame from the camera"
        self.fault_drive = 0

    def on_enter_safe(self) -> None:
        self.tripped = True
        self.holding = True
        self.trips = self.trips + 1

    def on_enter_lift(self) -> None:
        self.lift_z = self.Z_now + self.lift_height

    def on_exit_lift(self) -> None:
        self.lift_z = math.nan

    @does("reinit = True; holding = False; off_1 = off_2 = off_3 = False; still_1 = still_2 = still_3 = 0;"
          " servo_off = 0", summary="reinit = True; holding = False; off_1 = off_2 = off_3 = False")
    def on_enter_reinitialising(self) -> None:
        self.reinit = True
        self.holding = False
        self.off_1 = self.off_2 = self.off_3 = False
        self.still_1 = self.still_2 = self.still_3 = 0.0
        self.servo_off = 0.0

    def on_exit_reinitialising(self) -> None:
        self.reinit = False

    def on_exit_safe(self) -> None:
        self.tripped = False

    @does("count_still(1, 2, 3); servo_off = servo_off + dt if abs(servo_err) > max_servo_error else 0",
          summary="count_still(1, 2, 3)")
    def _count_still(self) -> None:
        """still_k: how long drive k's encoder has run at most stall_ratio of its commanded speed (0 while
        initialising); servo_off: how long the servo's feedback has been off its model."""
        d = self.data_mapping()
        # while initialising, only a silent encoder counts: the searches push their stops on purpose
        dt, moving, ratio = self.tick_period_s, d["moving_speed"], d["stall_ratio"] if d["initialised"] else 0.0
        c1, c2, c3 = abs(d["cmd_speed_1"]), abs(d["cmd_speed_2"]), abs(d["cmd_speed_3"])
        d["still_1"] = d["still_1"] + dt if c1 > moving and d["speed_1"] <= ratio * c1 else 0.0
        d["still_2"] = d["still_2"] + dt if c2 > moving and d["speed_2"] <= ratio * c2 else 0.0
        d["still_3"] = d["still_3"] + dt if c3 > moving and d["speed_3"] <= ratio * c3 else 0.0
        d["servo_off"] = d["servo_off"] + dt if abs(d["servo_err"]) > d["max_servo_error"] else 0.0


    # the encoder-still timers (and the servo's) run wherever a drive fault can still trip the chart
    during_monitoring = during_lift = during_hold = during_reinitialising = _count_still


__all__ = ["Safety"]
