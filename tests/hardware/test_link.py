"""The link protocol on both sides: the firmware's C (ctypes) against the PC's Python, the same spec.

Frames (COBS, CRC-16/CCITT-FALSE, a sequence number) built by one side are
read by the other; a whole session (hello, gains download and read-back,
start, setpoints, status, heartbeat) runs between the PC's
:class:`~ttt_sm.hardware.link.Receiver`/``Sender`` and the C firmware; and
every kind of bad frame is rejected, counted under its reason and never
acted on, by both sides alike.
"""

from __future__ import annotations

import ctypes
import logging

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ttt_sm.hardware import link as L
from ttt_sm.hardware.native import NativeFirmware, board_for
from ttt_sm.params import load_params
from ttt_sm.twin import layout
from ttt_sm.twin.cascade import CascadeController

P = load_params()
PEN_UP = 0.9
R = L.Reason


def _u8(data: bytes):
    return (ctypes.c_uint8 * max(1, len(data))).from_buffer_copy(data + b"\0")


def c_crc(lib, data: bytes) -> int:
    return lib.lib.ttt_crc16(_u8(data), len(data))


def c_cobs_encode(lib, data: bytes) -> bytes:
    out = (ctypes.c_uint8 * (len(data) + len(data) // 254 + 2))()
    n = lib.lib.ttt_cobs_encode(_u8(data), len(data), out)
    return bytes(out[:n])


def c_cobs_decode(lib, data: bytes) -> bytes | None:
    out = (ctypes.c_uint8 * (len(data) + 1))()
    n = lib.lib.ttt_cobs_decode(_u8(data), len(data), out)
    return None if n < 0 else bytes(out[:n])


def c_frame(lib, kind: int, seq: int, body: bytes) -> bytes:
    out = (ctypes.c_uint8 * (L.MAX_ENCODED + 1))()
    n = lib.lib.ttt_frame_encode(kind, seq, _u8(body), len(body), out)
    return bytes(out[:n])


@pytest.fixture(params=["float", "double"])
def lib(request, firmware_libs):
    return firmware_libs[request.param]


def test_crc_is_ccitt_false_on_both_sides(lib):
    assert L.crc16(b"123456789") == 0x29B1 == c_crc(lib, b"123456789")  # the catalogue's check value


EXAMPLES = (
    L.Hello(), L.GainsRead(3), L.Heartbeat(0x12345678), L.Drive(2, L.Op.OPEN, -0.25), L.Start(),
    L.Gains(1, tuple(0.5 * k for k in range(L.N_CP))), L.GainsReadback(3, tuple(-1.0 * k for k in range(L.N_CG))),
    L.Setpoints(123456, (0.5, -0.25, 1.5, 0.75), True),
    L.Handshake(L.PROTOCOL_VERSION, (1, 2, 3), 3, 4, 1000, (1e-4, 2e-4, 3e-4), (-1.5, -0.5, -2.5), (1.5, 0.5, 2.5),
                -1.0, 1.0, 0.5),
    L.Status(1000, 1, 5, 21, (100000, -5, 7), (1, 2, 3), (1, 0, 2), (100, -200, 30), 2048),
    L.HeartbeatReply(7, 1000, 500, 2, tuple(range(L.N_REASONS))),
    L.EmuTruth(1000, 1, (0.5, -0.25, 1.5, 0.75), (0.125, -0.5, 0.25)),
)


def test_every_message_reads_back_from_its_body_as_it_was():
    """A message's fields and its body's values, one for one or grouped: pack, then unpack, gives it back."""
    assert sorted(m.KIND for m in EXAMPLES) == sorted(L.MESSAGES)
    for message in EXAMPLES:
        body = message.pack()
        assert len(body) == L.body_length(message.KIND, body), message
        assert L.MESSAGES[message.KIND].unpack(body) == message
        assert message.check() is None
    assert L.Drive(1, L.Op.CLOSED, 2.0).pack() == bytes.fromhex("01 01 00 00 00 00 00 00 00 40")  # in field order


@settings(max_examples=300, deadline=None)
@given(data=st.binary(max_size=600))
def test_cobs_is_the_same_on_both_sides(firmware_libs, data):
    lib = firmware_libs["float"]
    encoded = L.cobs_encode(data)
    assert 0 not in encoded and c_cobs_encode(lib, data) == encoded
    assert L.cobs_decode(encoded) == data == c_cobs_decode(lib, encoded)
    assert c_crc(lib, data) == L.crc16(data)


@settings(max_examples=300, deadline=None)
@given(data=st.binary(min_size=1, max_size=300))
def test_both_cobs_decoders_judge_any_bytes_alike(firmware_libs, data):
    try:
        python: bytes | None = L.cobs_decode(data)
    except ValueError:
        python = None
    assert c_cobs_decode(firmware_libs["float"], data) == python


@settings(max_examples=200, deadline=None)
@given(kind=st.integers(0, 255), seq=st.integers(0, 0xFFFF), body=st.binary(max_size=L.MAX_BODY))
def test_frames_are_the_same_bytes_on_both_sides(firmware_libs, kind, seq, body):
    wire = L.encode_frame(kind, seq, body)
    assert c_frame(firmware_libs["float"], kind, seq, body) == wire
    assert wire.index(0) == len(wire) - 1 and len(wire) <= L.MAX_ENCODED + 1


# ---- a session between the PC (Python) and the firmware (C) -------------------------------------


class Session:
    """The PC's two halves and a C firmware, wired by hand (no port): bytes go both ways on request."""

    def __init__(self, lib, status_every: int = 2) -> None:
        self.fw = NativeFirmware(lib, board_for(P, PEN_UP, status_every))
        self.rx = L.Receiver()
        self.tx = L.Sender()

    def send(self, *messages: L.Message) -> list[L.Message]:
        self.fw.rx(b"".join(self.tx.frame(m) for m in messages))
        return self.rx.feed(self.fw.tx())

    def step(self, n: int = 1, counts=(0, 0, 0)) -> list[L.Message]:
        for _ in range(n):
            self.fw.sensors.counts[:] = counts
            self.fw.step()
        return self.rx.feed(self.fw.tx())

    def configure(self, gains) -> list[L.Message]:
        pc = CascadeController(P, gains, servo_angle=0.0)
        blocks = [L.Gains(d, tuple(pc.cp[d, :layout.N_CP])) for d in range(3)]
        blocks.append(L.Gains(3, tuple(pc.cg[:layout.N_CG])))
        return self.send(L.Hello(), *blocks, L.Start())


def test_a_whole_session_hello_gains_start_setpoints_status_heartbeat(lib, gains):
    s = Session(lib)
    (hs,) = s.send(L.Hello())
    assert isinstance(hs, L.Handshake)
    assert hs.protocol == L.PROTOCOL_VERSION and hs.drives == 3 and hs.control_period_us == 1000
    assert hs.real_size == (4 if lib.precision == "float" else 8)
    assert hs.rad_per_count == tuple(d.rad_per_count for d in P.drives)  # f64 on the wire: exact
    assert hs.limit_max_rad == pytest.approx([d.limit_max_rad for d in P.drives], abs=1e-6)
    assert hs.servo_safe_rad == pytest.approx(PEN_UP)
    # no setpoints before the gains and START: refused, nothing moves
    assert s.send(L.Setpoints(0, (0.1, 0.0, 0.0, 0.0))) == []
    assert s.fw.rejections()[R.REFUSED] == 1 and s.fw.state == 0
    replies = s.configure(gains)
    pc = CascadeController(P, gains, servo_angle=0.0)
    readback = {m.block: m.values_ for m in replies if isinstance(m, L.GainsReadback)}
    assert sorted(readback) == [0, 1, 2, 3]
    dtype = np.float32 if lib.precision == "float" else np.float64
    for d in range(3):  # read back as the firmware holds them: its number type, nothing else lost
        assert np.array_equal(readback[d], pc.cp[d, :layout.N_CP].astype(dtype))
    assert np.array_equal(readback[3], pc.cg[:layout.N_CG].astype(dtype))
    assert s.fw.state == 1
    s.send(L.Setpoints(0, (0.2, 0.0, -0.2, 0.4), fr_sw=True))
    cs = np.ctypeslib.as_array(s.fw.cascade.cs)
    assert cs[:, layout.CS_R_RAW] == pytest.approx([0.2, 0.0, -0.2])
    statuses = s.step(3) + s.step(1, counts=(10, -20, 30))
    assert s.fw.act[0] > 0 and s.fw.act[2] < 0  # the cascade drives towards the setpoints
    assert [m.step for m in statuses if isinstance(m, L.Status)] == [2, 4]
    st_ = statuses[-1]
    assert isinstance(st_, L.Status) and st_.counts == (10, -20, 30) and st_.state_name == "running"
    assert st_.modes == 0b010101  # three drives closed
    (hb,) = s.send(L.Heartbeat(0xC0FFEE))
    assert isinstance(hb, L.HeartbeatReply) and hb.token == 0xC0FFEE and hb.step == 4
    # hello, hello, 4 gains, start, setpoints before it; the heartbeat itself after
    assert hb.frames_ok == 8 and s.fw.frames_ok == 9 and hb.rejections[R.REFUSED] == 1 and hb.lost == 0
    assert s.rx.rejected == 0 and s.rx.frames_ok == len(replies) + 1 + 2 + 1


def _clean_stream(tx: L.Sender) -> list[bytes]:
    return [tx.frame(m) for m in (L.Hello(), L.Heartbeat(1), L.GainsRead(3), L.Heartbeat(2))]


def _frames_with(kind: int, seq: int, body: bytes) -> bytes:
    return L.encode_frame(kind, seq, body)


BAD = {
    # reason: bytes that must be rejected for it (after a HELLO with seq 0 and a HEARTBEAT with seq 1)
    R.COBS: b"\x05\x01\x02\x00",  # a block of 5 announced, 2 bytes follow
    R.CRC: None,  # built below: a valid frame with one body bit flipped
    R.SHORT: L.cobs_encode(b"\x05\x02") + b"\x00",
    R.OVERLONG: b"\x07" * (L.MAX_ENCODED + 5) + b"\x00",
    R.UNKNOWN_TYPE: _frames_with(0x42, 7, b""),
    R.PARTIAL: _frames_with(L.Msg.SETPOINTS, 8, b"\x00" * 12),  # a setpoints frame cut short
    R.LENGTH: _frames_with(L.Msg.HEARTBEAT, 9, b"\x00" * 6),
    R.DUPLICATE: _frames_with(L.Msg.HEARTBEAT, 1, b"\x00" * 4),  # seq 1 again
    R.OUT_OF_ORDER: _frames_with(L.Msg.HEARTBEAT, 0xFFF0, b"\x00" * 4),  # behind seq 1
    R.VALUE: _frames_with(L.Msg.GAINS_READ, 10, b"\x09"),  # block 9
}


def _crc_broken() -> bytes:
    frame = bytearray(L.cobs_decode(L.encode_frame(L.Msg.HEARTBEAT, 11, b"\x01\x02\x03\x04")[:-1]))
    frame[4] ^= 0x10
    return L.cobs_encode(bytes(frame)) + b"\x00"


@pytest.mark.parametrize("reason", list(BAD), ids=lambda r: r.name.lower())
def test_each_bad_frame_is_rejected_for_its_reason_by_both_sides(lib, reason, caplog):
    bad = BAD[reason] if BAD[reason] is not None else _crc_broken()
    start = L.encode_frame(L.Msg.HELLO, 0, b"\x01") + L.encode_frame(L.Msg.HEARTBEAT, 1, b"\x00" * 4)
    after = L.encode_frame(L.Msg.HEARTBEAT, 20, b"\x05\x00\x00\x00")  # the link goes on afterwards
    fw = NativeFirmware(lib, board_for(P, PEN_UP))
    fw.rx(start + bad + after)
    counts = fw.rejections()
    assert counts[reason] == 1 and sum(counts.values()) == 1, counts
    assert fw.frames_ok == 3
    pc_side = L.Receiver(accepts=L.TO_FIRMWARE, name="firmware-spec")
    with caplog.at_level(logging.WARNING, logger="ttt_sm.link"):
        messages = pc_side.feed(start + bad + after)
    assert dict(pc_side.rejections) == {reason: 1} and len(messages) == 3
    assert f"rejected {reason.name.lower()}" in caplog.text  # one log line names it
    replies = L.Receiver().feed(fw.tx())
    assert [m.token for m in replies if isinstance(m, L.HeartbeatReply)] == [0, 5]


def test_late_setpoints_and_state_refusals_are_never_acted_on(lib, gains):
    s = Session(lib)
    s.configure(gains)
    s.step(10)  # the firmware is at step 10
    cs = np.ctypeslib.as_array(s.fw.cascade.cs)
    s.send(L.Setpoints(7, (0.3, 0.3, 0.3, 0.0)))  # 3 steps late (the limit is 2)
    assert s.fw.rejections()[R.LATE] == 1 and np.all(cs[:, layout.CS_R_RAW] == 0.0)
    s.send(L.Setpoints(8, (0.3, 0.3, 0.3, 0.0)))  # 2 steps: in time
    assert cs[:, layout.CS_R_RAW] == pytest.approx([0.3] * 3)
    s.send(L.Gains(0, (1.0,) * layout.N_CP))  # gains while running: refused, not changed
    assert s.fw.rejections()[R.REFUSED] == 1 and s.fw.cascade.cp[0][layout.CP_RPC] != 1.0
    s.send(L.Setpoints(12, (float("nan"), 0.0, 0.0, 0.0)))
    assert s.fw.rejections()[R.VALUE] == 1 and cs[0, layout.CS_R_RAW] == pytest.approx(0.3)


def test_the_pc_counts_lost_frames_and_refuses_replays_from_the_firmware(lib, gains):
    s = Session(lib, status_every=1)
    s.configure(gains)
    wire = bytearray()
    for _ in range(5):
        s.fw.sensors.counts[:] = (1, 2, 3)
        s.fw.step()
        wire += s.fw.tx()
    frames = [f + b"\x00" for f in bytes(wire).split(b"\x00")[:-1]]
    got = s.rx.feed(frames[0] + frames[2] + frames[2] + frames[1] + frames[4])
    assert [m.step for m in got if isinstance(m, L.Status)] == [1, 3, 5]
    assert s.rx.rejections == {R.DUPLICATE: 1, R.OUT_OF_ORDER: 1} and s.rx.seq.lost == 2


# ---- fuzz: any bytes, and valid streams broken every way ------------------------------------------


def _framing(counts) -> dict[int, int]:
    keep = (R.COBS, R.CRC, R.SHORT, R.OVERLONG, R.UNKNOWN_TYPE, R.PARTIAL, R.LENGTH, R.DUPLICATE, R.OUT_OF_ORDER)
    return {int(r): counts.get(r, 0) for r in keep}


def _segments(data: bytes) -> int:
    """Non-empty 0x00-terminated runs: each is one frame or one rejection."""
    return sum(1 for part in data.split(b"\x00")[:-1] if part)


@settings(max_examples=400, deadline=None)
@given(data=st.binary(max_size=2000), cut=st.integers(0, 2000))
def test_fuzz_any_bytes_only_counted_rejections_on_both_sides(firmware_libs, data, cut):
    fw = NativeFirmware(firmware_libs["float"], board_for(P, PEN_UP))
    fw.rx(data[:cut])
    fw.rx(data[cut:])  # chunking does not matter
    pc = L.Receiver(accepts=L.TO_FIRMWARE)
    logging.getLogger("ttt_sm.link").disabled = True
    try:
        messages = pc.feed(data)
    finally:
        logging.getLogger("ttt_sm.link").disabled = False
    c_counts = fw.rejections()
    assert fw.frames_ok + sum(c_counts.values()) == _segments(data)
    assert len(messages) + pc.rejected == _segments(data)
    assert _framing({R(k): v for k, v in c_counts.items()}) == _framing(pc.rejections)


@st.composite
def broken_streams(draw):
    """A valid PC -> firmware stream, then frames dropped, repeated, swapped, cut, flipped and garbage put in."""
    tx = L.Sender()
    kinds = draw(st.lists(st.sampled_from(["hb", "sp", "read", "drive", "gains", "start", "hello"]),
                          min_size=1, max_size=25))
    frames = []
    for k in kinds:
        m: L.Message = {"hb": L.Heartbeat(draw(st.integers(0, 2**32 - 1))),
                        "sp": L.Setpoints(draw(st.integers(0, 50)), (0.1, -0.1, 0.2, 0.0)),
                        "read": L.GainsRead(draw(st.integers(0, 5))),
                        "drive": L.Drive(draw(st.integers(0, 3)), draw(st.integers(0, 4)), 0.0),
                        "gains": L.Gains(3, (0.5,) * layout.N_CG), "start": L.Start(), "hello": L.Hello()}[k]
        frames.append(bytearray(tx.frame(m)))
    for _ in range(draw(st.integers(0, 8))):
        i = draw(st.integers(0, len(frames) - 1))
        action = draw(st.sampled_from(["drop", "dup", "swap", "cut", "flip", "garbage"]))
        f = frames[i]
        if action == "drop" and len(frames) > 1:
            frames.pop(i)
        elif action == "dup":
            frames.insert(i, bytearray(f))
        elif action == "swap" and i + 1 < len(frames):
            frames[i], frames[i + 1] = frames[i + 1], frames[i]
        elif action == "cut":
            k = draw(st.integers(0, len(f) - 1))
            frames[i] = f[:k] + b"\x00"
        elif action == "flip":
            k = draw(st.integers(0, len(f) - 1))
            f[k] ^= 1 << draw(st.integers(0, 7))
        elif action == "garbage":
            frames.insert(i, bytearray(draw(st.binary(min_size=1, max_size=40))))
    return b"".join(frames)


@settings(max_examples=400, deadline=None)
@given(data=broken_streams())
def test_fuzz_broken_streams_are_judged_alike_by_both_sides(firmware_libs, data):
    fw = NativeFirmware(firmware_libs["float"], board_for(P, PEN_UP))
    fw.rx(data)
    for _ in range(3):
        fw.step()
    pc = L.Receiver(accepts=L.TO_FIRMWARE)
    logging.getLogger("ttt_sm.link").disabled = True
    try:
        messages = pc.feed(data)
    finally:
        logging.getLogger("ttt_sm.link").disabled = False
    c_counts = {R(k): v for k, v in fw.rejections().items()}
    assert _framing(c_counts) == _framing(pc.rejections)
    # what passed framing and sequence: acted on by the firmware, or refused for its state or a value
    c_judged = fw.frames_ok + c_counts[R.REFUSED] + c_counts[R.LATE] + c_counts[R.VALUE]
    assert c_judged == len(messages) + pc.rejections.get(R.VALUE, 0)
    assert len(L.Receiver().feed(fw.tx())) >= 0  # whatever the firmware answered decodes


def test_the_documented_examples_are_the_bytes_on_both_sides(firmware_libs):
    """docs/hardware.md, "Framing": a HEARTBEAT and a START, byte by byte."""
    heartbeat = bytes.fromhex("0a 05 02 01 78 56 34 12 79 82 00")
    start = bytes.fromhex("03 07 07 03 d0 9b 00")
    assert L.Sender().frame(L.Heartbeat(0x12345678)) != heartbeat  # seq 0, not 0x0102
    assert L.encode_frame(L.Msg.HEARTBEAT, 0x0102, L.Heartbeat(0x12345678).pack()) == heartbeat
    assert L.encode_frame(L.Msg.START, 7, b"") == start
    lib = firmware_libs["float"]
    assert c_frame(lib, L.Msg.HEARTBEAT, 0x0102, bytes.fromhex("78563412")) == heartbeat
    assert c_frame(lib, L.Msg.START, 7, b"") == start
    wire = {L.Msg.SETPOINTS: 28, L.Msg.STATUS: 52}  # "On the wire at the chart rate"
    assert len(L.Sender().frame(L.Setpoints(123456, (0.1, 0.2, 0.3, 0.4), True))) == wire[L.Msg.SETPOINTS]
    assert len(L.Sender().frame(L.Status(1000, 1, 5, 21, (100000, -5, 7), (1, 2, 3), (1, 0, 2),
                                         (100, -200, 30), 2048))) == wire[L.Msg.STATUS]


# -- issue 28: the firmware checks every field against its range (docs/hardware.md) --------------

def _bad_gains(pc_row, index, value):
    row = list(pc_row)
    row[index] = value
    return tuple(row)


@pytest.mark.parametrize("block, index, value", [
    (3, layout.CG_DT, 0.0),  # a control step of 0
    (3, layout.CG_DT, 1e308),
    (3, layout.CG_DT, -1e-3),
    (3, layout.CG_SV_PERIOD, 0.0),
    (3, layout.CG_SV_MAX, -10.0),  # servo range upside down
    (3, layout.CG_SF_NORMAL, 1e308),
    (0, layout.CP_KP_POS, 1e308),
    (1, layout.CP_KP_SPD, -1e308),
    (2, layout.CP_RPC, 0.0),
    (0, layout.CP_WMAX, -1.0),
    (1, layout.CP_ALPHA_W, 2.0),
])
def test_gains_out_of_range_are_rejected_counted_and_not_taken(lib, gains, block, index, value):
    s = Session(lib)
    pc = CascadeController(P, gains, servo_angle=0.0)
    good = tuple(pc.cp[block, :layout.N_CP]) if block < 3 else tuple(pc.cg[:layout.N_CG])
    assert s.send(L.Hello(), L.Gains(block, _bad_gains(good, index, value)))[1:] == []  # no read-back
    assert s.fw.rejections()[R.VALUE] == 1
    s.configure(gains)  # the good ones are taken: the check is no blanket refusal
    assert s.fw.state == 1 and s.fw.rejections()[R.VALUE] == 1
    (hb,) = s.send(L.Heartbeat(7))
    assert hb.rejections[R.VALUE] == 1  # the PC sees the count by reason


@pytest.mark.parametrize("setpoints", [
    (1e30, -1e30, 3e38, 1e30),  # the issue's: drive 1 into its hard stop at stall current
    (0.0, 0.0, 0.0, 1e30),  # the servo beyond its range
    (0.0, 0.0, 0.0, P.servo.max_rad + 0.05),
    (0.0, 0.0, 0.0, P.servo.min_rad - 0.05),
    (2 * P.drives[0].limit_max_rad - P.drives[0].limit_min_rad + 0.01, 0.0, 0.0, 0.0),
    (0.0, P.drives[1].limit_min_rad - (P.drives[1].limit_max_rad - P.drives[1].limit_min_rad) - 0.01, 0.0, 0.0),
    (0.0, 0.0, 1e6, 0.0),
])
def test_setpoints_out_of_range_are_rejected_counted_and_not_taken(lib, gains, setpoints):
    s = Session(lib)
    s.configure(gains)
    s.send(L.Setpoints(0, (0.2, 0.1, -0.2, 0.4)))
    s.send(L.Setpoints(1, setpoints))
    assert s.fw.rejections()[R.VALUE] == 1
    cs = np.ctypeslib.as_array(s.fw.cascade.cs)
    assert cs[:, layout.CS_R_RAW] == pytest.approx([0.2, 0.1, -0.2])  # the last good ones hold
    (hb,) = s.send(L.Heartbeat(8))
    assert hb.rejections[R.VALUE] == 1
