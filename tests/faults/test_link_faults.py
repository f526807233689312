"""Faults of the serial link, on the emulator's wire, against the C firmware in real time (docs/safety.md).

The tap (:class:`~ttt_sm.faults.link.LinkTap`) is checked on its own first:
what each fault does to a stream of frames.  Then each fault runs as one
cell of the link-fault matrix: the firmware emulator on a real
pseudo-terminal stepping on the wall clock, the PC (``SerialArm``)
streaming setpoints at the chart rate.  The assertions are on what the
two ends counted and on the firmware's own step counter, not on the test's
clock: a loaded machine may hold either end up, which adds late frames of
its own but changes none of these.
"""

from __future__ import annotations

import logging

import pytest

from ttt_sm.faults.link import EVERY, LATE_S, LinkFaultError, LinkTap, garble, run_link_cell
from ttt_sm.hardware import link as L
from ttt_sm.hardware.native import WATCHDOG_S
from ttt_sm.hardware.serial_arm import LINK_TIMEOUT_S
from ttt_sm.params import load_params

P = load_params()
WATCHDOG_STEPS = round(WATCHDOG_S / P.control.dt)


def _frames(n: int, start: int = 0) -> list[bytes]:
    return [L.encode_frame(L.Msg.HEARTBEAT, start + k, L.Heartbeat(k).pack()) for k in range(n)]


def _judge(data: bytes) -> L.Receiver:
    rx = L.Receiver(accepts=L.TO_FIRMWARE, name="firmware")
    rx.feed(data)
    return rx


def test_the_tap_passes_every_byte_while_no_fault_is_on_however_the_bytes_are_chunked() -> None:
    tap, frames = LinkTap(), b"".join(_frames(6))
    out = b"".join(tap.to_firmware(frames[k:k + 7], 0.0) for k in range(0, len(frames), 7))
    assert out == frames and tap.counts == {"pc_to_firmware": {}, "firmware_to_pc": {}}


@pytest.mark.parametrize("fault, reason, key", [("frames_garbled", L.Reason.CRC, "garbled"),
                                                ("frames_duplicated", L.Reason.DUPLICATE, "duplicated"),
                                                ("frames_out_of_order", L.Reason.OUT_OF_ORDER, "overtaken")])
def test_each_bad_frame_the_tap_makes_is_rejected_for_its_reason_and_none_is_taken(fault, reason, key) -> None:
    tap = LinkTap()
    tap.inject(fault)
    n = 4 * EVERY + 1  # the last overtakes the one held back before it
    out = b"".join(tap.to_firmware(f, 0.0) for f in _frames(n))
    rx = _judge(out)
    made = tap.counts["pc_to_firmware"][key]
    assert made == 4
    assert rx.rejections == {reason: made}
    assert rx.frames_ok == n - (made if fault != "frames_duplicated" else 0)


def test_garbling_flips_one_bit_under_the_cobs_so_the_frame_ends_where_it_did_with_a_bad_crc() -> None:
    frame = _frames(1)[0]
    bad = garble(frame)
    assert bad.count(0) == 1 and bad.endswith(b"\x00")
    raw, good = L.cobs_decode(bad[:-1]), L.cobs_decode(frame[:-1])
    assert len(raw) == len(good) and sum(bin(a ^ b).count("1") for a, b in zip(raw, good, strict=True)) == 1
    assert raw[-2:] == good[-2:]  # the CRC is the sender's: it no longer holds


def test_lost_frames_vanish_and_show_as_gaps_in_the_sequence_numbers() -> None:
    tap = LinkTap()
    tap.inject("frames_lost")
    rx = _judge(b"".join(tap.to_firmware(f, 0.0) for f in _frames(4 * EVERY + 1)))  # a gap shows by the next
    assert tap.counts["pc_to_firmware"] == {"dropped": 4} and rx.frames_ok == 4 * EVERY + 1 - 4
    assert rx.seq.lost == 4
    assert rx.rejected == 0


def test_late_frames_wait_their_delay_in_order_and_a_cut_link_passes_nothing_until_cleared() -> None:
    tap = LinkTap()
    tap.inject("frames_late")
    frames = _frames(3)
    assert tap.to_firmware(frames[0], 1.0) == b"" and tap.to_firmware(frames[1], 1.001) == b""
    assert tap.to_pc(frames[2], 1.001) == frames[2]  # only the PC's frames are late
    assert tap.to_firmware(b"", 1.0 + LATE_S) == frames[0]
    tap.clear()
    assert tap.to_firmware(frames[2], 1.002) == b""  # behind the one still held: the order is kept
    assert tap.to_firmware(b"", 1.001 + LATE_S) == frames[1] + frames[2]
    tap.inject("link_cut")
    assert tap.to_firmware(frames[0][:5], 2.0) == b"" and tap.to_pc(frames[1], 2.0) == b""
    tap.clear()
    assert tap.to_firmware(frames[2], 2.1) == frames[2]
    with pytest.raises(LinkFaultError, match="no link fault 'frames_eaten'; faults: frames_lost"):
        tap.inject("frames_eaten")


# ---- against the firmware in real time ----------------------------------------------------------------

def clean_cell(fault: str, cache, tries: int = 3, before=lambda: None):
    """One cell of `fault`; again (up to `tries` times) while the machine held an end up past half the
    watchdog (``disturbed``): what such a cell saw may be the machine's doing.  `before` runs before each.

    A cell is real time: the firmware's watchdog and the PC's link timeout run
    on the wall clock.  When the machine held this process up in every try,
    the test cannot judge the fault and says so (a skip with the numbers).
    """
    for _ in range(tries):
        before()
        cell = run_link_cell(P, fault, cache=cache)
        if not cell.disturbed:
            return cell
    pytest.skip(f"{fault}: the machine held this process up in each of {tries} tries (the last: PC loop "
                f"{cell.pc_max_stall_ms} ms, emulator {cell.emulator_max_behind_ms} ms behind, a 1 ms sleep "
                f"{cell.process_max_late_ms} ms late, the limit half the watchdog's 50 ms; {cell.late_outside_fault}"
                f" setpoints late with no fault on)")


REJECTING = {"frames_garbled": "crc", "frames_duplicated": "duplicate", "frames_out_of_order": "out_of_order"}
TAPPED = {"frames_garbled": "garbled", "frames_duplicated": "duplicated", "frames_out_of_order": "overtaken"}


@pytest.mark.parametrize("fault", list(REJECTING))
def test_bad_frames_are_counted_and_rejected_by_both_ends_and_never_acted_on(fault, firmware_cache, caplog):
    with caplog.at_level(logging.WARNING, logger="ttt_sm"):
        cell = clean_cell(fault, firmware_cache, before=caplog.clear)
    reason = REJECTING[fault]
    to_fw, to_pc = cell.injected["pc_to_firmware"][TAPPED[fault]], cell.injected["firmware_to_pc"][TAPPED[fault]]
    assert to_fw > 0 and to_pc > 0
    assert cell.rejected_by_firmware.get(reason) == to_fw and cell.rejected_by_pc.get(reason) == to_pc
    assert cell.bad_frames_acted_on == 0
    # each was named in a log line: the PC's with its type and number, the firmware's by its reason
    # (from the onset on: the PC may join the firmware's stream mid-frame when it opens the port)
    lines = [r.getMessage() for r in caplog.records if r.created >= cell.onset_time]
    pc_lines = [m for m in lines if m.startswith(f"link (pc): rejected {reason}")]
    fw_lines = [m for m in lines if m.startswith("link (firmware): rejected") and m.split(": ")[2].startswith(reason)]
    assert len(pc_lines) == to_pc
    assert sum(int(line.split("rejected ")[1].split(" ")[0]) for line in fw_lines) == to_fw
    # the drives ran on: neither end stopped
    assert not cell.firmware_stopped and not cell.pc_declared and cell.recovered, (cell.pc_reason, cell.end_state)


def test_lost_frames_are_counted_as_gaps_and_a_third_of_them_lost_does_not_stop_the_arm(firmware_cache):
    cell = clean_cell("frames_lost", firmware_cache)
    assert cell.lost_frames_firmware == cell.injected["pc_to_firmware"]["dropped"] > 0
    assert cell.lost_frames_pc == cell.injected["firmware_to_pc"]["dropped"] > 0
    assert not cell.firmware_stopped and not cell.pc_declared and cell.recovered, (cell.pc_reason, cell.end_state)


def test_a_cut_link_stops_the_drives_after_50_ms_and_the_pc_declares_it_lost_then_rearms(firmware_cache):
    cell = clean_cell("link_cut", firmware_cache)
    assert cell.injected["firmware_to_pc"]["cut_bytes"] > 0
    # the firmware: 50 control steps without setpoints, then its safe stop (the step after the 50th)
    assert cell.firmware_stopped and cell.watchdog_steps == WATCHDOG_STEPS + 1
    # the PC: declared at the first look that found more than 50 ms of silence
    assert cell.pc_declared and cell.pc_silence_ms is not None and cell.pc_silence_ms > LINK_TIMEOUT_S * 1e3
    assert cell.pc_reason.startswith("no status from the firmware for 50 ms")
    # the cable back: START again, and the firmware takes setpoints
    assert cell.rearmed and cell.recovered and cell.as_expected, cell.end_state


def test_late_setpoints_are_refused_and_their_absence_stops_the_drives(firmware_cache):
    cell = clean_cell("frames_late", firmware_cache)
    assert cell.rejected_by_firmware.get("late", 0) > 0 and cell.bad_frames_acted_on == 0
    assert cell.firmware_stopped and cell.watchdog_steps == WATCHDOG_STEPS + 1
    assert cell.pc_declared and "the firmware stopped the drives (safe_stop" in cell.pc_reason
    assert cell.rearmed and cell.recovered, cell.end_state
