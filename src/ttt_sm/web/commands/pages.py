"""A page joins the session (``hello``)."""

from __future__ import annotations

from ..fields import identifier, optional
from .spec import Cockpit, command


@command("hello", page=optional(identifier, "charts"))
def hello(session: Cockpit, cid: int, page: str) -> None:
    """A page joins: the session answers with ``session`` (what it runs) and a full ``frame``, then sends it
    every frame."""
    session.join(cid, page)
