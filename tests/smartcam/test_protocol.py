"""The line protocol: examples, every strict-decoder reason, and properties of encoder and decoder."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ttt_sm.smartcam import (
    MAX_SENTENCE_BYTES,
    EncodeError,
    Frame,
    FrameError,
    Level,
    Reason,
    Status,
    crc16,
    decode_line,
    encode_frame,
    encode_status,
)
from ttt_sm.smartcam.protocol import format_percentage

# Reproducible (derandomized) and without per-example deadlines: a loaded machine is slow, not wrong.
PROPERTY = settings(derandomize=True, max_examples=150, deadline=None)


def wrap(body: bytes) -> bytes:
    """A sentence with a right checksum around ``body``: only the content can be wrong."""
    return b"$" + body + b"*" + f"{crc16(body):04X}".encode() + b"\r\n"


def frame_body(seq: bytes = b"7", fields: list[bytes] | None = None) -> bytes:
    fields = fields if fields is not None else [b"0.0"] * 25
    return b"TTT," + seq + b"," + b",".join(fields)


def test_crc16_is_ccitt_false():
    assert crc16(b"123456789") == 0x29B1


def test_a_frame_reads_as_documented():
    line = encode_frame(7, [i * 4.0 for i in range(25)])
    assert line == (b"$TTT,7,0.0,4.0,8.0,12.0,16.0,20.0,24.0,28.0,32.0,36.0,40.0,44.0,48.0,52.0,56.0,60.0,"
                    b"64.0,68.0,72.0,76.0,80.0,84.0,88.0,92.0,96.0*B6D0\r\n")
    frame = decode_line(line)
    assert frame == Frame(7, tuple(i * 4.0 for i in range(25)))
    assert frame.cell(1, 1) == 0.0 and frame.cell(1, 5) == 16.0 and frame.cell(5, 5) == 96.0


def test_a_status_reads_as_documented():
    line = encode_status("WARN", "board not found, check light")
    assert line == b"$TTS,WARN,board not found, check light*2FB3\r\n"
    assert decode_line(line) == Status(Level.WARN, "board not found, check light")


def test_the_longest_frame_is_the_documented_maximum():
    assert len(encode_frame(65535, [100.0] * 25)) == MAX_SENTENCE_BYTES == 167


def test_xor_would_miss_a_dropped_pair_the_crc_catches():
    good = encode_frame(1, [100.0] + [0.0] * 24)
    damaged = good.replace(b",100.0,", b",1.0,", 1)  # "00" lost on the wire
    body = damaged[1:damaged.rindex(b"*")]
    xor = 0
    for b in good[1:good.rindex(b"*")]:
        xor ^= b
    for b in body:
        xor ^= b
    assert xor == 0  # NMEA's XOR checksum would accept the damaged line
    with pytest.raises(FrameError) as err:
        decode_line(damaged)
    assert err.value.reason is Reason.CHECKSUM_MISMATCH


REJECTED = {
    "no dollar": (b"TTT,1*0000\r\n", Reason.BAD_FRAMING),
    "LF without CR": (wrap(frame_body())[:-2] + b"\n", Reason.BAD_FRAMING),
    "no line end": (wrap(frame_body())[:-2], Reason.BAD_FRAMING),
    "overlong": (wrap(frame_body(fields=[b"100.0"] * 25) + b"," + b"1" * 10), Reason.OVERLONG),
    "no star": (b"$" + frame_body() + b"\r\n", Reason.NO_CHECKSUM),
    "lower-case hex": (wrap(frame_body()).replace(b"*", b"*x", 1)[:-7] + b"abcd\r\n", Reason.BAD_CHECKSUM_FORMAT),
    "short checksum": (b"$" + frame_body() + b"*12\r\n", Reason.BAD_CHECKSUM_FORMAT),
    "checksum mismatch": (b"$" + frame_body() + b"*0000\r\n", Reason.CHECKSUM_MISMATCH),
    "control byte, right CRC": (wrap(frame_body().replace(b"0.0", b"0\x07.0", 1)), Reason.BAD_FRAMING),
    "non-ASCII byte, right CRC": (wrap(frame_body() + b"\xe9"), Reason.BAD_FRAMING),
    "unknown tag": (wrap(b"XYZ,1,2"), Reason.UNKNOWN_SENTENCE),
    "24 percentages": (wrap(frame_body(fields=[b"1.0"] * 24)), Reason.FIELD_COUNT),
    "26 percentages": (wrap(frame_body(fields=[b"1.0"] * 26)), Reason.FIELD_COUNT),
    "empty field": (wrap(frame_body(fields=[b"1.0"] * 24 + [b""])), Reason.NON_NUMERIC),
    "seq negative": (wrap(frame_body(seq=b"-1")), Reason.BAD_SEQUENCE),
    "seq leading zero": (wrap(frame_body(seq=b"07")), Reason.BAD_SEQUENCE),
    "seq too big": (wrap(frame_body(seq=b"65536")), Reason.BAD_SEQUENCE),
    "seq not a number": (wrap(frame_body(seq=b"x")), Reason.BAD_SEQUENCE),
    "text": (wrap(frame_body(fields=[b"abc"] + [b"1.0"] * 24)), Reason.NON_NUMERIC),
    "NaN": (wrap(frame_body(fields=[b"1.0"] * 12 + [b"nan"] + [b"1.0"] * 12)), Reason.NOT_FINITE),
    "NaN capitalised": (wrap(frame_body(fields=[b"NaN"] + [b"1.0"] * 24)), Reason.NOT_FINITE),
    "infinity": (wrap(frame_body(fields=[b"inf"] + [b"1.0"] * 24)), Reason.NOT_FINITE),
    "over 100": (wrap(frame_body(fields=[b"100.1"] + [b"1.0"] * 24)), Reason.OUT_OF_RANGE),
    "negative": (wrap(frame_body(fields=[b"-0.5"] + [b"1.0"] * 24)), Reason.OUT_OF_RANGE),
    "no decimal": (wrap(frame_body(fields=[b"5"] + [b"1.0"] * 24)), Reason.BAD_NUMBER_FORMAT),
    "two decimals": (wrap(frame_body(fields=[b"5.25"] + [b"1.0"] * 24)), Reason.BAD_NUMBER_FORMAT),
    "plus sign": (wrap(frame_body(fields=[b"+5.0"] + [b"1.0"] * 24)), Reason.BAD_NUMBER_FORMAT),
    "leading zero": (wrap(frame_body(fields=[b"05.0"] + [b"1.0"] * 24)), Reason.BAD_NUMBER_FORMAT),
    "exponent": (wrap(frame_body(fields=[b"1e1"] + [b"1.0"] * 24)), Reason.BAD_NUMBER_FORMAT),
    "minus zero": (wrap(frame_body(fields=[b"-0.0"] + [b"1.0"] * 24)), Reason.BAD_NUMBER_FORMAT),
    "status level": (wrap(b"TTS,DEBUG,hello"), Reason.BAD_STATUS),
    "status without text": (wrap(b"TTS,INFO"), Reason.FIELD_COUNT),
    "status text too long": (wrap(b"TTS,INFO," + b"x" * 81), Reason.BAD_STATUS),
}


@pytest.mark.parametrize("line, reason", REJECTED.values(), ids=REJECTED.keys())
def test_the_strict_decoder_names_what_is_wrong(line, reason):
    with pytest.raises(FrameError) as err:
        decode_line(line)
    assert err.value.reason is reason
    assert err.value.detail and reason.value in str(err.value)


def test_every_decoder_reason_is_exercised():
    framer_only = {Reason.GARBAGE, Reason.TRUNCATED}
    assert {r for _, r in REJECTED.values()} == set(Reason) - framer_only


def test_a_bad_percentage_error_names_its_cell():
    with pytest.raises(FrameError, match=r"cell 13 \(row 3, column 3\)"):
        decode_line(REJECTED["NaN"][0])


@pytest.mark.parametrize("bad, match", [
    ([math.nan] + [0.0] * 24, "cell 1: .* not finite"),
    ([0.0] * 24 + [math.inf], "cell 25: .* not finite"),
    ([0.0] * 3 + [100.06] + [0.0] * 21, "cell 4: .* outside 0..100"),
    ([-0.1] + [0.0] * 24, "outside 0..100"),
    ([0.0] * 24, "25 percentages, got 24"),
    (["x"] + [0.0] * 24, "cell 1"),
])
def test_the_encoder_refuses_what_the_decoder_would(bad, match):
    with pytest.raises(EncodeError, match=match):
        encode_frame(1, bad)


@pytest.mark.parametrize("seq", [-1, 65536, 1.0, True, "3"])
def test_the_encoder_refuses_bad_sequence_numbers(seq):
    with pytest.raises(EncodeError, match="sequence number"):
        encode_frame(seq, [0.0] * 25)


@pytest.mark.parametrize("level, text", [("DEBUG", "x"), ("INFO", "a$b"), ("INFO", "a*b"), ("INFO", "x" * 81),
                                         ("INFO", "tab\there"), ("INFO", "caf\u00e9")])
def test_the_encoder_refuses_bad_status_lines(level, text):
    with pytest.raises(EncodeError):
        encode_status(level, text)


def test_tiny_negative_rounding_noise_is_sent_as_zero():
    assert format_percentage(-0.04) == "0.0" and format_percentage(100.04) == "100.0"


percentages = st.lists(st.floats(min_value=0.0, max_value=100.0, allow_nan=False), min_size=25, max_size=25)
seqs = st.integers(min_value=0, max_value=65535)


@PROPERTY
@given(seqs, percentages)
def test_round_trip_keeps_the_sequence_and_one_decimal(seq, ps):
    line = encode_frame(seq, ps)
    assert len(line) <= MAX_SENTENCE_BYTES
    frame = decode_line(line)
    assert isinstance(frame, Frame) and frame.seq == seq
    assert frame.percentages == tuple(float(format_percentage(p)) for p in ps)
    assert all(abs(a - b) <= 0.05 + 1e-9 for a, b in zip(frame.percentages, ps, strict=True))
    assert encode_frame(seq, frame.percentages) == line  # what was read encodes to the same bytes


@PROPERTY
@given(seqs, percentages, st.data())
def test_any_single_byte_changed_is_rejected(seq, ps, data):
    line = encode_frame(seq, ps)
    i = data.draw(st.integers(min_value=0, max_value=len(line) - 1))
    b = data.draw(st.integers(min_value=0, max_value=255).filter(lambda b: b != line[i]))
    with pytest.raises(FrameError):
        decode_line(line[:i] + bytes([b]) + line[i + 1:])


@PROPERTY
@given(seqs, percentages, st.data())
def test_any_cut_line_is_rejected(seq, ps, data):
    line = encode_frame(seq, ps)
    end = data.draw(st.integers(min_value=0, max_value=len(line) - 1))
    with pytest.raises(FrameError):
        decode_line(line[:end])


@PROPERTY
@given(st.binary(max_size=300))
def test_arbitrary_bytes_raise_only_frame_errors(data):
    try:
        decode_line(data)
    except FrameError as exc:
        assert isinstance(exc.reason, Reason)


@PROPERTY
@given(st.sampled_from(list(Level)), st.text(alphabet=st.characters(min_codepoint=0x20, max_codepoint=0x7E,
                                                                    exclude_characters="$*"), max_size=80))
def test_status_round_trip(level, text):
    assert decode_line(encode_status(level, text)) == Status(level, text)


def test_values_helper_is_a_valid_frame(values):
    assert decode_line(encode_frame(0, values(3))).percentages == tuple(values(3))
