"""The debugger's one exception type: a request it cannot take, said in one line."""

from __future__ import annotations


class DebugError(ValueError):
    """A debugger command or API call that cannot be done: unknown chart, state,
    datum or event, a malformed condition, a replay without a recipe.

    The message is one line naming what was wrong and, where it helps, what
    exists instead; the REPL prints it and the session goes on.
    """
