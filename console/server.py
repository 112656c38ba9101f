"""The console's web server: the page, its static files and one WebSocket per page (Starlette on uvicorn).

The page and the socket need the run's token (``?token=``); the page's own files (``/static/``) need it too, in their
URL or in the cookie the page was served with (HttpOnly, SameSite=Strict, named after the port); anything else gets
403. A request from another origin gets 403 whatever its token: a browser says where a request comes from
(``Origin``, on every WebSocket and cross-origin request; ``Sec-Fetch-Site``), and only the console's own page
(``Origin`` the scheme and ``Host`` the request was sent to), an address typed in or a client that says nothing
(``aeroexec``'s tests, curl) are served. Updates are pushed: each
:class:`~aeroexec.console.feed.ConsoleFeed` hands its snapshots to the server's event loop, which sends them to
every page; nothing polls. A page's commands (pause, resume, abort, suspend, inhibit, answer, add, remove, query,
and the changes of the mission: skip, jump, insert, modify, delete, replace, load) go to the
drone's supervisor with the web console as their origin, as ``aeroexec ctl`` sends them. A replay serves a
finished run's records and refuses commands.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import logging
import secrets
import socket
import threading
import time
from http.cookies import CookieError, SimpleCookie
from pathlib import Path
from typing import Any
from urllib.parse import parse_qs

from aeroexec.console.feed import ConsoleFeed

from aeroexec.extras import require

with require("console"):  # without it: the pip line that installs it, not "No module named 'uvicorn'"
    import uvicorn
    from starlette.applications import Starlette
    from starlette.datastructures import Headers
    from starlette.middleware import Middleware
    from starlette.requests import Request
    from starlette.responses import FileResponse, PlainTextResponse, Response
    from starlette.routing import Mount, Route, WebSocketRoute
    from starlette.staticfiles import StaticFiles
    from starlette.types import ASGIApp, Receive, Scope, Send
    from starlette.websockets import WebSocket, WebSocketDisconnect

logger = logging.getLogger(__name__)

STATIC = Path(__file__).with_name("static")
COMMANDS = ("pause", "resume", "abort", "suspend", "inhibit", "answer", "add", "remove", "query", "status", "items",
            "skip", "jump", "insert", "modify", "delete", "replace", "load")
COMMAND_TIMEOUT = 5.0  # s: a command the engine has not served by then is answered as not done
QUEUE_SIZE = 64  # messages waiting for a slow page; past that it skips snapshots until it catches up
MAX_MESSAGE = 64 * 1024  # bytes of one message from a page
ORIGIN = "web console"


class ConsoleError(RuntimeError):
    """The console cannot be served (the port is taken, the server did not start)."""


class _Guard:
    """ASGI middleware: a request :meth:`ConsoleServer.refusal` refuses gets 403 (a WebSocket is closed before it is
    accepted, which its client sees as 403)."""

    def __init__(self, app: ASGIApp, server: ConsoleServer) -> None:
        self.app, self.server = app, server

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        refusal = self.server.refusal(scope) if scope["type"] in ("http", "websocket") else None
        if refusal is None:
            await self.app(scope, receive, send)
        elif scope["type"] == "http":
            await PlainTextResponse(refusal, 403)(scope, receive, send)
        else:
            logger.warning("web console: %s", refusal)
            await WebSocket(scope, receive, send).close(code=1008)


def _cookies(headers: Headers) -> dict[str, str]:
    jar = SimpleCookie()
    with contextlib.suppress(CookieError):
        jar.load(headers.get("cookie", ""))
    return {name: morsel.value for name, morsel in jar.items()}


class ConsoleServer:
    """Serves the console for some drones' feeds (live) or for a finished run's records (replay)."""

    def __init__(self, feeds: dict[str, ConsoleFeed] | None = None, world: dict[str, Any] | None = None,
                 host: str = "127.0.0.1", port: int = 0, token: str | None = None,
                 replay: dict[str, Any] | None = None) -> None:
        self.feeds = dict(feeds or {})
        self.world, self.replay = world, replay
        self.host, self.token = host, token or secrets.token_urlsafe(16)
        self._clients: set[asyncio.Queue[str]] = set()
        self._loop: asyncio.AbstractEventLoop | None = None
        self._unsubscribe: list[Any] = []
        try:
            self._socket = socket.create_server((host, port))
        except OSError as error:
            raise ConsoleError(f"the web console cannot listen on {host}:{port}: {error.strerror or error}") from None
        self.port = self._socket.getsockname()[1]
        app = Starlette(routes=[Route("/", self._page), WebSocketRoute("/ws", self._socket_endpoint),
                                Mount("/static", StaticFiles(directory=STATIC), name="static")],
                        middleware=[Middleware(_Guard, server=self)])
        config = uvicorn.Config(app, log_level="warning", lifespan="off", access_log=False,
                                ws_max_size=MAX_MESSAGE)
        self._server = uvicorn.Server(config)
        self._thread = threading.Thread(target=self._run, name="aeroexec-console", daemon=True)

    @property
    def url(self) -> str:
        host = f"[{self.host}]" if ":" in self.host else self.host
        return f"http://{host}:{self.port}/?token={self.token}"

    def start(self, timeout: float = 10.0) -> ConsoleServer:
        """Serve from a thread of its own; returns once the server listens."""
        self._thread.start()
        deadline = time.monotonic() + timeout
        while not self._server.started:
            if not self._thread.is_alive() or time.monotonic() > deadline:
                raise ConsoleError(f"the web console did not start on {self.host}:{self.port}")
            time.sleep(0.01)
        for feed in self.feeds.values():
            self._unsubscribe.append(feed.subscribe(self._from_engine))
        return self

    def _run(self) -> None:
        try:
            self._server.run(sockets=[self._socket])
        except Exception:
            logger.exception("the web console stopped")

    def close(self, timeout: float = 5.0) -> None:
        """Stop serving; never hangs."""
        for unsubscribe in self._unsubscribe:
            unsubscribe()
        self._server.should_exit = True
        if self._thread.is_alive():
            self._thread.join(timeout)
        with contextlib.suppress(OSError):
            self._socket.close()

    # -- from the engines' threads --------------------------------------------------------------
    def _from_engine(self, message: dict[str, Any]) -> None:
        loop = self._loop
        if loop is not None and not loop.is_closed():
            text = json.dumps(message, separators=(",", ":"))
            with contextlib.suppress(RuntimeError):  # the loop closed meanwhile
                loop.call_soon_threadsafe(self._broadcast, text)

    def _broadcast(self, text: str) -> None:
        for queue in list(self._clients):
            with contextlib.suppress(asyncio.QueueFull):
                queue.put_nowait(text)

    # -- on the server's loop ---------------------------------------------------------------------
    def _authorized(self, token: str | None) -> bool:
        return token is not None and secrets.compare_digest(token.encode(), self.token.encode())

    @property
    def cookie(self) -> str:
        """The name of the cookie holding the token for the page's files (one per port: cookies ignore ports)."""
        return f"aeroexec_console_{self.port}"

    def refusal(self, scope: Scope) -> str | None:
        """Why a request (HTTP or WebSocket) is refused before it reaches its route (None: it goes on)."""
        headers = Headers(scope=scope)
        origin = headers.get("origin")
        if origin is not None:
            secure = scope.get("scheme") in ("https", "wss")
            own = f"{'https' if secure else 'http'}://{headers.get('host', '')}"
            if origin.lower() != own.lower():
                return f"403: a request from another origin ({origin[:200]}) is refused: the console answers its own " \
                       f"page only"
        if headers.get("sec-fetch-site", "same-origin") not in ("same-origin", "none"):
            return "403: a request from another site is refused: the console answers its own page only"
        if scope["path"] in ("/", "/ws"):  # they need the token in their URL
            return None
        query = parse_qs(scope.get("query_string", b"").decode("latin-1"))
        token = (query.get("token") or [None])[0]
        if self._authorized(token) or self._authorized(_cookies(headers).get(self.cookie)):
            return None
        return "403: this console needs its token (the URL aeroexec printed)"

    async def _page(self, request: Request) -> Response:
        if not self._authorized(request.query_params.get("token")):
            return PlainTextResponse("403: this console needs its token (the URL aeroexec printed)", 403)
        response = FileResponse(STATIC / "index.html", headers={"Cache-Control": "no-store"})
        response.set_cookie(self.cookie, self.token, httponly=True, samesite="strict", path="/")
        return response

    async def _socket_endpoint(self, websocket: WebSocket) -> None:
        if not self._authorized(websocket.query_params.get("token")):
            await websocket.close(code=1008)  # before accept: the client gets 403
            return
        self._loop = asyncio.get_running_loop()
        await websocket.accept()
        queue: asyncio.Queue[str] = asyncio.Queue(QUEUE_SIZE)
        await websocket.send_text(json.dumps(self._hello()))
        self._clients.add(queue)
        sender = asyncio.create_task(self._send(websocket, queue))
        try:
            while True:
                text = await websocket.receive_text()
                reply = await self._command(text)
                await queue.put(json.dumps(reply))
        except (WebSocketDisconnect, RuntimeError):
            pass
        finally:
            self._clients.discard(queue)
            sender.cancel()

    async def _send(self, websocket: WebSocket, queue: asyncio.Queue[str]) -> None:
        with contextlib.suppress(WebSocketDisconnect, RuntimeError, asyncio.CancelledError):
            while True:
                await websocket.send_text(await queue.get())

    def _hello(self) -> dict[str, Any]:
        hello: dict[str, Any] = {"type": "hello", "world": self.world, "drones": sorted(self.feeds),
                                 "read_only": self.replay is not None, "replay": self.replay, "latest": {}}
        for name, feed in self.feeds.items():
            hello["latest"][name] = {"snapshot": feed.latest, "events": list(feed.recent)}
        return hello

    async def _command(self, text: str) -> dict[str, Any]:
        try:
            message = json.loads(text)
        except (ValueError, RecursionError):
            return {"type": "result", "ok": False, "message": "not a JSON message"}
        if not isinstance(message, dict):
            return {"type": "result", "ok": False, "message": "a command is a JSON object"}
        reply = {"type": "result", "id": message.get("id"), "command": message.get("command")}
        if self.replay is not None:
            return {**reply, "ok": False, "message": "this console replays a finished run: it takes no commands"}
        command, argument = message.get("command"), message.get("argument", "")
        feed = self.feeds.get(str(message.get("drone")))
        if feed is None:
            return {**reply, "ok": False, "message": f"no drone named {message.get('drone')!r}"}
        if command not in COMMANDS or not isinstance(argument, str):
            return {**reply, "ok": False, "message": f"unknown command {command!r}: expected one of "
                                                     f"{', '.join(COMMANDS)} with a text argument"}
        ticket = feed.engine.supervisor.submit(command, argument, origin=ORIGIN)
        result = await asyncio.to_thread(ticket.wait, COMMAND_TIMEOUT)
        if result is None:
            return {**reply, "ok": False, "message": f"the engine did not serve {command} within {COMMAND_TIMEOUT:g} s"}
        return {**reply, "ok": result.ok, "message": result.message, "data": result.data}
