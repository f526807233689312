"""The reference board layer's arithmetic (firmware/board/nucleo_f446re/board_io.c), compiled and checked here.

The sketch itself (nucleo_f446re.ino) needs the STM32 Arduino core and a
board: it was not compiled or flashed here (docs/hardware.md says so).  What
it computes is in board_io.c, portable C99 built with the firmware's own
flags, warnings as errors, in both precisions, and run against the checks
of board_io_check.c: the encoders' 16-bit counters unwrapped, the index
edges latched, the bridges' and the servo's compare values, the currents.
"""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

from ttt_sm.hardware.firmware import CFLAGS, compiler, firmware_root, sources

HERE = Path(__file__).parent
BOARD = firmware_root() / "board" / "nucleo_f446re"


@pytest.mark.parametrize("precision", ["float", "double"])
def test_the_board_layer_builds_with_the_firmware_flags_and_passes_its_checks(tmp_path, precision):
    exe = tmp_path / f"board_io_check_{precision}"
    define = ["-DTTT_FW_DOUBLE"] if precision == "double" else []
    cmd = [compiler(), *CFLAGS, *define, f"-I{firmware_root() / 'include'}", f"-I{BOARD}",
           str(BOARD / "board_io.c"), *(str(s) for s in sources()), str(HERE / "board_io_check.c"), "-lm", "-o",
           str(exe)]
    built = subprocess.run(cmd, capture_output=True, text=True)
    assert built.returncode == 0, built.stderr
    ran = subprocess.run([str(exe)], capture_output=True, text=True)
    assert ran.returncode == 0 and ran.stdout.strip() == "ok", ran.stdout
