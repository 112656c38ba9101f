"""The remote surfaces of ``aeroexec run``: the web console (``--web [PORT]``) and Groot2 monitoring
(``--groot [PORT]``), started beside the engine and closed with it."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from aeroexec.cli.console import WEB_HOST_WARNING


class SurfaceError(Exception):
    """A surface that cannot start (its port is taken), phrased for the operator."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_console_arguments(parser)
    parser.add_argument("--groot", nargs="?", type=int, const=1667, metavar="PORT",
                        help="serve tree missions to Groot2 (its publisher protocol on PORT and PORT+1, default 1667)")


def add_console_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--web", nargs="?", type=int, const=0, metavar="PORT",
                        help="serve the operator console in a browser on 127.0.0.1:PORT (a free port without PORT); "
                             "the URL with its token is printed")
    parser.add_argument("--web-host", default="127.0.0.1", metavar="HOST",
                        help="the address the console listens on (default 127.0.0.1: this machine only)")


def wanted(args: argparse.Namespace) -> bool:
    """Whether an operator may watch and answer from a browser (the run is then paced to real time)."""
    return getattr(args, "web", None) is not None


def start_console(args: argparse.Namespace, engine: Any, world: Any, mission_file: str | Path | None) -> Any:
    """The web console of one robot's engine, or None without ``--web``."""
    name = getattr(args, "robot", "drone")  # the robot's kind names it on the map
    return serve_console(args, {name: engine}, world, {name: mission_file})


def serve_console(args: argparse.Namespace, engines: dict[str, Any], world: Any,
                  mission_files: dict[str, str | Path | None] | None = None) -> Any:
    """The web console of several engines by name (a fleet: one map, a drone selector), or None without
    ``--web``; prints its URL with the token."""
    if not wanted(args):
        return None
    from aeroexec.console.feed import ConsoleFeed
    from aeroexec.console.server import ConsoleError, ConsoleServer
    from aeroexec.console.world_map import world_map

    if args.web_host != "127.0.0.1":
        print(WEB_HOST_WARNING.format(host=args.web_host), file=sys.stderr)
    files = mission_files or {}
    feeds = {name: ConsoleFeed(engine, name, files.get(name)) for name, engine in engines.items()}
    try:
        server = ConsoleServer(feeds, world_map(world), host=args.web_host, port=args.web).start()
    except ConsoleError as error:
        for feed in feeds.values():
            feed.close()
        raise SurfaceError(str(error)) from None
    print(f"web console: {server.url}", file=sys.stderr, flush=True)
    return _Closer(*feeds.values(), server)


def start_groot(args: argparse.Namespace, tree_mission: Any, catalog: Any) -> Any:
    """The Groot2 publisher of a tree mission, or None without ``--groot``."""
    if getattr(args, "groot", None) is None:
        return None
    from aeroexec.trees.groot_publisher import GrootPublisher, GrootPublisherError

    try:
        publisher = GrootPublisher(tree_mission, port=args.groot, catalog=catalog)
    except GrootPublisherError as error:
        raise SurfaceError(str(error)) from None
    print(f"Groot2: connect to 127.0.0.1:{args.groot}", file=sys.stderr, flush=True)
    return publisher


class _Closer:
    def __init__(self, *parts: Any) -> None:
        self.parts = parts

    def close(self) -> None:
        for part in self.parts:
            part.close()
