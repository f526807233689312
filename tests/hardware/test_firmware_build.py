"""Building the firmware: the system compiler, warnings as errors, and one clear error when it cannot."""

from __future__ import annotations

import shutil

import pytest

from ttt_sm.hardware import firmware
from ttt_sm.hardware.firmware import FirmwareError, build, compile_command, firmware_root


def test_the_build_is_c99_pedantic_with_warnings_as_errors(tmp_path):
    command = compile_command("float", tmp_path / "x.so")
    for flag in ("-std=c99", "-pedantic", "-Wall", "-Wextra", "-Werror", "-Wdouble-promotion"):
        assert flag in command
    assert "-DTTT_FW_DOUBLE" not in command and "-DTTT_FW_DOUBLE" in compile_command("double", tmp_path / "y.so")
    assert any(arg.endswith("cascade.c") for arg in command)


def test_a_warning_fails_the_build_and_the_error_quotes_the_compiler(tmp_path, monkeypatch):
    copy = tmp_path / "firmware"
    shutil.copytree(firmware_root(), copy)
    source = copy / "src" / "cascade.c"
    # a float literal without TTT_R(): a silent promotion to double on the float build
    source.write_text(source.read_text().replace("> TTT_R(0.5)", "> 0.5"))
    monkeypatch.setenv("TTT_SM_FIRMWARE", str(copy))
    with pytest.raises(FirmwareError) as err:
        build("float", tmp_path / "cache")
    assert "does not build" in str(err.value) and "cascade.c" in str(err.value)
    assert "double" in str(err.value)  # gcc: "implicit conversion from 'float' to 'double'"
    assert not list((tmp_path / "cache").glob("*.so"))  # nothing half-built is left to load
    assert build("double", tmp_path / "cache").exists()  # no promotion on the double build: it builds


def test_missing_sources_and_compiler_are_named(tmp_path, monkeypatch):
    monkeypatch.setenv("TTT_SM_FIRMWARE", str(tmp_path / "nowhere"))
    with pytest.raises(FirmwareError, match="no firmware sources at .*nowhere"):
        firmware_root()
    monkeypatch.delenv("TTT_SM_FIRMWARE")
    monkeypatch.setenv("CC", "no-such-cc")
    with pytest.raises(FirmwareError, match="no C compiler 'no-such-cc'"):
        firmware.compiler()


def test_make_firmware_builds_both_precisions(tmp_path, capsys):
    assert firmware.main([str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "firmware (float)" in out and "firmware (double)" in out
    assert len(list(tmp_path.glob("ttt_fw_*.so"))) == 2
