"""CRC-16/CCITT-FALSE: the checksum of both serial links (the camera's lines, the arm's frames).

The camera's sentences carry it as four hex digits (docs/smartcam.md), the
arm's frames as two bytes, MSB first (docs/hardware.md); the firmware
computes the same CRC bit by bit in C (``ttt_crc16``, ``firmware/src/link.c``),
and tests/hardware/test_link.py holds the two to each other on random bytes.
"""

from __future__ import annotations

import binascii


def crc16(data: bytes) -> int:
    """CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF, no reflection, no final XOR) of `data`.

    ``binascii.crc_hqx`` is this polynomial, unreflected and without a
    final XOR (CRC-16/XMODEM when started at 0); started at 0xFFFF it is
    CCITT-FALSE.  Check value: ``crc16(b"123456789") == 0x29B1``.
    """
    return binascii.crc_hqx(data, 0xFFFF)


__all__ = ["crc16"]
