"""The commands a page may send the session, each declared once where it is handled.

A command is a function decorated with :func:`.spec.command`, which names its
type on the wire and its fields with their checks (:mod:`..fields`); from these
:mod:`..protocol` checks every message, and the session calls the handler.
Adding a command is writing one such function in the module of its page or
concern:

- :mod:`.pages`: ``hello`` (a page joins);
- :mod:`.run`: ``run``, ``pause``, ``step``, ``tick``, ``next``, ``speed``;
- :mod:`.breakpoints`: ``break``, ``break_delete``, ``break_enable``;
- :mod:`.inputs`: ``set``, ``release``, ``post``;
- :mod:`.history`: ``replay``, ``timeline``;
- :mod:`.coverage`: ``coverage_run``, ``coverage_scenario``, ``coverage_load``, ``coverage_clear``,
  ``coverage_suggest``;
- :mod:`.latency`: ``ack`` (a page has drawn a frame);
- :mod:`.game`: the Tic-tac-toe page's ``game_symbol``, ``game_cell``, ``game_play``, ``game_stop``,
  ``game_engine``, ``game_new``;
- :mod:`.operate`: the Operational page's ``operate_trigger``, ``operate_stop``;
- :mod:`.safety`: every page's ``safety_reset``; ``drive1_stop`` (the chart cockpit, the Operational page).
"""

from __future__ import annotations

from collections.abc import Mapping

from . import breakpoints, coverage, game, history, inputs, latency, operate, pages, run, safety
from .spec import CommandSpec, collect

#: Every command a page may send, by type (in the order of the modules above).
SPECS: Mapping[str, CommandSpec] = collect(
    (pages, run, breakpoints, inputs, history, coverage, latency, game, operate, safety))
