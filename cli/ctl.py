"""``aeroexec ctl COMMAND``: command a running ``aeroexec run`` from another terminal, over its control socket.

Without options, the one live run of this user, wherever it was started (each run lists itself in the per-user
runtime directory, ``$XDG_RUNTIME_DIR/aeroexec/``, from the moment it starts); with several live runs nothing is
sent: they are listed and one must be named. ``aeroexec ctl list`` shows them. ``--run DIR`` names a run by its
output folder (its ``control.json`` holds the port and token) or by its process id; ``--port P --token T``
skips the files. Every answer names the run it comes from (a wrong token gets only "refused: wrong token"). The
changes of the running mission (skip, jump, insert, modify, delete, replace, load) send their words as a shell line,
so a name or a fragment with spaces stays one word, and a file to load by its full path; a refusal's problems follow
it, one a line.
"""

from __future__ import annotations

import argparse
import json
import os
import shlex
import sys
from pathlib import Path
from typing import Any

from aeroexec.engine.supervision.output import DEFAULT_BASE
from aeroexec.flight.control import CONTROL_FILE, live_runs, read_control_file, send_command
from aeroexec.flight.signals import ending_signals

COMMANDS = {
    "pause": "stop the mission where it is; the drone hovers",
    "resume": "go on with the mission",
    "abort": "stop every behavior and the mission, then land",
    "suspend": "stop the mission as abort does, to go on later (a battery swap): the run ends suspended and "
               "aeroexec run --resume RUN_DIR continues it",
    "inhibit": "NAME: stop a behavior and keep reactions from starting it again",
    "answer": "TEXT: answer the oldest question the drone asked (ASK_OPERATOR)",
    "add": "BELIEF: add a belief, e.g. visible(marker_3)",
    "remove": "PATTERN: remove the beliefs matching a pattern, e.g. visible(?x)",
    "status": "where the run is: state, active behaviors, questions, drone",
    "query": "EXPRESSION: what the drone believes, e.g. object(?X, aruco)",
    "items": "the mission's items: number, name, done, running or to come",
    "skip": "end the item running now (SKIPPED) and go on with the next one",
    "jump": "TARGET: go on from an item (its number) or a node (its name)",
    "insert": "before|after TARGET FRAGMENT: new items, e.g. insert after 5 'GO_TO_POINT COORDINATES=\"1, 2, 5\"'",
    "modify": "TARGET PORT=VALUE...: new values for an item's ports, e.g. modify 7 SPEED=3",
    "delete": "TARGET: take an item out of the mission",
    "replace": "TARGET FRAGMENT: put FRAGMENT (XML or BEHAVIOR PORT=VALUE) in the place of an item or subtree",
    "load": "FILE: fly a new mission (any format) in place of the running one",
    "update": "ACTION [ITEM_ID] [FILE|FRAGMENT]: an Aerostack2 mission update (LOAD, START, PAUSE, RESUME, STOP, "
              "NEXT_ITEM, REPEAT, INSERT, MODIFY, REMOVE...; item ids from 0) as the change it means",
    "list": "the live runs of this user, wherever they were started",
}
#: Changes of the mission: their argument is sent as a shell line (quoting kept), a file to load by its full path.
CHANGES = {"skip", "jump", "insert", "modify", "delete", "replace", "load", "update"}
NEEDS_ARGUMENT = {"inhibit", "answer", "add", "remove", "query", *(CHANGES - {"skip"})}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--run", dest="run_dir", metavar="DIR|PID",
                        help="the run's output folder or process id (default: the one live run of this user; "
                             "with several, name one: see aeroexec ctl list)")
    parser.add_argument("--port", type=int, metavar="P", help="the run's control port (with --token)")
    parser.add_argument("--token", metavar="T", help="the run's control token (with --port)")
    parser.add_argument("--json", action="store_true", help="print the answer as JSON")
    parser.add_argument("--fleet", metavar="NAME", help="command the drones of fleet NAME over Zenoh")
    parser.add_argument("--drone", metavar="D", help="only drone D of the fleet (default: every drone)")
    parser.add_argument("--connect", action="append", metavar="ENDPOINT",
                        help="the fleet's endpoint (default: from the fleet's fleet.json)")
    parser.add_argument("--credentials", metavar="DIR|CERT",
                        help="the operator's identity for --fleet: a folder holding operator.pem, operator.key and "
                             "the fleet's ca.pem, or the certificate file (default: from the fleet's fleet.json)")
    parser.add_argument("--stdin", action="store_true",
                        help="with --fleet: read commands from standard input, one a line (COMMAND [ARGUMENT] "
                             "[--drone D]), through links to the fleet opened once and kept (a ground station's "
                             "console: no handshakes before each command); with --json one answer a line")
    parser.add_argument("command", choices=list(COMMANDS), metavar="COMMAND", nargs="?",
                        help="; ".join(f"{name} {text}" for name, text in COMMANDS.items()))
    parser.add_argument("argument", nargs="*", help="the command's argument (NAME, TEXT, BELIEF, PATTERN, TARGET, "
                                                    "FRAGMENT or FILE; quote what holds spaces)")


def run(args: argparse.Namespace) -> int:
    if args.stdin:
        if not args.fleet or args.command:
            print("aeroexec ctl --stdin reads a fleet's commands from standard input: give --fleet NAME and no "
                  "COMMAND", file=sys.stderr)
            return 2
        with ending_signals():  # SIGTERM and SIGHUP as Ctrl-C: the links to the fleet closed before the exit
            return fleet_commands(args, sys.stdin)
    if args.command is None:
        print(f"aeroexec ctl: give a COMMAND ({', '.join(COMMANDS)})", file=sys.stderr)
        return 2
    argument = command_argument(args.command, args.argument)
    if args.command == "list":
        runs = live_runs()
        for live in runs:
            print(live)
        if not runs:
            print("no live run", file=sys.stderr)
        return 0 if runs else 1
    if args.command in NEEDS_ARGUMENT and not argument:
        print(f"aeroexec ctl {args.command}: {COMMANDS[args.command]}; give the argument", file=sys.stderr)
        return 2
    if args.fleet:
        with ending_signals():
            return fleet_command(args, argument)
    try:
        port, token = endpoint(args)
    except AmbiguousRun as error:
        print(error, file=sys.stderr)
        return 2
    except ValueError as error:
        print(error, file=sys.stderr)
        return 1
    try:
        answer = send_command(port, token, args.command, argument)
    except (OSError, ValueError) as error:
        print(f"cannot reach the run on port {port}: {error}{_stale_hint(args)}", file=sys.stderr)
        return 1
    if args.json:
        print(json.dumps(answer, indent=2))
    elif answer.get("ok"):
        print(f"{run_name(answer)}{answer.get('message', 'ok')}")
        if "position" in answer.get("status", {}):
            print(describe_status(answer["status"]))
        for unification in answer.get("answers", []):
            print("  " + (", ".join(f"{k} = {v}" for k, v in unification.items()) or "true"))
        print(describe_items(answer.get("items", [])), end="")
    else:
        print(f"{run_name(answer)}refused: {answer.get('error', 'no reason given')}", file=sys.stderr)
        for problem in answer.get("problems", [])[1:]:
            print(f"  {problem}", file=sys.stderr)
    return 0 if answer.get("ok") else 1


def command_argument(command: str, words: list[str]) -> str:
    """A command's argument as the run reads it (a change's: :func:`change_argument`)."""
    return change_argument(command, words) if command in CHANGES else " ".join(words)


def change_argument(command: str, words: list[str]) -> str:
    """A change's argument as the run reads it: the words as a shell line (a name or fragment with spaces stays one
    word), a file to load by its full path (the run may work in another folder)."""
    if command == "load" and words:
        return shlex.quote(str(Path(" ".join(words)).expanduser().resolve()))
    if command == "update" and words and words[0].upper() in ("LOAD", "EXECUTE", "RESET") and words[1:]:
        item = words[1:2] if words[1].isdigit() else []
        mission = " ".join(words[1 + len(item):])
        if not mission.strip():  # refused by the run, saying the file is missing (not this folder loaded)
            return shlex.join(words)
        return shlex.join([words[0], *item, str(Path(mission).expanduser().resolve())])
    return shlex.join(words)


def describe_items(items: list[dict]) -> str:
    """One line per item: its number, status and name(s)."""
    return "".join(f"  {item.get('item', '?'):>5}  {item.get('status', ''):<8} {item.get('name', '')}\n"
                   for item in items)


class AmbiguousRun(ValueError):
    """Several live runs and none named: nothing is sent."""


def run_name(answer: dict) -> str:
    """``figure10.py (pid 4242, /path/to/folder): `` from the answer's ``run``, or nothing."""
    run = answer.get("run")
    if not isinstance(run, dict):
        return ""
    folder = f", {run['folder']}" if run.get("folder") else ""
    return f"{run.get('mission') or '?'} (pid {run.get('pid', '?')}{folder}): "


def _stale_hint(args: argparse.Namespace) -> str:
    """When the port came from a control file whose run is gone (killed), say so and which file it is."""
    if args.port is not None:
        return ""
    folder = Path(args.run_dir) if args.run_dir else None
    if folder is None:
        files = sorted(DEFAULT_BASE.glob(f"*/{CONTROL_FILE}"), key=lambda p: p.stat().st_mtime)
        folder = files[-1].parent if files else None
    if folder is None:
        return ""
    try:
        pid = int(json.loads((folder / CONTROL_FILE).read_text(encoding="utf-8")).get("pid", 0))
    except (OSError, ValueError, TypeError, AttributeError):
        return ""
    if pid <= 0:
        return ""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return (f" (the run that wrote {folder / CONTROL_FILE}, process {pid}, is no longer running: the file was "
                "left by a run that was killed; remove it)")
    except (OSError, ValueError):
        return ""
    return ""


def endpoint(args: argparse.Namespace) -> tuple[int, str]:
    """The port and token from --port/--token, --run DIR|PID or the one live run; ``ValueError`` if none,
    :class:`AmbiguousRun` when several are live and none is named."""
    if args.port is not None or args.token is not None:
        if args.port is None or args.token is None:
            raise ValueError("--port and --token go together")
        return args.port, args.token
    runs = live_runs()
    if args.run_dir and args.run_dir.isdigit():
        chosen = [r for r in runs if r.pid == int(args.run_dir)]
        if not chosen:
            raise ValueError(f"no live run has the process id {args.run_dir} (aeroexec ctl list shows them)")
        return chosen[-1].port, chosen[-1].token
    if args.run_dir:
        return read_control_file(args.run_dir)
    if len(runs) == 1:
        return runs[0].port, runs[0].token
    if runs:
        listed = "\n".join(f"  {run}" for run in runs)
        raise AmbiguousRun(f"{len(runs)} live runs: name one with --run DIR|PID (nothing was sent)\n{listed}")
    files = sorted(DEFAULT_BASE.glob(f"*/{CONTROL_FILE}"), key=lambda p: p.stat().st_mtime)
    if not files:
        raise ValueError("no live run found (aeroexec ctl list): give --run DIR (the run's --output folder)")
    return read_control_file(files[-1].parent)


def describe_status(status: dict) -> str:
    lines = [f"  drone: position {tuple(status.get('position', ()))}, speed {status.get('speed')} m/s, "
             f"battery {status.get('battery')} %, {status.get('landed_state')}"]
    for active in status.get("active", []):
        timeout = f"/{active['timeout']:g} s" if active.get("timeout") else " s"
        lines.append(f"  {active['name']} ({active['priority']}, {active['source']}) {active['elapsed']:.1f}"
                     f"{timeout}")
    lines += [f"  question waiting: {question}" for question in status.get("questions", [])]
    return "\n".join(lines)


def fleet_operator(args: argparse.Namespace) -> Any:
    """The operator's links to ``--fleet`` (a :class:`~aeroexec.fleet.control.FleetOperator`), from the options
    or the fleet's ``fleet.json``; ValueError or FleetCommandError saying what is missing."""
    import os

    from aeroexec.fleet.control import FleetOperator
    from aeroexec.fleet.fleet_json import TOKEN_VARIABLE, read_fleet_file
    from aeroexec.fleet.members import operator_identity

    given = args.connect and args.credentials and (args.token or os.environ.get(TOKEN_VARIABLE))
    known = read_fleet_file(args.fleet, args.run_dir) if args.run_dir or not given else {}
    token = args.token or os.environ.get(TOKEN_VARIABLE) or known.get("token", "")
    credentials = args.credentials or known.get("credentials")
    if not credentials:
        where = " (the run's fleet.json names none: the operator's identity is not in its credentials folder)" \
            if known else ""
        raise ValueError(f"no operator credentials for fleet {args.fleet}: give --credentials DIR (the folder of "
                         f"operator.pem, operator.key and ca.pem){where}")
    members = known.get("drones") if isinstance(known.get("drones"), list) else ()
    return FleetOperator(args.connect or known.get("endpoints") or [], args.fleet, token,
                         operator_identity(credentials), [m for m in members if isinstance(m, str)])


def fleet_commands(args: argparse.Namespace, lines: Any) -> int:
    """``--stdin``: each line a command to the fleet (``COMMAND [ARGUMENT] [--drone D]``; the command line's
    ``--drone`` for a line without one), through links opened once; each command's answers printed as
    :func:`fleet_command` prints them. 0 when every command was done by every drone it was for."""
    from aeroexec.fleet.control import FleetCommandError

    try:
        operator = fleet_operator(args)
    except (ValueError, FleetCommandError) as error:
        print(error, file=sys.stderr)
        return 1
    worst = 0
    with operator:
        for number, line in enumerate(lines, 1):
            try:
                words = shlex.split(line)
            except ValueError as error:
                print(f"<stdin>:{number}: {error}: {line.strip()}", file=sys.stderr)
                worst = 1
                continue
            drone = None
            if "--drone" in words:
                at = words.index("--drone")
                drone = words[at + 1] if at + 1 < len(words) else ""
                words = words[:at] + words[at + 2:]
            if not words:
                continue
            command, rest = words[0], words[1:]
            if command not in COMMANDS or command == "list" or command in NEEDS_ARGUMENT and not rest or \
                    drone == "":
                print(f"<stdin>:{number}: not a fleet command: {line.strip()} (COMMAND [ARGUMENT] [--drone D]; "
                      f"COMMAND one of {', '.join(c for c in COMMANDS if c != 'list')})", file=sys.stderr)
                worst = 1
                continue
            try:
                answers = operator.command(command, command_argument(command, rest),
                                           drone=drone or args.drone or "*")
            except (ValueError, FleetCommandError) as error:
                print(f"<stdin>:{number}: {error}", file=sys.stderr)
                worst = 1
                continue
            worst = max(worst, print_fleet_answers(args, answers, compact=True))
    return worst


def fleet_command(args: argparse.Namespace, argument: str) -> int:
    """The command to every drone of ``--fleet`` (or ``--drone``) as a Zenoh query guarded by the fleet's token."""
    from aeroexec.fleet.control import FleetCommandError

    try:
        with fleet_operator(args) as operator:
            answers = operator.command(args.command, argument, drone=args.drone or "*")
            return print_fleet_answers(args, answers)  # printed before the links close (a path opening is waited for)
    except (ValueError, FleetCommandError) as error:
        print(error, file=sys.stderr)
        return 1


def print_fleet_answers(args: argparse.Namespace, answers: dict[str, dict], compact: bool = False) -> int:
    """Each drone's answer (``--json``: one JSON object, on one line when ``compact``) and those that did not
    answer; 1 unless every drone did what it was asked."""
    if args.json:
        print(json.dumps(answers, indent=None if compact else 2), flush=True)
        return 0 if answers and all(a.get("ok") for a in answers.values()) else 1
    for drone, answer in sorted(answers.items()):
        if answer.get("ok"):
            print(f"{drone}: {answer.get('message', 'ok')}")
            if "status" in answer:
                print(describe_status(answer["status"]))
            print(describe_items(answer.get("items", [])), end="")
            if answer.get("silent"):
                print(f"  silent (nothing heard for 2 s or more): {', '.join(answer['silent'])}")
        elif answer.get("answered") is False:
            print(f"{drone}: {answer.get('error')}", file=sys.stderr)
        else:
            print(f"{drone}: refused: {answer.get('error') or answer.get('message') or 'no reason given'}",
                  file=sys.stderr)
            for problem in answer.get("problems", [])[1:]:
                print(f"  {problem}", file=sys.stderr)
    unanswered = sorted(d for d, a in answers.items() if a.get("answered") is False)
    if not answers or len(unanswered) == len(answers):
        print(f"no drone of fleet {args.fleet} answered", file=sys.stderr)
    elif unanswered:
        print(f"{len(unanswered)} of {len(answers)} drones of fleet {args.fleet} did not answer: "
              f"{', '.join(unanswered)}", file=sys.stderr)
    sys.stdout.flush()
    return 0 if answers and all(a.get("ok") for a in answers.values()) else 1
