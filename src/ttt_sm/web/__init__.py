"""The browser cockpit (``ttt-sm gui``): one running session, viewed and driven from web pages.

- :mod:`.session`: the simulation thread over the :class:`~ttt_sm.debug.Debugger`,
  paced, with throttled frames and queued commands;
- :mod:`.frames`: what the pages are sent: the state now, the transitions since the last frame;
- :mod:`.commands`: every command a page may send, its fields declared beside its handler;
- :mod:`.protocol`, :mod:`.fields`: the WebSocket messages a page may send, checked;
- :mod:`.server`: the Starlette app (pages, diagrams, the WebSocket, the token);
- :mod:`.diagrams`, :mod:`.catalogue`, :mod:`.coverage`: what the pages draw;
- ``static/``: the pages, plain HTML, CSS and JavaScript modules, no build step.

See docs/gui.md.
"""
