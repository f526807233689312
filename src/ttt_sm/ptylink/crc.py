"""CRC-16/CCITT-FALSE, the check of every frame on the two serial links (camera and arm).

One definition for both links and the firmware's C (``ttt_crc16`` in
firmware/src/link.c computes the same; tests/hardware/test_link.py compares
them).
"""

from __future__ import annotations

import binascii


def crc16(data: bytes) -> int:
    """CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF, no reflection, no final XOR) of ``data``.

    Check value: ``crc16(b"123456789") == 0x29B1``.  Chosen over NMEA's XOR
    because XOR cannot see a dropped pair of equal bytes (``100.0`` losing
    ``00`` reads as a valid ``1.0``); a CRC-16 catches every error burst up to
    16 bits and all but 1 in 65536 of the rest.
    """
    return binascii.crc_hqx(data, 0xFFFF)
