"""The one-feature set as the cases BehaviorTree.CPP 4.10's traces were recorded from (``data/btcpp410``).

``cases()`` gives each tree as the C++ driver (``data/btcpp410/trace_driver.cpp``) reads it: name, XML, the scripted
leaves, ticks, seconds between ticks and the blackboard set before the first tick -- the trees of
``one_feature_trees`` (ONE_FEATURE, LENIENT), ``test_btcpp_parity.HAND_WRITTEN`` and the 4.10-only trees;
``generated_cases()`` draws trees from the parity test's generators, ``generated_scripts()`` script expressions,
``generated_remaps()`` SubTrees three levels deep. ``python btcpp410_cases.py data/btcpp410/cases.json`` writes both
(data/btcpp410/SOURCES.md).
"""

from __future__ import annotations

import json
import random
import sys
from typing import Any

from one_feature_trees import DATA, LENIENT, ONE_FEATURE
from test_btcpp_one_feature import ONLY_4_10, tree
from test_btcpp_parity import BLACKBOARDS, HAND_WRITTEN, SUBTREES, generated, generated_with_conditions
from test_btcpp_parity import tree as parity_tree

S, F, R = "SUCCESS", "FAILURE", "RUNNING"
#: The 4.10-only trees' leaves (TryCatch: behaviortreepy's 4.8.2 lacks it)
_ONLY_4_10_SCRIPTS = {"TryCatch catch_on_halt": ({"A": [R], "B": [S]}, 3),
                      "TryCatch": ({"A": [S], "B": [R, F], "C": [R, S]}, 5)}


def cases() -> list[dict[str, Any]]:
    out = []
    for name, case in sorted(ONE_FEATURE.items()):
        out.append({"name": f"one feature: {name}", "xml": tree(case), "scripts": case.scripts, "ticks": case.ticks,
                    "between": case.between, "blackboard": case.blackboard or {}})
    for name, (body, scripts) in sorted(HAND_WRITTEN.items()):
        out.append({"name": f"hand written: {name}", "xml": parity_tree(body, *SUBTREES.get(name, [])),
                    "scripts": scripts, "ticks": 8, "between": 0.2 if name in ("Sleep", "Timeout", "Delay") else 0.0,
                    "blackboard": BLACKBOARDS.get(name) or {}})
    for name, (scripts, blackboard) in sorted(LENIENT.items()):
        out.append({"name": f"lenient: {name}", "xml": (DATA / name).read_text(), "scripts": scripts, "ticks": 6,
                    "between": 0.0, "blackboard": blackboard or {}})
    bodies = {**ONLY_4_10, "TryCatch": "<TryCatch><A/><B/><C/></TryCatch>"}
    for name, body in sorted(bodies.items()):
        scripts, ticks = _ONLY_4_10_SCRIPTS[name]
        out.append({"name": f"4.10 only: {name}", "xml": parity_tree(body), "scripts": scripts, "ticks": ticks,
                    "between": 0.0, "blackboard": {}})
    return out


def generated_cases(plain: int = 120, scripted: int = 80) -> list[dict[str, Any]]:
    """Trees drawn (derandomized) from the parity test's generators: controls and decorators with edge counts, and
    trees whose leaves carry pre- and post-conditions, Switch and Precondition on a tick counter. Recorded with their
    traces: the records hold the trees, so a new hypothesis version draws no other ones for the test."""
    from hypothesis import HealthCheck, given, settings

    out: list[dict[str, Any]] = []
    boards = {"plain": {}, "scripted": {"t": 0, "ok": 0, "ko": 0, "all": 0, "halts": 0}}
    for kind, strategy, count in (("plain", generated(), plain), ("scripted", generated_with_conditions(), scripted)):
        drawn: list[tuple[str, dict[str, list[str]]]] = []

        @settings(max_examples=count, database=None, derandomize=True, deadline=None,
                  suppress_health_check=list(HealthCheck))
        @given(strategy)
        def collect(case: tuple[str, dict[str, list[str]]]) -> None:
            if case not in drawn:  # noqa: B023 (run at once, in this iteration)
                drawn.append(case)  # noqa: B023

        collect()
        out += [{"name": f"generated {kind} {i}", "xml": xml, "scripts": scripts, "ticks": 8, "between": 0.0,
                 "blackboard": boards[kind]} for i, (xml, scripts) in enumerate(drawn, 1)]
    return out


_OPERATORS = ("+", "-", "*", "/", "..", "&", "|", "^", "&&", "||", "==", "!=", "<", ">", "<=", ">=")
_OPERANDS = ("1", "2", "0", "3", "2.5", "0.5", "true", "false", "'x'", "'3'", "a", "b", "s", "0x10", "7")


def generated_scripts(count: int = 300, seed: int = 44) -> list[dict[str, Any]]:
    """Script expressions over every operator (binary, prefix ``- ! ~`` repeated, ``?:`` nested, parentheses) on
    integers, doubles, text, booleans and the entries ``a`` (int), ``b`` (double), ``s`` (text): each tree assigns one
    to ``r`` in one tick, so the record holds its value or where it threw."""
    rng = random.Random(seed)

    def atom(depth: int) -> str:
        pick = rng.random()
        if depth > 2 or pick < 0.45:
            return rng.choice(_OPERANDS)
        if pick < 0.55:
            return rng.choice(("-", "!", "~", "- -")) + atom(depth + 1)
        if pick < 0.65:
            return "(" + expression(depth + 1) + ")"
        if pick < 0.72:
            return f"{expression(depth + 1)} ? {expression(depth + 1)} : {expression(depth + 1)}"
        return expression(depth + 1)

    def expression(depth: int = 0) -> str:
        text = atom(depth)
        for _ in range(rng.randint(0, 2)):
            text += f" {rng.choice(_OPERATORS)} {atom(depth + 1)}"
        return text

    out: list[dict[str, Any]] = []
    seen: set[str] = set()
    while len(out) < count:
        text = expression()
        if text in seen:
            continue
        seen.add(text)
        code = text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;").replace('"', "&quot;")
        xml = parity_tree(f'<Sequence><Script code="a := 3; b := 2.5; s := \'x\'"/><Script code="r := {code}"/>'
                          "</Sequence>")
        out.append({"name": f"generated script {len(out) + 1}: {text}", "xml": xml, "scripts": {}, "ticks": 1,
                    "between": 0.0, "blackboard": {}})
    return out


def generated_remaps(count: int = 80, seed: int = 3) -> list[dict[str, Any]]:
    """SubTrees three levels deep, each passing ports down by ``{key}`` remaps, ``{=}``, literals (numbers and text)
    or ``_autoremap``, with scripts at each level reading and writing remapped, literal, ``_private`` and
    ``@root`` keys: the record holds the root blackboard after two ticks, or where a read threw."""
    rng = random.Random(seed)
    writes = ("x := 4", "y := 2.5", "z := 'q'", "_p := 1", "@top := 7", "v := 2", "w := 1", "w := x .. y",
              "n := @top", "m := _p", "k := x + 1")

    def ports() -> str:
        chosen = [rng.choice(('x="{x}"', 'x="{a}"', 'x="{=}"', 'x="3"', 'x="2.5"', "")),
                  rng.choice(('y="{y}"', 'y="{b}"', 'y="4"', "")), rng.choice(('z="{z}"', 'z="t"', 'z="{=}"', "")),
                  rng.choice(('_autoremap="true"', "", ""))]
        return " ".join(p for p in chosen if p)

    out = []
    for index in range(1, count + 1):
        levels = []
        for level in range(1, 4):
            script = "; ".join(rng.sample(writes, rng.randint(1, 3)))
            inner = f'<SubTree ID="L{level + 1}" {ports()}/>' if level < 3 else "<A/>"
            levels.append(f'<BehaviorTree ID="L{level}"><Sequence><Script code="{script}"/>{inner}</Sequence>'
                          "</BehaviorTree>")
        xml = parity_tree(f'<Sequence><Script code="a := 1; b := 2; x := 5; y := 6; z := \'s\'"/>'
                          f'<SubTree ID="L1" {ports()}/></Sequence>', *levels)
        out.append({"name": f"generated remap {index}", "xml": xml, "scripts": {"A": [S]}, "ticks": 2,
                    "between": 0.0, "blackboard": {}})
    return out


if __name__ == "__main__":
    with open(sys.argv[1], "w", encoding="utf-8") as file:
        everything = cases() + generated_cases() + generated_scripts() + generated_remaps()
        json.dump(everything, file, indent=1, sort_keys=True)
        file.write("\n")
