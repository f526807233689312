"""The shipped opening book: it covers every early position, and its answers are re-proved on samples."""

from __future__ import annotations

import random

import pytest

from ttt_sm.game.bitboard import FULL, N_CELLS
from ttt_sm.game.book import (
    Book,
    BookError,
    build_book,
    decode,
    encode,
    engine_lines,
    load_book,
    positions,
)
from ttt_sm.game.solver import Solver


@pytest.fixture(scope="module")
def book() -> Book:
    return load_book()


def holds(solver: Solver, key: int, cell: int, outcome: str) -> bool:
    """Re-prove one entry from scratch: the cell is empty and the outcome exact for the player to move."""
    mover, other = key & FULL, key >> N_CELLS
    b = 1 << cell
    if (mover | other) & b:
        return False
    if outcome == "win":
        return solver.attacker_wins(mover | b, other, attacker_to_move=False)
    if outcome == "draw":  # the cell holds the draw, and nothing better exists
        return (not solver.attacker_wins(other, mover | b, attacker_to_move=True)
                and not solver.attacker_wins(mover, other, attacker_to_move=True))
    return solver.attacker_wins(other, mover, attacker_to_move=False)  # loss: nothing holds


def sample(book: Book, per_level: int, seed: int, levels: range) -> list[tuple[int, tuple[int, str]]]:
    rng = random.Random(seed)
    chosen = []
    for stones in levels:
        keys = sorted(k for k in book.entries if k.bit_count() == stones)
        chosen += [(k, book.entries[k]) for k in rng.sample(keys, min(per_level, len(keys)))]
    return chosen


def test_the_book_covers_every_early_position_and_its_own_lines(book):
    assert (book.max_stones, book.line_stones) == (4, 8)
    every = {mover | other << N_CELLS for _, mover, other in positions(book.max_stones)}
    lines = {stones: engine_lines(book.entries, stones) for stones in range(5, 9)}
    assert len(every) == 10_660 and [len(v) for v in lines.values()] == [869, 904, 6314, 2478]
    assert set(book.entries) == every.union(*lines.values())


def test_entries_re_prove_from_scratch(book):
    solver = Solver()
    for key, (cell, outcome) in sample(book, per_level=3, seed=1, levels=range(3, book.line_stones + 1)):
        assert holds(solver, key, cell, outcome), (bin(key), cell, outcome)


def test_the_book_knows_the_opening_theory(book):
    # X's best first move is the centre and the game is a draw; after it only a diagonal neighbour holds.
    assert book.get(0) == (12, "draw")
    centre = 1 << 12
    reply = book.get(0 | centre << N_CELLS)
    assert reply is not None and reply[0] in {6, 8, 16, 18} and reply[1] == "draw"
    outcomes = {o for _, o in book.entries.values()}
    assert outcomes == {"win", "draw", "loss"}


def test_the_file_round_trips_and_damage_is_named(book, tmp_path):
    small = Book(2, 2, {k: v for k, v in book.entries.items() if k.bit_count() <= 2})
    assert decode(encode(small)) == small
    with pytest.raises(BookError, match="not an opening book"):
        decode(b"PNG....")
    data = bytearray(encode(small))
    data[4] = 9
    with pytest.raises(BookError, match="version 9"):
        decode(bytes(data))
    with pytest.raises(BookError, match="damaged"):
        decode(encode(small)[:-5])
    with pytest.raises(BookError, match="cannot read"):
        load_book(tmp_path / "missing.bin")
    (tmp_path / "b.bin").write_bytes(encode(small))
    assert load_book(tmp_path / "b.bin") == small


@pytest.mark.soak
def test_the_book_rebuilds_to_the_same_answers(book):
    """Regenerating the first three levels (the search behind build_book) gives the shipped entries."""
    rebuilt = build_book(2, 3)  # levels 0-2, and the second player's positions at 3 marks
    lines = engine_lines(rebuilt.entries, 3)
    assert len(rebuilt) == 92 + len(lines)
    assert rebuilt.entries == {k: v for k, v in book.entries.items() if k.bit_count() <= 2 or k in lines}


@pytest.mark.soak
def test_more_entries_re_prove_from_scratch(book):
    solver = Solver(max_entries=5_000_000)
    for key, (cell, outcome) in sample(book, per_level=60, seed=2, levels=range(0, book.line_stones + 1)):
        assert holds(solver, key, cell, outcome), (bin(key), cell, outcome)


def test_an_unwritable_book_is_said_in_one_line_before_the_solving(tmp_path, capsys):
    from ttt_sm.game import book

    blocker = tmp_path / "a_file"
    blocker.write_text("")
    assert book.main(["--max-stones", "0", "--line-stones", "0", "--out", str(blocker / "book.bin")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "not a folder" in err and "Traceback" not in err


def test_a_book_the_disk_refuses_is_said_in_one_line_and_the_old_one_kept(tmp_path, capsys, monkeypatch):
    import errno
    import os

    from ttt_sm.game import book

    out = tmp_path / "book.bin"
    out.write_bytes(b"the old book")
    real_write = os.write

    def full_disk(fd, data):  # the real write path, refused as a full disk refuses it
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(os, "write", full_disk)
    try:
        status = book.main(["--max-stones", "0", "--line-stones", "0", "--out", str(out)])
    finally:
        monkeypatch.setattr(os, "write", real_write)
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 1 and err[-1].startswith("python -m ttt_sm.game.book: error: ")
    assert "No space left on device" in err[-1] and out.read_bytes() == b"the old book"
    assert [p.name for p in tmp_path.iterdir()] == ["book.bin"]
