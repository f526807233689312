"""``ttt-sm ai move``: ask an engine for its move on a board.

``ttt-sm ai move --board B --symbol X|O [--engine thesis|strong] [--json]``
prints the cell (``row``, ``column``) and the engine's thinking time
(``time_ms``), or ``game_over`` with the winner when the game had already
ended.  A malformed or impossible board is one line naming the problem and
exit status 2.  :func:`register` adds the command to the ``ttt-sm`` parser.
"""

from __future__ import annotations

import argparse
import time
from typing import Any

from .common import CliError, add_group, print_json

ENGINES = ("strong", "thesis")


def register(sub: Any) -> argparse.ArgumentParser:
    """Add ``ai`` (with its ``move`` action) to the subcommands of ``ttt-sm``."""
    help_ = "the tic-tac-toe engines: ask one for its move (thesis 3.6.2)"
    sp, actions = add_group(sub, "ai", help_)
    mv = actions.add_parser("move", help="the engine's next cell on a board",
                            description="Print the engine's next cell on BOARD, or that the game is over.")
    mv.add_argument("--board", required=True, metavar="BOARD",
                    help="25 characters row by row: '.' empty, 'X', 'O' (e.g. ............X............)")
    mv.add_argument("--symbol", required=True, metavar="X|O", help="the symbol the engine plays")
    mv.add_argument("--engine", choices=ENGINES, default="strong",
                    help="strong (never loses, default) or thesis (the thesis' three-ply minimax)")
    mv.add_argument("--json", action="store_true", help="print one JSON document")
    mv.set_defaults(func=cmd_ai_move)
    return sp


def ai_move(board: str, symbol: str, engine: str = "strong") -> dict[str, Any]:
    """What ``ttt-sm ai move`` prints, as a dict; raises :class:`~ttt_sm.game.rules.GameError` for bad input."""
    from ..game.engine import GameOver
    from ..game.rules import GameError, check_symbol, parse_board
    from ..game.strong_engine import Analysis, StrongEngine
    from ..game.thesis_engine import ThesisEngine

    if engine not in ENGINES:
        raise GameError(f"unknown engine {engine!r}; choose from {', '.join(ENGINES)}")
    me = check_symbol(symbol, "--symbol")
    try:
        b = parse_board(board)
    except GameError as exc:
        raise type(exc)(f"--board: {exc}") from None
    t0 = time.perf_counter()
    strong = StrongEngine() if engine == "strong" else None
    startup_ms = (time.perf_counter() - t0) * 1000.0
    t1 = time.perf_counter()
    result = strong.analyse(b, me) if strong is not None else ThesisEngine().move(b, me)
    time_ms = (time.perf_counter() - t1) * 1000.0
    out: dict[str, Any] = {"engine": engine, "symbol": me, "board": str(b)}
    if isinstance(result, GameOver):
        out.update(game_over=True, winner=result.winner, reason=result.reason)
        if result.thesis_output is not None:
            out["thesis_output"] = list(result.thesis_output)
    else:
        move = result.move if isinstance(result, Analysis) else result
        out.update(game_over=False, row=move.row, column=move.column)
        if isinstance(result, Analysis):
            out.update(outcome=result.outcome, source=result.source)
    out["time_ms"] = round(time_ms, 3)
    if strong is not None:
        out["startup_ms"] = round(startup_ms, 3)
    return out


def _text(out: dict[str, Any]) -> str:
    if out["game_over"]:
        extra = f"; the thesis block would output {tuple(out['thesis_output'])}" if "thesis_output" in out else ""
        return f"game over: {out['reason']}{extra}"
    proof = f", {out['outcome']} ({out['source']})" if "outcome" in out else ""
    return (f"{out['engine']} plays {out['symbol']} at row {out['row']}, column {out['column']}"
            f"{proof} in {out['time_ms']:.1f} ms")


def cmd_ai_move(args: argparse.Namespace) -> int:
    """Run ``ttt-sm ai move``: a game error becomes the CLI's one-line error (exit status 2)."""
    from ..game.book import BookError
    from ..game.rules import GameError

    try:
        out = ai_move(args.board, args.symbol, args.engine)
    except (GameError, BookError) as exc:
        raise CliError(str(exc)) from exc
    if args.json:
        print_json(out)
    else:
        print(_text(out))
    return 0
