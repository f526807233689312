"""The strong engine's opening book: the early positions, solved offline.

In the first few moves an exact search costs seconds in Python (the reply
to the opening move most of all), so the book holds, up to the eight
symmetries, the cell to play and the exact outcome for the player to move in

* every position with up to ``max_stones`` marks that a game can reach, and
* every position with more marks, up to ``line_stones``, that a player
  meets when it follows the book and the other plays anything (its *lines*;
  they are few, and there the search still costs up to a few hundred ms).

It is built by :func:`build_book` (``python -m ttt_sm.game.book``) with the
same :func:`~ttt_sm.game.solver.choose` the engine uses, searching
for wins without a budget, and shipped as ``book.bin`` in this package.  The
tests re-solve a sample of its entries and check what it covers.

File format (little-endian): ``b"TTTB"``, version (1 byte), ``max_stones``
(1 byte), ``line_stones`` (1 byte), entry count (4 bytes), then
zlib-compressed: the sorted position keys as 8-byte ints
(:func:`~ttt_sm.game.bitboard.canonical`: the mover's cells in the low 25
bits, the other side's above), then one byte per entry: the cell in the
canonical frame (bits 0-4) and the outcome (bits 5-6: 0 win, 1 draw, 2 loss).
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

from ..files import RecordWriteError, write_atomic
from .bitboard import FULL, N_CELLS, bits, canonical, has_four
from .solver import Outcome, Solver, choose

OUTCOMES: tuple[Outcome, Outcome, Outcome] = ("win", "draw", "loss")
MAGIC = b"TTTB"
VERSION = 2
BOOK_FILE = "book.bin"
DEFAULT_MAX_STONES = 4
DEFAULT_LINE_STONES = 8
_HEADER = "<BBBI"


class BookError(ValueError):
    """The opening book file is missing, damaged or of another version."""


@dataclass(frozen=True)
class Book:
    """Solved positions: canonical key -> (cell in the canonical frame, outcome for the mover).

    Complete up to ``max_stones`` marks; a book-following player's lines up to ``line_stones`` marks.
    """

    max_stones: int
    line_stones: int
    entries: dict[int, tuple[int, Outcome]] = field(default_factory=dict)

    @classmethod
    def empty(cls) -> Book:
        """A book that knows nothing (the engine then searches every move)."""
        return cls(-1, -1, {})

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


def engine_lines(entries: dict[int, tuple[int, Outcome]], stones: int) -> set[int]:
    """Canonical keys of the positions with ``stones`` marks met by a player that follows the book.

    That player moves when the field holds as many marks as ``stones`` modulo
    two (first player: even, second: odd) and answers from ``entries``
    (which must hold its positions with fewer marks); the other player tries
    every cell.  Lines that end in a four are dropped.
    """
    level = {canonical(0, 0)[0]}
    for k in range(stones):
        nxt: set[int] = set()
        for key in level:
            mover, other = key & FULL, key >> N_CELLS
            cells = [entries[key][0]] if k % 2 == stones % 2 else bits(FULL & ~(mover | other))
            for c in cells:
                if not has_four(mover | 1 << c):
                    nxt.add(canonical(other, mover | 1 << c)[0])
        level = nxt
    return level


def build_book(max_stones: int = DEFAULT_MAX_STONES, line_stones: int = DEFAULT_LINE_STONES,
               progress: Callable[[str], None] | None = None, known: Book | None = None) -> Book:
    """Solve every position of :func:`positions` and :func:`engine_lines` with one shared table.

    ``known`` entries are taken as they are instead of solved again (to extend
    a book; :func:`choose` is deterministic, so the result is the same).
    """
    solver = Solver(max_entries=20_000_000)
    entries: dict[int, tuple[int, Outcome]] = {}
    old = known.entries if known is not None else {}
    t0 = time.perf_counter()

    def solve(stones: int, mover: int, other: int) -> None:
        key = mover | other << N_CELLS
        if progress and len(entries) % 1000 == 0:
            progress(f"{stones} marks: {len(entries)} entries so far, {time.perf_counter() - t0:.0f} s")
        if key in old:
            entries[key] = old[key]
        else:
            cell, outcome, _ = choose(solver, mover, other, win_budget=None)
            entries[key] = (cell, outcome)

    for stones, mover, other in positions(max_stones):
        solve(stones, mover, other)
    for stones in range(max_stones + 1, line_stones + 1):
        for key in sorted(engine_lines(entries, stones)):
            solve(stones, key & FULL, key >> N_CELLS)
    return Book(max_stones, max(line_stones, max_stones), entries)


def encode(book: Book) -> bytes:
    """The book as the bytes of a ``book.bin`` file."""
    keys = sorted(book.entries)
    payload = b"".join(struct.pack("<Q", k) for k in keys)
    payload += bytes(cell | OUTCOMES.index(book.entries[k][1]) << 5 for k in keys
                     for cell in (book.entries[k][0],))
    return MAGIC + struct.pack(_HEADER, VERSION, book.max_stones, book.line_stones, len(keys)) \
        + zlib.compress(payload, 9)


def decode(data: bytes, source: str = "book") -> Book:
    """Read the bytes of a ``book.bin`` file; :class:`BookError` if they are not one."""
    start = 4 + struct.calcsize(_HEADER)
    if data[:4] != MAGIC or len(data) < start:
        raise BookError(f"{source} is not an opening book (no {MAGIC!r} header)")
    version = data[4]
    if version != VERSION:
        raise BookError(f"{source} is book version {version}; this code reads version {VERSION}: "
                        f"rebuild it with python -m ttt_sm.game.book")
    _, max_stones, line_stones, count = struct.unpack(_HEADER, data[4:start])
    try:
        payload = zlib.decompress(data[start:])
    except zlib.error as exc:
        raise BookError(f"{source} is damaged: {exc}") from None
    if len(payload) != 9 * count:
        raise BookError(f"{source} is damaged: {len(payload)} bytes for {count} entries")
    keys = struct.unpack(f"<{count}Q", payload[:8 * count])
    values = payload[8 * count:]
    entries = {k: (v & 31, OUTCOMES[v >> 5]) for k, v in zip(keys, values, strict=True)}
    return Book(max_stones, line_stones, entries)


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
    """``python -m ttt_sm.game.book [--max-stones N] [--line-stones M] [--known FILE] [--out FILE]``."""
    p = argparse.ArgumentParser(prog="python -m ttt_sm.game.book",
                                description="Build the strong engine's opening book (about half an hour).")
    p.add_argument("--max-stones", type=int, default=DEFAULT_MAX_STONES,
                   help=f"solve every position with up to this many marks (default {DEFAULT_MAX_STONES})")
    p.add_argument("--line-stones", type=int, default=DEFAULT_LINE_STONES,
                   help="and the positions up to this many marks a player meets when it follows the book "
                        f"(default {DEFAULT_LINE_STONES})")
    p.add_argument("--known", default=None, help="reuse the entries of this book instead of solving them again")
    p.add_argument("--out", default=str(Path(__file__).with_name(BOOK_FILE)),
                   help="file to write (default: the packaged book.bin)")
    args = p.parse_args(argv)
    prog = p.prog
    out = Path(args.out)
    folder = out.parent if str(out.parent) else Path(".")
    if not folder.is_dir() or out.is_dir():  # said before the half hour of solving, not after it
        what = "is a folder where a file belongs" if out.is_dir() else f"is in {str(folder)!r}, which is not a folder"
        print(f"{prog}: error: --out {str(out)!r} {what}; choose another path", file=sys.stderr)
        return 2
    t0 = time.perf_counter()
    try:
        known = load_book(args.known) if args.known else None
    except BookError as exc:
        print(f"{prog}: error: --known: {exc}", file=sys.stderr)
        return 2
    book = build_book(args.max_stones, args.line_stones, known=known,
                      progress=lambda msg: print(msg, file=sys.stderr, flush=True))
    data = encode(book)
    try:
        write_atomic(out, data)  # the whole book or the one that was there (docs/reliability.md)
    except RecordWriteError as exc:
        print(f"{prog}: error: {exc.filename}: {exc.strerror}; the book was not written", file=sys.stderr)
        return 1
    print(f"{len(book)} positions (all up to {book.max_stones} marks, the book's lines up to "
          f"{book.line_stones}), {len(data)} bytes, {time.perf_counter() - t0:.0f} s -> {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
