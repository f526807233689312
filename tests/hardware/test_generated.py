"""The firmware's generated sources are current, and the generator writes what the tables say.

``firmware/include/ttt_fw/layout.h`` is generated from ``ttt_sm.twin.layout``
(``python -m ttt_sm.hardware.generate``): the C port of the controller step
and the PC's compiled step index the same memory because both take their
offsets from one table.
"""

from __future__ import annotations

import re
import shutil
from dataclasses import replace

import pytest

from ttt_sm.hardware import generate
from ttt_sm.hardware.firmware import firmware_root
from ttt_sm.twin import layout


def _defines(text: str) -> dict[str, int]:
    return {name: int(value) for name, value in re.findall(r"^#define TTT_(\w+) (\d+)", text, re.MULTILINE)}


def test_every_generated_source_is_current():
    paths = list(generate.generated())
    assert [p.name for p in paths] == ["layout.h"]
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
