"""YAML with line numbers: a ``SafeLoader`` whose mappings and lists remember where they were.

Scenario errors must name ``FILE:LINE``.  :class:`MarkedLoader` is PyYAML's
``SafeLoader`` (no Python objects, only plain data) that builds
:class:`MarkedDict` and :class:`MarkedList` instead of ``dict`` and ``list``:
the same values, plus the line of every key, value and list item.  It also
refuses a key given twice in one mapping, which plain YAML silently accepts
(the second ``set:`` of a step would hide the first), and reads booleans as
YAML 1.2 does: only ``true`` and ``false`` (``on``, ``off``, ``yes``, ``no``
stay text: they may be state names).

It refuses what could make a small file take the machine down (limits in
docs/reliability.md): files over :data:`MAX_FILE_BYTES`, aliases (``*name``:
ten lines of them expand to a billion values, the "billion laughs"), and
nesting deeper than :data:`MAX_NESTING` levels (it would exhaust Python's
stack).  Text that is not UTF-8 is named by line and column.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import yaml

from ..params import shown_path
from .errors import ScenarioError

#: Largest scenario file read, bytes (the longest packaged one has about 3 kB).
MAX_FILE_BYTES = 1_000_000
#: Deepest nesting of mappings and lists in a scenario file (the format needs 4).
MAX_NESTING = 40


class MarkedDict(dict[Any, Any]):
    """A YAML mapping; ``line`` is where it starts, ``key_lines``/``value_lines`` where each entry is."""

    line: int
    key_lines: dict[Any, int]
    value_lines: dict[Any, int]

    def line_of(self, key: Any) -> int:
        """The line of ``key``'s value (the mapping's line if the key is absent)."""
        return self.value_lines.get(key, self.line)


class MarkedList(list[Any]):
    """A YAML sequence; ``line`` is where it starts, ``item_lines[i]`` where item ``i`` is."""

    line: int
    item_lines: list[int]


def _line(node: yaml.Node) -> int:
    return node.start_mark.line + 1


class MarkedLoader(yaml.SafeLoader):
    """``yaml.SafeLoader`` that keeps line numbers and refuses duplicate keys, aliases and deep nesting."""

    _depth = 0

    def compose_node(self, parent: yaml.Node | None, index: Any) -> yaml.Node:  # type: ignore[override]
        event = self.peek_event()
        if isinstance(event, yaml.AliasEvent):
            raise ScenarioError(self.name, event.start_mark.line + 1,
                                f"YAML aliases (*{_cut(event.anchor)}) are not allowed in a scenario: write each"
                                " value out (aliases can expand a small file to gigabytes)")
        self._depth += 1
        if self._depth > MAX_NESTING:
            raise ScenarioError(self.name, event.start_mark.line + 1,
                                f"nested deeper than {MAX_NESTING} levels: not a scenario")
        try:
            return super().compose_node(parent, index)  # type: ignore[no-any-return]
        finally:
            self._depth -= 1

    def construct_marked_map(self, node: yaml.MappingNode) -> Any:
        data = MarkedDict()
        data.line, data.key_lines, data.value_lines = _line(node), {}, {}
        yield data
        self.flatten_mapping(node)
        for key_node, value_node in node.value:
            key = self.construct_object(key_node, deep=True)
            try:
                hash(key)
            except TypeError:
                raise ScenarioError(self.name, _line(key_node),
                                    "a mapping key must be a plain value") from None
            if key in data:
                raise ScenarioError(self.name, _line(key_node),
                                    f"key {key!r} given twice (first on line {data.key_lines[key]});"
                                    " a step holds one action: start a new step with '- '")
            data[key] = self.construct_object(value_node, deep=True)
            data.key_lines[key] = _line(key_node)
            data.value_lines[key] = _line(value_node)

    def construct_marked_seq(self, node: yaml.SequenceNode) -> Any:
        data = MarkedList()
        data.line, data.item_lines = _line(node), [_line(n) for n in node.value]
        yield data
        data.extend(self.construct_object(n, deep=True) for n in node.value)


MarkedLoader.add_constructor("tag:yaml.org,2002:map", MarkedLoader.construct_marked_map)
MarkedLoader.add_constructor("tag:yaml.org,2002:seq", MarkedLoader.construct_marked_seq)

# Booleans as YAML 1.2 has them: only true / false.  PyYAML follows YAML 1.1, where
# on, off, yes, no, y, n are booleans too, and a state named `on` or `off` in
# `sequence: [off, on]` would silently become [False, True].
_BOOL = "tag:yaml.org,2002:bool"
MarkedLoader.yaml_implicit_resolvers = {
    first: [(tag, regexp) for tag, regexp in resolvers if tag != _BOOL]
    for first, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()
}
MarkedLoader.add_implicit_resolver(_BOOL, re.compile(r"^(?:true|True|TRUE|false|False|FALSE)$"), list("tTfF"))
# Numbers in exponent form as YAML 1.2 reads them: 1e12, 2.5e-3, 1.0e12.  YAML 1.1 (PyYAML) wants a dot
# and a signed exponent (1.0e+12), so `timeout_s: 1e12` was the text '1e12' and its message "expected a
# number, got text" named the wrong problem.
MarkedLoader.add_implicit_resolver("tag:yaml.org,2002:float",
                                   re.compile(r"^[-+]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)[eE][-+]?[0-9]+$"),
                                   list("-+0123456789."))


def _cut(text: Any, limit: int = 40) -> str:
    text = str(text)
    return text if len(text) <= limit else text[:limit] + "..."


def load_yaml(text: str, file: str) -> Any:
    """Parse YAML text safely; a syntax error becomes a :class:`ScenarioError` at its line."""
    try:
        loader = MarkedLoader(text)
    except yaml.reader.ReaderError as exc:  # a character YAML does not allow, found before parsing
        raise _reader_error(exc, text, file) from None
    loader.name = file
    try:
        return loader.get_single_data()
    except yaml.reader.ReaderError as exc:
        raise _reader_error(exc, text, file) from None
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        problem = exc.problem or exc.context or "not valid YAML"
        if exc.context and exc.context_mark is not None:
            # "while parsing a flow sequence" on the line it starts: where the mistake usually is,
            # when the problem itself only shows at the end of the file.
            problem += f" ({exc.context} started on line {exc.context_mark.line + 1})"
            if "<stream end>" in str(exc.problem):
                mark = exc.context_mark
        line = mark.line + 1 if mark is not None else 0
        raise ScenarioError(file, line, f"not valid YAML: {problem}") from None
    except yaml.YAMLError as exc:
        raise ScenarioError(file, 0, f"not valid YAML: {_cut(exc, 200)}") from None
    finally:
        loader.dispose()


def _reader_error(exc: yaml.reader.ReaderError, text: str, file: str) -> ScenarioError:
    at = exc.position
    line = text.count("\n", 0, at) + 1
    column = at - (text.rfind("\n", 0, at) + 1) + 1
    return ScenarioError(file, line, f"not valid YAML: character #x{exc.character:04x} at column {column}:"
                                     " special characters are not allowed")


def load_yaml_file(path: str | Path) -> Any:
    """Read and parse a YAML file (see :func:`load_yaml`): at most :data:`MAX_FILE_BYTES`, UTF-8."""
    path = Path(path)
    name = shown_path(path)
    try:
        with path.open("rb") as f:
            raw = f.read(MAX_FILE_BYTES + 1)  # a device or a pipe may never end
    except (OSError, ValueError) as exc:  # ValueError: a NUL character in the name
        raise ScenarioError(name, 0, f"cannot read the file: {getattr(exc, 'strerror', None) or exc}") from None
    if len(raw) > MAX_FILE_BYTES:
        raise ScenarioError(name, 0, f"more than {MAX_FILE_BYTES} bytes: not a scenario file")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw.count(b"\n", 0, exc.start) + 1
        column = exc.start - (raw.rfind(b"\n", 0, exc.start) + 1) + 1
        raise ScenarioError(name, line, f"not UTF-8 text (byte 0x{raw[exc.start]:02x} at column {column});"
                                             " save the file as UTF-8") from None
    return load_yaml(text, name)
