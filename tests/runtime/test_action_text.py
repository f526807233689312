"""What an action does, as a diagram writes it: declared beside the method, or its own statements."""

from __future__ import annotations

import math

import pytest
from statemachine import State

from ttt_sm.runtime import Data, TickChart, does
from ttt_sm.runtime.action_text import MAX_CHARS, action_text, statements, unknown_names
from ttt_sm.runtime.diagram import edge_text, state_actions


class Pen(TickChart):
    timed = True
    tick_period_s: float
    inputs = (Data("speed", "m/s", 0.02, "drawing speed"),)
    outputs = (Data("X_out", "m", 0.0, "tool x"), Data("n", "1", 0, "strokes"))
    local = (Data("tx", "m", -0.01, "target x"), Data("note", "text", "", "what happened"))
    action_helpers = {"move(v)": "one step towards tx at speed v"}

    down = State(initial=True)
    done = State()
    down.to(done, cond="X_out <= tx", on="finish")

    def during_down(self) -> None:
        self._move(self.speed * 2)

    def _move(self, v: float) -> None:
        self.X_out = max(self.X_out_p - v * self.tick_period_s, self.tx)

    @does("n = n + 1; note = 'a long note that says a great deal about the stroke just drawn, too much'",
          summary="n = n + 1")
    def finish(self) -> None:
        self.n = self.n + 1
        self.note = "a long note that says a great deal about the stroke just drawn, too much"

    def on_enter_done(self) -> None:
        if self.n > 1:  # not a plain statement: no text of its own
            self.note = "again"


def test_a_method_without_a_declaration_reads_as_its_own_statements() -> None:
    text = action_text(Pen, "during_down")
    assert text is not None and not text.declared
    assert text.full == "move(speed * 2)"  # self. dropped, the private helper by its name
    assert state_actions(Pen.structure().state("down"), Pen) == ["du: move(speed * 2)"]
    assert action_text(Pen, "on_enter_done") is None  # an `if`: the diagram shows the name
    assert state_actions(Pen.structure().state("done"), Pen) == ["en: on_enter_done"]


def test_a_declared_summary_is_drawn_and_the_whole_text_kept() -> None:
    text = action_text(Pen, "finish")
    assert text is not None and text.declared and not text.short
    assert text.lines == ("n = n + 1 …",)
    t = next(t for t in Pen.structure().transitions if t.source == "down")
    assert edge_text(t, Pen.structure(), Pen) == ("[X_out <= tx]", "/ n = n + 1 …")
    assert edge_text(t, Pen.structure(), Pen, full=True)[1] == "/ " + text.full


def test_does_leaves_the_method_as_it_was() -> None:
    pen = Pen(tick_period_s=0.002)
    pen.X_out = -0.0099
    for _ in range(3):
        pen.tick()
    assert pen.configuration_values == {"done"} and pen.n == 1
    assert math.isclose(pen.X_out, -0.01)
    with pytest.raises(ValueError, match="empty"):
        does("  ")


def test_unknown_names_are_those_neither_data_nor_documented_helpers() -> None:
    assert unknown_names(Pen, "X_out = max(X_out_p - speed*dt, tx) (eq. 3.40)") == []
    assert unknown_names(Pen, "move(speed); note = 'any words here'") == []
    assert unknown_names(Pen, "X_out = Y_out + inc") == ["Y_out", "inc"]
    assert unknown_names(Pen, "tx_p = 0") == ["tx_p"]  # only an output has a previous value


def test_statements_split_at_semicolons_outside_quotes_and_brackets() -> None:
    assert statements("a = 1; b = f(x; y); c = 'p; q'") == ["a = 1", "b = f(x; y)", "c = 'p; q'"]


def test_a_long_statement_without_a_summary_is_cut_on_the_picture() -> None:
    class Long(Pen):
        @does("X_out = " + " + ".join(["speed"] * 20))
        def during_down(self) -> None:
            self.X_out = 20 * self.speed

    text = action_text(Long, "during_down")
    assert text is not None and len(text.lines) == 1 and text.lines[0].endswith(" …")
    assert len(text.lines[0]) <= MAX_CHARS + 2 and text.full.startswith(text.lines[0][:-2])
