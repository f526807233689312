"""The condition language under fuzz: any text parses to an Expression or an ExprError, and
whatever parses evaluates to a value or an ExprError, in bounded time and memory."""

from __future__ import annotations

import math

import pytest
from hypothesis import strategies as st

from fuzzing import fuzz, one_line
from ttt_sm.runtime.conditions import FUNCTIONS, KEYWORDS, MAX_CONDITION_CHARS, UNITS, ExprError, parse

# Words of the language and pieces that sit near its edges, joined into token soup.
_TOKENS = st.one_of(
    st.sampled_from(["(", ")", "[", "]", ".", ",", "+", "-", "*", "/", "==", "!=", "<", "<=", ">", ">=",
                     "=", "&", "|", "!", '"', "'", "1", "0", "2.5", ".5", "1e308", "1e-400", "1" + "0" * 400,
                     "9" * 30, '"text"', "'x'", "t", "q_true", "DriveInit1", "ini_23", "Chart.name", "q_true[1]",
                     "a.b.c", "٣", "é", "\x00", "\n", " ", "(" * 45, "(" * 150, ")" * 150, "- " * 120,
                     "not " * 120, "abs(" * 45, "1 +" * 45, '"x" * 99999999999', *sorted(KEYWORDS), *FUNCTIONS,
                     *UNITS]),
    st.text(max_size=4))
SOUP = st.lists(_TOKENS, max_size=60).map(" ".join)
VALUES = st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.integers(-(10**30), 10**30),
                   st.booleans(), st.text(max_size=5), st.none())


def parse_and_evaluate(text: str, values: st.DataObject) -> None:
    try:
        expr = parse(text)
    except ExprError as exc:
        one_line(str(exc).replace("\n", " "), "")
        assert len(str(exc)) < MAX_CONDITION_CHARS + 200
        return
    try:
        expr.evaluate(lambda ref: values.draw(VALUES, label=str(ref)))
    except ExprError:
        pass


test_any_text_parses_or_gives_an_expr_error, test_any_text_parses_or_gives_an_expr_error_soak = fuzz(
    st.text(max_size=MAX_CONDITION_CHARS + 50), st.data())(parse_and_evaluate)

test_token_soup_parses_and_evaluates_or_gives_an_expr_error, \
    test_token_soup_parses_and_evaluates_or_gives_an_expr_error_soak = fuzz(
        SOUP, st.data())(parse_and_evaluate)


@pytest.mark.parametrize("text", ['"x" * 1000000000', "'ab' + 'cd'", "1" + "0" * 400 + " / 3",
                                  "-'x'", "abs('x')", "min('a', 1)"])
def test_arithmetic_on_text_or_beyond_floats_is_an_expr_error_not_a_memory_bomb(text):
    with pytest.raises(ExprError, match=r"cannot compute|abs\(\)|min\(\)"):
        parse(text).evaluate(lambda ref: 0)


def test_arithmetic_on_numbers_still_overflows_to_infinity_as_floats_do():
    assert parse("1e308 * 10").evaluate(lambda ref: 0) == math.inf
