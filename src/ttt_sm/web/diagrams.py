"""The charts' diagrams for the cockpit: Graphviz SVG from the same DOT as ``charts/``, annotated.

Each picture is drawn once per session (real Graphviz ``dot``, the same
:func:`~ttt_sm.runtime.dot.to_dot` as ``ttt-sm charts export``) and cached;
the page then only toggles attributes on it, frame after frame.  The SVG
elements keep their stable ids (``state-<id>``, ``stub-<id>``, ``tr-<n>``)
and get what a page, a test and a screen reader need:

* a state (box, closed sub-chart or cluster): ``data-state`` (its qualified
  name, ``Control.start_stop.wait_1``), ``data-state-id``, ``data-active``,
  and on a closed sub-chart ``data-subchart``;
* a transition's edge: ``data-transition`` (``Chart.source->target``; several,
  space-separated, where one edge draws several transitions), ``data-index``
  (their indices) and ``data-taken-count``;
* a stub (a state drawn in another picture): ``data-stub`` and ``data-view``,
  the picture that draws it;
* all of them ``role="button"``, ``tabindex="0"`` and an ``aria-label``.

Graphviz writes a ``-`` in an id as ``&#45;``; the links Graphviz draws for
closed sub-charts and stubs (to the ``charts/`` files) are dropped: in the
cockpit a click opens the picture in place.
"""

from __future__ import annotations

import html
import re
import threading
from collections import OrderedDict

from ..runtime import TickChart
from ..runtime.dot import WHOLE, View, overview_with, subcharts, to_dot
from ..runtime.export import svg_from_dot
from ..runtime.structure import ChartStructure
from .catalogue import qualified_names, transition_name

_GROUP = re.compile(r'<g id="([^"]+)" class="(node|cluster|edge)">')
_LINK_OPEN = re.compile(r'<a xlink:href="[^"]*"(?: xlink:title="[^"]*")?>')
#: Pictures kept per session (a few hundred kB each at most).
CACHE_SIZE = 64


class DiagramError(ValueError):
    """A picture that does not exist: an unknown chart, view or sub-chart."""


def view_of(cls: type[TickChart], key: str, opened: tuple[str, ...] = ()) -> View:
    """The :class:`View` a page asks for: ``overview`` (with ``opened`` sub-charts open in
    place), a sub-chart's id (on its own) or ``whole``."""
    subs = subcharts(cls)
    if key == "whole":
        if opened:
            raise DiagramError("only the overview opens sub-charts in place")
        return WHOLE
    if key == "overview":
        if not subs:
            raise DiagramError(f"{cls.__name__} has no sub-charts: its one picture is 'whole'")
        try:
            return overview_with(cls, opened)
        except ValueError as exc:
            raise DiagramError(str(exc)) from None
    if key in subs and not opened:
        return View(key, root=key)
    raise DiagramError(f"{cls.__name__} has no picture {key!r}; pictures: "
                       + ", ".join(["overview", *subs, "whole"] if subs else ["whole"]))


def _picture_key(structure: ChartStructure, state_id: str) -> str:
    """The picture where a state is drawn open: its top-level sub-chart, else the overview."""
    by_id = {s.id: s for s in structure.states}
    top = state_id
    while by_id[top].parent is not None:
        top = by_id[top].parent  # type: ignore[assignment]
    return top if by_id[top].is_compound else "overview"


def annotate(svg: str, chart_name: str, structure: ChartStructure) -> str:
    """Add the cockpit's data attributes to the SVG Graphviz drew (see the module's docstring)."""
    qnames = qualified_names(chart_name, structure)
    compound = {s.id for s in structure.states if s.is_compound}
    names = {t.index: transition_name(chart_name, t.source, t.target) for t in structure.transitions}

    def tag(match: re.Match[str]) -> str:
        raw, kind = match.group(1), match.group(2)
        ident = html.unescape(raw)
        attrs: list[tuple[str, str]] = []
        if ident.startswith("state-") and ident[6:] in qnames:
            sid = ident[6:]
            attrs = [("data-state", qnames[sid]), ("data-state-id", sid), ("data-active", "false")]
            if kind == "node" and sid in compound:
                attrs.append(("data-subchart", sid))
            attrs += [("role", "button"), ("tabindex", "0"), ("aria-label", f"state {qnames[sid]}")]
        elif ident.startswith("stub-") and ident[5:] in qnames:
            sid = ident[5:]
            attrs = [("data-stub", qnames[sid]), ("data-view", _picture_key(structure, sid)),
                     ("role", "button"), ("tabindex", "0"),
                     ("aria-label", f"state {qnames[sid]}, drawn in another picture: open it")]
        elif ident.startswith("tr-"):
            indices = [int(p) for p in ident[3:].split("-") if p.isdigit()]
            transitions = [n for n in (names.get(i) for i in indices) if n]
            if transitions:
                attrs = [("data-transition", " ".join(dict.fromkeys(transitions))),
                         ("data-index", " ".join(str(i) for i in indices)), ("data-taken-count", "0"),
                         ("role", "button"), ("tabindex", "0"),
                         ("aria-label", "transition " + ", ".join(dict.fromkeys(transitions)))]
        extra = "".join(f' {k}="{html.escape(v, quote=True)}"' for k, v in attrs)
        return f'<g id="{raw}" class="{kind}"{extra}>'

    svg = _GROUP.sub(tag, svg)
    svg = _LINK_OPEN.sub("", svg).replace("</a>", "")
    # The <svg> element sizes itself from its viewBox in the page.
    return svg[svg.find("<svg"):] if "<svg" in svg else svg


class Diagrams:
    """The session's pictures, drawn on first use and cached (thread-safe)."""

    def __init__(self, charts: dict[str, type[TickChart]]) -> None:
        self.charts = dict(charts)
        self._cache: OrderedDict[tuple[str, str, tuple[str, ...]], str] = OrderedDict()
        self._lock = threading.Lock()

    def svg(self, chart: str, key: str = "overview", opened: tuple[str, ...] = ()) -> str:
        """One picture of a chart, annotated; :class:`DiagramError` names what does not exist."""
        cls = self.charts.get(chart)
        if cls is None:
            raise DiagramError(f"no chart {chart!r}; charts: {', '.join(self.charts)}")
        if key == "overview" and not subcharts(cls):
            key = "whole"
        view = view_of(cls, key, opened)
        cache_key = (chart, view.key or "whole", view.opened)
        with self._lock:
            if cache_key in self._cache:
                self._cache.move_to_end(cache_key)
                return self._cache[cache_key]
        picture = annotate(svg_from_dot(to_dot(cls, view=view)), chart, cls.structure())
        with self._lock:
            self._cache[cache_key] = picture
            while len(self._cache) > CACHE_SIZE:
                self._cache.popitem(last=False)
        return picture
