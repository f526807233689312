"""The parameter loader under fuzz: any bytes, damaged TOML and wrong values give ParameterError only.

What loads is within every documented limit; what does not gets one line
naming the file (and the key).  docs/reliability.md has the numbers of the
last runs.
"""

from __future__ import annotations

import copy
import datetime
import math
import tempfile
import tomllib
from importlib import resources
from pathlib import Path
from typing import Any

from hypothesis import strategies as st

from fuzzing import fuzz, one_line
from ttt_sm.params import LIMITS, ArmParams, ParameterError, load_params, parse_params

TEXT = resources.files("ttt_sm.data").joinpath("arm.toml").read_text()
DOC = tomllib.loads(TEXT)
KEYS = [(table,) for table in DOC if table != "drive"] + [("drive", n) for n in DOC["drive"]]
VALUE_KEYS = [(*table, key) for table in KEYS for key in
              (DOC[table[0]] if len(table) == 1 else DOC["drive"][table[1]])]


def sane(params: ArmParams) -> None:
    """What loaded keeps every limit: the check at load did its job."""
    for name, (lo, hi) in LIMITS.items():
        family, key = name.split(".")
        for obj in params.drives if family == "drive" else (getattr(params, family),):
            value = getattr(obj, key)
            assert math.isfinite(value) and lo <= value <= hi, (name, value)


def load_file(data: bytes) -> None:
    with tempfile.TemporaryDirectory() as d:
        f = Path(d) / "arm.toml"
        f.write_bytes(data)
        try:
            params = load_params(f)
        except ParameterError as exc:
            one_line(str(exc), str(f))
            return
    sane(params)


def parse_doc(doc: dict[str, Any]) -> None:
    try:
        params = parse_params(doc, "fuzz.toml")
    except ParameterError as exc:
        one_line(str(exc), "fuzz.toml")
        return
    sane(params)


def table_of(doc: dict[str, Any], key: tuple[str, ...]) -> dict[str, Any]:
    return doc[key[0]] if len(key) == 2 else doc["drive"][key[1]]


# -- any bytes ---------------------------------------------------------------------------------

test_any_bytes_give_a_parameter_error, test_any_bytes_give_a_parameter_error_soak = fuzz(
    st.binary(max_size=3000))(load_file)

# -- the packaged file, damaged by a few edits -------------------------------------------------

_PIECES = st.one_of(st.sampled_from(["=", "[", "]", "[[", '"', "'", ".", ",", "#", "\n", " ", "-", "+", "e",
                                     "inf", "nan", "1e999", "0", "0.0", "true", "{", "}", "\x00", "\r",
                                     "drive.4", "L2", "[geometry]", "_deg", "9" * 40, "é", "\ud7ff"]),
                    st.text(max_size=6))
_EDITS = st.lists(st.tuples(st.integers(0, len(TEXT)), st.integers(0, 8), _PIECES), min_size=1, max_size=4)


def damaged(edits: list[tuple[int, int, str]]) -> None:
    text = TEXT
    for at, cut, piece in edits:
        at = min(at, len(text))
        text = text[:at] + piece + text[at + cut:]
    load_file(text.encode("utf-8", "surrogatepass"))


test_damaged_files_give_a_parameter_error, test_damaged_files_give_a_parameter_error_soak = fuzz(
    _EDITS)(damaged)

# -- one value replaced by anything TOML can hold ----------------------------------------------

_TOML_VALUES = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True), st.integers(min_value=-(10**400), max_value=10**400),
    st.booleans(), st.text(max_size=20), st.lists(st.integers(), max_size=3),
    st.dictionaries(st.text(max_size=5), st.integers(), max_size=2),
    st.datetimes(min_value=datetime.datetime(1, 1, 1)), st.dates(), st.times())


def replaced(key: tuple[str, ...], value: Any) -> None:
    doc = copy.deepcopy(DOC)
    table_of(doc, key)[key[-1]] = value
    parse_doc(doc)


test_any_value_gives_a_parameter_error, test_any_value_gives_a_parameter_error_soak = fuzz(
    st.sampled_from(VALUE_KEYS), _TOML_VALUES)(replaced)

# -- plausible numbers, scaled: the physics checks (limits, relations, reach) -----------------

#: The keys whose values are numbers (a text such as ``[tuning] preset`` is not scaled).
NUMBER_KEYS = [k for k in VALUE_KEYS if isinstance(table_of(DOC, k)[k[-1]], (int, float))
               and not isinstance(table_of(DOC, k)[k[-1]], bool)]

_FACTORS = st.one_of(st.floats(-3.0, 3.0), st.sampled_from([0.0, -1.0, 0.5, 1.5, 2.0, 10.0, 1e-3, 1e3]))


def scaled(changes: list[tuple[tuple[str, ...], float]]) -> None:
    doc = copy.deepcopy(DOC)
    for key, factor in changes:
        table = table_of(doc, key)
        value = table[key[-1]]
        table[key[-1]] = type(value)(value * factor) if isinstance(value, float) else round(value * factor)
    parse_doc(doc)


test_scaled_values_load_sane_or_give_a_parameter_error, \
    test_scaled_values_load_sane_or_give_a_parameter_error_soak = fuzz(
        st.lists(st.tuples(st.sampled_from(NUMBER_KEYS), _FACTORS), min_size=1, max_size=3))(scaled)
