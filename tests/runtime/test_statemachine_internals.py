"""The python-statemachine internals the runtime relies on are still there, with the shape it expects.

The chart runtime's quiet-tick fast path (``ttt_sm.runtime.chart`` and
``ttt_sm.runtime.guards``) and its structure reader (``ttt_sm.runtime.structure``)
use parts of python-statemachine that are not its public API.  pyproject.toml
pins the minor series they were written against; when a new release changes
one of them, the test named after it fails and says what changed and what to do.
"""

from __future__ import annotations

import inspect
import tomllib
from collections.abc import Callable, MutableSet
from importlib import metadata
from pathlib import Path

import pytest
from packaging.requirements import Requirement
from statemachine import State, StateChart

PYPROJECT = Path(__file__).resolve().parents[2] / "pyproject.toml"
VERSION = metadata.version("python-statemachine")


def advice(internal: str, user: str, found: str) -> str:
    return (f"python-statemachine {VERSION} changed {internal}, which {user} relies on: {found}. "
            "Either install the series pyproject.toml pins, or adapt that code (and this test) to the new "
            "release and move the pin.")


class Lamp(StateChart):
    """A plain library chart: the internals are read off its classes and an instance."""

    off = State(initial=True)
    on = State()
    done = State(final=True)
    switch = off.to(on, cond="power") | on.to(off, unless="power")
    finish = on.to(done, cond=["power", "ready"])
    power = True

    @property
    def ready(self) -> bool:
        return True


def _always() -> bool:
    return True


class Gate(StateChart):
    """A chart with a plain function as its guard."""

    closed = State(initial=True)
    opened = State(final=True)
    open = closed.to(opened, cond=_always)


def _transition(source: State, target: State):
    return next(t for t in source.transitions if t.target is target)


def check_the_installed_version_is_in_the_pinned_series() -> None:
    deps = tomllib.loads(PYPROJECT.read_text(encoding="utf-8"))["project"]["dependencies"]
    req = next(Requirement(d) for d in deps if Requirement(d).name == "python-statemachine")
    assert req.specifier.contains(VERSION), (
        f"python-statemachine {VERSION} is installed but pyproject.toml pins {req.specifier}: the runtime "
        "uses internals of the pinned series; install it (make setup) or adapt the runtime and move the pin")
    assert any(s.operator == "<" for s in req.specifier), (
        f"pyproject.toml must cap python-statemachine to a minor series (found {req.specifier}): "
        "the runtime uses its internals")


def check_the_configuration_lives_on_the_model() -> None:
    chart = Lamp()
    d = chart.__dict__
    assert "model" in d and isinstance(d.get("state_field"), str), advice(
        "the instance's __dict__ keys 'model' and 'state_field'", "TickChart.tick (the per-tick plan cache)",
        f"instance keys are {sorted(d)}")
    raw = getattr(d["model"], d["state_field"])
    assert raw == "off" or (isinstance(raw, MutableSet) and set(raw) == {"off"}), advice(
        "the raw configuration getattr(model, state_field)", "TickChart.tick",
        f"it is {raw!r}, not a state id or a set of ids")
    chart.send("switch")
    assert getattr(d["model"], d["state_field"]) in ("on", {"on"}), advice(
        "the raw configuration after a transition", "TickChart.tick", "it did not follow the transition")


def check_each_instance_keeps_its_states_in_its_dict() -> None:
    chart = Lamp()
    assert isinstance(chart.__dict__.get("off"), State) and chart.__dict__["off"].id == "off", advice(
        "the per-instance copies of the states in the instance's __dict__",
        "TickChart's state-name descriptors (_StateName)", f"__dict__['off'] is {chart.__dict__.get('off')!r}")
    assert isinstance(Lamp._events, dict) and "switch" in Lamp._events, advice(  # type: ignore[attr-defined]
        "the chart class's _events mapping", "TickChartMeta (names that are events keep their descriptor)",
        f"_events is {getattr(Lamp, '_events', None)!r}")


def check_the_metaclass_and_setattr_can_be_taken_over() -> None:
    from statemachine.factory import StateMachineMetaclass

    assert isinstance(Lamp, StateMachineMetaclass), advice(
        "statemachine.factory.StateMachineMetaclass", "TickChartMeta", "it is no longer the charts' metaclass")
    assert StateChart.__setattr__ is not object.__setattr__, advice(
        "StateChart.__setattr__", "TickChart (which replaces it with plain assignment and protects state "
        "names by descriptors instead)", "StateChart no longer defines its own; check what protects state names")


def check_guard_specs_have_the_fields_the_compiler_reads() -> None:
    from statemachine.callbacks import SpecReference

    specs = list(_transition(Lamp.on, Lamp.done).cond)
    assert [str(s) for s in specs] == ["power", "ready"], advice(
        "iterating a transition's cond", "runtime.guards.compile_guard", f"it yields {specs!r}")
    for spec in specs:
        for field in ("reference", "func", "attr_name", "expected_value", "lookup_name"):
            assert hasattr(spec, field), advice(f"CallbackSpec.{field}", "runtime.guards._compile_spec",
                                                f"{type(spec).__name__} has no {field}")
    assert specs[0].reference is SpecReference.NAME, advice("SpecReference.NAME", "runtime.guards._compile_spec",
                                                            f"a name guard has reference {specs[0].reference}")
    unless = next(iter(_transition(Lamp.on, Lamp.off).cond))
    assert unless.expected_value is False, advice("CallbackSpec.expected_value of an unless= guard",
                                                  "runtime.guards._compile_spec", f"it is {unless.expected_value!r}")
    assert {SpecReference.CALLABLE, SpecReference.PROPERTY} <= set(SpecReference), advice(
        "SpecReference", "runtime.guards._compile_spec", f"members are {list(SpecReference)}")
    callable_spec = next(iter(_transition(Gate.closed, Gate.opened).cond))
    assert callable_spec.reference is SpecReference.CALLABLE and hasattr(callable_spec, "is_bounded"), advice(
        "CallbackSpec.is_bounded of a callable guard", "runtime.guards._compile_callable", "it is missing")


def check_the_library_guard_evaluation_still_takes_these_arguments() -> None:
    from statemachine.event_data import EventData, TriggerData

    chart = Lamp()
    transition = _transition(Lamp.off, Lamp.on)
    key = transition.cond.key
    kwargs = EventData(trigger_data=TriggerData(machine=chart, event=None), transition=transition).extended_kwargs
    assert isinstance(kwargs, dict) and "machine" in kwargs, advice(
        "EventData(trigger_data=TriggerData(machine, event), transition).extended_kwargs",
        "runtime.guards._library_guard", f"it gave {kwargs!r}")
    result = chart._callbacks.all(key, **kwargs)
    assert result is True, advice("StateChart._callbacks.all(transition.cond.key, **kwargs)",
                                  "runtime.guards._library_guard", f"it returned {result!r} for a guard that holds")


def check_the_boolean_expression_parser() -> None:
    from statemachine.spec_parser import operator_mapping, parse_boolean_expr, replace_operators

    names: dict[str, Callable[..., bool]] = {"a": lambda *a, **k: True, "b": lambda *a, **k: False}
    expr = replace_operators("a and not b")
    compiled = parse_boolean_expr(expr, lambda name: names[name], operator_mapping)
    assert compiled() is True, advice("statemachine.spec_parser (parse_boolean_expr, replace_operators, "
                                      "operator_mapping)", "runtime.guards._compile_expression",
                                      f"'a and not b' compiled to {compiled!r}, which gave {compiled()!r}")


def check_the_engine_gives_the_transition_domain() -> None:
    chart = Lamp()
    get_domain = getattr(getattr(chart, "_engine", None), "get_transition_domain", None)
    assert callable(get_domain), advice("StateChart._engine.get_transition_domain",
                                        "runtime.structure.states_entered_by (coverage, traces)", "it is missing")
    assert len(inspect.signature(get_domain).parameters) == 1, advice(
        "StateChart._engine.get_transition_domain's signature", "runtime.structure.states_entered_by",
        f"it is {inspect.signature(get_domain)}")


def check_humanize_id() -> None:
    from statemachine.utils import humanize_id

    assert humanize_id("turn_back") == "Turn back", advice(
        "statemachine.utils.humanize_id", "runtime.structure (state names in diagrams)",
        f"'turn_back' became {humanize_id('turn_back')!r}")


CHECKS = [check for name, check in sorted(globals().items()) if name.startswith("check_")]


@pytest.mark.parametrize("check", CHECKS, ids=[c.__name__.removeprefix("check_") for c in CHECKS])
def test_internal(check: Callable[[], None]) -> None:
    check()


def test_a_changed_internal_is_named_with_what_to_do(monkeypatch):
    """What a reader sees when a release moves one: the internal, who uses it, what to do."""
    import statemachine.utils

    monkeypatch.setattr(statemachine.utils, "humanize_id", lambda s: s)
    with pytest.raises(AssertionError) as failed:
        check_humanize_id()
    message = str(failed.value)
    assert message.startswith(f"python-statemachine {VERSION} changed statemachine.utils.humanize_id, which "
                              "runtime.structure (state names in diagrams) relies on: 'turn_back' became 'turn_back'")
    assert "install the series pyproject.toml pins" in message
