"""The remote surfaces of a flight: the web console (one engine, or a fleet's on one map) and Groot2 monitoring
of a tree mission, started beside the engine and closed with it."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from aeroexec.flight.spec import FlightError

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

WEB_HOST_WARNING = "warning: --web-host {host} serves the console beyond this machine; anyone who has the URL " \
                   "(with its token) can see and command the drone"


def serve_console(engines: dict[str, Any], world: Any, mission_files: dict[str, str | Path | None] | None = None,
                  *, port: int = 0, host: str = "127.0.0.1", notify: Callable[[str], None] = print) -> Any:
    """The web console of engines by name (a fleet: one map, a drone selector) on ``host:port``; says its URL
    with the token to ``notify``. Raises FlightError when it cannot start (its port is taken)."""
    from aeroexec.console.feed import ConsoleFeed
    from aeroexec.console.server import ConsoleError, ConsoleServer
    from aeroexec.console.world_map import world_map

    if host != "127.0.0.1":
        notify(WEB_HOST_WARNING.format(host=host))
    files = mission_files or {}
    feeds = {name: ConsoleFeed(engine, name, files.get(name)) for name, engine in engines.items()}
    try:
        server = ConsoleServer(feeds, world_map(world), host=host, port=port).start()
    except ConsoleError as error:
        for feed in feeds.values():
            feed.close()
        raise FlightError(str(error)) from None
    notify(f"web console: {server.url}")
    return Surfaces(*feeds.values(), server)


def serve_groot(tree_mission: Any, catalog: Any, port: int, notify: Callable[[str], None] = print) -> Any:
    """The Groot2 publisher of a tree mission on ``port`` (and ``port + 1``); raises FlightError when it cannot."""
    from aeroexec.trees.groot.publisher import GrootPublisher, GrootPublisherError

    try:
        publisher = GrootPublisher(tree_mission, port=port, catalog=catalog)
    except GrootPublisherError as error:
        raise FlightError(str(error)) from None
    notify(f"Groot2: connect to 127.0.0.1:{port}")
    return publisher


class Surfaces:
    """Parts closed together, in order; closing twice does nothing."""

    def __init__(self, *parts: Any) -> None:
        self.parts = list(parts)

    def add(self, part: Any) -> Any:
        if part is not None:
            self.parts.append(part)
        return part

    def close(self) -> None:
        parts, self.parts = self.parts, []
        for part in reversed(parts):
            part.close()


__all__ = ["WEB_HOST_WARNING", "Surfaces", "serve_console", "serve_groot"]
