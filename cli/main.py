"""The ``aeroexec`` command: one sub-command per job (catalog, sim, ...), wiring every layer together."""

from __future__ import annotations

import argparse
import importlib
import logging
import sys
import threading

from aeroexec.engine.errors import CatalogError

from aeroexec import __version__

#: Exit statuses: 0 done, 1 refused or failed mission, 2 usage, 70 internal error (EX_SOFTWARE), 130 interrupted.
REFUSED, USAGE, INTERNAL_ERROR = 1, 2, 70

#: sub-command -> (module in aeroexec.cli, one-line help)
COMMANDS = {
    "run": ("run", "check a mission (Python or behavior tree), then fly it on the simulator or a MAVSDK drone"),
    "verify": ("verify", "check missions without flying: every error with file:line"),
    "groot-model": ("groot", "write the catalog's node palette (TreeNodesModel) for Groot2"),
    "catalog": ("catalog", "list a behavior catalog, or check a catalog file"),
    "sim": ("sim", "run the simulated drone behind a MAVLink (PX4) endpoint for MAVSDK or QGroundControl"),
    "ctl": ("ctl", "command a running mission from another terminal: pause, resume, abort, inhibit, answer..."),
    "report": ("report", "a flight report from an event log: the path over the world, a timeline, an HTML page"),
    "beliefs": ("beliefs", "query the beliefs an event log ends with, at a prompt"),
}


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="aeroexec", description="An execution engine for aerial robot missions.")
    parser.add_argument("--version", action="version", version=f"aeroexec {__version__}")
    parser.add_argument("-v", "--verbose", action="store_true", help="log debug messages")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, (module_name, help_text) in COMMANDS.items():
        module = importlib.import_module(f"aeroexec.cli.{module_name}")
        sub = commands.add_parser(name, help=help_text, description=help_text)
        module.add_arguments(sub)
        sub.set_defaults(run=module.run)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    quiet = logging.INFO if args.command == "sim" else logging.WARNING  # run prints events, not log lines
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(OneLineFormatter("%(levelname)s %(name)s: %(message)s", tracebacks=args.verbose))
    logging.basicConfig(level=logging.DEBUG if args.verbose else quiet, handlers=[handler])
    threading.excepthook = _thread_failed
    if not getattr(args, "run", None):
        parser.print_help()
        return 2
    try:
        return int(args.run(args) or 0)
    except CatalogError as error:  # a --catalog that cannot be loaded: every problem, file:line
        for problem in error.problems:
            print(problem, file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return 130
    except Exception as error:  # a bug in aeroexec, not a mistake in the input: its own status and one line
        logging.getLogger("aeroexec").debug("internal error", exc_info=True)
        print(internal_error_message(error), file=sys.stderr)
        return INTERNAL_ERROR


class OneLineFormatter(logging.Formatter):
    """Log lines without tracebacks (unless ``-v``): a failure inside a background task is one line with its reason."""

    def __init__(self, fmt: str, tracebacks: bool = False) -> None:
        super().__init__(fmt)
        self.tracebacks = tracebacks

    def format(self, record: logging.LogRecord) -> str:
        if self.tracebacks or not record.exc_info or record.exc_info[1] is None:
            return super().format(record)
        error = record.exc_info[1]
        saved = record.exc_info, record.exc_text
        record.exc_info, record.exc_text = None, None
        try:
            line = super().format(record)
        finally:
            record.exc_info, record.exc_text = saved
        detail = " ".join(str(error).split())[:200]
        return f"{line} ({type(error).__name__}{': ' + detail if detail else ''}; -v shows the traceback)"


def internal_error_message(error: BaseException, where: str = "") -> str:
    """The one line an internal error prints: what broke, and a request to report it."""
    detail = " ".join(str(error).split())
    detail = detail if len(detail) <= 200 else detail[:197] + "..."
    place = f" in {where}" if where else ""
    return (f"aeroexec: internal error{place} ({type(error).__name__}{': ' + detail if detail else ''}); this is a "
            f"bug in aeroexec, not in your input: please report it with the command you ran (-v shows the traceback)")


def _thread_failed(hook: threading.ExceptHookArgs) -> None:
    """A background thread that dies says so in one logged line, never with a traceback on stderr."""
    if hook.exc_type is SystemExit or hook.exc_value is None:
        return
    logging.getLogger("aeroexec").debug("thread %s failed", getattr(hook.thread, "name", "?"),
                                        exc_info=(hook.exc_type, hook.exc_value, hook.exc_traceback))
    logging.getLogger("aeroexec").error("%s", internal_error_message(
        hook.exc_value, f"the thread {getattr(hook.thread, 'name', '?')}"))


if __name__ == "__main__":
    sys.exit(main())
