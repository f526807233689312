"""The scenario loader under fuzz: any bytes, any YAML data, damaged files give ScenarioError only.

Each loads to a Scenario or is refused with one line per mistake, naming the file and
line, within the limits of docs/reliability.md.
"""

from __future__ import annotations

import tempfile
from pathlib import Path
from typing import Any

import yaml
from hypothesis import strategies as st

from fuzzing import fuzz, one_line
from ttt_sm.scenario import ScenarioError, load_scenario, load_scenario_text
from ttt_sm.scenario.loader import TOP_KEYS
from ttt_sm.scenario.steps import STEP_OPTIONS

FOLDER = Path(__file__).resolve().parents[1] / "scenarios"
FILES = {f.name: f.read_text() for f in sorted(FOLDER.glob("*.yaml"))}
_WORDS = sorted({*TOP_KEYS, *STEP_OPTIONS, "chart", "event", "data", "sequence", "match", "condition", "timeout_s",
                 "within_s", "for_s", "seconds", "chart_steps", "entered", "active", "q_deg", "settle_s", "force",
                 "exact", "subsequence"})
_NAMES = st.sampled_from(["DriveInit1", "DriveInit1.stop", "DriveInit1.turn_back", "DriveInit1.ini_23", "Control",
                          "Game", "AlgorithmActivator", "q_true[1]", "t > 1", "t >", "DriveInit1.pos_Encoder > 1deg",
                          "Nope.x", "a.b.c", "button", "run", "on", "off", "yes", "null", "~", "<<"])
_SCALARS = st.one_of(st.none(), st.booleans(), st.integers(-(10**30), 10**30), st.floats(allow_nan=True),
                     st.text(max_size=12), _NAMES, st.sampled_from(_WORDS))
_DATA = st.recursive(_SCALARS, lambda inner: st.one_of(
    st.lists(inner, max_size=4), st.dictionaries(st.one_of(st.sampled_from(_WORDS), _NAMES, st.text(max_size=6)),
                                                 inner, max_size=4)), max_leaves=25)
_STEPS = st.lists(st.dictionaries(st.sampled_from(_WORDS), _DATA, min_size=1, max_size=2), max_size=6)
_DOCS = st.fixed_dictionaries({"name": _SCALARS, "steps": _STEPS},
                              optional={k: _DATA for k in ("description", "seed", "start", "chart", "charts",
                                                           "max_step_s", "extra")})


def load_text(text: str) -> None:
    try:
        load_scenario_text(text, "fuzz.yaml")
    except ScenarioError as exc:
        for mistake in exc.errors:  # a file with several mistakes: one line each
            one_line(str(mistake), "fuzz.yaml")


def load_bytes(data: bytes) -> None:
    with tempfile.TemporaryDirectory() as d:
        f = Path(d) / "fuzz.yaml"
        f.write_bytes(data)
        try:
            load_scenario(f)
        except ScenarioError as exc:
            for mistake in exc.errors:
                one_line(str(mistake), str(f))


def load_data(doc: dict[str, Any]) -> None:
    load_text(yaml.safe_dump(doc, allow_unicode=True))


_PIECES = st.one_of(st.sampled_from([":", "- ", "[", "]", "{", "}", ",", "&a ", "*a", "!!python/object:os.system",
                                     "!!binary", "'", '"', "#", "\n", "\t", "  ", "\x00", "\ufeff", "1e12", "nan",
                                     "timeout_s: 1.0e+12", "<<: *a", "---\n", "...\n", "%YAML 1.1\n"]),
                    st.text(max_size=5))
_EDITS = st.tuples(st.sampled_from(sorted(FILES)),
                   st.lists(st.tuples(st.integers(0, 4000), st.integers(0, 10), _PIECES), min_size=1, max_size=4))


def damaged(case: tuple[str, list[tuple[int, int, str]]]) -> None:
    name, edits = case
    text = FILES[name]
    for at, cut, piece in edits:
        at = min(at, len(text))
        text = text[:at] + piece + text[at + cut:]
    load_text(text)


test_any_bytes_give_a_scenario_error, test_any_bytes_give_a_scenario_error_soak = fuzz(
    st.binary(max_size=3000))(load_bytes)

test_any_yaml_data_gives_a_scenario_or_a_scenario_error, \
    test_any_yaml_data_gives_a_scenario_or_a_scenario_error_soak = fuzz(_DOCS)(load_data)

test_damaged_scenario_files_give_a_scenario_error, test_damaged_scenario_files_give_a_scenario_error_soak = fuzz(
    _EDITS)(damaged)
