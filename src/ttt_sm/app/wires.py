"""The robot's wiring table: which chart feeds which, and the charts' links to the arm.

Read it as the signal lines of the thesis' Simulink model (figs. 3.2, 3.23,
3.30): one row per line, ``Wire(source, target)``.  Besides the charts, the
loop has these blocks (what each declares, the table reads):

- ``Encoder``: the Encoder blocks of fig. 3.2, one per DC drive: the index
  switch, the encoder angle with its offset, the angle latched at the index
  switch's last edge; the init charts' `offset` goes back into them;
- ``IK``: inverse kinematics (eq. 3.35): the Control chart's tool pose in,
  joint coordinates out;
- ``FK``: forward kinematics of the encoder angles: where the tool is;
- ``Drives``: the setpoint filters and cascade controllers of drives 1-3;
- ``Homing``: whether every drive passes its position through (a logical AND
  of the init charts' `passing`);
- ``EraseFlag``: the thesis' Erase_flag: set by whoever asks for erasing
  (the game, `ttt-sm play`), and in a game when the symbols drawn by the
  manipulator (the Control chart's `ctr`) and those the camera detected
  add up to 25, a full board (thesis section 3.6.1); reset once the Control
  chart erases;
- ``Session``: the game around the charts (the Tic-tac-toe GUI, the engine,
  the camera's moves): the result, the person's moves, the algorithm's answer;
- ``Monitor``: what the Safety chart watches of each drive (following error,
  encoder speed, commanded speed, current, angle) and of the pen servo (its
  feedback against a model of it), from the arm's readings;
- ``Link``, ``Camera``: whether the arm's link and the camera answer;
- ``SafeState``: what the Safety chart asks of the drives (hold, lift, a
  bridge off, re-initialise).

:data:`INIT_WIRES` wires the init charts (`ttt-sm init` runs them alone),
:data:`ROBOT_WIRES` adds the Control and Safety charts (every
:class:`~ttt_sm.app.robot.Robot`) and :data:`GAME_WIRES` the Game and
AlgorithmActivator charts of a game.  The Robot checks them against the
charts' declarations when it is built (docs/architecture.md, "Wiring").
"""

from __future__ import annotations

from .wiring import Block, Port, Wire

ENCODER = Block("Encoder", "the Encoder blocks of drives 1-3 (thesis fig. 3.2), read from the arm", outputs=(
    Port("index", "bool", "index switch level", size=3),
    Port("angle", "rad", "encoder angle plus the offset applied so far", size=3),
    Port("index_angle", "rad", "encoder angle latched at the index switch's last edge", size=3),
), inputs=(
    Port("offset", "rad", "correction added to the encoder angle from now on", size=3),
))
IK = Block("IK", "inverse kinematics (eq. 3.35): joint coordinates for the tool pose", inputs=(
    Port("X", "m", "tool x to reach"),
    Port("Y", "m", "tool y to reach"),
    Port("Z", "m", "tool z to reach"),
    Port("phi", "rad", "tool angle about the global X axis"),
), outputs=(
    Port("q_des", "rad", "joint coordinates q1..q4", size=4),
))
FK = Block("FK", "forward kinematics of the encoder angles (eqs. 3.17-3.21): where the tool is", outputs=(
    Port("X", "m", "tool x"),
    Port("Y", "m", "tool y"),
    Port("Z", "m", "tool z"),
))
DRIVES = Block("Drives", "setpoint filters and cascade controllers of drives 1-3 (fig. 3.6)", inputs=(
    Port("q_set", "rad", "position setpoint of drives 1-3", size=3),
    Port("fr_sw", "bool", "slow setpoint filters"),
))
HOMING = Block("Homing", "every drive passes its position through: a logical AND", inputs=(
    Port("passing", "bool", "the drive's init chart passes its position through", size=3),
    Port("gave_up", "bool", "the drive's init chart gave up", size=3),
), outputs=(
    Port("done", "bool", "every drive is initialised"),
    Port("any_gave_up", "bool", "a drive's init chart gave up"),
))
ERASE_FLAG = Block("EraseFlag", "the thesis' Erase_flag: erase at the next wait", inputs=(
    Port("request", "bool", "erasing asked for (set on its rising edge)"),
    Port("erasing", "bool", "the Control chart erases: the flag is reset"),
    Port("ctr", "1", "symbols drawn by the manipulator (thesis section 3.6.1)"),
    Port("detected", "1", "symbols the camera has detected: with ctr, 25 is a full board and sets the flag"),
), outputs=(
    Port("flag", "bool", "erase at the next wait", attr="erase_requested"),
))
SESSION = Block("Session", "the game around the charts: GUI, engine, the camera's moves", inputs=(
    Port("enable", "bool", "the game algorithm answers now (the activator's pulse)"),
    Port("erasing", "bool", "the Control chart erases"),
    Port("field_drawn", "bool", "the playing field is drawn"),
), outputs=(
    Port("result", "1", "0: game on; 1: the manipulator won; 2: the person won; 3: draw; 4: the person gave up",
         attr="result_code"),
    Port("erased", "bool", "the board has been erased since the game ended", attr="erased_seen"),
    Port("play_again", "bool", "start a new game after erasing"),
    Port("o_pos", "1", "the person's moves, one bit per cell"),
    Port("detected", "1", "the person's symbols the camera has detected (the bits of o_pos)",
         attr="detected_count"),
))

MONITOR = Block("Monitor", "what the Safety chart watches of each drive, from the arm's readings", outputs=(
    Port("err", "rad", "following error: the setpoint filter's output minus the encoder angle", size=3),
    Port("speed", "rad/s", "encoder speed over the last chart step, from the counts", size=3),
    Port("cmd_speed", "rad/s", "commanded speed: the setpoint filter's rate", size=3),
    Port("current", "A", "measured motor current, magnitude", size=3),
    Port("q", "rad", "encoder angle", size=3),
    Port("fast", "bool", "the setpoints move the drive at its speed clamp (or did within 0.1 s)", size=3),
    Port("servo_err", "rad", "pen servo: the model of the servo following its setpoints minus its feedback angle"),
    Port("servo_q", "rad", "pen servo: the angle its feedback wire reads"),
))
LINK = Block("Link", "the arm's link, where the backend has one", outputs=(
    Port("ok", "bool", "valid status keeps arriving (always true for the simulated arm)", attr="link_ok"),
))
CAMERA = Block("Camera", "the camera that sees the board, where the robot has one", outputs=(
    Port("ok", "bool", "the camera answers (always true without one)"),
))
SAFE_STATE = Block("SafeState", "what the Safety chart asks of the drives", inputs=(
    Port("tripped", "bool", "the setpoints are the Safety chart's"),
    Port("hold", "bool", "hold the pose of the trip (or of the lift)"),
    Port("lift_z", "m", "tool height to lift the pen to (NaN: none)"),
    Port("bridge_off", "bool", "switch the drive's bridge off", size=3),
    Port("reinit", "bool", "restart the drive-initialisation charts"),
))

#: The blocks of the loop that are not charts.
BLOCKS = (ENCODER, IK, FK, DRIVES, HOMING, ERASE_FLAG, SESSION, MONITOR, LINK, CAMERA, SAFE_STATE)


def _per_drive(source: str, target: str) -> list[Wire]:
    """Drive k's row of a per-drive signal: `{k}` in a name is 1..3, `{i}` the element 0..2."""
    return [Wire(source.format(k=k, i=k - 1), target.format(k=k, i=k - 1)) for k in (1, 2, 3)]


#: The init charts between inverse kinematics and the drives (thesis fig. 3.2).
INIT_WIRES: tuple[Wire, ...] = (
    # the Encoder blocks and IK into the init charts (fig. 3.2)
    *_per_drive("Encoder.index[{i}]", "DriveInit{k}.index"),
    *_per_drive("Encoder.index_angle[{i}]", "DriveInit{k}.index_pos"),
    Wire("Encoder.angle[0]", "DriveInit1.pos_Encoder"),
    *_per_drive("IK.q_des[{i}]", "DriveInit{k}.pos_in"),
    # the init charts tell each other where they are
    Wire("DriveInit1.ini_23", "DriveInit2.ini1"),
    Wire("DriveInit1.ini_23", "DriveInit3.ini1"),
    Wire("DriveInit2.ini2", "DriveInit1.ini2"),
    Wire("DriveInit2.ini2", "DriveInit3.ini2"),
    Wire("DriveInit3.ini3", "DriveInit1.ini3"),
    Wire("DriveInit3.ini3", "DriveInit2.ini3"),
    # ... and drive the drives, correct the encoders, report
    *_per_drive("DriveInit{k}.pos_out", "Drives.q_set[{i}]"),
    *_per_drive("DriveInit{k}.offset", "Encoder.offset[{i}]"),
    *_per_drive("DriveInit{k}.passing", "Homing.passing[{i}]"),
    *_per_drive("DriveInit{k}.gave_up", "Homing.gave_up[{i}]"),
)

#: The Control chart between the game and inverse kinematics (thesis fig. 3.23).
CONTROL_WIRES: tuple[Wire, ...] = (
    Wire("FK.X", "Control.X_now"),
    Wire("FK.Y", "Control.Y_now"),
    Wire("FK.Z", "Control.Z_now"),
    Wire("Homing.done", "Control.initialised"),
    Wire("EraseFlag.flag", "Control.erase"),
    Wire("Control.X_out", "IK.X"),
    Wire("Control.Y_out", "IK.Y"),
    Wire("Control.Z_out", "IK.Z"),
    Wire("Control.phi", "IK.phi"),
    Wire("Control.fr_sw", "Drives.fr_sw"),
    Wire("Control.erasing", "EraseFlag.erasing"),
)

#: The Safety chart between the arm's readings and the drives (docs/safety.md).
SAFETY_WIRES: tuple[Wire, ...] = (
    Wire("Homing.done", "Safety.initialised"),
    Wire("Homing.any_gave_up", "Safety.init_failed"),
    *_per_drive("Monitor.err[{i}]", "Safety.err_{k}"),
    *_per_drive("Monitor.speed[{i}]", "Safety.speed_{k}"),
    *_per_drive("Monitor.cmd_speed[{i}]", "Safety.cmd_speed_{k}"),
    *_per_drive("Monitor.current[{i}]", "Safety.current_{k}"),
    *_per_drive("Monitor.q[{i}]", "Safety.q_{k}"),
    *_per_drive("Monitor.fast[{i}]", "Safety.fast_{k}"),
    Wire("Monitor.servo_err", "Safety.servo_err"),
    Wire("Monitor.servo_q", "Safety.servo_q"),
    Wire("FK.Z", "Safety.Z_now"),
    Wire("Link.ok", "Safety.link_ok"),
    Wire("Camera.ok", "Safety.camera_ok"),
    Wire("Safety.tripped", "SafeState.tripped"),
    Wire("Safety.holding", "SafeState.hold"),
    Wire("Safety.lift_z", "SafeState.lift_z"),
    *_per_drive("Safety.off_{k}", "SafeState.bridge_off[{i}]"),
    Wire("Safety.reinit", "SafeState.reinit"),
)

#: What every :class:`~ttt_sm.app.robot.Robot` runs: the init charts, the Control chart and the Safety chart.
ROBOT_WIRES: tuple[Wire, ...] = INIT_WIRES + CONTROL_WIRES + SAFETY_WIRES

#: A game adds the Game chart and the AlgorithmActivator (fig. 3.30) and the session around them.
GAME_WIRES: tuple[Wire, ...] = (
    Wire("Homing.done", "Game.initialised"),
    Wire("Control.ready", "Game.ready"),
    Wire("Control.busy", "Game.busy"),
    Wire("Control.at_start", "Game.finished"),
    Wire("Session.result", "Game.result"),
    Wire("Session.erased", "Game.erased"),
    Wire("Session.play_again", "Game.play_again"),
    Wire("Game.erase", "EraseFlag.request"),
    Wire("Control.ctr", "EraseFlag.ctr"),
    Wire("Session.detected", "EraseFlag.detected"),
    Wire("Control.erasing", "Game.sponge"),
    Wire("Game.finish", "Control.finish"),
    Wire("Control.erasing", "Session.erasing"),
    Wire("Control.Pl_fld", "Session.field_drawn"),
    Wire("Session.o_pos", "AlgorithmActivator.o_pos"),
    Wire("AlgorithmActivator.enable", "Session.enable"),
)
