"""The firmware's generated sources: written from the PC's tables, never by hand.

``firmware/include/ttt_fw/layout.h`` holds the ``#define``\\ s the C port of
the controller step indexes its arrays with (``TTT_CP_RPC``, ``TTT_N_CS``,
``TTT_MODE_CLOSED``, ...).  They are generated from the same tables the
compiled step's offsets are computed from (``ttt_sm.twin.layout``), so the
C and the PC index the same memory by construction;
``tests/hardware/test_cascade_c.py`` holds the operations to each other
bit for bit.

``firmware/include/ttt_fw/structs.h`` holds the typedefs of the structs the
PC reads and writes through ctypes (``ttt_board``, ``ttt_sensors``,
``ttt_cascade``), generated from the tables of :mod:`.structs` that
:mod:`.native` builds its ctypes Structures from.

``firmware/include/ttt_fw/protocol.h`` holds the serial link's numbers
(``TTT_MSG_*``, ``TTT_REJ_*``, ``TTT_STATE_*``, ``TTT_OP_*``, the framing's
sizes) and every message body's length and field offsets
(``TTT_BODY_STATUS``, ``TTT_STATUS_COUNTS``, ...), generated from the
protocol's tables (``ttt_sm.hardware.link.protocol``) that the PC's link
packs and checks its frames by: ``link.c`` and ``fw.c`` write and read
the bytes the PC reads and writes.

``firmware/board/nucleo_f446re/arm_board.h`` fills the reference board's
``ttt_board`` with the arm of the packaged parameter file, as
:func:`.native.board_for` fills the emulator's.

The texts are made in :mod:`.headers`.  ``python -m ttt_sm.hardware.generate``
writes every generated file; ``--check`` writes nothing and fails, naming
the files, when a committed one differs from what the tables make
(``tests/hardware/test_generated.py`` runs the check).
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable, Sequence
from pathlib import Path

from ..files import RecordWriteError, write_atomic
from .firmware import firmware_root
from .headers import arm_board_h, layout_h, protocol_h, structs_h

#: Every generated file: its path under firmware/, the function that makes its text, and the module
#: of the tables it is made from.
FILES: tuple[tuple[str, Callable[[], str], str], ...] = (
    ("include/ttt_fw/layout.h", layout_h, "ttt_sm.twin.layout"),
    ("include/ttt_fw/structs.h", structs_h, "ttt_sm.hardware.structs"),
    ("include/ttt_fw/protocol.h", protocol_h, "ttt_sm.hardware.link.protocol"),
    ("board/nucleo_f446re/arm_board.h", arm_board_h, "ttt_sm.hardware.native"),
)


def generated(root: Path | None = None) -> dict[Path, Callable[[], str]]:
    """Every generated source of the firmware: its path, and the function that makes its text."""
    root = (firmware_root() if root is None else root).resolve()  # the checkout's firmware/, not a link to it
    return {root / rel: make for rel, make, _ in FILES}


def _stale_texts(root: Path | None) -> dict[Path, str]:
    """Each generated file that is missing or differs from what its tables make now, with that text."""
    texts = {path: make() for path, make in generated(root).items()}
    return {path: text for path, text in texts.items()
            if not path.is_file() or path.read_text(encoding="utf-8") != text}


def stale(root: Path | None = None) -> list[Path]:
    """The generated files that are missing or differ from what their tables make now."""
    return list(_stale_texts(root))


def write(root: Path | None = None) -> list[Path]:
    """Write every generated file that is stale (each made once); return those written."""
    written = []
    for path, text in _stale_texts(root).items():
        write_atomic(path, text)  # the whole file or the one that was there
        written.append(path)
    return written


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m ttt_sm.hardware.generate",
                                     description="Write the firmware's generated sources (layout.h, structs.h,"
                                                 " protocol.h, the reference board's arm_board.h) from the"
                                                 " PC's tables (ttt_sm.twin.layout, ttt_sm.hardware.structs,"
                                                 " ttt_sm.hardware.link.protocol) and its parameter file.")
    parser.add_argument("--check", action="store_true",
                        help="write nothing; exit 1 naming each generated file that is not current")
    args = parser.parse_args(argv)
    if args.check:
        old = stale()
        for path in old:
            print(f"{path}: stale; regenerate it with python -m ttt_sm.hardware.generate", file=sys.stderr)
        return 1 if old else 0
    try:
        written = write()
    except RecordWriteError as exc:
        print(f"{parser.prog}: error: {exc.filename}: {exc.strerror}; it was not written", file=sys.stderr)
        return 1
    for path in written:
        print(f"wrote {path}")
    return 0


__all__ = ["FILES", "arm_board_h", "generated", "layout_h", "main", "protocol_h", "stale", "structs_h", "write"]


if __name__ == "__main__":
    sys.exit(main())

