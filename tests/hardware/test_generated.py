"""The firmware's generated sources are current, and the generator writes what the tables say.

``firmware/include/ttt_fw/layout.h`` is generated from ``ttt_sm.twin.layout``
(``python -m ttt_sm.hardware.generate``): the C port of the controller step
and the PC's compiled step index the same memory because both take their
offsets from one table.  ``structs.h`` is generated from
``ttt_sm.hardware.structs``, the table the ctypes Structures of
``ttt_sm.hardware.native`` are built from: the C compiler's ``offsetof`` and
``sizeof`` of every field are compared here with ctypes'.  ``protocol.h`` is
generated from ``ttt_sm.hardware.link.protocol``: the firmware reads and
writes each body's fields at the bytes the PC's messages pack them at.  The
reference board's ``arm_board.h`` is the emulator's board, field for field.
"""

from __future__ import annotations

import ctypes
import dataclasses
import re
import shutil
import struct
import subprocess
from dataclasses import replace
from pathlib import Path

import pytest

from ttt_sm.hardware import generate, native, structs
from ttt_sm.hardware import link as L
from ttt_sm.hardware.firmware import CFLAGS, compiler, firmware_root
from ttt_sm.hardware.link import protocol
from ttt_sm.params import LIMITS, load_params
from ttt_sm.twin import layout
from ttt_sm.twin.plant import REST_POSE


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
    assert [p.name for p in paths] == ["layout.h", "structs.h", "protocol.h", "arm_board.h"]
    for _, make, tables in generate.FILES:  # the module docs/architecture.md names is the one the file names
        assert f"src/{tables.replace('.', '/')}.py" in make()
    assert generate.stale() == [], "stale; regenerate with python -m ttt_sm.hardware.generate"


def test_the_header_defines_the_controllers_layout_and_nothing_else():
    header = (firmware_root() / "include" / "ttt_fw" / "layout.h").read_text()
    assert "do not edit" in header and "src/ttt_sm/twin/layout.py" in header
    expected = {name: value for b in layout.FIRMWARE for name, value in b.constants().items()}
    assert _defines(header) == expected
    assert expected["CS_OFFSET"] == layout.CS_OFFSET and expected["N_CP"] == layout.N_CP  # the PC's own numbers
    assert "N_MODE" not in expected  # an enumeration has no length
    cascade_h = (firmware_root() / "include" / "ttt_fw" / "cascade.h").read_text()
    assert '#include "layout.h"' in cascade_h and '#include "structs.h"' in cascade_h
    assert _defines(cascade_h) == {}  # no offset or length is written by hand any more


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


# ==== structs.h: the structs the PC reads and writes through ctypes ==========================


INCLUDE = firmware_root() / "include"


def _typedefs(text: str) -> dict[str, list[tuple[str, str, tuple[str, ...], str]]]:
    """Each ``typedef struct`` of a header: its members as (C type, name, length names, comment)."""
    out = {}
    for name, body, again in re.findall(r"^typedef struct (\w+) \{\n(.*?)^\} (\w+);", text, re.MULTILINE | re.DOTALL):
        assert again == name
        out[name] = [(ctype, member, tuple(re.findall(r"\[(\w+)\]", dims)), doc)
                     for ctype, member, dims, doc in re.findall(r"^ +(\w+) (\w+)((?:\[\w+\])*);(?: +/\* (.*) \*/)?$",
                                                                body, re.MULTILINE)]
        assert len(out[name]) == body.count(";"), body  # every member read, none skipped
    return out


def _table(t: structs.CStruct) -> list[tuple[str, str, tuple[str, ...], str]]:
    return [(f.ctype, f.name, tuple(d.name for d in f.dims), f.doc) for f in t.fields]


def test_the_struct_header_declares_the_tables_fields_and_no_other_header_does():
    header = (INCLUDE / "ttt_fw" / "structs.h").read_text()
    assert "do not edit" in header and "src/ttt_sm/hardware/structs.py" in header
    assert _typedefs(header) == {t.name: _table(t) for t in structs.STRUCTS}
    assert _defines(header) == {"DRIVES": structs.DRIVES}
    assert [t.name for t in structs.STRUCTS] == ["ttt_cascade", "ttt_board", "ttt_sensors"]
    for other in (INCLUDE / "ttt_fw").glob("*.h"):  # the hand-written copies are gone
        if other.name != "structs.h":
            declared = re.findall(r"^typedef struct (\w+)", other.read_text(), re.MULTILINE)
            assert not set(declared) & {t.name for t in structs.STRUCTS}, other.name
    assert '#include "structs.h"' in (INCLUDE / "ttt_fw" / "fw.h").read_text()


def _c_layout(include: Path, tables, precision: str, tmp_path: Path) -> dict[str, tuple[int, int]]:
    """``{"<struct>.<field>": (offsetof, sizeof), "<struct>": (0, sizeof)}`` as the C compiler lays out `tables`.

    The program includes fw.h, as the firmware's sources do, and is built with the firmware's flags.
    """
    lines = ['#include <stddef.h>', '#include <stdio.h>', '#include "ttt_fw/fw.h"', "int main(void)", "{"]
    for t in tables:
        lines.append(f'    printf("{t.name} 0 %zu\\n", sizeof({t.name}));')
        for f in t.fields:
            lines.append(f'    printf("{t.name}.{f.name} %zu %zu\\n", offsetof({t.name}, {f.name}),'
                         f" sizeof((({t.name} *)0)->{f.name}));")
    lines += ["    return 0;", "}", ""]
    src, exe = tmp_path / f"layout_{precision}.c", tmp_path / f"layout_{precision}"
    src.write_text("\n".join(lines))
    define = ["-DTTT_FW_DOUBLE"] if precision == "double" else []
    built = subprocess.run([compiler(), *CFLAGS, *define, f"-I{include}", str(src), "-o", str(exe)],
                           capture_output=True, text=True)
    assert built.returncode == 0, built.stderr
    ran = subprocess.run([str(exe)], capture_output=True, text=True, check=True)
    return {key: (int(offset), int(size)) for key, offset, size in (row.split() for row in ran.stdout.splitlines())}


def _ctypes_layout(classes: dict[str, type[ctypes.Structure]]) -> dict[str, tuple[int, int]]:
    """The same, as the ctypes Structures lay them out."""
    out = {}
    for name, cls in classes.items():
        out[name] = (0, ctypes.sizeof(cls))
        for field, _ in cls._fields_:
            member = getattr(cls, field)
            out[f"{name}.{field}"] = (member.offset, member.size)
    return out


@pytest.mark.parametrize("precision", ["float", "double"])
def test_every_field_sits_where_the_ctypes_structures_read_it(firmware_libs, tmp_path, precision):
    lib = firmware_libs[precision]
    python = _ctypes_layout({"ttt_cascade": lib.Cascade, "ttt_board": native.Board, "ttt_sensors": native.SensorsIn})
    c = _c_layout(INCLUDE, structs.STRUCTS, precision, tmp_path)
    assert c == python
    assert len(c) == sum(1 + len(t.fields) for t in structs.STRUCTS)
    assert c["ttt_cascade.cp"] == (0, ctypes.sizeof(lib.real) * 3 * layout.N_CP)  # the build's ttt_real, layout's N_CP


@pytest.mark.parametrize("precision", ["float", "double"])
def test_a_field_added_to_a_table_is_in_the_header_and_the_ctypes_struct_at_one_offset(tmp_path, precision):
    sensors = structs.SENSORS
    fields = list(sensors.fields)
    at = [f.name for f in fields].index("current_a")
    fields.insert(at, structs.CField("new", "double", (), "a new number"))  # 8-aligned: moves what follows
    grown = replace(sensors, fields=tuple(fields))
    tables = (structs.CASCADE, structs.BOARD, grown)
    include = tmp_path / "include"
    shutil.copytree(INCLUDE, include)
    header = generate.structs_h(tables)
    assert "    double new;" in header and _typedefs(header)["ttt_sensors"] == _table(grown)
    (include / "ttt_fw" / "structs.h").write_text(header)

    class Grown(ctypes.Structure):
        _fields_ = grown.ctypes_fields()

    c = _c_layout(include, tables, precision, tmp_path)
    assert c["ttt_sensors.new"] == (native.SensorsIn.current_a.offset, 8) == (Grown.new.offset, 8)
    assert c["ttt_sensors.current_a"][0] == Grown.current_a.offset > native.SensorsIn.current_a.offset
    real = ctypes.c_double if precision == "double" else ctypes.c_float

    class Cascade(ctypes.Structure):
        _fields_ = structs.CASCADE.ctypes_fields(real)

    assert c == _ctypes_layout({"ttt_cascade": Cascade, "ttt_board": native.Board, "ttt_sensors": Grown})


def test_a_struct_doc_that_would_close_the_c_comment_is_refused():
    bad = structs.struct("ttt_x", "a struct", [("a", "float", (), "ends */ early")])
    with pytest.raises(ValueError, match="ttt_x.a"):
        generate.structs_h([bad])


def test_a_ttt_real_struct_needs_the_builds_real_type():
    with pytest.raises(ValueError, match="cp: a ttt_real field"):
        structs.CASCADE.ctypes_fields()
    assert dict(structs.CASCADE.ctypes_fields(ctypes.c_float))["act"]._type_ is ctypes.c_float


def _c_board(header: str, tmp_path: Path) -> dict[str, float]:
    """``{"<field>" or "<field>[i]": value}`` of the ``ttt_board`` that `header`'s ``ttt_arm_board()`` fills, as
    compiled C prints it (the reference board's sketch includes the header beside the firmware's)."""
    board_dir = tmp_path / "board"
    board_dir.mkdir(exist_ok=True)
    (board_dir / "arm_board.h").write_text(header)
    lines = ['#include <stdio.h>', '#include "arm_board.h"', "int main(void)", "{",
             "    ttt_board b;", "    ttt_arm_board(&b);"]
    for f in structs.BOARD.fields:
        names = [f"{f.name}[{i}]" for i in range(f.dims[0].value)] if f.dims else [f.name]
        lines += [f'    printf("{n} %.17g\\n", (double)b.{n});' for n in names]
    lines += ["    return 0;", "}", ""]
    src, exe = tmp_path / "arm_board.c", tmp_path / "arm_board"
    src.write_text("\n".join(lines))
    built = subprocess.run([compiler(), *CFLAGS, f"-I{INCLUDE}", f"-I{board_dir}", str(src), "-o", str(exe)],
                           capture_output=True, text=True)
    assert built.returncode == 0, built.stderr
    ran = subprocess.run([str(exe)], capture_output=True, text=True, check=True)
    return {name: float(value) for name, value in (row.split() for row in ran.stdout.splitlines())}


def _python_board(board: native.Board) -> dict[str, float]:
    out = {}
    for f in structs.BOARD.fields:
        value = getattr(board, f.name)
        out.update({f"{f.name}[{i}]": float(v) for i, v in enumerate(value)} if f.dims else {f.name: float(value)})
    return out


def test_the_reference_boards_arm_is_the_emulators_board_field_for_field(tmp_path):
    header = (firmware_root() / "board" / "nucleo_f446re" / "arm_board.h").read_text()
    assert "do not edit" in header and "src/ttt_sm/data/arm.toml" in header
    params = load_params()
    want = _python_board(native.board_for(params, servo_safe_rad=REST_POSE[3]))
    assert _c_board(header, tmp_path) == want  # every field, to the bit of its C type
    assert want["rad_per_count[1]"] == params.drives[1].rad_per_count and want["watchdog_steps"] == 50
    sketch = (firmware_root() / "board" / "nucleo_f446re" / "nucleo_f446re.ino").read_text()
    assert '#include "src/arm_board.h"' in sketch and "ttt_arm_board(&board);" in sketch
    assert "rad_per_count" not in sketch.replace("control_period_us", "")  # no hand-kept copy of the numbers


def test_a_recalibrated_arm_toml_changes_the_boards_numbers(tmp_path):
    params = load_params()
    geared = replace(params, drives=(replace(params.drives[0], gear_ratio=100.0), *params.drives[1:]))
    c = _c_board(generate.arm_board_h(geared), tmp_path)
    assert c["rad_per_count[0]"] == geared.drives[0].rad_per_count != params.drives[0].rad_per_count
    assert c["rad_per_count[1]"] == params.drives[1].rad_per_count

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
