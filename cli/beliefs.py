"""``aeroexec beliefs``: belief queries at a prompt, against the beliefs an event log ends with (rebuilt from its
belief changes); the unifications are printed as a table, one row per answer, one column per variable.

At the prompt: a belief expression (``object(?X, ?Y), ?Y = box``) is answered; ``list [PREDICATE]`` lists the
beliefs; ``help``; ``quit`` (or end of input). ``--query EXPR`` answers without a prompt. Computed predicates of a
live engine (distances, the drone's sensors) are not in a log, so only stored beliefs are answered.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from aeroexec.beliefs import BeliefError, BeliefMemory, Struct, format_term
from aeroexec.engine.supervision.output import DEFAULT_BASE
from aeroexec.flight.flight_log import read_flight_log
from aeroexec.flight.summary import final_beliefs

HELP = ("a belief expression, e.g. object(?X, ?Y) or charge(battery, ?C), ?C < 50 | list [PREDICATE] | "
        "help | quit")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--log", metavar="FILE",
                        help="the event log to query (default: the newest aeroexec_output/*/events.jsonl)")
    parser.add_argument("--query", "-q", action="append", metavar="EXPR",
                        help="answer EXPR and exit (may be repeated) instead of opening the prompt")


def run(args: argparse.Namespace) -> int:
    log = Path(args.log) if args.log else newest_log()
    if log is None:
        print(f"no event log given and none found in {DEFAULT_BASE}/: use --log FILE", file=sys.stderr)
        return 1
    try:
        records = read_flight_log(log)
    except (OSError, UnicodeDecodeError, ValueError) as error:
        print(f"{log}: cannot read the event log: {error}", file=sys.stderr)
        return 1
    memory = memory_from_log(records)
    print(f"{log}: {len(memory)} beliefs at t={max((r.get('time', 0.0) for r in records), default=0.0):.1f} s",
          file=sys.stderr)
    if args.query:
        return max(answer(memory, expression) for expression in args.query)
    return prompt(memory)


def newest_log(base: Path = DEFAULT_BASE) -> Path | None:
    logs = sorted(base.glob("*/events.jsonl"), key=lambda p: p.stat().st_mtime)
    return logs[-1] if logs else None


def memory_from_log(records: list[dict[str, Any]]) -> BeliefMemory:
    """A memory holding the beliefs the log ends with (every predicate multivalued: the log already says what
    an exclusive value replaced)."""
    beliefs = final_beliefs(records)
    memory = BeliefMemory(multivalued={b.split("(", 1)[0].strip() for b in beliefs})
    for belief in beliefs:
        try:
            memory.add(belief)
        except BeliefError as error:
            print(f"a logged belief cannot be read back: {belief}: {error}", file=sys.stderr)
    return memory


def prompt(memory: BeliefMemory) -> int:
    interactive = sys.stdin.isatty()
    if interactive:
        print(HELP)
    while True:
        if interactive:
            print("belief> ", end="", flush=True)
        line = sys.stdin.readline()
        if not line:
            return 0
        line = line.strip()
        if not line:
            continue
        if line in ("quit", "exit", "q"):
            return 0
        if line in ("help", "?"):
            print(HELP)
        elif line == "list" or line.startswith("list "):
            predicate = line[4:].strip() or None
            for belief in sorted(format_term(b) for b in memory.beliefs(predicate)):
                print(belief)
        else:
            answer(memory, line)


def answer(memory: BeliefMemory, expression: str) -> int:
    """Print the unifications of ``expression`` as a table; 0 when it holds, 1 when not or when it is wrong."""
    try:
        solutions = memory.query_all(expression)
    except BeliefError as error:
        print(f"{expression}: {error}", file=sys.stderr)
        return 1
    if not solutions:
        print(f"{expression}: no")
        return 1
    variables = list(dict.fromkeys(v for solution in solutions for v in solution))
    if not variables:
        print(f"{expression}: yes")
        return 0
    print_table(expression, variables, [[_shown(s.get(v)) for v in variables] for s in solutions])
    return 0


def print_table(title: str, headers: list[str], rows: list[list[str]]) -> None:
    from rich.console import Console
    from rich.table import Table
    from rich.text import Text

    table = Table(title=f"{title}: {len(rows)} answer{'s' if len(rows) != 1 else ''}")
    for header in headers:
        table.add_column(header)
    for row in rows:
        table.add_row(*(Text(cell) for cell in row))  # values as they are, never rich markup
    Console(soft_wrap=True).print(table)


def _shown(value: Any) -> str:
    if isinstance(value, Struct):
        return format_term(value)
    if isinstance(value, list | tuple):
        return "(" + ", ".join(_shown(v) for v in value) + ")"
    return "" if value is None else str(value)
