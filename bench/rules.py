"""Rule evaluation against SWI-Prolog with tabling and clingo, on the same workloads, as ratios in one run.

Run ``python bench/rules.py`` (``--repeat N``, ``--links N``, ``--facts N``; ``--readme`` writes the table into
docs/performance.md). Workloads:

- closure: ``reachable/2`` over 10,000 random links between 10,000 places (seeded), every pair derived;
- join: ``route(?A, ?D) :- leg(?A, ?B), hop(?B, ?C), last(?C, ?D)`` over 100,000 facts;
- update: one link added, the closure asked again, the link removed, asked again, for each of ``UPDATES``
  links, the time per update (SWI: incremental tabling; clingo has no maintained answers: it grounds and
  solves again).

Each figure is the median of ``--repeat`` runs (CPU time of the evaluation alone: loading the facts is not
counted), and the ratio printed is aeroexec's speed over the other's (> 1: aeroexec is faster). Goals: the
closure within 2x of SWI-Prolog (ratio >= 0.5), the update faster than it (ratio > 1).
"""

from __future__ import annotations

import argparse
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

README = Path(__file__).resolve().parent.parent / "docs" / "performance.md"  # the tables moved there from README.md
MARKS = ("<!-- bench/rules.py: start -->", "<!-- bench/rules.py: end -->")
CLOSURE = """reachable(?A, ?B) :- link(?A, ?B).
reachable(?A, ?C) :- link(?A, ?B), reachable(?B, ?C)."""
JOIN = "route(?A, ?D) :- leg(?A, ?B), hop(?B, ?C), last(?C, ?D)."
UPDATES = 5


def links(n: int, seed: int = 1) -> list[tuple[int, int]]:
    rng = random.Random(seed)
    found: dict[tuple[int, int], None] = {}
    while len(found) < n:
        found[(rng.randrange(n), rng.randrange(n))] = None
    return list(found)


def join_facts(n: int, seed: int = 2) -> dict[str, list[tuple[int, int]]]:
    """``n`` facts over three relations, keyed so the join has about as many answers as facts."""
    rng = random.Random(seed)
    third = n // 3
    return {name: [(rng.randrange(third), rng.randrange(third)) for _ in range(third)]
            for name in ("leg", "hop", "last")}


def cpu() -> float:
    return time.process_time()


# -- aeroexec ---------------------------------------------------------------------------------------------------------
def ours(edges: list[tuple[int, int]], joined: dict[str, list], extras: list[tuple[int, int]]
         ) -> dict[str, float | int]:
    memory = BeliefMemory(multivalued={"link"})
    for a, b in edges:
        memory.add(Struct("link", (a, b)))
    memory.add_rules(CLOSURE)
    start = cpu()
    memory.holds("reachable(?A, ?B)")
    closure = cpu() - start
    pairs = len(memory.beliefs("reachable"))
    start = cpu()
    for extra in extras:
        memory.add(Struct("link", extra))
        memory.holds("reachable(?A, ?B)")
        memory.remove(Struct("link", extra))
        memory.holds("reachable(?A, ?B)")
    update = (cpu() - start) / (2 * len(extras))
    assert len(memory.beliefs("reachable")) == pairs
    memory = BeliefMemory(multivalued=set(joined))
    for name, rows in joined.items():
        for row in rows:
            memory.add(Struct(name, row))
    memory.add_rules(JOIN)
    start = cpu()
    memory.holds("route(?A, ?D)")
    join = cpu() - start
    return {"closure": closure, "pairs": pairs, "update": update, "join": join,
            "routes": len(memory.beliefs("route"))}


# -- SWI-Prolog -------------------------------------------------------------------------------------------------------
SWI_PROGRAM = """
:- set_prolog_flag(verbose, silent).
:- dynamic([link/2], [incremental(true)]).
:- table reachable/2 as incremental.
reachable(A, B) :- link(A, B).
reachable(A, C) :- link(A, B), reachable(B, C).
:- table route/2.
route(A, D) :- leg(A, B), hop(B, C), last(C, D).
timed(Goal, T) :- statistics(cputime, T0), call(Goal), statistics(cputime, T1), T is T1 - T0.
main :-
    timed(aggregate_all(count, reachable(_, _), Pairs), Closure),
    findall(X-Y, extra(X, Y), Extras), length(Extras, N),
    timed(forall(member(X-Y, Extras),
                 (assertz(link(X, Y)), aggregate_all(count, reachable(_, _), _),
                  retract(link(X, Y)), aggregate_all(count, reachable(_, _), _))), Updates),
    aggregate_all(count, reachable(_, _), Again),
    Update is Updates / (2 * N),
    timed(aggregate_all(count, route(_, _), Routes), Join),
    format("closure ~6f~npairs ~w~nupdate ~6f~nagain ~w~njoin ~6f~nroutes ~w~n",
           [Closure, Pairs, Update, Again, Join, Routes]).
"""


def swi(edges: list, joined: dict, extras: list[tuple[int, int]], folder: Path) -> dict[str, float | int] | None:
    swipl = shutil.which("swipl")
    if swipl is None:
        return None
    facts = folder / "facts.pl"
    lines = [":- dynamic([link/2], [incremental(true)]).", *(f"link({a}, {b})." for a, b in edges)]
    for name, rows in joined.items():
        lines += [f"{name}({a}, {b})." for a, b in rows]
    lines += [f"extra({a}, {b})." for a, b in extras]
    facts.write_text("\n".join(lines) + "\n")
    program = folder / "bench.pl"
    program.write_text(SWI_PROGRAM)
    done = subprocess.run([swipl, "-q", "-g", "main", "-t", "halt", str(facts), str(program)],
                          capture_output=True, text=True, timeout=3600)
    if done.returncode != 0:
        raise RuntimeError(done.stderr[-2000:])
    found = dict(re.findall(r"^(\w+) (\S+)$", done.stdout, re.M))
    return {k: (float(v) if "." in v else int(v)) for k, v in found.items()}


# -- clingo ------------------------------------------------------------------------------------------------------------
def clingo_run(edges: list, joined: dict, extras: list[tuple[int, int]]) -> dict[str, float | int] | None:
    try:
        import clingo
    except ImportError:
        return None

    def solve(program: str, count: str) -> tuple[float, int]:
        start = cpu()
        control = clingo.Control(["--warn=none"])
        control.add("base", [], program)
        control.ground([("base", [])])
        found = 0
        with control.solve(yield_=True) as handle:
            for model in handle:
                found = sum(1 for s in model.symbols(atoms=True) if s.name == count)
        return cpu() - start, found

    facts = "".join(f"link({a},{b})." for a, b in edges)
    rules = "reachable(A,B) :- link(A,B). reachable(A,C) :- link(A,B), reachable(B,C)."
    closure, pairs = solve(facts + rules, "reachable")
    again, _ = solve(facts + f"link({extras[0][0]},{extras[0][1]})." + rules, "reachable")
    joins = "".join(f"{name}({a},{b})." for name, rows in joined.items() for a, b in rows)
    join, routes = solve(joins + "route(A,D) :- leg(A,B), hop(B,C), last(C,D).", "route")
    return {"closure": closure, "pairs": pairs, "update": again, "join": join, "routes": routes}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--links", type=int, default=10_000)
    parser.add_argument("--facts", type=int, default=100_000)
    parser.add_argument("--readme", action="store_true", help="write the table into docs/performance.md")
    args = parser.parse_args()
    edges = links(args.links)
    joined = join_facts(args.facts)
    rng = random.Random(3)
    known = set(edges)
    extras: list[tuple[int, int]] = []
    while len(extras) < UPDATES:
        extra = (rng.randrange(args.links), rng.randrange(args.links))
        if extra not in known:
            extras.append(extra)
            known.add(extra)
    runs: dict[str, list[dict]] = {"aeroexec": [], "SWI-Prolog": [], "clingo": []}
    with tempfile.TemporaryDirectory() as folder:
        for _ in range(args.repeat):  # interleaved, so a change of load touches all three alike
            runs["aeroexec"].append(ours(edges, joined, extras))
            other = swi(edges, joined, extras, Path(folder))
            if other is not None:
                runs["SWI-Prolog"].append(other)
            other = clingo_run(edges, joined, extras)
            if other is not None:
                runs["clingo"].append(other)
    median = {who: {k: statistics.median(r[k] for r in found) for k in found[0]}
              for who, found in runs.items() if found}
    mine = median["aeroexec"]
    for who, figures in median.items():
        if who != "aeroexec":
            for count in ("pairs", "routes"):
                if figures[count] != mine[count]:
                    sys.exit(f"{who} found {figures[count]} {count}, aeroexec {mine[count]}")
    print(f"closure: {mine['pairs']:,} pairs from {args.links:,} links; join: {mine['routes']:,} routes from "
          f"{args.facts:,} facts; median of {args.repeat}, CPU seconds; × other: aeroexec's speed over theirs")
    goals = {"closure": ("SWI-Prolog", 0.5, "within 2x of SWI-Prolog"), "update": ("SWI-Prolog", 1.0, "faster")}
    others = [who for who in median if who != "aeroexec"]
    headers = ["workload", *(f"{who} (s)" for who in median), *(f"× {who}" for who in others), "goal"]
    labels = {"closure": f"closure ({args.links:,} links)", "join": f"three-way join ({args.facts:,} facts)",
              "update": "update one link"}
    body = []
    for key, label in labels.items():
        row = [label, *(f"{figures[key]:.4f}" for figures in median.values()),
               *(f"{median[who][key] / mine[key]:.2f}×" for who in others)]
        goal = goals.get(key)
        if goal is not None and goal[0] in median:
            ratio = median[goal[0]][key] / mine[key]
            row.append(f"{goal[2]}: {'met' if ratio >= goal[1] else 'missed'}")
        else:
            row.append("")
        body.append(row)
    widths = [max(len(r[i]) for r in [headers, *body]) for i in range(len(headers))]
    for row in [headers, ["-" * w for w in widths], *body]:
        print("  ".join(c.ljust(w) if i in (0, len(row) - 1) else c.rjust(w)
                        for i, (c, w) in enumerate(zip(row, widths, strict=True))))
    if args.readme:
        table = ["| " + " | ".join(headers) + " |", "|---|" + "---:|" * (len(headers) - 2) + "---|"]
        table += ["| " + " | ".join(r) + " |" for r in body]
        text = README.read_text()
        start, end = text.index(MARKS[0]) + len(MARKS[0]), text.index(MARKS[1])
        README.write_text(text[:start] + "\n" + "\n".join(table) + "\n" + text[end:])
        print(f"wrote the table into {README}")


if __name__ == "__main__":
    main()
