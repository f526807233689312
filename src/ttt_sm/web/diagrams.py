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
* all of them ``role="button"``, ``tabindex="0"`` and an ``aria-label``;
* a state or a transition: ``data-detail`` and its ``<title>``, what its actions
  do with their whole texts (the picture may show a summary ending in ``…``).

The ids are read with an XML parser (Graphviz writes a ``-`` in an id as
``&#45;``); the links Graphviz draws for closed sub-charts and stubs (to the
``charts/`` files) are dropped, their contents kept: in the cockpit a click
opens the picture in place.
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from xml.dom import minidom

from ..runtime import TickChart
from ..runtime.dot import legend_features, to_dot
from ..runtime.dot_text import legend_dot
from ..runtime.dot_views import WHOLE, View, overview_with, subcharts
from ..runtime.export import svg_from_dot
from ..runtime.structure import ChartStructure
from .catalogue import qualified_names, transition_name

#: The Graphviz classes of the groups that draw a state or a transition.
_KINDS = ("node", "cluster", "edge")
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
    """Add the cockpit's data attributes to the SVG Graphviz drew (see the module's docstring).

    The SVG is read and written as an XML document (:mod:`xml.dom.minidom`:
    its namespaces, comments and every element kept, but the ``<a>`` links,
    whose children take their place); what comes back is the ``<svg>`` element
    alone, without the XML declaration and the doctype, as a page puts it inline.
    """
    document = minidom.parseString(svg)
    root = document.documentElement
    if root is None or root.tagName != "svg":
        raise ValueError("Graphviz drew no <svg> element")
    marker = Marker(chart_name, structure)
    for group in root.getElementsByTagName("g"):
        kind, ident = group.getAttribute("class"), group.getAttribute("id")
        if kind in _KINDS and ident:
            for name, value in marker.attributes(kind, ident).items():
                group.setAttribute(name, value)
    for link in root.getElementsByTagName("a"):
        parent = link.parentNode
        assert isinstance(parent, minidom.Element)  # an <a> below the <svg> element
        _keep_tooltip(link)
        _unwrap(link)
        # the group Graphviz wraps a link in (id "a_<id>") goes too: the element's path, polygon
        # and texts are its own children again, as the page's styles expect (`.edge > path`)
        if parent.tagName == "g" and parent.getAttribute("id").startswith("a_") and not parent.getAttribute("class"):
            _unwrap(parent)
    text = root.toxml()
    document.unlink()
    return text


def _unwrap(element: minidom.Element) -> None:
    """Replace an element by its children."""
    parent = element.parentNode
    assert isinstance(parent, minidom.Element)  # below the <svg> element
    while (child := element.firstChild) is not None:
        parent.insertBefore(child, element)
    parent.removeChild(element)


def _keep_tooltip(link: minidom.Element) -> None:
    """The tooltip Graphviz put on a link (what a state's or an edge's actions do, whole) kept on the
    element it belongs to: its ``<title>`` (what a browser shows on hover) and ``data-detail`` (the
    cockpit's click panel)."""
    text = link.getAttribute("xlink:title")
    group: minidom.Node | None = link.parentNode
    while isinstance(group, minidom.Element) and group.getAttribute("class") not in _KINDS:
        group = group.parentNode
    if not text or not isinstance(group, minidom.Element) or group.hasAttribute("data-detail"):
        return
    group.setAttribute("data-detail", text)
    titles = [c for c in group.childNodes if isinstance(c, minidom.Element) and c.tagName == "title"]
    if titles:
        while titles[0].firstChild is not None:
            titles[0].removeChild(titles[0].firstChild)
        titles[0].appendChild(group.ownerDocument.createTextNode(text))  # type: ignore[union-attr]


class Marker:
    """The data attributes of one chart's picture, element by element, from its stable ids."""

    def __init__(self, chart_name: str, structure: ChartStructure) -> None:
        self.structure = structure
        self.qnames = qualified_names(chart_name, structure)
        self.compound = {s.id for s in structure.states if s.is_compound}
        self.names = {t.index: transition_name(chart_name, t.source, t.target) for t in structure.transitions}

    def attributes(self, kind: str, ident: str) -> dict[str, str]:
        """What an element Graphviz drew as ``kind`` (node, cluster, edge) with id ``ident`` gets, if anything."""
        qnames = self.qnames
        if ident.startswith("state-") and ident[6:] in qnames:
            sid = ident[6:]
            attrs = {"data-state": qnames[sid], "data-state-id": sid, "data-active": "false"}
            if kind == "node" and sid in self.compound:
                attrs["data-subchart"] = sid
            return {**attrs, "role": "button", "tabindex": "0", "aria-label": f"state {qnames[sid]}"}
        if ident.startswith("stub-") and ident[5:] in qnames:
            sid = ident[5:]
            return {"data-stub": qnames[sid], "data-view": _picture_key(self.structure, sid),
                    "role": "button", "tabindex": "0",
                    "aria-label": f"state {qnames[sid]}, drawn in another picture: open it"}
        if ident.startswith("tr-"):
            indices = [int(p) for p in ident[3:].split("-") if p.isdigit()]
            transitions = [n for n in (self.names.get(i) for i in indices) if n]
            if transitions:
                return {"data-transition": " ".join(dict.fromkeys(transitions)),
                        "data-index": " ".join(str(i) for i in indices), "data-taken-count": "0",
                        "role": "button", "tabindex": "0",
                        "aria-label": "transition " + ", ".join(dict.fromkeys(transitions))}
        return {}


class Diagrams:
    """The session's pictures, drawn on first use and cached (thread-safe)."""

    def __init__(self, charts: dict[str, type[TickChart]]) -> None:
        self.charts = dict(charts)
        self._cache: OrderedDict[tuple[str, str, tuple[str, ...]], str] = OrderedDict()
        self._lock = threading.Lock()

    def replace(self, chart: str, cls: type[TickChart]) -> None:
        """Chart `chart` is now drawn from `cls` (a student's chart reloaded): its cached pictures are dropped."""
        with self._lock:
            self.charts[chart] = cls
            for key in [k for k in self._cache if k[0] == chart]:
                del self._cache[key]

    def svg(self, chart: str, key: str = "overview", opened: tuple[str, ...] = ()) -> str:
        """One picture of a chart, annotated; :class:`DiagramError` names what does not exist.

        ``key`` ``"legend"``: the legend of what the chart's pictures use (they carry none).
        """
        cls = self.charts.get(chart)
        if cls is None:
            raise DiagramError(f"no chart {chart!r}; charts: {', '.join(self.charts)}")
        if key == "overview" and not subcharts(cls):
            key = "whole"
        if key == "legend":
            if opened:
                raise DiagramError("a legend opens no sub-charts")
            view = View("legend")  # only its key: the cache's
        else:
            view = view_of(cls, key, opened)
        cache_key = (chart, view.key or "whole", view.opened)
        with self._lock:
            if cache_key in self._cache:
                self._cache.move_to_end(cache_key)
                return self._cache[cache_key]
        if key == "legend":  # what this chart's pictures use, once per page (collapsible)
            picture = annotate(svg_from_dot(legend_dot(legend_features(cls))), chart, cls.structure())
        else:
            picture = annotate(svg_from_dot(to_dot(cls, view=view)), chart, cls.structure())
        with self._lock:
            if self.charts.get(chart) is not cls:  # replaced while it was drawn: not kept
                return picture
            self._cache[cache_key] = picture
            while len(self._cache) > CACHE_SIZE:
                self._cache.popitem(last=False)
        return picture
