"""The cockpit's HTML pages: each page's file under ``static/`` holds its body; the head they share is written here.

Every page starts alike (the doctype, the character set, the viewport, no
icon to fetch, the cockpit's stylesheet); what differs is its title and its
own stylesheets and script, declared in :data:`HEADS`.  :func:`page` serves a
page: its head from here, then its file, from ``<body>`` to the end.
"""

from __future__ import annotations

from dataclasses import dataclass
from importlib import resources

from starlette.responses import HTMLResponse, Response

#: The head every page shares, up to its own stylesheets and script (``{title}``: the page's).
COMMON_HEAD = """<!doctype html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>ttt_sm — {title}</title>
<link rel="icon" href="data:,">
<link rel="stylesheet" href="/static/cockpit.css">
"""

#: What every page is served with: never cached (a page and its scripts change together), no sniffing, no referrer.
HEADERS = {"Cache-Control": "no-store", "X-Content-Type-Options": "nosniff", "Referrer-Policy": "no-referrer"}


@dataclass(frozen=True)
class PageHead:
    """What a page's head holds of its own: its title (after ``ttt_sm — ``), its stylesheets, its script."""

    title: str
    styles: tuple[str, ...] = ()
    #: The page's module script under ``/static/`` (it imports the rest), or None: a page with no script.
    script: str | None = None

    def html(self) -> str:
        """The page's whole head, ``<!doctype html>`` to ``</head>``."""
        own = [f'<link rel="stylesheet" href="/static/{s}">\n' for s in self.styles]
        if self.script is not None:
            own.append(f'<script type="module" src="/static/{self.script}"></script>\n')
        return COMMON_HEAD.format(title=self.title) + "".join(own) + "</head>\n"


#: Every page, by its file under ``static/``.
HEADS: dict[str, PageHead] = {
    "index.html": PageHead("the robot's pages"),
    "charts.html": PageHead("chart cockpit", script="charts.js"),
    "game.html": PageHead("Tic-tac-toe", ("game.css",), "game.js"),
    "operate.html": PageHead("Operational", ("operate.css",), "operate.js"),
    "kinematics.html": PageHead("kinematics: workspace, DH table, IK race", ("kinematics.css",), "kinematics.js"),
    "kinematics_motion.html": PageHead("kinematics: trajectories and forces",
                                       ("kinematics.css", "kinematics_motion.css"), "kinematics_motion.js"),
    "lab.html": PageHead("lab: live while writing", ("lab.css",), "lab.js"),
}


def page_html(name: str) -> str:
    """Page ``name`` (a key of :data:`HEADS`) as it is served: its head, then its file's body."""
    body = (resources.files("ttt_sm.web") / "static" / name).read_text(encoding="utf-8")
    return HEADS[name].html() + body


def page(name: str) -> Response:
    """The response that serves page ``name``."""
    return HTMLResponse(page_html(name), headers=HEADERS)
