"""The firmware's generated sources are current, and the generator writes what the tables say.

``firmware/include/ttt_fw/layout.h`` is generated from ``ttt_sm.twin.layout``
(``python -m ttt_sm.hardware.generate``): the C port of the controller step
and the PC's compiled step index the same memory because both take their
offsets from one table.  ``structs.h`` is generated from
``ttt_sm.hardware.structs``, the table the ctypes Structures of
``ttt_sm.hardware.native`` are built from: the C compiler's ``offsetof`` and
``sizeof`` of every field are compared here with ctypes'.
"""

from __future__ import annotations

import ctypes
import re
import shutil
import subprocess
from dataclasses import replace
from pathlib import Path

import pytest

from ttt_sm.hardware import generate, native, structs
from ttt_sm.hardware.firmware import CFLAGS, compiler, firmware_root
from ttt_sm.params import load_params
from ttt_sm.twin import layout
from ttt_sm.twin.plant import REST_POSE


def _defines(text: str) -> dict[str, int]:
    return {name: int(value) for name, value in re.findall(r"^#define TTT_(\w+) (\d+)", text, re.MULTILINE)}


def test_every_generated_source_is_current():
    paths = list(generate.generated())
    assert [p.name for p in paths] == ["layout.h", "structs.h", "arm_board.h"]
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


# ==== structs.h: the structs the PC reads and writes through ctypes =================================

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
