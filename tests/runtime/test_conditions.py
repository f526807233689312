"""The condition language of scenarios and debugger breakpoints: parsed, never eval-ed."""

from __future__ import annotations

import math

import pytest

from ttt_sm.runtime.conditions import ExprError, Ref, parse

VALUES = {
    "DriveInit1.ini_23": True,
    "DriveInit1.pos_Encoder": 1.5,
    "DriveInit2.travel": 0.25,
    "t": 3.0,
    "q_true[1]": -1.0,
    "q_true[2]": 0.5,
}


def ev(text: str) -> object:
    return parse(text).evaluate(lambda ref: VALUES[str(ref)])


@pytest.mark.parametrize("text, expected", [
    ("1 + 2 * 3", 7),
    ("(1 + 2) * 3", 9),
    ("-2 - -3", 1),
    ("7 / 2", 3.5),
    ("true and not false", True),
    ("false or true and false", False),  # and binds tighter than or
    ("not 1 > 2", True),  # not binds looser than a comparison
    ("0 < DriveInit1.pos_Encoder < 2", True),  # chained, as in Python
    ("0 < DriveInit1.pos_Encoder < 1", False),
    ("DriveInit1.ini_23 == true", True),
    ("DriveInit1.ini_23 != True", False),
    ("abs(q_true[1]) == 1", True),
    ("min(q_true[1], q_true[2], 0) == -1", True),
    ("max(t, 4) == 4", True),
    ("1e-3 * 1000 == 1", True),
    (".5 == 0.5", True),
    ("t > 2 and DriveInit2.travel <= 0.25", True),
])
def test_evaluates_like_python(text: str, expected: object) -> None:
    assert ev(text) == expected


def test_numbers_carry_units_converted_to_si() -> None:
    assert ev("180deg") == pytest.approx(math.pi)
    assert ev("180 deg") == pytest.approx(math.pi)
    assert ev("20mm") == pytest.approx(0.02)
    assert ev("5ms") == pytest.approx(0.005)
    assert ev("2 rad + 1m + 1s") == 4
    assert ev("q_true[1] < -45deg") is True


def test_a_name_compared_with_numbers_of_one_unit_is_read_in_that_unit() -> None:
    q1, stop = Ref(None, "q_true", 1), Ref("DriveInit1", "stop")
    assert parse("q_true[1] > 175deg").unit_of(q1) == "deg"
    assert parse("abs(q_true[1] - -45deg) < 1deg").unit_of(q1) == "deg"
    assert parse("DriveInit1.stop or q_true[1] > 20 mm").unit_of(q1) == "mm"
    assert parse("DriveInit1.stop or q_true[1] > 20 mm").unit_of(stop) is None  # in no comparison
    assert parse("q_true[1] > 1rad + 10deg").unit_of(q1) is None  # two units: as held, SI
    assert parse("q_true[1] > 3").unit_of(q1) is None
    assert parse("q_true[1] > 3 and q_true[2] < 5deg").unit_of(q1) is None  # each comparison on its own


def test_references_are_listed_with_their_column() -> None:
    expr = parse("DriveInit1.stop or q_true[2] > t")
    assert expr.refs == (Ref("DriveInit1", "stop", None, 1), Ref(None, "q_true", 2, 20),
                         Ref(None, "t", None, 32))
    assert [str(r) for r in expr.refs] == ["DriveInit1.stop", "q_true[2]", "t"]


def test_bind_asks_for_each_getter_once() -> None:
    asked: list[str] = []
    box = {"x": 1.0}

    def get(ref: Ref):
        asked.append(str(ref))
        return lambda: box["x"]

    f = parse("C.x > 0 and C.x < 2").bind(get)
    assert asked == ["C.x", "C.x"]
    assert f() is True
    box["x"] = 3.0
    assert f() is False
    assert asked == ["C.x", "C.x"]


def test_and_or_short_circuit() -> None:
    def get(ref: Ref):
        if ref.name == "boom":
            def boom() -> bool:
                raise AssertionError("evaluated")
            return boom
        return lambda: False
    assert parse("C.off and C.boom").bind(get)() is False
    assert parse("not C.off or C.boom").bind(get)() is True


@pytest.mark.parametrize("text, message, column", [
    ("", "empty condition", 1),
    ("DriveInit1.pos_Encoder >> 1", "expected a number, a name or '('", 25),
    ("x = 1", "use == to compare", 3),
    ("a && b", "use 'and'", 3),
    ("(1 + 2", "expected ')'", 7),
    ("1 2", "unexpected '2'; expected 'and', 'or', an operator or the end", 3),
    ("C.x > 1 )", "unexpected ')'", 9),
    ("sqrt(2)", "unknown function 'sqrt'", 1),
    ("abs(1, 2)", "abs() takes 1 argument(s), got 2", 1),
    ("min(1)", "min() takes 2 or more arguments", 1),
    ("q_true[x]", "expected an element number (1, 2, ...) inside [ ], found 'x'", 8),
    ("q_true[1.5]", "found '1.5'", 8),
    ("q_true[1", "expected ']'", 9),
    ("5 furlongs", "unknown unit 'furlongs'", 3),
    ("DriveInit1.", "expected a datum or state name", 12),
    ("DriveInit1.pos.x > 1", "a name has one dot at most (Chart.name): DriveInit1.pos is followed by '.'", 15),
    ("and 1", "'and' needs something before it", 1),
    ("__import__('os')", "unknown function '__import__'", 1),
    ("C.message == 'You win.", "unexpected character \"'\" (text in quotes ends with the quote it starts"
                               " with)", 14),
    ('"a\' == 1', "text in quotes ends with the quote it starts with", 1),
    # found by the soak fuzz: a whole number beyond any float with a unit raised OverflowError
    ("1" + "0" * 400 + " deg", "a number of 401 digits in deg is too large", 1),
])
def test_syntax_errors_name_the_column(text: str, message: str, column: int) -> None:
    with pytest.raises(ExprError) as info:
        parse(text)
    assert message in str(info.value)
    assert info.value.column == column


def test_the_message_says_the_column_and_quotes_the_condition() -> None:
    with pytest.raises(ExprError) as info:
        parse("C.x > > 1")
    assert str(info.value) == "expected a number, a name or '(', found '>' at column 7 in 'C.x > > 1'"
    assert (info.value.message, info.value.text) == ("expected a number, a name or '(', found '>'", "C.x > > 1")


@pytest.mark.parametrize("text, refs", [
    ("C.x", [Ref("C", "x", None, 1)]),
    ("C . x [ 2 ]", [Ref("C", "x", 2, 1)]),  # spaces between tokens; an index is the caller's to check
    ("q_true[1]>0", [Ref(None, "q_true", 1, 1)]),
    ("(t)", [Ref(None, "t", None, 2)]),
    ("1. + .5e1 + 2E-3 + 170 deg", []),
    ("not not true", []),
    ("'and' == \"or\"", []),  # keywords in quotes are text
])
def test_accepted_forms_and_the_names_they_read(text: str, refs: list[Ref]) -> None:
    assert list(parse(text).refs) == refs


def test_names_are_identifiers_as_in_python() -> None:
    assert parse("Δq_1 > 0 and Chart_2.x_y").refs == (Ref(None, "Δq_1", None, 1), Ref("Chart_2", "x_y", None, 14))
    with pytest.raises(ExprError, match="unknown unit '_x'"):
        parse("1_x")  # a name cannot start with a digit: 1 then an unknown unit


def test_nothing_is_executed() -> None:
    # Attribute access beyond Chart.name, calls of anything but the listed functions, indexing text: refused.
    for text in ("C.x.y", "open(1)", "C.__class__()", "'a'.upper()", "'a'[0]", "[1][0]", "'os'()"):
        with pytest.raises(ExprError):
            parse(text)


def test_text_in_quotes_is_a_constant_compared_with_text_data() -> None:
    message = "The manipulator is drawing."

    def ev_text(text: str) -> object:
        return parse(text).evaluate(lambda ref: {"Game.message": message}[str(ref)])
    assert ev_text('Game.message == "The manipulator is drawing."') is True
    assert ev_text("Game.message == 'The manipulator is drawing.'") is True
    assert ev_text('Game.message != "The manipulator is drawing"') is True  # exact: the full stop counts
    assert ev_text("'Draw: the board is full.' == \"Draw: the board is full.\"") is True
    assert ev_text("'' == \"\"") is True
    assert parse("Game.message == 'and or not 1 + C.x'").refs == (Ref("Game", "message", None, 1),)
    with pytest.raises(ExprError, match="cannot compare"):
        ev_text("Game.message < 1")
    with pytest.raises(ExprError, match="cannot compute '-'"):
        ev_text("-Game.message")


def test_runtime_errors_are_expr_errors() -> None:
    with pytest.raises(ExprError, match="cannot compute '/'"):
        ev("t / 0")
    with pytest.raises(ExprError, match="not a condition|a condition is text"):
        parse(3)  # type: ignore[arg-type]
