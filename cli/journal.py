"""``aeroexec journal RUN_DIR``: questions over a run's flight journal (``journal.sqlite``), while it flies too.

Without a question: each part of the run (the first flight, then each resume) and how it ended, where the mission
stopped, how many of its steps are done, and how to go on. ``--behavior X``: every request of behavior X (when,
from whom, with what, how it ended); ``--belief B``: every change of the beliefs of a predicate or matching a
pattern (``charge`` or ``object(?X, aruco)``); ``--done``: the mission's steps done, in order (a tree's leaves, a
plan's items, a Python mission's goals); ``--sql QUERY``: any query (the journal is opened read-only; the schema
is in ``flight/journal/schema.py`` and the README). ``--json`` prints rows as JSON.
"""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

from aeroexec.flight.journal import Journal, JournalError
from aeroexec.flight.journal.resume_point import resume_point


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("run_dir", metavar="RUN_DIR", help="a run's output folder (or its journal.sqlite)")
    question = parser.add_mutually_exclusive_group()
    question.add_argument("--behavior", metavar="NAME", help="what happened to behavior NAME, request by request")
    question.add_argument("--belief", metavar="PATTERN", help="when the beliefs of a predicate (charge) or "
                                                              "matching a pattern (object(?X, aruco)) changed")
    question.add_argument("--done", action="store_true", help="the mission's steps done, in order")
    question.add_argument("--sql", metavar="QUERY", help="any read-only SQL query over the journal's tables")
    parser.add_argument("--json", action="store_true", help="print the rows as JSON, one object a line")


def run(args: argparse.Namespace) -> int:
    try:
        with Journal(args.run_dir) as journal:
            if args.behavior:
                rows = [_request(r, journal) for r in journal.behavior(args.behavior)]
                return _print(rows, args.json, f"no request of {args.behavior.upper()} in the journal")
            if args.belief:
                rows = [{"time": r["time"], "change": "+" if r["change"] == "added" else "-", "belief": r["belief"],
                         "reason": r["reason"], "segment": r["segment"]} for r in journal.belief_changes(args.belief)]
                return _print(rows, args.json, f"no change of {args.belief} in the journal")
            if args.done:
                return _print(journal.done(), args.json, "no step of the mission is done")
            if args.sql:
                return _print([dict(r) for r in journal.rows(args.sql)], args.json, "no rows")
            return _summary(journal, args.run_dir)
    except JournalError as error:
        print(error, file=sys.stderr)
        return 1


def _request(row: Any, journal: Journal) -> dict[str, Any]:
    return {"time": row["activated_at"], "source": row["source"], "arguments": journal.json(row["arguments"]),
            "outcome": row["outcome"] or "RUNNING", "ended": row["ended_at"], "message": row["message"] or "",
            "segment": row["segment"]}


def _summary(journal: Journal, run_dir: str) -> int:
    meta = journal.meta()
    print(f"{meta.get('mission', run_dir)} ({meta.get('kind', '?')} mission)")
    for part in journal.segments():
        ended = (f"ended {part.status} at t={part.ended_at:.1f} s" if part.status else
                 "did not end (the process was killed, or it still flies)")
        went = "" if part.live_at is not None else "; its mission never went on"
        print(f"  part {part.segment}: {part.started_wall}, from t={part.started_at:.1f} s, {ended}{went}")
        for reason in part.reasons[:3]:
            print(f"    {reason}")
    done = journal.done()
    print(f"  steps done: {len(done)}" + (f" (the last: {done[-1]['step']} at t={done[-1]['time']:.1f} s)"
                                          if done else ""))
    try:
        point = resume_point(journal.path)
    except JournalError as error:
        print(f"  resume: {str(error).split(': ', 1)[-1]}")
        return 0
    print(f"  stopped at {point.where()}")
    print(f"  to go on: aeroexec run --resume {journal.path.parent}")
    return 0


def _print(rows: list[dict[str, Any]], as_json: bool, empty: str) -> int:
    if as_json:
        for row in rows:
            print(json.dumps(row, default=str))
        return 0
    if not rows:
        print(empty, file=sys.stderr)
        return 0
    columns = list(rows[0])
    shown = [[_cell(row.get(c)) for c in columns] for row in rows]
    widths = [min(60, max(len(c), *(len(r[i]) for r in shown))) for i, c in enumerate(columns)]
    print("  ".join(c.ljust(w) for c, w in zip(columns, widths, strict=True)).rstrip())
    for row in shown:
        print("  ".join(v[:w].ljust(w) for v, w in zip(row, widths, strict=True)).rstrip())
    return 0


def _cell(value: Any) -> str:
    if value is None:
        return ""
    if isinstance(value, float):
        return f"{value:.2f}"
    if isinstance(value, dict | list):
        return json.dumps(value, separators=(",", ":"))
    return str(value)
