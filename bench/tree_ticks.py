"""Tree ticks for ``bench/engine.py --only trees``: aeroexec's tree runtime against a bare py_trees tree of the same
shape and plain recursion over the same nodes, all three asking the belief memory the same questions.

The floor is the plain recursion: one method call per node, a sequence a ``for`` loop over its children that returns
at the first failure (not ``all()`` over a generator, which costs a generator per sequence and is ~30 % slower).

The three are measured in turn within each repeat (interleaved), so a load that comes and goes weighs on all alike.
Two cases per size. *Standing beliefs*: every condition asks the same question and nothing changes between ticks,
so the memory answers from its standing answer when asked (the floor and py_trees ask at every tick; aeroexec's
CheckBelief asks again only when the memory's ``version`` moved, and keeps its answer meanwhile). *Changing
beliefs*: every condition asks a question of its own and the battery's charge changes before every tick, so every
question is solved again: the worst case for the memory, the same for all three.
"""

from __future__ import annotations

import statistics
import time
from pathlib import Path
from typing import Any

from provenance import load, measured_at, write_section

from engine import line, spread, verdict

PAGE = Path(__file__).resolve().parents[1] / "docs" / "performance" / "run.md"
BEGIN, END = "<!-- tree-ticks: begin (python bench/engine.py --only trees --docs) -->", "<!-- tree-ticks: end -->"


def tree_xml(groups: int, distinct: bool = False) -> str:
    """A tree that runs forever: 5 nodes per group (a Sequence of a CheckBelief, an Inverter of AlwaysFailure
    and AlwaysSuccess) under one Sequence under KeepRunningUntilFailure (``distinct``: a question per group)."""
    body = "".join(f'<Sequence><CheckBelief belief="{question(i, distinct)}"/>'
                   '<Inverter><AlwaysFailure/></Inverter><AlwaysSuccess/></Sequence>' for i in range(groups))
    return (f'<root BTCPP_format="4" main_tree_to_execute="Main"><BehaviorTree ID="Main">'
            f'<KeepRunningUntilFailure><Sequence>{body}</Sequence></KeepRunningUntilFailure>'
            f'</BehaviorTree></root>')


def question(index: int, distinct: bool) -> str:
    return f"charge(battery, ?C), ?C > {index % 20}.{index}" if distinct else "charge(battery, ?C), ?C > 20"


def trees(repeat: int, quick: bool, docs: bool = False) -> None:
    """Print the tick figures; ``docs``: write them as the tree-tick table of docs/performance/run.md as well."""
    import py_trees
    from aeroexec.drones.sim import SimulatedDrone
    from aeroexec.engine.engine import Engine
    from aeroexec.trees import read_mission_tree
    from aeroexec.trees.runtime.runner import TreeMission
    from py_trees.common import Status

    print("Tree ticks (ratios to bare py_trees and to plain recursion over the same shape, asking the belief memory "
          "the same questions)")
    engine = Engine(SimulatedDrone())
    engine.step(0.2)
    memory = engine.memory

    class Query(py_trees.behaviour.Behaviour):
        def __init__(self, text: str) -> None:
            super().__init__("condition")
            self.text = text

        def update(self) -> Status:
            return Status.SUCCESS if memory.holds(self.text) else Status.FAILURE

    def bare_tree(groups: int, distinct: bool) -> py_trees.behaviour.Behaviour:
        children = [py_trees.composites.Sequence("g", memory=False, children=[
            Query(question(i, distinct)), py_trees.decorators.Inverter("i", py_trees.behaviours.Failure("f")),
            py_trees.behaviours.Success("s")]) for i in range(groups)]
        return py_trees.composites.Sequence("root", memory=False, children=children)

    class Plain:
        __slots__ = ("children", "kind", "text")

        def __init__(self, kind: str, children: tuple = (), text: str = "") -> None:
            self.kind, self.children, self.text = kind, children, text

        def tick(self) -> bool:
            kind = self.kind
            if kind == "sequence":
                for child in self.children:  # noqa: SIM110 (the floor: all() over a generator is ~30 % slower)
                    if not child.tick():
                        return False
                return True
            if kind == "condition":
                return memory.holds(self.text)
            if kind == "inverter":
                return not self.children[0].tick()
            return kind == "success"

    def plain_tree(groups: int, distinct: bool) -> Plain:
        return Plain("sequence", tuple(Plain("sequence", (
            Plain("condition", text=question(i, distinct)), Plain("inverter", (Plain("failure"),)),
            Plain("success"))) for i in range(groups)))

    charge = [50]
    began = load()
    rows = ["| tree | aeroexec tick (min / median CPU) | bare py_trees (median) | plain recursion (the floor: a for "
            "loop per sequence; median) | aeroexec / plain recursion (median of the ticks' ratios, each pair measured "
            "side by side) | goal |", "|---|---:|---:|---:|---:|---|"]

    def change(changing: bool) -> None:
        if changing:  # the battery drains: every question reads it
            charge[0] = 51 - charge[0] % 2
            memory.add(f"charge(battery, {charge[0]})")

    for groups, target in ((100, 0.5), (1000, 5.0)):
        for changing in (False, True):
            mission = TreeMission(read_mission_tree(tree_xml(groups, changing), "bench.xml"), engine)
            mission.start()
            bare, plain = bare_tree(groups, changing), plain_tree(groups, changing)
            ticks = 20 if groups > 500 or quick else 100

            # interleaved tick by tick: aeroexec's tree and the plain recursion take turns (which goes first
            # alternates), so a load that comes and goes weighs on both alike and each pair's ratio is taken in the
            # same moment; bare py_trees (tens of times slower: it would flush the caches between them) is timed in
            # a block of its own in every repeat
            times: list[list[float]] = [[], [], []]

            def timed(tick: Any, measured: list[float], changing: bool = changing) -> None:
                change(changing)
                began_at = time.process_time()
                tick()
                measured.append(time.process_time() - began_at)

            for _ in range(repeat):
                for _ in range(max(ticks // 5, 2)):
                    timed(bare.tick_once, times[1])
                for n in range(ticks):
                    turns = ((mission.tick, times[0]), (plain.tick, times[2]))
                    for tick, measured in turns if n % 2 else reversed(turns):
                        timed(tick, measured)
            ours_t, py_t, plain_t = (spread(measured) for measured in times)
            pairs = sorted(o / p for o, p in zip(times[0], times[2], strict=True) if p > 0)
            nodes = len(mission.nodes)
            case = "changing beliefs" if changing else "standing beliefs"
            line(f"{nodes} nodes, {case}: bare py_trees", f"{py_t[1] * 1000:.2f} ms")
            line(f"{nodes} nodes, {case}: plain recursion", f"{plain_t[1] * 1000:.2f} ms",
                 f"{plain_t[1] / py_t[1]:.2f}x py_trees")
            line(f"{nodes} nodes, {case}: aeroexec tree tick", f"{ours_t[0] * 1000:.2f} / {ours_t[1] * 1000:.2f} ms",
                 f"{ours_t[1] / py_t[1]:.1f}x py_trees", verdict(ours_t[1] * 1000, target) if not changing else "")
            ratio = statistics.median(pairs)  # the median of the ticks' ratios, each pair measured side by side
            quartiles = pairs[len(pairs) // 4], pairs[3 * len(pairs) // 4]
            line(f"{nodes} nodes, {case}: aeroexec / plain recursion", "",
                 f"{ratio:.2f}x ({quartiles[0]:.2f}-{quartiles[1]:.2f})", verdict(ratio, 2))
            goals = [f"≤ {target:g} ms: {'met' if ours_t[1] * 1000 <= target else 'MISSED'}"] if not changing else []
            goals.append(f"≤ 2× plain recursion: {'met' if ratio <= 2 else 'MISSED'}")
            rows.append(f"| {nodes:,} nodes, {groups:,} belief conditions, {case} | {ours_t[0] * 1000:.2f} / "
                        f"{ours_t[1] * 1000:.2f} ms | {py_t[1] * 1000:.2f} ms ({ours_t[1] / py_t[1]:.2f}×) | "
                        f"{plain_t[1] * 1000:.2f} ms | {ratio:.2f}× (quartiles {quartiles[0]:.2f}–"
                        f"{quartiles[1]:.2f}×) | "
                        f"{'; '.join(goals)} |")
            mission.halt("bench")
    engine.stop()
    said = (f"Measured by `python bench/engine.py --only trees --repeat {repeat}{' --quick' if quick else ''} "
            f"--docs` (CPU time of this process, each tick measured alone, aeroexec's and the plain recursion's in "
            f"turns, bare py_trees' in a block of its own in every repeat, "
            f"{repeat} repeats of {20 if quick else 100} ticks of each, 20 at 5,002 nodes) at {measured_at(began)}.")
    print(said)
    if docs:
        write_section(PAGE, BEGIN, END, "\n".join([*rows, "", said]))
        print(f"{PAGE}: tree-tick table rewritten")
