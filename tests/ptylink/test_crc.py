"""The one CRC-16 of both serial links: CCITT-FALSE, as docs/smartcam.md writes it out bit by bit.

tests/hardware/test_link.py holds it to the firmware's C (``ttt_crc16``) on
random bytes; here it is held to the catalogue's parameters, and both links
are shown to carry this one function.
"""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from ttt_sm.hardware import link
from ttt_sm.ptylink import crc16
from ttt_sm.smartcam import protocol


def bit_by_bit(data: bytes, init: int = 0xFFFF) -> int:
    """docs/smartcam.md's loop: polynomial 0x1021, unreflected, no final XOR."""
    crc = init
    for byte in data:
        crc ^= byte << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x1021) if crc & 0x8000 else crc << 1
            crc &= 0xFFFF
    return crc


def test_the_check_value_is_ccitt_false_not_xmodem():
    assert crc16(b"123456789") == 0x29B1  # CRC-16/CCITT-FALSE's check value
    assert bit_by_bit(b"123456789", init=0) == 0x31C3 != crc16(b"123456789")  # XMODEM's: another init
    assert crc16(b"") == 0xFFFF


@settings(max_examples=300, deadline=None)
@given(data=st.binary(max_size=400))
def test_it_is_the_bit_by_bit_crc_on_any_bytes(data):
    assert crc16(data) == bit_by_bit(data)


def test_both_links_carry_this_one_function():
    assert protocol.crc16 is crc16 and link.crc16 is crc16
    body = b"TTS,INFO,hello"
    assert protocol.encode_status("INFO", "hello") == b"$" + body + b"*" + f"{crc16(body):04X}".encode() + b"\r\n"
    wire = link.cobs_decode(link.encode_frame(link.Msg.START, 7, b"")[:-1])
    assert int.from_bytes(wire[-2:], "big") == crc16(wire[:-2])
