"""BehaviorTree.CPP itself as the judge of aeroexec's tree runtime. The reference is BT.CPP 4.10; the live oracle is
behaviortreepy, which embeds 4.8.2: where 4.10 changed a result, the case records 4.8.2's and 4.10's
(``SINCE_4_10``, ``btcpp_harness.as_4_10``), and the trees only 4.10 runs are checked against 4.10's source.

Every tree runs in both with scripted leaves, and what each tick does to every node (the status it returned,
a halt, or nothing) is the same, tick after tick; ``btcpp_harness`` says exactly what is compared and why.
One hand-written tree per built-in node and rule, then hypothesis-generated trees (depth <= 6). The seed of
the generated trees is printed on failure; set ``PARITY_SEED`` to replay it (``PARITY_SEED=random`` explores new
trees; the default is fixed so CI runs the same trees every time).
"""

from __future__ import annotations

import os
import random

import pytest
from btcpp_harness import compare, run_aeroexec, run_btcpp
from depth import examples
from hypothesis import HealthCheck, assume, given, seed, settings
from hypothesis import strategies as st
from one_feature_trees import TRUE_4_10

#: The generated trees' seed: fixed, so CI runs the same trees every time; PARITY_SEED=N (or "random") explores.
SEED = int(random.randrange(1 << 30) if os.environ.get("PARITY_SEED") == "random"
           else os.environ.get("PARITY_SEED", 20261123))
S, F, R = "SUCCESS", "FAILURE", "RUNNING"


def tree(body: str, *subtrees: str) -> str:
    return ('<root BTCPP_format="4" main_tree_to_execute="M"><BehaviorTree ID="M">' + body + "</BehaviorTree>"
            + "".join(subtrees) + "</root>")


HAND_WRITTEN = {
    "Sequence": ("<Sequence><A/><B/><C/></Sequence>", {"A": [S], "B": [R, S, F], "C": [R, S]}),
    "SequenceWithMemory": ("<SequenceWithMemory><A/><B/></SequenceWithMemory>", {"A": [S, F], "B": [F, R, S]}),
    "ReactiveSequence": ("<ReactiveSequence><A/><B/><C/></ReactiveSequence>",
                         {"A": [S, S, F, S], "B": [S, R, R], "C": [R, S]}),
    "Fallback": ("<Fallback><A/><B/></Fallback>", {"A": [F, R, F], "B": [R, S, F]}),
    "AsyncSequence": ("<AsyncSequence><A/><B/><C/></AsyncSequence>", {"A": [S, R, S], "B": [S, F], "C": [R, S]}),
    "AsyncFallback": ("<AsyncFallback><A/><B/><C/></AsyncFallback>", {"A": [F, R, F], "B": [F, S], "C": [R, F]}),
    "ReactiveFallback": ("<ReactiveFallback><A/><B/></ReactiveFallback>", {"A": [F, F, S, R], "B": [R]}),
    "Parallel": ('<Parallel success_count="2" failure_count="2"><A/><B/><C/></Parallel>',
                 {"A": [R, S], "B": [R, R, F], "C": [F, R, S]}),
    "IfThenElse": ("<IfThenElse><A/><B/><C/></IfThenElse>", {"A": [R, S, F], "B": [R, S], "C": [F]}),
    "WhileDoElse": ("<WhileDoElse><A/><B/><C/></WhileDoElse>", {"A": [S, S, F, S], "B": [R], "C": [R, S]}),
    "Inverter": ("<Inverter><A/></Inverter>", {"A": [R, S, F]}),
    "ForceSuccess": ("<ForceSuccess><A/></ForceSuccess>", {"A": [R, F]}),
    "ForceFailure": ("<ForceFailure><A/></ForceFailure>", {"A": [S, R]}),
    "Repeat": ('<Repeat num_cycles="3"><A/></Repeat>', {"A": [S, R, S, F]}),
    "RetryUntilSuccessful": ('<RetryUntilSuccessful num_attempts="3"><A/></RetryUntilSuccessful>',
                             {"A": [F, R, F, S]}),
    "KeepRunningUntilFailure": ("<KeepRunningUntilFailure><A/></KeepRunningUntilFailure>", {"A": [S, R, F]}),
    "RunOnce": ('<Sequence><RunOnce><A/></RunOnce><B/></Sequence>', {"A": [R, S], "B": [S]}),
    "RunOnce then_skip false": ('<Sequence><RunOnce then_skip="false"><A/></RunOnce><B/></Sequence>',
                                {"A": [F], "B": [S]}),
    "SubTree": ('<Sequence><A/><SubTree ID="Sub"/></Sequence>', {"A": [S], "B": [R, S]}),
    "AlwaysSuccess/AlwaysFailure": ("<Fallback><AlwaysFailure/><Sequence><AlwaysSuccess/><A/></Sequence></Fallback>",
                                    {"A": [R, F]}),
}
HAND_WRITTEN.update({
    "Script": ('<Sequence><Script code="a := 1; b := a + 2.5; c := \'x\' .. b; d := true; e := 0x10"/><A/>'
               '</Sequence>', {"A": [S]}),
    "ScriptCondition": ('<Sequence><Script code="n := 0"/><Repeat num_cycles="6"><Sequence><Script code="n += 1"/>'
                        '<Fallback><ScriptCondition code="n &lt; 3"/><A/></Fallback></Sequence></Repeat></Sequence>',
                        {"A": [R, F]}),
    "script operators": ('<Sequence><Script code="a := 7; b := 2; s := \'ab\'"/>'
                         '<Script code="r1 := a / b; r2 := a - b * 3; r3 := -a; r4 := a &amp; 3; r5 := a | 8; '
                         'r6 := a ^ 5; r7 := ~a; r8 := !0; r9 := a &gt; b &amp;&amp; b &gt; 0 || false"/>'
                         '<Script code="c1 := 1 &lt; b &lt;= 2; c2 := a == 7.0; c3 := s == \'ab\'; '
                         'c4 := s != \'x\'; t := a &gt; 5 ? \'big\' : \'small\'; u := s .. a; '
                         'a -= 1; b *= 4; a /= 2; s += \'c\'"/>'
                         '<ScriptCondition code="a == 3 &amp;&amp; b == 8"/><A/></Sequence>', {"A": [S]}),
    "SetBlackboard/UnsetBlackboard": ('<Sequence><SetBlackboard output_key="k" value="hello"/>'
                                      '<Script code="gone := 1"/><UnsetBlackboard key="gone"/>'
                                      '<ScriptCondition code="k == \'hello\'"/><A/></Sequence>', {"A": [S]}),
    "Switch2": ('<Sequence><Script code="c := c + 1; v := c &gt; 5 ? \'none\' : (c &gt; 2 ? \'b\' : \'a\')"/>'
                '<Switch2 variable="{v}" case_1="a" case_2="b"><A/><B/><C/></Switch2></Sequence>',
                {"A": [R, S], "B": [R, F], "C": [S]}),
    "Switch3": ('<Switch3 variable="{mode}" case_1="land" case_2="hover" case_3="go"><A/><B/><C/><D/></Switch3>',
                {"A": [S], "B": [R], "C": [S], "D": [F]}),
    "Precondition": ('<Sequence><Script code="n := (n + 1) * 1"/>'
                     '<Precondition if="n &gt;= 2 &amp;&amp; n != 4" else="SUCCESS"><A/></Precondition></Sequence>',
                     {"A": [R, S]}),
    "_skipIf/_successIf/_failureIf": ('<Sequence><Script code="n := n + 1"/><A _skipIf="n == 2"/>'
                                      '<B _successIf="n == 3"/><C _failureIf="n &gt; 4"/></Sequence>',
                                      {"A": [S], "B": [R, S], "C": [S]}),
    "_while": ('<Sequence><Script code="n := n + 1"/><A _while="n &lt; 4"/></Sequence>', {"A": [R]}),
    "_onSuccess/_onFailure/_post": ('<Sequence><A _onSuccess="ok := ok + 1" _onFailure="ko := ko + 1" '
                                    '_post="all := all + 1"/><B/></Sequence>', {"A": [S, F, R, S], "B": [S]}),
    "_onHalted": ('<ReactiveSequence><A/><B _onHalted="halts := halts + 1"/></ReactiveSequence>',
                  {"A": [S, S, F], "B": [R]}),
    "ParallelAll": ('<ParallelAll max_failures="2"><A/><B/><C/></ParallelAll>',
                    {"A": [R, S], "B": [F, R], "C": [R, R, F]}),
    "Sleep": ('<Sequence><A/><Sleep msec="300"/><B/></Sequence>', {"A": [S], "B": [R, S]}),
    "Timeout": ('<Fallback><Timeout msec="300"><A/></Timeout><B/></Fallback>', {"A": [R, R, R, S], "B": [S]}),
    "Delay": ('<Sequence><Delay delay_msec="300"><A/></Delay><B/></Sequence>', {"A": [S, R], "B": [S]}),
    "LoopInt": ('<Sequence><LoopInt queue="1;2;3" value="{v}"><Sequence><Script code="sum := sum + v"/><A/>'
                '</Sequence></LoopInt><B/></Sequence>', {"A": [S, R, S], "B": [S]}),
    "LoopDouble": ('<LoopDouble queue="1.5;2.5" value="{v}" if_empty="FAILURE"><Sequence>'
                   '<Script code="sum := sum + v"/><A/></Sequence></LoopDouble>', {"A": [S, F, S]}),
    "LoopString": ('<LoopString queue="a;b;c" value="{v}"><Sequence><Script code="s := s .. v"/><A/></Sequence>'
                   '</LoopString>', {"A": [S]}),
    "LoopBool": ('<LoopBool queue="true;false;true" value="{v}"><Fallback><ScriptCondition code="v"/><A/>'
                 '</Fallback></LoopBool>', {"A": [R, S]}),
    "SkipUnlessUpdated": ('<Sequence><Script code="n := n + 1"/><Fallback>'
                          '<ScriptCondition code="n == 1 || n == 3 || n == 5 || n == 7"/>'
                          '<Script code="x := n"/></Fallback><SkipUnlessUpdated entry="x"><A/></SkipUnlessUpdated>'
                          '</Sequence>', {"A": [R, S]}),
    "WaitValueUpdate": ('<Sequence><Script code="n := n + 1"/><Fallback><ScriptCondition code="n &lt; 4"/>'
                        '<Script code="x := n"/></Fallback><WaitValueUpdate entry="x"><A/></WaitValueUpdate>'
                        '</Sequence>', {"A": [S]}),
    "WasEntryUpdated": ('<Sequence><Script code="n := n + 1"/><Fallback><ScriptCondition code="n == 2 || n == 5"/>'
                        '<Script code="x := n"/></Fallback><Fallback><WasEntryUpdated entry="x"/><A/></Fallback>'
                        '</Sequence>', {"A": [S]}),
    "skipped Sequence under a ReactiveSequence": ('<ReactiveSequence><Sequence><A _skipIf="true"/></Sequence><B/>'
                                                  '</ReactiveSequence>', {"A": [S], "B": [R, R, S]}),
    "RunOnce skipped on a second pass in one tick": ('<Repeat num_cycles="2"><Sequence><A/><RunOnce><B/></RunOnce>'
                                                      '</Sequence></Repeat>', {"A": [R, S, S], "B": [S]}),
    "Repeat num_cycles={n}": ('<Sequence><Script code="n := 2"/><Repeat num_cycles="{n}"><A/></Repeat></Sequence>',
                              {"A": [S, R, S]}),
})
BLACKBOARDS = {"LoopInt": {"sum": 0}, "LoopDouble": {"sum": 0.0}, "LoopString": {"s": ""},
               "SkipUnlessUpdated": {"n": 0}, "WaitValueUpdate": {"n": 0}, "WasEntryUpdated": {"n": 0},
               "Switch2": {"c": 0}, "Switch3": {"mode": "hover"}, "Precondition": {"n": 0},
               "_skipIf/_successIf/_failureIf": {"n": 0}, "_while": {"n": 0},
               "_onSuccess/_onFailure/_post": {"ok": 0, "ko": 0, "all": 0}, "_onHalted": {"halts": 0}}
HAND_WRITTEN.update({
    "SubTree literal port": ('<Sequence><SubTree ID="Leg" target="3"/><SubTree ID="Leg" target="4"/></Sequence>',
                             {"A": [S], "B": [R, S]}),
    "SubTree port default from TreeNodesModel": ('<Sequence><SubTree ID="Leg"/><SubTree ID="Leg" target="4"/>'
                                                 '</Sequence>', {"A": [S], "B": [R, S]}),
})
HAND_WRITTEN["@key: the root blackboard"] = ('<Sequence><SubTree ID="Deep"/><ScriptCondition code="g == 5"/><A/>'
                                             '</Sequence>', {"A": [S]})
SUBTREE_DEEP = '<BehaviorTree ID="Deep"><Script code="@g := @start + 4; local := 1"/></BehaviorTree>'
BLACKBOARDS["@key: the root blackboard"] = {"start": 1}
LEG = ('<BehaviorTree ID="Leg"><Fallback><Sequence><ScriptCondition code="target == 3"/><A/></Sequence><B/>'
       '</Fallback></BehaviorTree>')
SUBTREES = {"SubTree literal port": [LEG], "@key: the root blackboard": [SUBTREE_DEEP],
            "SubTree port default from TreeNodesModel": [LEG, '<TreeNodesModel><SubTree ID="Leg">'
                                                              '<input_port name="target" default="3"/></SubTree>'
                                                              '</TreeNodesModel>'],
            "SubTree": ['<BehaviorTree ID="Sub"><Fallback><AlwaysFailure/><B/></Fallback></BehaviorTree>']}


#: Where BT.CPP 4.10 (the reference) gives another result than the embedded 4.8.2: key -> (4.8.2's, 4.10's).
SINCE_4_10 = {"Script": {"d": ("1", TRUE_4_10)}}


@pytest.mark.parametrize("case", sorted(HAND_WRITTEN))
def test_built_in_node_ticks_as_in_btcpp(case, tmp_path):
    body, scripts = HAND_WRITTEN[case]
    between = 0.0
    if case in ("Sleep", "Timeout", "Delay"):
        # time runs on the wall clock in BT.CPP, on the engine clock here: ticks 0.5 s apart, timers of 0.75 s, so
        # BT.CPP's timer thread and its ticks may each be a quarter of a second late on a loaded machine (with
        # 0.2 s and 0.3 s, a timer thread starved for 100 ms fired a tick late: seen in CI)
        body, between = body.replace('msec="300"', 'msec="750"'), 0.5
    compare(tree(body, *SUBTREES.get(case, [])), scripts, 8, tmp_path, between, BLACKBOARDS.get(case),
            SINCE_4_10.get(case))


def test_try_catch_ticks_as_btcpp_4_10_documents_it():
    """TryCatch came with BT.CPP 4.10; behaviortreepy embeds 4.8.2, which lacks it. The expected ticks are read
    off 4.10's try_catch_node.cpp: children 1..N-1 run as a Sequence; when one fails the try-block is reset and the
    last child runs; when it completes the node fails, whatever the catch child answered."""
    run = run_aeroexec(tree("<TryCatch><A/><B/><C/></TryCatch>"), {"A": [S], "B": [R, F], "C": [R, S]}, 5)
    assert run.ticks == [[R, S, R, "-"],
                         [R, "-", F, R],
                         [F, "-", "-", S],
                         [R, S, R, "-"],
                         [R, "-", F, R]]
    assert run.roots == [R, R, F, R, R]


def test_try_catch_all_succeeding_succeeds_and_catch_on_halt_runs_the_catch_child():
    run = run_aeroexec(tree("<TryCatch><A/><B/></TryCatch>"), {"A": [S], "B": [S]}, 2)
    assert run.roots == [S, S] and run.ticks[0] == [S, S, "-"]
    halting = run_aeroexec(tree('<ReactiveSequence><C/><TryCatch catch_on_halt="true"><A/>'
                                '<Script code="caught := 1"/></TryCatch></ReactiveSequence>'),
                           {"A": [R], "C": [S, F]}, 2)
    assert halting.ticks[1][:4] == [F, F, "HALTED", "HALTED"]
    assert halting.blackboard == {"caught": "1"}  # halted in its try-block: the catch child ran


def test_a_script_error_in_a_try_block_escapes_the_tick_as_in_btcpp_4_10():
    """4.10's TryCatch catches a child's FAILURE, not an exception (try_catch_node.cpp has no try/catch): a script
    error in the try-block throws out of the tick, and the catch child does not run."""
    run = run_aeroexec(tree('<TryCatch><Script code="y := missing"/><Script code="caught := 1"/></TryCatch>'), {}, 2)
    assert run.error_at == 0 and "Variable not found: missing" in run.error and run.blackboard == {}


def test_nested_conditionals_without_parentheses_run_as_in_btcpp_4_10(tmp_path):
    """4.10's Pratt parser (script_parser.cpp: parseTernary) takes a ``?:`` in either branch; 4.8.2 refused it as
    the tree loaded, which behaviortreepy still shows."""
    xml = tree('<Script code="x := 0 ? 1 : 0 ? 2 : 3; y := 1 ? 0 ? 4 : 5 : 6"/>')
    assert run_btcpp(xml, {}, 1, tmp_path).error_at == -1  # 4.8.2 (behaviortreepy): refused as it loads
    run = run_aeroexec(xml, {}, 1)
    assert run.error_at is None and run.blackboard == {"x": "3", "y": "5"}


def test_bit_operators_on_an_infinity_throw_as_in_btcpp_4_10_not_crash():
    """4.10 (operators.hpp): ``|`` on a number that is no int64 throws "Binary operators are not allowed...", ``~``
    out of int64's range "Number out of range for bitwise operation"; both end the run naming the Script."""
    for code, message in (("r := (1 / 0) | 1", "Binary operators are not allowed if one of the operands is not an "
                                                "integer"),
                          ("r := ~(1 / 0)", "Number out of range for bitwise operation")):
        run = run_aeroexec(tree(f'<Script code="{code}"/>'), {}, 1)
        assert run.error_at == 0 and run.error.endswith(message) and "Script" in run.error


def test_a_single_behavior_tree_without_id_runs_as_in_btcpp(tmp_path):
    xml = '<root BTCPP_format="4"><BehaviorTree><Sequence><A/><B/></Sequence></BehaviorTree></root>'
    compare(xml, {"A": [S, F], "B": [R, S]}, 6, tmp_path)


# -- generated trees ---------------------------------------------------------------------------------
CONTROLS = ("Sequence", "SequenceWithMemory", "Fallback", "AsyncSequence", "AsyncFallback", "ReactiveSequence",
            "ReactiveFallback", "Parallel", "ParallelAll",
            "IfThenElse", "WhileDoElse")
DECORATORS = ("Inverter", "ForceSuccess", "ForceFailure", "Repeat", "RetryUntilSuccessful",
              "KeepRunningUntilFailure", "RunOnce")
scripts_of = st.lists(st.sampled_from((S, F, R)), min_size=1, max_size=4)


ATTRIBUTES = st.sampled_from(('_skipIf="t == {n}"', '_successIf="t == {n}"', '_failureIf="t == {n}"',
                               '_while="t != {n}"', '_onSuccess="ok := ok + {n}"', '_onFailure="ko := ko + {n}"',
                               '_post="all := all + 1"', '_onHalted="halts := halts + 1"'))


@st.composite
def node(draw, depth: int, leaves: list[list[str]], condition: bool = False, scripted: bool = False) -> str:
    """A node; ``condition``: the first child of IfThenElse/WhileDoElse (as a leaf, never RUNNING); ``scripted``:
    leaves may carry pre- and post-conditions on the tick counter ``t``."""
    kind = draw(st.sampled_from(("leaf",) * 3 + ("control",) * 2 + ("decorator",))) if depth < 6 else "leaf"
    if condition:
        kind = "leaf"  # BT.CPP's IfThenElse throws on a SKIPPED condition
    if kind == "leaf":
        leaves.append(draw(st.lists(st.sampled_from((S, F)), min_size=1, max_size=4) if condition else scripts_of))
        extra = ""
        if scripted and not condition and draw(st.booleans()):
            extra = " " + draw(ATTRIBUTES).format(n=draw(st.integers(1, 6)))
        return f"<L{len(leaves)}{extra}/>"
    if kind == "decorator":
        name = draw(st.sampled_from(DECORATORS + (("Precondition",) if scripted else ())))
        ports = ""
        if name == "Precondition":
            ports = (f' if="t != {draw(st.integers(1, 6))}" '
                     f'else="{draw(st.sampled_from(("SUCCESS", "FAILURE", "SKIPPED")))}"')
        if name == "Repeat":
            ports = f' num_cycles="{draw(st.integers(1, 3))}"'
        elif name == "RetryUntilSuccessful":
            ports = f' num_attempts="{draw(st.integers(1, 3))}"'
        elif name == "RunOnce":
            ports = f' then_skip="{draw(st.sampled_from(("true", "false")))}"'
        return f"<{name}{ports}>{draw(node(depth + 1, leaves, scripted=scripted))}</{name}>"
    name = draw(st.sampled_from(CONTROLS + (("Switch2", "Switch3") if scripted else ())))
    if name.startswith("Switch"):
        cases = int(name[-1])
        ports = "".join(f' case_{i}="{draw(st.integers(1, 6))}"' for i in range(1, cases + 1))
        children = "".join(draw(node(depth + 1, leaves, scripted=scripted)) for _ in range(cases + 1))
        return f'<{name} variable="{{s}}"{ports}>{children}</{name}>'  # s: t as text (a Switch reads text)
    low, high = (2, 3) if name in ("IfThenElse", "WhileDoElse") else (1, 4)
    count = draw(st.integers(low, high))
    conditional = name in ("IfThenElse", "WhileDoElse")
    children = "".join(draw(node(depth + 1, leaves, conditional and i == 0, scripted)) for i in range(count))
    ports = ""
    if name == "Parallel":
        success = draw(st.sampled_from([-1, *range(1, count + 1)]))
        failure = draw(st.integers(1, count))
        ports = f' success_count="{success}" failure_count="{failure}"'
    if name == "ParallelAll":
        ports = f' max_failures="{draw(st.integers(1, count))}"'
    return f"<{name}{ports}>{children}</{name}>"


@st.composite
def generated(draw) -> tuple[str, dict[str, list[str]]]:
    leaves: list[list[str]] = []
    body = draw(node(1, leaves))
    return tree(body), {f"L{i}": script for i, script in enumerate(leaves, 1)}


@st.composite
def generated_with_conditions(draw) -> tuple[str, dict[str, list[str]]]:
    """Trees whose leaves carry scripted pre- and post-conditions, with Switch and Precondition nodes on a tick
    counter that a Script in front of the tree increments."""
    leaves: list[list[str]] = []
    body = draw(node(1, leaves, scripted=True))
    return (tree(f'<Sequence><Script code="t := t + 1; s := t .. \'\'"/>{body}</Sequence>'),
            {f"L{i}": script for i, script in enumerate(leaves, 1)})


@seed(SEED)
@settings(max_examples=examples(50), deadline=None, database=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(generated_with_conditions())
def test_generated_trees_with_pre_and_post_conditions_tick_as_in_btcpp(tmp_path, case):
    xml, scripts = case
    try:
        compare(xml, scripts, 8, tmp_path, blackboard={"t": 0, "ok": 0, "ko": 0, "all": 0, "halts": 0})
    except RuntimeError as error:
        assume("more than one async child" not in str(error))
        raise
    except AssertionError as error:
        raise AssertionError(f"{error}\n(replay with PARITY_SEED={SEED})") from None


@seed(SEED)
@settings(max_examples=examples(90), deadline=None, database=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(generated())
def test_generated_trees_tick_as_in_btcpp(tmp_path, case):
    xml, scripts = case
    try:
        compare(xml, scripts, 8, tmp_path)
    except RuntimeError as error:  # trees BT.CPP refuses to load are no parity case
        assume("more than one async child" not in str(error))
        raise
    except AssertionError as error:
        raise AssertionError(f"{error}\n(replay with PARITY_SEED={SEED})") from None
