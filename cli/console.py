"""``aeroexec console RUN_DIR|LOG``: a finished run in the web console, read-only, with a time slider."""

from __future__ import annotations

import argparse
import sys
import threading


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("run_dir", metavar="RUN_DIR|LOG", help="a run's output folder or its events.jsonl")
    parser.add_argument("--port", type=int, default=0, help="the port to serve on (default: a free one)")
    parser.add_argument("--web-host", default="127.0.0.1", metavar="HOST",
                        help="the address to serve on (default 127.0.0.1: this machine only)")
    parser.add_argument("--world", metavar="FILE", help="the world the run flew in (default: the log's, else the "
                                                         "built-in one)")


def run(args: argparse.Namespace) -> int:
    from aeroexec.cli.report import world_of_run
    from aeroexec.console.server import ConsoleError, ConsoleServer
    from aeroexec.console.world_map import world_map
    from aeroexec.flight.replay import ReplayError, replay_of
    from aeroexec.flight.surfaces import WEB_HOST_WARNING

    try:
        replay = replay_of(args.run_dir)
        world = world_of_run(replay, args.world)
        if isinstance(world, str):
            raise ReplayError(world)
        if args.web_host != "127.0.0.1":
            print(WEB_HOST_WARNING.format(host=args.web_host), file=sys.stderr)
        server = ConsoleServer(world=world_map(world), host=args.web_host, port=args.port, replay=replay).start()
    except (ReplayError, ConsoleError) as error:
        print(error, file=sys.stderr)
        return 1
    print(f"web console: {server.url}", flush=True)
    print("replaying a finished run; Ctrl-C stops", file=sys.stderr)
    try:
        threading.Event().wait()
    except KeyboardInterrupt:
        pass
    finally:
        server.close()
    return 0
