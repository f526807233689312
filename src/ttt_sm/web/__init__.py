"""The browser cockpit (``ttt-sm gui``): one running session, viewed and driven from web pages.

- :mod:`.session`: the simulation thread over the :class:`~ttt_sm.debug.Debugger`,
  paced, with throttled frames and queued commands;
- :mod:`.protocol`: the WebSocket messages a page may send, checked;
- :mod:`.server`: the Starlette app (pages, diagrams, the WebSocket, the token);
- :mod:`.diagrams`, :mod:`.catalogue`, :mod:`.coverage`: what the pages draw;
- ``static/``: the pages, plain HTML, CSS and JavaScript modules, no build step.

See docs/gui.md.
"""
