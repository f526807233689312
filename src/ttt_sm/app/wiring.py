"""The wiring between charts, and between charts and the arm: one table, checked and compiled.

Simulink draws the signals between Stateflow blocks as lines; here each line
is a row of a table, :class:`Wire`, from a source to a target:

- a source is a chart's output (``"Control.ready"``) or an output of one of
  the other blocks of the loop (``"Encoder.index[0]"``: drive 1's index
  switch);
- a target is a chart's input (``"Game.ready"``) or an input of another block
  (``"IK.X"``: the tool pose inverse kinematics solves for).

Charts declare their ports as data (``inputs``, ``outputs``); the other
blocks declare theirs as :class:`Port` (name, unit, doc, and a size for a
vector such as one angle per drive, wired element by element: ``angle[0]``).
:func:`check` holds a table against the declarations: a misspelt or missing
block or port, a source that is not an output, a target that is not an
input, an element out of range, units that differ, or a target driven twice
raise :class:`WiringError` naming the row.

:class:`Wiring` compiles a checked table for running charts: a stage asks it
for :meth:`Wiring.feed` (a function that writes every wired input of its
charts) and :meth:`Wiring.collect` (a function that returns the values wired
to some block inputs).  Both are generated Python: one plain dictionary store
or read per wire, no name looked up per chart step.  Nothing outside a chart
reads its states: what others need to know, a chart declares as an output.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

from ..runtime import TickChart


class WiringError(ValueError):
    """A wiring table that does not match the blocks' declarations."""


@dataclass(frozen=True)
class Port:
    """A signal of a block that is not a chart.

    Parameters
    ----------
    name : str
        As the table writes it (``index``, ``X``).
    unit : str
        SI unit, ``"bool"`` or ``"1"``, as chart data declare theirs.
    doc : str
        One line saying what it is.
    size : int
        1 for a scalar; more for a vector (one value per drive), wired element by element.
    attr : str
        Attribute of the block's object that holds an output (default: `name`).
    """

    name: str
    unit: str
    doc: str
    size: int = 1
    attr: str = ""

    @property
    def attribute(self) -> str:
        return self.attr or self.name


@dataclass(frozen=True)
class Block:
    """A block of the loop with its ports: a chart (its declared data) or another part."""

    name: str
    doc: str
    inputs: tuple[Port, ...] = ()
    outputs: tuple[Port, ...] = ()
    chart: bool = False

    def port(self, kind: str, name: str) -> Port | None:
        for p in self.inputs if kind == "input" else self.outputs:
            if p.name == name:
                return p
        return None


def chart_block(chart: TickChart | type[TickChart], name: str | None = None) -> Block:
    """A chart as a block: its declared inputs and outputs are its ports."""
    cls = chart if isinstance(chart, type) else type(chart)
    label = name or (cls.__name__ if isinstance(chart, type) else chart.chart_name)
    decls = cls.declarations()
    doc = (cls.__doc__ or "").strip().splitlines()
    return Block(
        name=label, doc=doc[0] if doc else "", chart=True,
        inputs=tuple(Port(d.name, d.unit, d.doc) for d in decls if d.kind == "input"),
        outputs=tuple(Port(d.name, d.unit, d.doc) for d in decls if d.kind == "output"),
    )


_END = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*)\.([A-Za-z_][A-Za-z0-9_]*)(?:\[(\d+)\])?$")


@dataclass(frozen=True)
class End:
    """One end of a wire: ``Block.port`` or ``Block.port[index]``."""

    block: str
    port: str
    index: int | None = None

    def __str__(self) -> str:
        return f"{self.block}.{self.port}" + ("" if self.index is None else f"[{self.index}]")


@dataclass(frozen=True)
class Wire:
    """One row of the wiring table: `source` feeds `target` at every chart step."""

    source: str
    target: str

    def __str__(self) -> str:
        return f"{self.source} -> {self.target}"


def _parse(text: str, row: Wire) -> End:
    m = _END.match(text.strip()) if isinstance(text, str) else None
    if m is None:
        raise WiringError(f"wire {row}: {text!r} is not Block.port or Block.port[index]")
    return End(m.group(1), m.group(2), None if m.group(3) is None else int(m.group(3)))


@dataclass(frozen=True)
class CheckedWire:
    """A row with both ends resolved against the declarations."""

    wire: Wire
    source: End
    target: End
    source_port: Port
    target_port: Port


def check(wires: Iterable[Wire], blocks: Iterable[Block]) -> list[CheckedWire]:
    """Resolve every row against the blocks' declarations; raise :class:`WiringError` naming the first bad one."""
    by_name: dict[str, Block] = {}
    for block in blocks:
        if block.name in by_name:
            raise WiringError(f"two blocks are named {block.name!r}")
        by_name[block.name] = block
    checked: list[CheckedWire] = []
    driven: dict[tuple[str, str, int | None], Wire] = {}
    for wire in wires:
        source = _parse(wire.source, wire)
        target = _parse(wire.target, wire)
        sp = _resolve(source, "output", by_name, wire)
        tp = _resolve(target, "input", by_name, wire)
        if sp.unit != tp.unit:
            raise WiringError(f"wire {wire}: units differ: {source} is in {sp.unit!r}, {target} in {tp.unit!r}")
        key = (target.block, target.port, target.index)
        if key in driven:
            raise WiringError(f"wire {wire}: {target} is already driven by wire {driven[key]}")
        driven[key] = wire
        checked.append(CheckedWire(wire, source, target, sp, tp))
    return checked


def _resolve(end: End, kind: str, blocks: Mapping[str, Block], wire: Wire) -> Port:
    role = "source" if kind == "output" else "target"
    block = blocks.get(end.block)
    if block is None:
        raise WiringError(f"wire {wire}: no block named {end.block!r}; blocks: {', '.join(sorted(blocks))}")
    port = block.port(kind, end.port)
    if port is None:
        other = "input" if kind == "output" else "output"
        if block.port(other, end.port) is not None:
            raise WiringError(f"wire {wire}: {end.block}.{end.port} is an {other}; a wire's {role} must be"
                              f" an {kind}")
        names = [p.name for p in (block.outputs if kind == "output" else block.inputs)]
        raise WiringError(f"wire {wire}: {end.block} has no {kind} {end.port!r}; {kind}s:"
                          f" {', '.join(names) or '(none)'}")
    if port.size == 1 and end.index is not None:
        raise WiringError(f"wire {wire}: {end.block}.{end.port} is a scalar; drop [{end.index}]")
    if port.size > 1 and (end.index is None or end.index >= port.size):
        raise WiringError(f"wire {wire}: {end.block}.{end.port} has {port.size} elements; name one,"
                          f" {end.block}.{end.port}[0] .. [{port.size - 1}]")
    return port


class Wiring:
    """A checked table, compiled into plain functions over running charts and block objects.

    Parameters
    ----------
    wires : iterable of Wire
        The table.
    charts : mapping
        The running charts by name (their blocks are made from their declarations).
    blocks : iterable of Block
        The other blocks' declarations.
    objects : mapping
        For each block whose outputs are wired, the object holding them (an output
        is the attribute :attr:`Port.attribute` of it).
    """

    def __init__(self, wires: Iterable[Wire], charts: Mapping[str, TickChart], blocks: Iterable[Block],
                 objects: Mapping[str, object]) -> None:
        blocks = list(blocks)
        self.blocks = {b.name: b for b in blocks}
        self.rows = check(wires, [*(chart_block(c, name) for name, c in charts.items()), *blocks])
        self.charts = dict(charts)
        self.objects = dict(objects)
        self._used: set[int] = set()

    def feed(self, charts: Sequence[str], skip: Iterable[str] = (), args: Sequence[str] = (),
             flat: bool = False) -> Callable[..., None]:
        """A function that writes every wired input of `charts` from its source, now.

        Wires from the blocks named in `skip` are left out: their targets keep
        the value last written (a Simulink enabled subsystem that holds its outputs).
        The outputs of the blocks named in `args` are the function's arguments,
        every output port of each in declaration order (a vector as one
        sequence): the stage that computes them passes them straight in.
        With `flat`, they are one argument instead: a sequence of every
        element of those ports, in the same order (what a compiled function
        returns in one tuple, passed without cutting it up).
        """
        unknown = [c for c in charts if c not in self.charts]
        if unknown:
            raise WiringError(f"no chart named {', '.join(unknown)} to feed; charts: {', '.join(self.charts)}")
        skipped = set(skip)
        code = _Code(self, args, flat)
        for i, row in enumerate(self.rows):
            if row.target.block in charts and row.source.block not in skipped:
                target = code.chart(row.target.block)
                code.body.append(f"{target}[{row.target.port!r}] = {code.source(row)}")
                self._used.add(i)
        return code.function("feed_" + "_".join(charts), "")

    def routes(self, chart: str, args: Sequence[str]) -> list[tuple[int, str]]:
        """What :meth:`feed` with `args` and `flat` would write to `chart` from those blocks, as
        (element of the flat arguments, chart datum) pairs: for compiled code that writes them itself."""
        if chart not in self.charts:
            raise WiringError(f"no chart named {chart} to feed; charts: {', '.join(self.charts)}")
        code = _Code(self, args, flat=True)
        found = []
        for i, row in enumerate(self.rows):
            start = code.offsets.get(f"{row.source.block}.{row.source.port}")
            if row.target.block == chart and start is not None:
                found.append((start + (row.source.index or 0), row.target.port))
                self._used.add(i)
        return found

    def sources(self, chart: str) -> set[str]:
        """The blocks (and charts) the wiring table feeds `chart`'s inputs from."""
        return {row.source.block for row in self.rows if row.target.block == chart}

    def collect(self, *ports: str) -> Callable[[], Any]:
        """A function returning what is wired to these block inputs (or chart inputs) now (a tuple for several).

        A vector port comes back as a list, one value per element; every element must be wired.
        """
        code = _Code(self)
        values = []
        for text in ports:
            block, _, name = text.partition(".")
            if block in self.charts:  # a chart's input: what is wired to it (a chart's data are scalars)
                found = [(i, row) for i, row in enumerate(self.rows)
                         if row.target.block == block and row.target.port == name]
                if not found:
                    raise WiringError(f"nothing is wired to {text}")
                self._used.add(found[0][0])
                values.append(code.source(found[0][1]))
                continue
            spec = self.blocks.get(block)
            port = spec.port("input", name) if spec is not None else None
            if spec is None or port is None:
                raise WiringError(f"{text}: no such block input to collect")
            rows = {row.target.index: (i, row) for i, row in enumerate(self.rows)
                    if row.target.block == block and row.target.port == name}
            elements = [None] if port.size == 1 else list(range(port.size))
            missing = [e for e in elements if e not in rows]
            if missing:
                what = text if port.size == 1 else ", ".join(f"{text}[{e}]" for e in missing)
                raise WiringError(f"nothing is wired to {what}")
            exprs = []
            for e in elements:
                i, row = rows[e]
                exprs.append(code.source(row))
                self._used.add(i)
            values.append(exprs[0] if port.size == 1 else "[" + ", ".join(exprs) + "]")
        result = values[0] if len(values) == 1 else "(" + ", ".join(values) + ")"
        return code.function("collect_" + "_".join(p.replace(".", "_") for p in ports), result)

    def unused(self) -> list[Wire]:
        """Rows no feed or collect function has compiled so far: nothing reads their targets."""
        return [row.wire for i, row in enumerate(self.rows) if i not in self._used]


class _Code:
    """Source text of one generated function, its arguments, and the objects it binds (as default arguments)."""

    def __init__(self, wiring: Wiring, args: Sequence[str] = (), flat: bool = False) -> None:
        self.wiring = wiring
        self.args: dict[str, str] = {}  # "Block.port" -> argument name
        self.offsets: dict[str, int] = {}  # with `flat`: "Block.port" -> where its elements start in `outputs`
        start = 0
        for block in args:
            spec = wiring.blocks.get(block)
            if spec is None:
                raise WiringError(f"no block named {block!r} to pass as arguments")
            for port in spec.outputs:
                if flat:
                    self.offsets[f"{block}.{port.name}"] = start
                    start += port.size
                else:
                    self.args[f"{block}.{port.name}"] = f"{block}_{port.name}"
        self.flat = flat
        self.bound: dict[str, object] = {}
        self.prelude: list[str] = []
        self.body: list[str] = []
        self.hoisted: dict[tuple[str, str], str] = {}

    def chart(self, name: str) -> str:
        var = "d_" + name
        self.bound[var] = self.wiring.charts[name].data_mapping()  # the chart's data, read and written by name
        return var

    def source(self, row: CheckedWire) -> str:
        s = row.source
        if s.block in self.wiring.charts:
            return f"{self.chart(s.block)}[{s.port!r}]"
        arg = self.args.get(f"{s.block}.{s.port}")
        if arg is not None:
            return arg if s.index is None else f"{arg}[{s.index}]"
        start = self.offsets.get(f"{s.block}.{s.port}")
        if start is not None:
            return f"outputs[{start + (s.index or 0)}]"
        obj = self.wiring.objects.get(s.block)
        attr = row.source_port.attribute
        if obj is None or not hasattr(obj, attr):
            raise WiringError(f"wire {row.wire}: the robot holds no {s.block} object with {attr!r} to read {s} from")
        var = "b_" + s.block
        self.bound[var] = obj
        if s.index is None:
            return f"{var}.{attr}"
        key = (s.block, attr)
        if key not in self.hoisted:
            local = f"_{s.block}_{attr}"
            self.prelude.append(f"{local} = {var}.{attr}")
            self.hoisted[key] = local
        return f"{self.hoisted[key]}[{s.index}]"

    def function(self, name: str, result: str) -> Callable[..., Any]:
        args = ", ".join([*(["outputs"] if self.flat else []), *self.args.values(), *(f"{v}={v}" for v in self.bound)])
        lines = [f"def {name}({args}):", *(f"    {line}" for line in (*self.prelude, *self.body))]
        lines.append(f"    return {result}" if result else "    return None")
        source = "\n".join(lines) + "\n"
        namespace: dict[str, Any] = dict(self.bound)
        exec(compile(source, f"<wiring {name}>", "exec"), namespace)  # noqa: S102 - our own generated code
        fn = namespace[name]
        fn.source = source
        return fn  # type: ignore[no-any-return]


def not_wired(*args: Any) -> Any:
    """What a stage runs before it is wired: an error saying so."""
    raise RuntimeError("the stage is not wired yet: the Robot wires it when it is built")


class WiredStage(Protocol):
    """A scheduler stage that runs part of the wiring: it holds some blocks' objects and compiles its part."""

    def blocks(self) -> dict[str, object]:
        """The objects holding the outputs of the blocks this stage runs, by block name."""

    def wire(self, wiring: Wiring) -> None:
        """Compile this stage's feeds and collects."""


def wire_stages(wires: Iterable[Wire], charts: Mapping[str, TickChart], stages: Sequence[WiredStage],
                blocks: Iterable[Block], objects: Mapping[str, object] | None = None) -> Wiring:
    """Check `wires` against the charts and blocks, compile every stage's part, and check nothing is left.

    Raises :class:`WiringError` naming the row that does not fit, or a row whose
    target no stage reads.
    """
    held: dict[str, object] = {}
    for stage in stages:
        held.update(stage.blocks())
    held.update(objects or {})
    wiring = Wiring(wires, charts, blocks, held)
    for stage in stages:
        stage.wire(wiring)
    unused = wiring.unused()
    if unused:
        raise WiringError(f"wire {unused[0]}: nothing reads {unused[0].target} (no stage feeds or collects it)")
    return wiring
