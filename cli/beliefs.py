"""``aeroexec beliefs [RUN_DIR|LOG]``: belief queries at a prompt, against the beliefs a run's event log ends with
(rebuilt from its belief changes); the unifications are printed as a table, one row per answer, one column per
variable. Without a run, the newest in ``aeroexec_output/``, named on stderr before anything is answered.

At the prompt: a belief expression (``object(?X, ?Y), ?Y = box``) is answered; ``list [PREDICATE]`` lists the
beliefs; a rule (``safe(?Z) :- zone(?Z), not(occupied(?Z)).``) or a fact ending with a full stop is added;
``rules`` lists the rules; ``why EXPR`` shows the proof of its first answer, ``why not EXPR`` the goal that fails;
``help``; ``quit`` (or end of input). ``--query EXPR`` answers without a prompt; ``--rules FILE`` adds a rules
file. Computed predicates of a live engine (distances, the drone's sensors) are not in a log, so only stored
beliefs (and what rules derive from them) are answered.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from aeroexec.beliefs import BeliefError, BeliefMemory, RuleError, Struct, format_term, read_rules
from aeroexec.engine.supervision.output import DEFAULT_BASE
from aeroexec.flight.journal import read_records
from aeroexec.flight.summary import final_beliefs

HELP = ("a belief expression, e.g. object(?X, ?Y) or charge(battery, ?C), ?C < 50 | list [PREDICATE] | "
        "a rule or fact ending with '.', e.g. near(?X) :- position(?X, ?P). | rules | why EXPR | why not EXPR | "
        "help | quit")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("run_dir", nargs="?", metavar="RUN_DIR|LOG",
                        help="a run's output folder or its event log (default: the newest run in "
                             f"{DEFAULT_BASE}/; a run flown with --output elsewhere is named here)")
    parser.add_argument("--query", "-q", action="append", metavar="EXPR",
                        help="answer EXPR and exit (may be repeated) instead of opening the prompt")
    parser.add_argument("--rules", action="append", default=[], metavar="FILE",
                        help="rules deriving beliefs from the logged ones (repeatable)")


def run(args: argparse.Namespace) -> int:
    from aeroexec.flight.replay import ReplayError, find_log

    if args.run_dir:
        try:
            log = find_log(args.run_dir)
        except ReplayError as error:
            print(error, file=sys.stderr)
            return 1
        source = str(log)
    else:
        log = newest_log()
        if log is None:
            print(f"no run given and none in {DEFAULT_BASE}/: name a run's output folder or its event log "
                  f"(aeroexec beliefs RUN_DIR)", file=sys.stderr)
            return 1
        source = f"{log} (the newest run in {DEFAULT_BASE}/; name another: aeroexec beliefs RUN_DIR)"
    try:
        records = read_records(log)
    except (OSError, UnicodeDecodeError, ValueError) as error:
        print(f"{log}: cannot read the event log: {error}", file=sys.stderr)
        return 1
    memory = memory_from_log(records)
    try:
        for path in args.rules:
            memory.add_rules(read_rules(path))
    except RuleError as error:
        print(error, file=sys.stderr)
        return 1
    print(f"{source}: {len(memory)} beliefs at t={max((r.get('time', 0.0) for r in records), default=0.0):.1f} s",
          file=sys.stderr, flush=True)  # which run answers, before any answer
    if args.query:
        return max(command(memory, expression) for expression in args.query)
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
            command(memory, line)


def command(memory: BeliefMemory, line: str) -> int:
    """A line of the prompt other than list/help/quit: rules, why, why not, or an expression to answer."""
    if line == "rules":
        for rule in memory.rules:
            print(f"{rule}    % {rule.where}")
        return 0
    if line.endswith("."):
        try:
            added = memory.add_rules(line, "<prompt>")
        except (RuleError, BeliefError) as error:
            print(error, file=sys.stderr)
            return 1
        print(f"added {len(added)} clause{'s' if len(added) != 1 else ''}")
        return 0
    if line.startswith(("why not ", "why not(")):
        return explain(memory, line[len("why not"):].strip(), proof=False)
    if line.startswith(("why ", "why(")):
        return explain(memory, line[len("why"):].strip(), proof=True)
    return answer(memory, line)


def explain(memory: BeliefMemory, expression: str, proof: bool) -> int:
    """Print why ``expression`` holds (its proof) or why it does not (the goal that fails); 0 when it holds."""
    if expression.startswith("(") and expression.endswith(")"):
        expression = expression[1:-1]
    try:
        found = memory.why(expression) if proof else None
        reasons = [] if proof else memory.why_not(expression)
    except BeliefError as error:
        print(f"{expression}: {error}", file=sys.stderr)
        return 1
    if proof and found is None:
        reasons = memory.why_not(expression)
    for line in ([str(p) for p in found] if found else reasons) or [f"{expression} holds"]:
        print(line)
    return 0 if found or (not proof and not reasons) else 1


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
