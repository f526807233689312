"""The firmware's generated sources are current, and the generator writes what the tables say.

``firmware/include/ttt_fw/layout.h`` is generated from ``ttt_sm.twin.layout``
(``python -m ttt_sm.hardware.generate``): the C port of the controller step
and the PC's compiled step index the same memory because both take their
offsets from one table.  ``protocol.h`` is generated from
``ttt_sm.hardware.link.protocol``: the firmware reads and writes each body's
fields at the bytes the PC's messages pack them at.
"""

from __future__ import annotations

import dataclasses
import re
import shutil
import struct
from dataclasses import replace

import pytest

from ttt_sm.hardware import generate
from ttt_sm.hardware import link as L
from ttt_sm.hardware.firmware import firmware_root
from ttt_sm.hardware.link import protocol
from ttt_sm.params import LIMITS
from ttt_sm.twin import layout


def _defines(text: str) -> dict[str, int]:
    return {name: int(value, 0) for name, value in re.findall(r"^#define TTT_(\w+) (0x[0-9A-F]+|\d+)\b(?![.e])", text,
                                                              re.MULTILINE)}


def _names(text: str) -> set[str]:
    """Every name a C text defines with a value (a number or not)."""
    return set(re.findall(r"^#define TTT_(\w+) \S", text, re.MULTILINE))


def _header(name: str) -> str:
    return (firmware_root() / "include" / "ttt_fw" / name).read_text()


def test_every_generated_source_is_current():
    paths = list(generate.generated())
    assert [p.name for p in paths] == ["layout.h", "protocol.h"]
    assert generate.stale() == [], "stale; regenerate with python -m ttt_sm.hardware.generate"


def test_the_header_defines_the_controllers_layout_and_nothing_else():
    header = (firmware_root() / "include" / "ttt_fw" / "layout.h").read_text()
    assert "do not edit" in header and "src/ttt_sm/twin/layout.py" in header
    expected = {name: value for b in layout.FIRMWARE for name, value in b.constants().items()}
    assert _defines(header) == expected
    assert expected["CS_OFFSET"] == layout.CS_OFFSET and expected["N_CP"] == layout.N_CP  # the PC's own numbers
    assert "N_MODE" not in expected  # an enumeration has no length
    cascade_h = (firmware_root() / "include" / "ttt_fw" / "cascade.h").read_text()
    assert '#include "layout.h"' in cascade_h
    assert _defines(cascade_h) == {"DRIVES": 3}  # no offset is written by hand any more


def test_a_field_added_to_a_table_moves_the_offsets_after_it():
    cs = layout.CS
    fields = list(cs.fields)
    at = [f.name for f in fields].index("W_REF")
    fields.insert(at, layout.Field("NEW", "a new number", 2))
    grown = replace(cs, fields=tuple(fields))
    defines = _defines(generate.layout_h([layout.CP, grown]))
    assert defines["CS_NEW"] == layout.CS_W_REF
    assert defines["CS_W_REF"] == layout.CS_W_REF + 2 and defines["CS_OFFSET"] == layout.CS_OFFSET + 2
    assert defines["CS_R_F"] == layout.CS_R_F and defines["N_CS"] == layout.N_CS + 2


def test_the_check_names_a_stale_file_and_writing_makes_it_current(tmp_path, monkeypatch, capsys):
    root = tmp_path / "firmware"
    shutil.copytree(firmware_root(), root)
    header = root / "include" / "ttt_fw" / "layout.h"
    header.write_text(header.read_text().replace("#define TTT_CS_OFFSET 9", "#define TTT_CS_OFFSET 8"))
    monkeypatch.setenv("TTT_SM_FIRMWARE", str(root))
    assert generate.main(["--check"]) == 1
    assert f"{header.resolve()}: stale" in capsys.readouterr().err
    assert generate.main([]) == 0
    assert generate.main(["--check"]) == 0
    assert header.read_text() == generate.layout_h()


def test_a_doc_that_would_close_the_c_comment_is_refused():
    bad = layout.block("XX", "a block", [("A", "ends */ early")])
    with pytest.raises(ValueError, match="XX_A"):
        generate.layout_h([bad])


def test_an_unwritable_generated_file_is_said_in_one_line_and_nothing_half_written(tmp_path, monkeypatch, capsys):
    from ttt_sm.hardware import generate

    root = tmp_path / "firmware"
    (root / "src").mkdir(parents=True)
    (root / "include" / "ttt_fw" / "layout.h").mkdir(parents=True)  # a folder where the file belongs
    monkeypatch.setenv("TTT_SM_FIRMWARE", str(root))
    assert generate.main([]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert err.startswith("python -m ttt_sm.hardware.generate: error: ") and "layout.h" in err
    assert sorted(p.name for p in (root / "include" / "ttt_fw").iterdir()) == ["layout.h"]  # no temporary left


#: The attributes of a message its body's fields are not named after.
_FIELD_OF = {"fr_sw": "FLAGS"}
#: The fields a body repeats drive by drive, interleaved (docs/hardware.md: HANDSHAKE, "per drive: ...").
_PER_DRIVE = {"HANDSHAKE": ("rad_per_count", "limit_min_rad", "limit_max_rad")}


def _marker(value: object) -> object:
    """A value of `value`'s type whose first byte on the wire is not 0 (1/3: 0x55 as f64, 0xAB as f32)."""
    return True if isinstance(value, bool) else 1 / 3 if isinstance(value, float) else 0x11


def _where_the_pc_packs(message: L.Message) -> dict[str, list[int]]:
    """Each attribute's byte offsets (one per value of a tuple) in the PC's packed body: a marker packed alone."""
    zero = message.pack()
    out = {}
    for f in dataclasses.fields(message):
        value = getattr(message, f.name)
        offsets = []
        for i in range(len(value) if isinstance(value, tuple) else 1):
            marked = (*value[:i], _marker(value[i]), *value[i + 1:]) if isinstance(value, tuple) else _marker(value)
            body = replace(message, **{f.name: marked}).pack()
            offsets.append(next(k for k, (a, b) in enumerate(zip(zero, body, strict=True)) if a != b))
        out[f.name] = offsets
    return out


def _out_of_order(delta: int) -> bool:
    """Whether the PC's receiver refuses a sequence number `delta` after the last as out of order."""
    seq = L.SeqTracker()
    seq.accept(0)
    return seq.accept(delta) == L.Reason.OUT_OF_ORDER


def _protocol_as_the_pc_speaks_it() -> dict[str, int]:
    """What protocol.h must define, found from the PC's messages, their packed bytes and frames."""
    want = {"PROTOCOL_VERSION": L.PROTOCOL_VERSION, "HEADER": L.HEADER, "CRC": L.CRC_BYTES, "MAX_BODY": L.MAX_BODY,
            "MAX_FRAME": L.MAX_FRAME, "MAX_ENCODED": L.MAX_ENCODED, "N_REJ": L.N_REASONS,
            "GAINS_BLOCKS": L.GAINS_BLOCKS}
    want["SEQ_BEHIND"] = next(d for d in range(1, 0x10000) if _out_of_order(d))
    frame = L.cobs_decode(L.encode_frame(0x11, 0x0011, b"")[:-1])
    want |= {"FRAME_TYPE": frame.index(0x11), "FRAME_SEQ": frame.index(0x11, 1)}
    want |= {f"MSG_{m.name}": m.value for m in L.Msg if m is not L.Msg.EMU_TRUTH}  # the emulator's own: not the C's
    want["FIRST_TO_PC"] = 0x80  # docs/hardware.md: PC -> firmware below 0x80, firmware -> PC from 0x80
    assert max(L.TO_FIRMWARE) < want["FIRST_TO_PC"] <= min(L.TO_PC)
    want |= {f"REJ_{r.name}": r.value for r in L.Reason}
    want |= {f"STATE_{name.upper()}": i for i, name in enumerate(L.STATE_NAMES)}
    want |= {f"OP_{o.name}": o.value for o in L.Op}
    drive_row, global_row = L.Gains(0, (0.0,) * L.N_CP), L.Gains(L.GAINS_BLOCKS - 1, (0.0,) * L.N_CG)
    at = _where_the_pc_packs(drive_row)
    want |= {"GAINS_BLOCK": at["block"][0], "GAINS_VALUES": at["values_"][0], "GAINS_BLOCK_GLOBAL": global_row.block,
             "BODY_GAINS_DRIVE": len(drive_row.pack()), "BODY_GAINS_GLOBAL": len(global_row.pack())}
    slow = L.Setpoints(0, (0.0,) * 4, fr_sw=True).pack()
    want["SETPOINTS_FLAG_FR_SW"] = slow[-1]  # the flags byte ends the body
    want["STATUS_MODE_BITS"] = 2  # docs/hardware.md: 2 bits per drive
    for cls in L.MESSAGES.values():
        kind = cls.KIND.name
        if cls.KIND in (L.Msg.GAINS, L.Msg.GAINS_READBACK, L.Msg.EMU_TRUTH):
            continue
        size = L.body_length(cls.KIND, b"")
        assert size is not None
        message = cls.unpack(bytes(size))
        want[f"BODY_{kind}"] = len(message.pack())
        for name, offsets in _where_the_pc_packs(message).items():
            want[f"{kind}_{_FIELD_OF.get(name, name.upper())}"] = offsets[0]
            if name in _PER_DRIVE.get(kind, ()):
                stride = offsets[1] - offsets[0]
                assert offsets == [offsets[0] + d * stride for d in range(L.DRIVES)]
                assert want.setdefault(f"{kind}_DRIVE_STRIDE", stride) == stride  # one stride for the group
    return want


def test_the_protocol_header_defines_what_the_pc_sends_and_nothing_else():
    header = _header("protocol.h")
    assert "do not edit" in header and "src/ttt_sm/hardware/link/protocol.py" in header
    want = _protocol_as_the_pc_speaks_it()
    assert _defines(header) == want
    assert want["BODY_HANDSHAKE"] == 70 and want["HANDSHAKE_DRIVE_STRIDE"] == 16 and want["STATUS_SERVO_ADC"] == 43
    period = re.search(r"^#define TTT_SV_PERIOD_MAX_S (\S+) ", header, re.MULTILINE)
    assert period and float(period[1]) == LIMITS["servo.period_s"][1]  # what the PC's parameter files may hold
    for r in L.Reason:  # the reasons' docs are the C's comments
        assert re.search(rf"^#define TTT_REJ_{r.name} {r.value} +/\* {re.escape(r.doc)} \*/$", header, re.MULTILINE)


def test_link_h_and_fw_h_take_the_protocol_from_the_generated_header():
    generated = _names(_header("protocol.h"))
    for name in ("link.h", "fw.h"):
        text = _header(name)
        assert '#include "protocol.h"' in text, name
        assert not _names(text) & generated, f"{name} defines a number of protocol.h by hand"
    for name in ("link.c", "fw.c"):  # bodies are read and written at the generated offsets, never at a literal one
        text = (firmware_root() / "src" / name).read_text()
        assert not re.search(r"(?<![.\w])(?<!uint8_t )(b|body|frame)( \+ \d|\[\d)", text), name


def test_a_field_added_to_a_message_table_moves_the_offsets_after_it_and_the_length():
    before = _defines(generate.protocol_h())
    handshake = protocol.BODIES[L.Msg.HANDSHAKE]
    items = list(handshake.items)
    at = next(i for i, item in enumerate(items) if getattr(item, "name", "") == "SERVO_MIN_RAD")
    items.insert(at, protocol.Field("NEW", "H", doc="a new number"))
    group = next(i for i, item in enumerate(items) if isinstance(item, protocol.Group))
    old_group = items[group]
    assert isinstance(old_group, protocol.Group)
    items[group] = replace(old_group, fields=(*old_group.fields, protocol.Field("SPARE", "f")))  # 4 bytes a drive
    grown = protocol.Body(tuple(items))
    after = _defines(generate.protocol_h({**protocol.BODIES, L.Msg.HANDSHAKE: grown}))
    spare = 4 * L.DRIVES  # SPARE's bytes: one f32 a drive
    assert after["HANDSHAKE_DRIVE_STRIDE"] == before["HANDSHAKE_DRIVE_STRIDE"] + 4
    assert after["HANDSHAKE_SPARE"] == before["HANDSHAKE_LIMIT_MAX_RAD"] + 4
    assert after["HANDSHAKE_NEW"] == before["HANDSHAKE_SERVO_MIN_RAD"] + spare
    assert after["HANDSHAKE_SERVO_MIN_RAD"] == before["HANDSHAKE_SERVO_MIN_RAD"] + spare + 2
    assert after["HANDSHAKE_SERVO_SAFE_RAD"] == before["HANDSHAKE_SERVO_SAFE_RAD"] + spare + 2
    assert after["BODY_HANDSHAKE"] == before["BODY_HANDSHAKE"] + spare + 2 == struct.calcsize(grown.format)
    unmoved = ("HANDSHAKE_CONTROL_PERIOD_US", "HANDSHAKE_RAD_PER_COUNT", "HANDSHAKE_LIMIT_MAX_RAD", "BODY_STATUS")
    assert all(after[k] == before[k] for k in unmoved)


def test_a_protocol_name_defined_twice_is_refused():
    second = protocol.Field("RAD_PER_COUNT", "d")  # a field of the name a HANDSHAKE field has
    twice = protocol.Body((*protocol.BODIES[L.Msg.HANDSHAKE].items, second))
    with pytest.raises(ValueError, match="TTT_HANDSHAKE_RAD_PER_COUNT"):
        generate.protocol_h({**protocol.BODIES, L.Msg.HANDSHAKE: twice})
