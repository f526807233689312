"""Every action of every packaged chart says on its diagram what it does, in the chart's own data."""

from __future__ import annotations

import pytest

from ttt_sm.charts import ALL_CHARTS
from ttt_sm.runtime.action_text import action_text, unknown_names


def _actions(cls: type) -> list[tuple[str, str]]:
    """(where, action name) of every entry, during, exit, condition and transition action of a chart."""
    structure = cls.structure()
    found = []
    for s in structure.states:
        for kind in ("entry", "during", "exit"):
            found += [(f"{kind} of {s.id}", name) for name in getattr(s, kind)]
    for t in structure.transitions:
        for name in t.condition_actions + t.transition_actions + t.after_actions:
            found.append((f"{t.source} -> {t.target}", name))
    return found


@pytest.mark.parametrize("cls", ALL_CHARTS, ids=lambda c: c.__name__)
def test_every_action_has_a_text_naming_only_the_charts_data_and_documented_helpers(cls: type) -> None:
    actions = _actions(cls)
    assert actions, f"{cls.__name__} has no actions"
    problems = []
    for where, name in actions:
        text = action_text(cls, name)
        if text is None or not (text.declared or text.short):
            problems.append(f"{where}: {name} has no text short enough to draw (declare one with @does)")
            continue
        unknown = unknown_names(cls, text.full + "; " + "; ".join(text.lines))
        if unknown:
            problems.append(f"{where}: {name} names {', '.join(unknown)}: neither data nor a documented helper")
    assert not problems, "\n".join(problems)
