"""The cockpit's web server: pages, diagrams and one WebSocket over one :class:`~.session.Session`.

An ASGI app on Starlette, served by uvicorn (``ttt-sm gui``).  Starlette
because the cockpit needs exactly its pieces and little else: routes, a
WebSocket endpoint, static files served from the package, a lifespan to start
and stop the session, and a test client that speaks the same ASGI (the
protocol tests run without a browser or a socket).

Routes: ``/`` (links every page), ``/charts`` (the chart cockpit), ``/game``
(the Tic-tac-toe page, :mod:`.game`; its camera picture ``/api/game/photo.png``),
``/api/arm/ink.png`` (the whiteboard's ink under the arm's top view, :mod:`.arm_view`),
``/api/camera/frame.png`` (the newest picture of ``--camera``, :mod:`.camera_feed`),
``/operate`` (the Operational page, :mod:`.operate`),
``/kinematics`` and ``/api/kinematics/<view>`` (the kinematics lab: workspace, DH table, IK race, :mod:`.kinematics`),
``/kinematics/motion`` and ``/api/kinematics/motion/<view>`` (trajectories and forces, :mod:`.kinematics_motion`),
``/lab`` and ``/api/lab`` (with ``ttt-sm gui --lab``: the student's chart live while they write it, :mod:`.lab_watch`),
``/static/...`` (the pages' scripts and styles, from the package: nothing from
a CDN, no build step), ``/api/diagram/{chart}?view=&open=`` (an annotated
SVG, :mod:`.diagrams`), ``/api/trace.jsonl`` (the trace so far), ``/ws``.

Safe by default (:mod:`.access`; docs/gui.md, "Threat model"):

* the server binds 127.0.0.1; every start, loopback included, makes a token,
  printed in the URL at start (``?token=...``, as Jupyter does); a request
  with it gets a cookie, one without it gets 403 (a WebSocket: closed, 1008),
  except the pages' scripts and styles under ``/static/``;
* the ``Host`` header must name this server by an address or name of the
  interfaces it listens on (no DNS rebinding), and a WebSocket's ``Origin``,
  when a browser sends one, must be this server's;
* every WebSocket message is checked by :mod:`.protocol` before the session
  sees it; a bad one gets an ``error`` reply naming what was wrong (and
  echoing its ``id``) and the connection goes on;
* a request that needs the session (``/api/arm/ink.png``) waits for it
  :data:`SESSION_WAIT_S` at most, holding no thread, then gets 503; the
  other routes never wait for it.
"""

from __future__ import annotations

import asyncio
import contextlib
import hmac
import threading
import time
from collections.abc import AsyncIterator, Callable, Iterable
from importlib import resources
from typing import Any
from urllib.parse import urlsplit

from starlette.applications import Starlette
from starlette.requests import HTTPConnection, Request
from starlette.responses import JSONResponse, PlainTextResponse, Response, StreamingResponse
from starlette.routing import Mount, Route, WebSocketRoute
from starlette.staticfiles import StaticFiles
from starlette.types import ASGIApp, Receive, Scope, Send
from starlette.websockets import WebSocket, WebSocketDisconnect

from ..debug.debugger import Debugger
from ..runtime.errors import GraphvizMissingError
from .access import PUBLIC_PREFIXES, cookie_name, port_of
from .arm_view import ink_picture, png
from .camera_feed import feed_png
from .diagrams import DiagramError, Diagrams
from .game import photo_png
from .kinematics import routes as kinematics_routes
from .kinematics_motion import routes as kinematics_motion_routes
from .lab_watch import LabWatch
from .page_heads import page
from .protocol import MAX_MESSAGE_BYTES, ProtocolError, parse_command
from .session import Session

#: Messages queued for one page at most; a page that falls further behind gets a full frame again.
CLIENT_QUEUE = 64
#: Messages one page's WebSocket is read at, at most, a second (in bursts of as many): past it the server
#: reads that page's socket no faster, so a flood waits in its own connection and never takes the server's
#: thread (and with it the simulation's share of the interpreter) from the other pages.
MESSAGE_RATE = 500
#: When the session dies, ``ttt-sm gui`` stops its server once the pages have their messages (the last one
#: says why), waiting at most this long, s.
SEND_OUT_S = 5.0
#: How long a request that needs the session (``/api/arm/ink.png``) waits for it, seconds; then 503.
SESSION_WAIT_S = 5.0
#: Such requests waiting for the session at once, at most; one more gets 503 at once.
SESSION_WAITERS = 8


class SessionBusy(Exception):
    """The session did not answer a request in time (or no longer runs): the route answers 503."""


def static_dir() -> str:
    """The pages' files, inside the package."""
    return str(resources.files("ttt_sm.web") / "static")


class Guard:
    """ASGI middleware: the token (when there is one) and the Host header, for HTTP and WebSocket
    (:mod:`.access`).  The pages' scripts and styles (``/static/``) need the Host only."""

    def __init__(self, app: ASGIApp, token: str | None, hosts: Iterable[str]) -> None:
        self.app = app
        self.token = token
        self.hosts = {h.lower() for h in hosts}

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] not in ("http", "websocket"):
            await self.app(scope, receive, send)
            return
        conn = HTTPConnection(scope)
        host = conn.headers.get("host", "").lower()
        if self.hosts and host not in self.hosts:
            await self._refuse(scope, receive, send, f"host {host!r} is not this server")
            return
        if self.token is None or str(scope.get("path", "")).startswith(PUBLIC_PREFIXES):
            await self.app(scope, receive, send)
            return
        cookie = cookie_name(port_of(host))
        given = conn.query_params.get("token") or conn.cookies.get(cookie)
        if not (given and hmac.compare_digest(given.encode(), self.token.encode())):
            await self._refuse(scope, receive, send, "this cockpit needs its token: open the URL that"
                                                     " `ttt-sm gui` printed (it ends in ?token=...)")
            return
        if conn.query_params.get("token") and scope["type"] == "http":
            token = self.token

            async def send_with_cookie(message: Any) -> None:
                if message["type"] == "http.response.start":
                    headers = list(message.get("headers", []))
                    headers.append((b"set-cookie", f"{cookie}={token}; Path=/; HttpOnly;"
                                                   f" SameSite=Strict".encode()))
                    message = {**message, "headers": headers}
                await send(message)

            await self.app(scope, receive, send_with_cookie)
            return
        await self.app(scope, receive, send)

    @staticmethod
    async def _refuse(scope: Scope, receive: Receive, send: Send, why: str) -> None:
        if scope["type"] == "websocket":
            await send({"type": "websocket.close", "code": 1008, "reason": why[:120]})
            return
        await PlainTextResponse(f"403 Forbidden: {why}\n", status_code=403)(scope, receive, send)


def origin_ok(origin: str | None, host: str) -> bool:
    """A WebSocket's Origin must be this server (a page of another site may not drive the robot)."""
    if origin is None:
        return True  # not a browser: the token (checked before, by Guard) and the Host check apply
    parts = urlsplit(origin)
    return parts.scheme in ("http", "https") and parts.netloc.lower() == host.lower()


def create_app(session: Session, *, token: str | None = None, hosts: Iterable[str] = (),
               manage_session: bool = True, lab: LabWatch | None = None) -> Starlette:
    """The cockpit's ASGI app over ``session``.

    ``token``: required on every request but ``/static/`` when given (``ttt-sm
    gui`` always sets one).  ``hosts``: the ``host[:port]`` values the Host
    header may take (empty: any; :func:`.access.allowed_hosts`).  ``manage_session``: start the session with
    the app and stop it (saving the trace) when the app shuts down.
    ``lab``: a student's chart watched and reloaded into the session (the
    ``/lab`` page), started and stopped with the app.
    """
    diagrams = Diagrams(session.chart_classes)
    if lab is not None:
        lab.attach(session, diagrams)

    async def index(request: Request) -> Response:
        return page("index.html")

    async def charts(request: Request) -> Response:
        return page("charts.html")

    async def game(request: Request) -> Response:
        return page("game.html")

    async def operate(request: Request) -> Response:
        return page("operate.html")

    async def kinematics_page(request: Request) -> Response:
        return page("kinematics.html")

    async def lab_page(request: Request) -> Response:
        if lab is None:
            return PlainTextResponse("no lab here: start the cockpit with ttt-sm gui --lab DIR\n", status_code=404)
        return page("lab.html")

    async def lab_state(request: Request) -> Response:
        if lab is None:
            return JSONResponse({"error": "no lab here: start the cockpit with ttt-sm gui --lab DIR"}, status_code=404)
        return JSONResponse(lab.state(), headers={"Cache-Control": "no-store"})

    async def game_photo(request: Request) -> Response:
        png = await asyncio.to_thread(photo_png, session.debugger)
        if png is None:
            return PlainTextResponse("no photo yet: the camera looks after each move\n", status_code=404)
        return Response(png, media_type="image/png", headers={"Cache-Control": "no-store"})

    waiting = 0

    async def in_session(fn: Callable[[Debugger], Any]) -> Any:
        """``fn(debugger)`` in the simulation thread, between two control steps; :class:`SessionBusy` if the
        session does not answer within :data:`SESSION_WAIT_S` (no thread is held while it waits)."""
        nonlocal waiting
        if session.error is not None:
            raise SessionBusy(session.error)
        if waiting >= SESSION_WAITERS:
            raise SessionBusy(f"{waiting} requests wait for the session already")
        loop = asyncio.get_running_loop()
        answer: asyncio.Future[Any] = loop.create_future()
        gave_up = threading.Event()

        def settle(value: Any, error: BaseException | None) -> None:
            if answer.done():
                return
            if error is not None:
                answer.set_exception(error)
            else:
                answer.set_result(value)

        def answered(value: Any, error: BaseException | None) -> None:  # in the simulation thread
            loop.call_soon_threadsafe(settle, value, error)

        waiting += 1
        try:
            session.call_soon(fn, answered, wanted=lambda: not gave_up.is_set())
            return await asyncio.wait_for(answer, SESSION_WAIT_S)
        except TimeoutError:
            gave_up.set()
            raise SessionBusy(f"the session did not answer within {SESSION_WAIT_S:g} s") from None
        finally:
            waiting -= 1

    def busy(exc: SessionBusy) -> Response:
        return PlainTextResponse(f"503 Service Unavailable: {exc}; try again\n", status_code=503,
                                 headers={"Retry-After": "1", "Cache-Control": "no-store"})

    async def arm_ink(request: Request) -> Response:
        # drawn in the simulation thread, between two control steps (never a half-inked stroke), encoded here
        try:
            image = await in_session(lambda d: ink_picture(d.robot))
        except SessionBusy as exc:
            return busy(exc)
        data = await asyncio.to_thread(png, image)
        return Response(data, media_type="image/png", headers={"Cache-Control": "no-store"})

    async def camera_frame(request: Request) -> Response:
        png = await asyncio.to_thread(feed_png, session.camera_feed)
        if png is None:
            return PlainTextResponse("no picture: no --camera, none grabbed yet, or a camera that sends"
                                     " percentages only\n", status_code=404)
        return Response(png, media_type="image/png", headers={"Cache-Control": "no-store"})

    async def diagram(request: Request) -> Response:
        chart = request.path_params["chart"]
        key = request.query_params.get("view", "overview")
        opened = tuple(x for x in request.query_params.get("open", "").split(",") if x)
        try:
            svg = await asyncio.to_thread(diagrams.svg, chart, key, opened)
        except DiagramError as exc:
            return PlainTextResponse(f"{exc}\n", status_code=404)
        except GraphvizMissingError as exc:
            return PlainTextResponse(f"{exc}\n", status_code=503)
        return Response(svg, media_type="image/svg+xml", headers={"Cache-Control": "no-store"})

    async def trace(request: Request) -> Response:
        streamed = session.debugger.trace_file
        headers = {"Content-Disposition": 'attachment; filename="trace.jsonl"'}
        if streamed is not None and not streamed.closed:  # the whole trace, as written so far, a MB at a time
            path = streamed.path
            size = await asyncio.to_thread(lambda: path.stat().st_size)

            async def chunks() -> AsyncIterator[bytes]:
                with open(path, "rb") as f:
                    left = size
                    while left > 0:
                        data = await asyncio.to_thread(f.read, min(1 << 20, left))
                        if not data:
                            return
                        left -= len(data)
                        yield data

            return StreamingResponse(chunks(), media_type="application/x-ndjson", headers=headers)
        records = list(session.debugger.trace.records)  # the transitions kept in memory
        body = "".join(r.to_json() + "\n" for r in records)
        return Response(body, media_type="application/x-ndjson", headers=headers)

    outboxes: set[asyncio.Queue[str | None]] = set()  # every page's messages waiting for its socket
    sending = [0]  # messages being written to a socket now
    loops: list[asyncio.AbstractEventLoop] = []  # the server's loop, once it runs

    async def _sent_out(deadline: float) -> None:
        loop = asyncio.get_running_loop()
        while (sending[0] or any(not box.empty() for box in list(outboxes))) and loop.time() < deadline:
            await asyncio.sleep(0.01)

    def flush_pages(timeout_s: float = SEND_OUT_S) -> bool:
        """From another thread: wait until every page's messages queued so far are written to its socket, at
        most ``timeout_s``; whether they were.  ``ttt-sm gui`` calls it when the session died, before it stops
        the server (whose shutdown drops what a page has not been sent): the pages hear why first."""
        if not loops or loops[0].is_closed():
            return False
        loop = loops[0]
        # the messages the dying thread sent are handed to the loop with call_soon_threadsafe: this coroutine,
        # scheduled the same way after them, finds them in the outboxes
        future = asyncio.run_coroutine_threadsafe(_sent_out(loop.time() + timeout_s), loop)
        try:
            future.result(timeout_s + 1.0)
        except Exception:  # noqa: BLE001  timed out or the loop went: the server stops anyway
            future.cancel()
            return False
        return True

    async def ws(websocket: WebSocket) -> None:
        host = websocket.headers.get("host", "")
        if not origin_ok(websocket.headers.get("origin"), host):
            await websocket.close(code=1008, reason="the Origin is not this server")
            return
        await websocket.accept()
        loop = asyncio.get_running_loop()
        outbox: asyncio.Queue[str | None] = asyncio.Queue(maxsize=CLIENT_QUEUE)
        lagging = False

        def put(text: str) -> None:
            nonlocal lagging
            try:
                outbox.put_nowait(text)
            except asyncio.QueueFull:
                lagging = True

        def send_threadsafe(text: str) -> None:
            loop.call_soon_threadsafe(put, text)

        cid = session.pages.connect(send_threadsafe)
        outboxes.add(outbox)

        async def pump() -> None:
            nonlocal lagging
            while True:
                text = await outbox.get()
                if text is None:
                    return
                sending[0] += 1
                try:
                    await websocket.send_text(text)
                finally:
                    sending[0] -= 1
                if lagging and outbox.empty():
                    lagging = False  # dropped frames: join again for a full frame
                    session.submit(cid, parse_command('{"type": "hello"}'))

        sender = asyncio.create_task(pump())
        allowance, checked = float(MESSAGE_RATE), loop.time()
        try:
            while True:
                now = loop.time()
                allowance = min(float(MESSAGE_RATE), allowance + (now - checked) * MESSAGE_RATE)
                checked = now
                if allowance < 1.0:  # this page sends faster than it may: read it no faster (its TCP waits)
                    await asyncio.sleep((1.0 - allowance) / MESSAGE_RATE)
                    continue
                allowance -= 1.0
                message = await websocket.receive()
                if message["type"] == "websocket.disconnect":
                    break
                if session.pages.refusing(cid, time.perf_counter()):
                    continue  # refused anyway: dropped before it is parsed, the page told once a window
                raw = message.get("text")
                if raw is None:
                    raw = message.get("bytes") or b""
                try:
                    command = parse_command(raw)
                except ProtocolError as exc:
                    session.send_to(cid, {"type": "error", "id": exc.msg_id, "command": exc.command,
                                          "error": str(exc)})
                    continue
                session.submit(cid, command)
        except WebSocketDisconnect:
            pass
        finally:
            session.pages.disconnect(cid)
            outboxes.discard(outbox)
            with contextlib.suppress(asyncio.QueueFull):
                outbox.put_nowait(None)
            sender.cancel()
            with contextlib.suppress(asyncio.CancelledError, Exception):
                await sender

    @contextlib.asynccontextmanager
    async def lifespan(app: Starlette) -> AsyncIterator[None]:
        loops[:] = [asyncio.get_running_loop()]
        if manage_session:
            session.start()
        if lab is not None:
            lab.start()
        try:
            yield
        finally:
            if lab is not None:
                await asyncio.to_thread(lab.stop)
            if manage_session:
                saved = await asyncio.to_thread(session.stop)
                if saved is not None and session.debugger.trace_failure is None:  # else ttt-sm gui says why
                    print(f"ttt-sm gui: trace saved to {saved} ({session.debugger.trace.count}"
                          " transitions)", flush=True)

    routes = [
        Route("/", index),
        Route("/charts", charts),
        Route("/game", game),
        Route("/api/game/photo.png", game_photo),
        Route("/api/arm/ink.png", arm_ink),
        Route("/api/camera/frame.png", camera_frame),
        Route("/operate", operate),
        Route("/lab", lab_page),
        Route("/kinematics", kinematics_page),
        *kinematics_routes(lambda: session.params),
        *kinematics_motion_routes(lambda: session.params, page),
        Route("/api/lab", lab_state),
        Route("/api/diagram/{chart}", diagram),
        Route("/api/trace.jsonl", trace),
        WebSocketRoute("/ws", ws),
        Mount("/static", app=StaticFiles(directory=static_dir()), name="static"),
    ]
    app = Starlette(routes=routes, lifespan=lifespan)
    app.add_middleware(Guard, token=token, hosts=list(hosts))
    app.state.session = session
    app.state.flush_pages = flush_pages
    app.state.max_message_bytes = MAX_MESSAGE_BYTES
    return app
