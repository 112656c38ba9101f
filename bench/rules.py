"""Rule evaluation against SWI-Prolog with tabling and clingo, on the same workloads, as ratios in one run.

Run ``python bench/rules.py`` (``--repeat N``, ``--small`` for quick sizes while changing the code; ``--write``
puts the table into docs/performance/beliefs-and-rules.md). Workloads (every answer counted on every side, the
counts checked equal):

- closure over a random clustered graph: ``reachable/2`` over 5,000 places in clusters of 50 (4 links per place
  within its cluster, one link from each even cluster to the next), seeded;
- closure over a chain of 1,000 places (1,000 · 999 / 2 pairs: a chain of 2,000 would pass the million beliefs one
  derived predicate may hold);
- same generation over a binary tree of depth 9 (``sg(?X, ?Y) :- par(?X, ?P), par(?Y, ?P)`` and its recursion);
- stratified negation: the closure of the clustered graph, then the pairs reachable one way only
  (``not(reachable(?B, ?A))``; SWI answers the negated goal from the completed table: ``as subsumptive``);
- an edge update on the clustered closure: a link added then removed, the closure asked after each, for
  ``UPDATES`` links; asked for its first answer (``memory.query`` / ``once``) and with every answer counted
  (``memory.count`` / ``aggregate_all(count, ...)``) and with every answer read (a tuple each from
  ``memory.answers`` / ``forall``): SWI with incremental tabling; clingo grounds and solves again.

Each figure is the median of ``--repeat`` runs, the three systems interleaved, CPU time of the evaluation alone
(loading the facts is not counted; aeroexec's facts are loaded as terms). Each static workload is evaluated in a
fresh process of its own on both sides (SWI-Prolog's ``swipl``, aeroexec's ``python bench/rules.py --one NAME``):
in one process that had evaluated the others first, their garbage was still there for the collector to walk, and
a full collection during the same generation's evaluation made it up to twice as slow. A fresh process pays for
its memory as it first takes it, on both sides: aeroexec's evaluation in a process that has run (``aeroexec
(warm)``: this process, its garbage collected first, as a running engine's) is printed beside, not judged (the
chain: ~0.25 s warm, ~0.40 s fresh). The ratio printed is aeroexec's speed (fresh) over the other's (> 1: aeroexec
is faster). Goals (issue 45): every static workload ≥ 1×
SWI-Prolog tabled, the update with every answer counted ≥ 5× SWI's incremental tabling.
"""

from __future__ import annotations

import argparse
import gc
import random
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from aeroexec.beliefs import BeliefMemory, Struct
from performance_page import swi_version, write_section
from provenance import load, measured_at

CLOSURE = """reachable(?A, ?B) :- link(?A, ?B).
reachable(?A, ?C) :- link(?A, ?B), reachable(?B, ?C)."""
SAME_GENERATION = """sg(?X, ?Y) :- par(?X, ?P), par(?Y, ?P).
sg(?X, ?Y) :- par(?X, ?A), sg(?A, ?B), par(?Y, ?B)."""
ONE_WAY = CLOSURE + "\none_way(?A, ?B) :- reachable(?A, ?B), not(reachable(?B, ?A))."
UPDATES = 5


def clustered(places: int = 5000, size: int = 50, per_place: int = 4, seed: int = 1) -> list[tuple[int, int]]:
    """Links within clusters of ``size`` places (``per_place`` each, random), and one link from each even cluster
    to the next (so half the clusters reach a second one)."""
    rng = random.Random(seed)
    found: dict[tuple[int, int], None] = {}
    for first in range(0, places, size):
        want = len(found) + size * per_place
        while len(found) < want:
            a, b = first + rng.randrange(size), first + rng.randrange(size)
            if a != b:
                found[(a, b)] = None
    for cluster in range(0, places // size - 1, 2):
        found[(cluster * size, (cluster + 1) * size)] = None
    return list(found)


def chain(places: int) -> list[tuple[int, int]]:
    return [(i, i + 1) for i in range(places - 1)]


def tree(depth: int) -> list[tuple[int, int]]:
    """``par(child, parent)`` of a binary tree of ``depth`` levels below its root."""
    return [(child, (child - 1) // 2) for child in range(1, 2 ** (depth + 1) - 1)]


def extras(edges: list[tuple[int, int]], places: int, size: int, seed: int = 3) -> list[tuple[int, int]]:
    """Links not in ``edges``, each joining two clusters (an update that adds and removes answers)."""
    rng = random.Random(seed)
    known, found = set(edges), []
    while len(found) < UPDATES:
        a, b = rng.randrange(places), rng.randrange(places)
        if a // size != b // size and (a, b) not in known:
            found.append((a, b))
            known.add((a, b))
    return found


def cpu() -> float:
    return time.process_time()


# -- aeroexec ---------------------------------------------------------------------------------------------------------
def _memory(facts: dict[str, list[tuple]], rules: str) -> BeliefMemory:
    memory = BeliefMemory(multivalued=set(facts))
    for name, rows in facts.items():
        for row in rows:
            memory.add(Struct(name, row))
    memory.add_rules(rules)
    return memory


def ours_static(facts: dict[str, list[tuple]], rules: str, asked: str) -> tuple[float, int]:
    memory = _memory(facts, rules)
    start = cpu()
    found = memory.count(asked)
    return cpu() - start, found


def ours_update(facts: dict[str, list[tuple]], added: list[tuple[int, int]]) -> dict[str, float]:
    memory = _memory(facts, CLOSURE)
    pairs = memory.count("reachable(?A, ?B)")
    out = {}
    def read() -> None:
        for _ in memory.answers("reachable(?A, ?B)"):
            pass
    for label, ask in (("first", lambda: memory.query("reachable(?A, ?B)")),
                       ("counted", lambda: memory.count("reachable(?A, ?B)")), ("read", read)):
        start = cpu()
        for extra in added:
            memory.add(Struct("link", extra))
            ask()
            memory.remove(Struct("link", extra))
            ask()
        out[label] = (cpu() - start) / (2 * len(added))
        assert memory.count("reachable(?A, ?B)") == pairs
    return out


# -- SWI-Prolog -------------------------------------------------------------------------------------------------------
SWI_COMMON = """
:- set_prolog_flag(verbose, silent).
timed(Goal, T) :- statistics(cputime, T0), call(Goal), statistics(cputime, T1), T is T1 - T0.
"""
SWI_PROGRAMS = {
    "closure": """
:- table reachable/2.
reachable(A, B) :- link(A, B).
reachable(A, C) :- link(A, B), reachable(B, C).
main :- timed(aggregate_all(count, reachable(_, _), N), T), format("time ~6f~ncount ~w~n", [T, N]).
""",
    "sg": """
:- table sg/2.
sg(X, Y) :- par(X, P), par(Y, P).
sg(X, Y) :- par(X, A), sg(A, B), par(Y, B).
main :- timed(aggregate_all(count, sg(_, _), N), T), format("time ~6f~ncount ~w~n", [T, N]).
""",
    "one_way": """
:- table reachable/2 as subsumptive.
reachable(A, B) :- link(A, B).
reachable(A, C) :- link(A, B), reachable(B, C).
:- table one_way/2.
one_way(A, B) :- reachable(A, B), \\+ reachable(B, A).
main :- timed(aggregate_all(count, one_way(_, _), N), T), format("time ~6f~ncount ~w~n", [T, N]).
""",
    "update": """
:- dynamic([link/2], [incremental(true)]).
:- table reachable/2 as incremental.
reachable(A, B) :- link(A, B).
reachable(A, C) :- link(A, B), reachable(B, C).
updates(Ask, T) :-
    findall(X-Y, extra(X, Y), Extras), length(Extras, N),
    timed(forall(member(X-Y, Extras),
                 (assertz(link(X, Y)), \\+ \\+ call(Ask), retract(link(X, Y)), \\+ \\+ call(Ask))), S),
    T is S / (2 * N).
main :-
    aggregate_all(count, reachable(_, _), _),
    updates(once(reachable(_, _)), First),
    updates(aggregate_all(count, reachable(_, _), _), Counted),
    updates(forall(reachable(_, _), true), Read),
    format("first ~6f~ncounted ~6f~nread ~6f~n", [First, Counted, Read]).
""",
}


def swi(workload: str, facts: dict[str, list[tuple]], folder: Path) -> dict[str, float] | None:
    swipl = shutil.which("swipl")
    if swipl is None:
        return None
    data = folder / f"{workload}.facts.pl"
    lines = [":- dynamic([link/2], [incremental(true)])." if workload == "update" else ""]
    for name, rows in facts.items():
        lines += [f"{name}({a}, {b})." for a, b in rows]
    data.write_text("\n".join(lines) + "\n")
    program = folder / f"{workload}.pl"
    program.write_text(SWI_COMMON + SWI_PROGRAMS[workload])
    done = subprocess.run([swipl, "-q", "-g", "main", "-t", "halt", str(data), str(program)],
                          capture_output=True, text=True, timeout=3600)
    if done.returncode != 0:
        raise RuntimeError(done.stderr[-2000:])
    return {k: float(v) for k, v in re.findall(r"^(\w+) (\S+)$", done.stdout, re.M)}


# -- clingo ------------------------------------------------------------------------------------------------------------
def clingo_run(facts: dict[str, list[tuple]], rules: str, count: str) -> tuple[float, int] | None:
    try:
        import clingo
    except ImportError:
        return None
    program = "".join(f"{name}({a},{b})." for name, rows in facts.items() for a, b in rows) + rules
    start = cpu()
    control = clingo.Control(["--warn=none"])
    control.add("base", [], program)
    control.ground([("base", [])])
    found = 0
    with control.solve(yield_=True) as handle:
        for model in handle:
            found = sum(1 for s in model.symbols(atoms=True) if s.name == count)
    return cpu() - start, found


CLINGO = {"closure": "reachable(A,B) :- link(A,B). reachable(A,C) :- link(A,B), reachable(B,C).",
          "sg": "sg(X,Y) :- par(X,P), par(Y,P). sg(X,Y) :- par(X,A), sg(A,B), par(Y,B)."}
CLINGO["one_way"] = CLINGO["closure"] + " one_way(A,B) :- reachable(A,B), not reachable(B,A)."


def ours_apart(key: str, small: bool) -> tuple[float, int]:
    """:func:`ours_static` of workload ``key`` in a fresh process (``--one``), as SWI-Prolog's evaluation runs."""
    command = [sys.executable, __file__, "--one", key, *(["--small"] if small else [])]
    done = subprocess.run(command, capture_output=True, text=True, timeout=3600)
    if done.returncode != 0:
        raise RuntimeError(done.stderr[-2000:])
    said = dict(re.findall(r"^(\w+) (\S+)$", done.stdout, re.M))
    return float(said["time"]), int(said["count"])


def workloads(small: bool) -> tuple[dict[str, tuple], dict[str, list[tuple[int, int]]], int, int]:
    """The static workloads (name: label, facts, rules, the predicate counted, what aeroexec is asked), the
    clustered graph, its places and its clusters' size."""
    places, size, length, depth = (1000, 50, 300, 7) if small else (5000, 50, 1000, 9)
    graph = {"link": clustered(places, size)}
    found = {
        "closure": (f"closure, clustered ({places:,} places, {len(graph['link']):,} links)", graph, CLOSURE,
                    "reachable", "reachable(?A, ?B)"),
        "chain": (f"closure, chain of {length:,}", {"link": chain(length)}, CLOSURE, "reachable",
                  "reachable(?A, ?B)"),
        "sg": (f"same generation, binary tree of depth {depth}", {"par": tree(depth)}, SAME_GENERATION, "sg",
               "sg(?X, ?Y)"),
        "one_way": ("stratified negation (one-way pairs, clustered)", graph, ONE_WAY, "one_way",
                    "one_way(?A, ?B)"),
    }
    return found, graph, places, size


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--small", action="store_true", help="smaller graphs, for a quick look while iterating")
    parser.add_argument("--write", action="store_true", help="write the table into " + "docs/performance/"
                        "beliefs-and-rules.md")
    parser.add_argument("--one", help=argparse.SUPPRESS)  # one static workload of aeroexec's, in this process
    args = parser.parse_args()
    static, graph, places, size = workloads(args.small)
    if args.one:
        _, facts, rules, _, asked = static[args.one]
        spent, found = ours_static(facts, rules, asked)
        print(f"time {spent:.6f}\ncount {found}")
        return
    added = extras(graph["link"], places, size)
    began = load()
    times: dict[str, dict[str, list[float]]] = {}
    counts: dict[str, dict[str, set[int]]] = {}
    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch)
        for _ in range(args.repeat):  # interleaved, so a change of load touches all three alike
            for key, (_, facts, rules, predicate, asked) in static.items():
                spent, found = ours_apart(key, args.small)
                times.setdefault(key, {}).setdefault("aeroexec", []).append(spent)
                counts.setdefault(key, {}).setdefault("aeroexec", set()).add(found)
                gc.collect()  # the garbage of what this process evaluated before (not a running engine's)
                spent, found = ours_static(facts, rules, asked)
                times[key].setdefault("aeroexec (warm)", []).append(spent)
                counts[key]["aeroexec"].add(found)
                other = swi("sg" if key == "sg" else "one_way" if key == "one_way" else "closure", facts, folder)
                if other is not None:
                    times[key].setdefault("SWI-Prolog", []).append(other["time"])
                    counts[key].setdefault("SWI-Prolog", set()).add(int(other["count"]))
                answer = clingo_run(facts, CLINGO["closure" if key == "chain" else key], predicate)
                if answer is not None:
                    times[key].setdefault("clingo", []).append(answer[0])
                    counts[key].setdefault("clingo", set()).add(answer[1])
            mine = ours_update(graph, added)
            for label in ("first", "counted", "read"):
                times.setdefault(f"update {label}", {}).setdefault("aeroexec", []).append(mine[label])
            swi_data = {**graph, "extra": added}
            other = swi("update", swi_data, folder)
            if other is not None:
                for label in ("first", "counted", "read"):
                    times[f"update {label}"].setdefault("SWI-Prolog", []).append(other[label])
            answer = clingo_run({"link": [*graph["link"], added[0]]}, CLINGO["closure"], "reachable")
            if answer is not None:  # no maintained answers: an update is a new grounding and solving
                times["update counted"].setdefault("clingo", []).append(answer[0])
    for key, found in counts.items():
        if len({n for ns in found.values() for n in ns}) != 1:
            sys.exit(f"{key}: the systems disagree on the number of answers: {found}")
    labels = {key: spec[0] for key, spec in static.items()}
    labels["update first"] = "edge update, first answer (`query` / `once`)"
    labels["update counted"] = "edge update, every answer counted (`count` / `aggregate_all`)"
    labels["update read"] = "edge update, every answer read (`answers` / `forall`)"
    goals = {"closure": 1.0, "chain": 1.0, "sg": 1.0, "one_way": 1.0, "update counted": 5.0}
    systems = ["aeroexec", "aeroexec (warm)", "SWI-Prolog", "clingo"]
    median = {key: {who: statistics.median(found) for who, found in by.items()} for key, by in times.items()}
    headers = ["workload", "answers", *(f"{who} (s)" for who in systems), "× SWI-Prolog", "× clingo", "goal"]
    body = []
    for key, label in labels.items():
        figures = median[key]
        answers = counts.get(key, {}).get("aeroexec", {0})
        row = [label, f"{next(iter(answers)):,}" if key in counts else "",
               *(f"{figures[who]:.4f}" if who in figures else "" for who in systems)]
        for who in ("SWI-Prolog", "clingo"):
            row.append(f"{figures[who] / figures['aeroexec']:.2f}×" if who in figures else "")
        goal = goals.get(key)
        if goal is not None and "SWI-Prolog" in figures:
            ratio = figures["SWI-Prolog"] / figures["aeroexec"]
            row.append(f"≥ {goal:g}× SWI: {'met' if ratio >= goal else 'missed'}")
        else:
            row.append("")
        body.append(row)
    widths = [max(len(r[i]) for r in [headers, *body]) for i in range(len(headers))]
    for row in [headers, ["-" * w for w in widths], *body]:
        print("  ".join(c.ljust(w) if i in (0, len(row) - 1) else c.rjust(w)
                        for i, (c, w) in enumerate(zip(row, widths, strict=True))))
    command = "python bench/rules.py" + (" --small" if args.small else "") + f" --repeat {args.repeat}"
    said = (f"Measured by `{command}` at {measured_at(began)} (2 cores, shared); baseline: SWI-Prolog "
            f"{swi_version()} tabled (incremental tabling for the update), clingo as the peer; median of "
            f"{args.repeat}, CPU seconds, the systems interleaved.")
    print(said)
    if args.write:
        markdown = ["| " + " | ".join(headers) + " |", "|---|" + "---:|" * (len(headers) - 2) + "---|"]
        markdown += ["| " + " | ".join(r) + " |" for r in body]
        write_section("bench/rules.py", "\n".join([*markdown, "", said]))


if __name__ == "__main__":
    main()
