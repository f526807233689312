"""The pieces of a chart's DOT text: quoting, HTML-like labels, colours, and the legend of the pictures.

:func:`legend_dot` draws the legend alone (the cockpit shows it once a page),
:func:`legend_markdown` lists it in a chart's Markdown page; which rows a
chart needs is :func:`~.dot.legend_features`.
"""

from __future__ import annotations

import re

from .diagram import ACTIVE_FILL, FONT

EVENT_COLOR = "#1f4e9c"
CLOSED_FILL = "#ececec"
STUB_COLOR = "#707070"


def quote(text: str) -> str:
    """``text`` as a quoted DOT string."""
    escaped = text.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n")
    return '"' + escaped + '"'


def left_quote(text: str) -> str:
    """A quoted DOT label whose lines are left-aligned (``\\l`` after each), as a block of action text reads."""
    lines = text.split("\n")
    return '"' + "".join(quote(line)[1:-1] + "\\l" for line in lines) + '"'


def html(text: str) -> str:
    """``text`` escaped for an HTML-like label."""
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;").replace('"', "&quot;")


def html_label(title: str, lines: list[str]) -> str:
    """A state's box: its name in bold, then its lines."""
    if not lines:
        return f"<<b>{html(title)}</b>>"
    body = "<br/>".join(html(line) for line in lines)
    return (
        '<<table border="0" cellborder="0" cellspacing="0" cellpadding="2">'
        f"<tr><td><b>{html(title)}</b></td></tr><hr/>"
        f'<tr><td align="left" balign="left">{body}</td></tr></table>>'
    )


def closed_label(title: str, lines: list[str], ports: list[tuple[str, str, bool, bool]]) -> str:
    """A closed sub-chart: name, its own lines, then one row per port (inner state)."""
    rows = [f"<tr><td><b>{html(title)}</b></td></tr>"]
    if lines:
        body = "<br/>".join(html(line) for line in lines)
        rows.append(f'<hr/><tr><td align="left" balign="left">{body}</td></tr>')
    if ports:
        rows.append("<hr/>")
        for port, name, into, out_of in ports:
            text = ("▸ " if into else "") + html(name) + (" ▸" if out_of else "")
            align = "left" if into else "right"
            rows.append(f'<tr><td port="{port}" align="{align}">{text}</td></tr>')
    return '<<table border="0" cellborder="0" cellspacing="0" cellpadding="2">' + "".join(rows) + "</table>>"


# -- legend ------------------------------------------------------------------

_ARROW = "───▶"
#: (feature, symbol as an HTML-like label cell, meaning), in the order listed.
_LEGEND: tuple[tuple[str, str, str], ...] = (
    ("tick", f"<td>{_ARROW}</td>",
     "transition without an event: tried at every wake-up of the chart, valid when its [guard] holds"),
    ("event", f'<td><font color="{EVENT_COLOR}">{_ARROW}</font></td>',
     "transition with an event: tried only when that event wakes the chart"),
    ("priority", "<td>2: [guard]</td>",
     "execution order: a source's outer (or inner) transitions are tried in this order, 1 first"),
    ("condition", "<td>{f}</td>", "condition action: f runs as soon as the guard holds, before anything is left"),
    ("action", "<td>/ f</td>", "transition action: f runs once the path reaches a state, between exit and entry"),
    ("entry", "<td>en: f</td>", "entry action: f runs when the state is entered"),
    ("during", "<td>du: f</td>", "during action: f runs at every wake-up in which the state stays active"),
    ("exit", "<td>ex: f</td>", "exit action: f runs when the state is left"),
    ("previous", "<td>X_p</td>", "output X's value at the previous tick"),
    ("summary", "<td>f …</td>", "a long action, summarised: hover for its whole text"),
    ("handler", "<td>on event / f</td>", "the state's on action: f runs after its during action, when the"
                                          " event wakes the chart; the state stays"),
    ("inner", "<td>↻ [guard] / f</td>", "inner transition of the state to itself: f runs, nothing is left"),
    ("initial", "<td>●───▶</td>", "default transition: where the chart or a compound state starts"),
    ("final", '<td><table border="1" cellborder="1" cellspacing="2" cellpadding="1" style="rounded">'
              '<tr><td style="rounded">final</td></tr></table></td>', "final state: the chart rests there"),
    ("history", "<td>(H)  (H*)</td>",
     "history junction: the compound is entered in the sub-state that was active when it was left"
     " (H*: at every depth)"),
    ("connective", "<td>──○──▶</td>", "connective junction: a path's segments meet; those leaving it are"
                                      " tried in their order"),
    ("junction", "<td>──•──▶</td>", "the same transition from several states, drawn once from the dot"),
    ("closed", f'<td border="1" bgcolor="{CLOSED_FILL}">sub-chart</td>',
     "sub-chart, closed (its own picture shows it open; click); ▸ s: its state s entered from outside,"
     " s ▸: left to the outside"),
    ("stub", f'<td border="1" style="dashed"><font color="{STUB_COLOR}">state</font></td>',
     "a state outside this sub-chart (click for its picture)"),
    ("active", f'<td bgcolor="{ACTIVE_FILL}">state</td>', "active now"),
)


def title_label(title: str) -> str:
    """A picture's title."""
    return f'<<font point-size="16"><b>{html(title)}</b></font>>'


def _legend_table(features: set[str] | None) -> str:
    items = [(symbol, meaning) for feature, symbol, meaning in _LEGEND if features is None or feature in features]
    rows = "".join(f'<tr>{symbol}<td align="left">{html(meaning)}</td></tr>' for symbol, meaning in items)
    return ('<<table border="0" cellborder="0" cellspacing="0" cellpadding="3">'
            f'<tr><td align="left" colspan="2"><b>Legend</b></td></tr>{rows}</table>>')


def legend_dot(features: set[str] | None = None) -> str:
    """A picture of the legend alone (``features``: the rows to show, all by default).

    The charts' pictures carry no legend: a page shows it once (the cockpit, collapsible)
    and a chart's Markdown page lists it once (:func:`legend_markdown`).
    """
    return (f'digraph "legend" {{\n  graph [label={_legend_table(features)}, labelloc="t", labeljust="l",'
            f' fontname={quote(FONT)}, fontsize="10", margin="0"];\n}}\n')


def legend_markdown(features: set[str] | None = None) -> list[str]:
    """The legend as a Markdown table (symbol, meaning)."""
    out = ["| on the picture | meaning |", "|---|---|"]
    for feature, symbol, meaning in _LEGEND:
        if features is None or feature in features:
            text = re.sub(r"<[^>]+>", " ", symbol).replace("&lt;", "<").replace("&gt;", ">")
            out.append(f"| {_LEGEND_WORDS.get(feature, ' '.join(text.split()))} | {meaning} |")
    return out


#: How the Markdown legend names a symbol it cannot draw as text.
_LEGEND_WORDS = {
    "tick": "black arrow", "event": "blue arrow", "final": "double border", "closed": "grey box",
    "stub": "dashed box, grey name", "active": "turquoise box", "initial": "● arrow",
    "connective": "small circle", "junction": "small dot several arrows meet at",
}
