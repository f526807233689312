"""The strong engine's opening book: every position with few marks, solved offline.

In the first few moves an exact search costs seconds in Python (the reply
to the opening move most of all), so the book holds the answer for every
position with up to ``max_stones`` marks that a game can reach, up to the
eight symmetries: the cell to play and the exact outcome for the player to
move.  It is built by :func:`build_book` (``python -m ttt_sm.game.book``)
with the same :func:`~ttt_sm.game.strong_engine.choose` the engine uses,
searching for wins without a budget, and shipped as ``book.bin`` in this
package.  The tests re-solve a sample of its entries.

File format (little-endian): ``b"TTTB"``, version (1 byte), ``max_stones``
(1 byte), entry count (4 bytes), then zlib-compressed: the sorted position
keys as 8-byte ints (:func:`~ttt_sm.game.bitboard.canonical`: the mover's
cells in the low 25 bits, the other side's above), then one byte per entry:
the cell in the canonical frame (bits 0-4) and the outcome (bits 5-6:
0 win, 1 draw, 2 loss).
"""

from __future__ import annotations

import argparse
import struct
import sys
import time
import zlib
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Literal

from .bitboard import FULL, N_CELLS, bits, canonical, has_four

Outcome = Literal["win", "draw", "loss"]
OUTCOMES: tuple[Outcome, Outcome, Outcome] = ("win", "draw", "loss")
MAGIC = b"TTTB"
VERSION = 1
BOOK_FILE = "book.bin"
DEFAULT_MAX_STONES = 4


class BookError(ValueError):
    """The opening book file is missing, damaged or of another version."""


@dataclass(frozen=True)
class Book:
    """Solved positions: canonical key -> (cell in the canonical frame, outcome for the mover)."""

    max_stones: int
    entries: dict[int, tuple[int, Outcome]] = field(default_factory=dict)

    @classmethod
    def empty(cls) -> Book:
        """A book that knows nothing (the engine then searches every move)."""
        return cls(-1, {})

    def get(self, key: int) -> tuple[int, Outcome] | None:
        """The entry for a canonical key, if the book has it."""
        return self.entries.get(key)

    def __len__(self) -> int:
        return len(self.entries)


def positions(max_stones: int) -> Iterator[tuple[int, int, int]]:
    """Every reachable position with up to ``max_stones`` marks and no four, once per symmetry class.

    Yields ``(stones, mover, other)`` in the canonical frame, level by level;
    the mover is the side to play, whichever symbol started.
    """
    level = {canonical(0, 0)[0]}
    for stones in range(max_stones + 1):
        nxt: set[int] = set()
        for key in sorted(level):
            mover, other = key & FULL, key >> N_CELLS
            yield stones, mover, other
            if stones < max_stones:
                for c in bits(FULL & ~(mover | other)):
                    placed = mover | 1 << c
                    if not has_four(placed):
                        nxt.add(canonical(other, placed)[0])
        level = nxt


def build_book(max_stones: int = DEFAULT_MAX_STONES,
               progress: Callable[[str], None] | None = None) -> Book:
    """Solve every position of :func:`positions` exactly with one shared search table."""
    from .solver import Solver
    from .strong_engine import choose

    solver = Solver(max_entries=20_000_000)
    entries: dict[int, tuple[int, Outcome]] = {}
    t0 = time.perf_counter()
    last = -1
    for stones, mover, other in positions(max_stones):
        if progress and stones != last:
            progress(f"{stones} marks: {len(entries)} entries so far, {time.perf_counter() - t0:.0f} s")
            last = stones
        cell, outcome, _ = choose(solver, mover, other, win_budget=None)
        entries[mover | other << N_CELLS] = (cell, outcome)
    return Book(max_stones, entries)


def encode(book: Book) -> bytes:
    """The book as the bytes of a ``book.bin`` file."""
    keys = sorted(book.entries)
    payload = b"".join(struct.pack("<Q", k) for k in keys)
    payload += bytes(cell | OUTCOMES.index(book.entries[k][1]) << 5 for k in keys
                     for cell in (book.entries[k][0],))
    return MAGIC + struct.pack("<BBI", VERSION, book.max_stones, len(keys)) + zlib.compress(payload, 9)


def decode(data: bytes, source: str = "book") -> Book:
    """Read the bytes of a ``book.bin`` file; :class:`BookError` if they are not one."""
    if data[:4] != MAGIC or len(data) < 10:
        raise BookError(f"{source} is not an opening book (no {MAGIC!r} header)")
    version, max_stones, count = struct.unpack("<BBI", data[4:10])
    if version != VERSION:
        raise BookError(f"{source} is book version {version}; this code reads version {VERSION}: "
                        f"rebuild it with python -m ttt_sm.game.book")
    try:
        payload = zlib.decompress(data[10:])
    except zlib.error as exc:
        raise BookError(f"{source} is damaged: {exc}") from None
    if len(payload) != 9 * count:
        raise BookError(f"{source} is damaged: {len(payload)} bytes for {count} entries")
    keys = struct.unpack(f"<{count}Q", payload[:8 * count])
    values = payload[8 * count:]
    entries = {k: (v & 31, OUTCOMES[v >> 5]) for k, v in zip(keys, values, strict=True)}
    return Book(max_stones, entries)


def load_book(path: Path | str | None = None) -> Book:
    """The packaged opening book, or the one at ``path``."""
    if path is None:
        data = resources.files(__package__).joinpath(BOOK_FILE).read_bytes()
        return decode(data, f"the packaged {BOOK_FILE}")
    try:
        data = Path(path).read_bytes()
    except OSError as exc:
        raise BookError(f"cannot read the book {path}: {exc.strerror}") from None
    return decode(data, str(path))


def main(argv: list[str] | None = None) -> int:
    """``python -m ttt_sm.game.book [--max-stones N] [--out FILE]``: build the book."""
    p = argparse.ArgumentParser(prog="python -m ttt_sm.game.book", description=main.__doc__)
    p.add_argument("--max-stones", type=int, default=DEFAULT_MAX_STONES,
                   help=f"solve every position with up to this many marks (default {DEFAULT_MAX_STONES})")
    p.add_argument("--out", default=str(Path(__file__).with_name(BOOK_FILE)),
                   help="file to write (default: the packaged book.bin)")
    args = p.parse_args(argv)
    t0 = time.perf_counter()
    book = build_book(args.max_stones, progress=lambda msg: print(msg, file=sys.stderr, flush=True))
    data = encode(book)
    Path(args.out).write_bytes(data)
    print(f"{len(book)} positions up to {args.max_stones} marks, {len(data)} bytes, "
          f"{time.perf_counter() - t0:.0f} s -> {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
