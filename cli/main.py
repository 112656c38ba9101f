# PYTHON_ARGCOMPLETE_OK
"""The ``aeroexec`` command: one sub-command per job (catalog, sim, ...), wiring every layer together.

Shell completion (argcomplete): ``eval "$(register-python-argcomplete aeroexec)"`` in ``~/.bashrc``
(zsh too; fish: ``register-python-argcomplete --shell fish aeroexec | source``).
"""

from __future__ import annotations

import argparse
import contextlib
import gc
import importlib
import os
import re
import sys
import threading

from aeroexec import __version__

# typing and logging are imported when needed, not by ``aeroexec --help`` (~8 ms of its CPU: bench/startup.py)
TYPE_CHECKING = False
if TYPE_CHECKING:
    from collections.abc import Iterator
    from typing import Any

#: Exit statuses: 0 done, 1 refused or failed mission, 2 usage, 3 a run completed with refused requests, 4 a run
#: aborted (engine/supervision/run_status.py), 70 internal error (EX_SOFTWARE), 130 interrupted.
REFUSED, USAGE, INTERNAL_ERROR = 1, 2, 70

#: sub-command -> (module in aeroexec.cli, one-line help)
COMMANDS = {
    "run": ("run", "check a mission (Python, behavior tree or TML), then fly it on the simulator or a MAVSDK drone"),
    "verify": ("verify", "check missions without flying: every error with file:line"),
    "rehearse": ("rehearse", "fly a mission many times in the simulator with wind, battery, noise and link "
                             "variations, on every core or a Dask cluster; an HTML report"),
    "campaign": ("campaign", "fly a seeded campaign of whole flights (missions, operator commands, faults, rules) "
                             "in the simulator and check the invariants every run must keep; replay a seed"),
    "convert": ("convert", "write a mission tree in another format (--to, or -o's extension)"),
    "groot-model": ("groot", "write the catalog's node palette (TreeNodesModel) for Groot2"),
    "catalog": ("catalog", "list a behavior catalog, or check a catalog file"),
    "sim": ("sim", "run the simulated drone behind a MAVLink endpoint (PX4 or ArduPilot) for MAVSDK or QGroundControl"),
    "fleet": ("fleet", "fly every drone of a fleet file (one engine each, linked over Zenoh), or run a Zenoh router"),
    "ctl": ("ctl", "command a running mission from another terminal: pause, resume, abort, inhibit, answer..."),
    "report": ("report", "a flight report from an event log: the path over the world, a timeline, an HTML page"),
    "beliefs": ("beliefs", "query the beliefs an event log ends with, at a prompt"),
    "console": ("console", "replay a finished run in the web console (read-only, with a time slider)"),
    "journal": ("journal", "ask a run's flight journal: a behavior's requests, a belief's changes, the steps done"),
    "export": ("export", "a finished run as an MCAP recording (ROS 2 messages, aeroexec's records) for Foxglove, "
                         "rosbags, ros2 bag"),
}
#: What needs an extra (aeroexec/extras.py): a sub-command, or an option given (by its dest) to any sub-command.
#: Checked once the line is parsed, before anything runs, so a missing extra never stops a flight half-way.
COMMAND_EXTRAS = {"fleet": "fleet", "console": "console", "report": "report", "rehearse": "report", "export": "ros"}
OPTION_EXTRAS = {"fleet": "fleet", "web": "console", "groot": "groot", "mcap": "ros", "foxglove": "foxglove"}


def build_parser(argv: list[str] | None = None) -> argparse.ArgumentParser:
    """The command line's parser. Given ``argv``, only the sub-command it names is imported (none for
    ``aeroexec --help``, which lists the mission formats from their table and nothing more), so a command loads what
    it uses and nothing more; without, every sub-command is."""
    wanted = None if argv is None else next((a for a in argv if not a.startswith("-")), "")
    # a known sub-command (not after -h, which lists them all) has its parser alone: each is ~0.2 ms of every start
    alone = wanted in COMMANDS and not any(a in ("-h", "--help") for a in argv[:argv.index(wanted)])
    parser = CommandLine(prog="aeroexec", description="An execution engine for aerial robot missions.",
                         epilog=" ".join([*([] if wanted else [mission_formats(), *node_kinds()]),
                                          'shell completion: eval "$(register-python-argcomplete aeroexec)"']))
    parser.add_argument("--version", action="version", version=f"aeroexec {__version__}")
    parser.add_argument("-v", "--verbose", action="store_true", help="log debug messages")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, (module_name, help_text) in COMMANDS.items():
        if alone and name != wanted:
            continue
        sub = commands.add_parser(name, help=help_text, description=help_text)
        parser.commands[name] = sub
        if wanted is None or wanted == name:
            module = importlib.import_module(f"aeroexec.cli.{module_name}")
            module.add_arguments(sub)
            sub.set_defaults(run=module.run, sub_command=name)  # ``command`` may be a sub-command's own argument
    return parser


def mission_formats() -> str:
    """The mission formats (``aeroexec.trees.formats``) as the top-level help lists them: read, and written."""
    from aeroexec.trees import formats

    written = ", ".join(f"{fmt.summary} ({', '.join(fmt.suffixes)}; --to {word})"
                        for word, fmt in formats.writable().items())
    return f"Mission formats (run, verify, convert): {formats.described()}. convert writes {written}."


def node_kinds() -> list[str]:
    """The tree node kinds installed packages add (``aeroexec.trees.runtime.kinds``), as the top-level help lists
    them; none when no package adds one (then the node kinds' table, whose manifests import the value conversions,
    is not imported)."""
    from aeroexec.plugins import entry_points_of

    if not entry_points_of("aeroexec.node_kinds"):
        return []
    from aeroexec.trees.runtime.kinds import added

    shown = [f"{kind.name} ({kind.manifest.kind.lower()}, {kind.origin})" for kind in added()]
    return [f"Tree node kinds added by installed packages: {', '.join(shown)}."] if shown else []


_own_process = False  # this process is the ``aeroexec`` command's own (command_line was called)


@contextlib.contextmanager
def lasting() -> Iterator[None]:
    """A block whose objects live as long as the process (a run's set-up: the modules it imports, its world,
    catalog, engine and drone): in the ``aeroexec`` command's own process the cyclic garbage collector is paused
    meanwhile and what was made is frozen after, as :func:`command_line` does for the sub-command's imports (~2 ms of
    an empty run's CPU, ``bench/startup.py``); in a caller's process (a test, an embedding) nothing changes."""
    if not _own_process:
        yield
        return
    collecting = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        gc.freeze()
        if collecting:
            gc.enable()


def command_line(argv: list[str]) -> argparse.ArgumentParser:
    """:func:`build_parser` for the process's own command line (``aeroexec ...``), the cyclic garbage collector
    paused meanwhile: the sub-command's modules are imported then, and what an import makes lives as long as the
    process, so collecting it is wasted work. What was made is then frozen (``gc.freeze``): later collections, the
    engine loop's among them, never walk it again (~7 ms of verify's CPU, ``bench/startup.py``). The methods the
    sub-command's dataclasses are given are compiled once and kept (:mod:`aeroexec.dataclass_cache`: ~0.3 ms of CPU
    per class, ~85 classes in an empty run). A caller that runs :func:`main` with arguments in its own process (a
    test, an embedding) keeps its collector and its :mod:`dataclasses` as they are."""
    global _own_process
    _own_process = True
    collecting = gc.isenabled()
    gc.disable()
    try:
        wanted = next((a for a in argv if not a.startswith("-")), "")
        if wanted in COMMANDS:  # every sub-command builds dataclasses; the top-level help none
            from aeroexec import dataclass_cache

            dataclass_cache.install(wanted)
        return build_parser(argv)
    finally:
        gc.freeze()
        if collecting:
            gc.enable()


class CommandLine(argparse.ArgumentParser):
    """The top-level parser: an option no parser knows is refused by its sub-command's parser (its usage, not
    the top level's), with the closest option it does know: ``--sped 2`` -> ``did you mean --speed?``."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.commands: dict[str, argparse.ArgumentParser] = {}
        # A place south or west after a space (``--home -35.36,149.17``) is a value, as ``-35.36`` is: argparse
        # alone takes only a plain negative number for one, and refused it as an unknown option.
        self._negative_number_matcher = re.compile(r"^-\d+$|^-\d*\.\d+$|^-\d*\.?\d+,")

    def _get_formatter(self) -> argparse.HelpFormatter:
        """argparse's formatter, told the terminal's width (argparse imports :mod:`shutil` to ask it, and shutil
        imports bz2, lzma and zlib: ~3 ms of ``aeroexec --help``)."""
        return self.formatter_class(prog=self.prog, width=terminal_columns() - 2)

    def parse_args(self, args: Any = None, namespace: Any = None) -> argparse.Namespace:  # type: ignore[override]
        args = list(sys.argv[1:] if args is None else args)
        rest: list[str] | None = None
        command = self.commands.get(next((a for a in args if not a.startswith("-")), ""))
        if "--" in args and command is not None and command.get_default("script_args") is not None:
            # what follows a lone -- is the mission's own: a script's arguments (aeroexec run mission.py -- ARGS)
            args, rest = args[:args.index("--")], args[args.index("--") + 1:]
        parsed, unknown = self.parse_known_args(args, namespace)
        if rest is not None:
            parsed.script_args = rest
        if unknown:
            import difflib

            parser = self.commands.get(getattr(parsed, "sub_command", None) or "", self)
            options = [o for action in parser._actions for o in action.option_strings]
            guesses = [difflib.get_close_matches(u.split("=", 1)[0], options, n=1, cutoff=0.6)
                       for u in unknown if u.startswith("-")]
            hint = ", ".join(dict.fromkeys(g[0] for g in guesses if g))
            parser.error(f"unrecognized arguments: {' '.join(unknown)}" + (f" (did you mean {hint}?)" if hint else ""))
        return parsed


def terminal_columns() -> int:
    """The terminal's width as :func:`shutil.get_terminal_size` says it (``COLUMNS``, else standard output's
    terminal, else 80), without importing shutil."""
    try:
        columns = int(os.environ.get("COLUMNS", "0"))
    except ValueError:
        columns = 0
    if columns <= 0:
        try:
            columns = os.get_terminal_size(sys.__stdout__.fileno()).columns  # type: ignore[union-attr]
        except (AttributeError, ValueError, OSError):
            columns = 0
    return columns or 80


def main(argv: list[str] | None = None) -> int:
    """The command's exit status. Ctrl-C before a command has anything to stop is one line and 130; a reader
    that closed standard output (``| head``) ends the command quietly."""
    try:
        status = _main(sys.argv[1:] if argv is None else argv, own_process=argv is None)
        sys.stdout.flush()  # here, not at exit: a reader that is gone is noticed where it is handled
        return status
    except KeyboardInterrupt:
        print("aeroexec: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        _stdout_gone()
        return 0


def _stdout_gone() -> None:
    """Standard output was closed by its reader: what is still buffered for it goes nowhere (Python would
    otherwise complain at exit)."""
    with contextlib.suppress(OSError, ValueError):
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)


def _main(argv: list[str], own_process: bool = False) -> int:
    if "_ARGCOMPLETE" in os.environ:  # the shell asks for completions: every sub-command's options
        import argcomplete

        argcomplete.autocomplete(build_parser())  # answers and exits
    parser = command_line(argv) if own_process else build_parser(argv)
    args = parser.parse_args(argv)
    import logging

    quiet = logging.INFO if getattr(args, "sub_command", None) == "sim" else logging.WARNING  # run prints events
    handler = logging.StreamHandler(sys.stderr)
    from aeroexec.cli.log_lines import OneLineFormatter

    handler.setFormatter(OneLineFormatter("%(levelname)s %(name)s: %(message)s", tracebacks=args.verbose))
    logging.basicConfig(level=logging.DEBUG if args.verbose else quiet, handlers=[handler])
    threading.excepthook = _thread_failed
    if not getattr(args, "run", None):
        parser.print_help()
        return 2
    from aeroexec.engine.errors import CatalogError

    try:
        check_extras(args)
        return int(args.run(args) or 0)
    except _missing_extra() as error:  # an optional part that is not installed: the pip line that adds it
        print(f"aeroexec {args.sub_command}: {error}", file=sys.stderr)
        return USAGE
    except CatalogError as error:  # a --catalog that cannot be loaded: every problem, file:line
        for problem in error.problems:
            print(problem, file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("aeroexec: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        _stdout_gone()
        return 0
    except Exception as error:  # a bug in aeroexec, not a mistake in the input: its own status and one line
        logging.getLogger("aeroexec").debug("internal error", exc_info=True)
        print(internal_error_message(error), file=sys.stderr)
        return INTERNAL_ERROR


def _missing_extra() -> type[Exception]:
    """:class:`~aeroexec.extras.MissingExtra`, imported when a command raised something (an ``except`` clause's class
    is looked up only then)."""
    from aeroexec.extras import MissingExtra

    return MissingExtra


def check_extras(args: argparse.Namespace) -> None:
    """Raise :class:`~aeroexec.extras.MissingExtra` for the first extra the command line needs that is missing."""
    given = {dest for dest in OPTION_EXTRAS if getattr(args, dest, None) is not None}  # --web with no port is 0
    wanted = dict.fromkeys(e for e in (COMMAND_EXTRAS.get(args.sub_command),
                                       *(OPTION_EXTRAS[dest] for dest in sorted(given))) if e)
    if not wanted:
        return  # (aeroexec.extras is not imported: ~1 ms of a verify or a run)
    from aeroexec.extras import MissingExtra, missing

    for extra in wanted:
        if absent := missing(extra):
            raise MissingExtra(extra, absent)


def __getattr__(name: str) -> Any:
    """:class:`~aeroexec.cli.log_lines.OneLineFormatter`, by its old place (made when first asked for: it needs
    :mod:`logging`)."""
    if name == "OneLineFormatter":
        from aeroexec.cli.log_lines import OneLineFormatter

        return OneLineFormatter
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


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
    import logging

    logging.getLogger("aeroexec").debug("thread %s failed", getattr(hook.thread, "name", "?"),
                                        exc_info=(hook.exc_type, hook.exc_value, hook.exc_traceback))
    logging.getLogger("aeroexec").error("%s", internal_error_message(
        hook.exc_value, f"the thread {getattr(hook.thread, 'name', '?')}"))


if __name__ == "__main__":
    sys.exit(main())
