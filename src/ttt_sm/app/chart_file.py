"""Load a chart class from a student's file: ``path/to/file.py:ClassName``.

Loading a file runs the student's code.  It is imported from its path under a
module name of its own (never one a second file could share), and whatever
goes wrong is one :class:`ChartFileError` whose message is one line starting
with ``file:line``: a syntax error, an import that fails, a chart definition
python-statemachine or the runtime refuses (``InvalidDefinition``,
:class:`~ttt_sm.runtime.errors.ChartDefinitionError`), any other exception
the module raises while it loads, a class that is not there.
"""

from __future__ import annotations

import importlib.util
import inspect
import itertools
import sys
import traceback
from pathlib import Path
from types import ModuleType

from ..params import shown_path
from ..runtime import TickChart
from .slots import ChartSlots, SlotError, slot

_SERIAL = itertools.count(1)


class ChartFileError(ValueError):
    """A chart file that cannot be loaded, or a class that is not there: one line, ``file:line: ...``."""


def _one_line(text: str) -> str:
    return " ".join(str(text).split())


def _where_in(path: Path, exc: BaseException) -> int:
    """The line of `path` nearest to where `exc` was raised (the deepest frame in that file), else 1."""
    if isinstance(exc, SyntaxError) and exc.filename and Path(exc.filename).resolve() == path:
        return exc.lineno or 1
    line = 0
    for frame in traceback.extract_tb(exc.__traceback__):
        if frame.filename and Path(frame.filename).resolve() == path:
            line = frame.lineno or line
    return line or 1


def load_module(path: str | Path) -> ModuleType:
    """Import the Python file at `path` under a fresh module name; a :class:`ChartFileError` if it fails."""
    file = Path(path)
    shown = shown_path(file)
    if file.suffix != ".py":
        raise ChartFileError(f"{shown}: a chart file is a Python file (.py)")
    if not file.is_file():
        raise ChartFileError(f"{shown}: no such file")
    resolved = file.resolve()
    name = f"ttt_sm_chart_{resolved.stem}_{next(_SERIAL)}"
    spec = importlib.util.spec_from_file_location(name, resolved)
    assert spec is not None and spec.loader is not None  # a .py path always has one
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # dataclasses and typing look the module up while it runs
    try:
        spec.loader.exec_module(module)
    except SyntaxError as exc:
        sys.modules.pop(name, None)
        raise ChartFileError(f"{shown}:{_where_in(resolved, exc)}: syntax error: {_one_line(exc.msg)}") from None
    except Exception as exc:  # the student's code: anything it raises is reported, in one line
        sys.modules.pop(name, None)
        kind = type(exc).__name__
        raise ChartFileError(f"{shown}:{_where_in(resolved, exc)}: {kind}: {_one_line(str(exc)) or kind}") from None
    return module


def class_line(cls: type) -> int:
    """The line a class statement starts on (1 when its source cannot be read)."""
    try:
        return inspect.getsourcelines(cls)[1]
    except (OSError, TypeError):
        return 1


def load_chart(path: str | Path, class_name: str) -> tuple[type[TickChart], str]:
    """The class `class_name` of the file at `path`, and where it is written (``file:line``)."""
    module = load_module(path)
    shown = shown_path(Path(path))
    cls = getattr(module, class_name, None)
    if cls is None:
        charts = sorted(n for n, v in vars(module).items()
                        if isinstance(v, type) and issubclass(v, TickChart) and v.states)
        raise ChartFileError(f"{shown}:1: no class {class_name!r} in the file;"
                             f" charts there: {', '.join(charts) or '(none)'}")
    line = class_line(cls) if getattr(cls, "__module__", None) == module.__name__ else 1
    return cls, f"{shown}:{line}"


def parse_choice(text: str) -> tuple[str, str, str]:
    """``SLOT=path/to/file.py:ClassName`` as (slot, path, class name); a :class:`ChartFileError` if malformed."""
    slot_name, eq, rest = text.partition("=")
    path, colon, class_name = rest.rpartition(":")
    if not eq or not colon or not slot_name or not path or not class_name.isidentifier():
        raise ChartFileError(f"--chart {text!r}: expected SLOT=path/to/file.py:ClassName,"
                             " e.g. DriveInit3=my_init.py:MyDriveInit3")
    return slot_name.strip(), path, class_name


def slots_from(choices: list[str], base: ChartSlots | None = None) -> ChartSlots:
    """Slots with each ``SLOT=file.py:Class`` of `choices` loaded and checked against its slot's contract."""
    slots = base or ChartSlots()
    for text in choices:
        slot_name, path, class_name = parse_choice(text)
        if slot_name in slots.chosen:
            raise SlotError(f"--chart {text!r}: slot {slot_name} is given twice")
        slot(slot_name)  # an unknown slot before the student's code runs
        cls, where = load_chart(path, class_name)
        slots = slots.with_chart(slot_name, cls, where)
    return slots
