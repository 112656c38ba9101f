"""A tree's state captured mid-run and put back into a tree built afresh: ticked on side by side, the two agree tick
by tick (statuses and blackboard), for every built-in node kind; a state does not go into another tree."""

from __future__ import annotations

import re

import pytest
from aeroexec.drones.sim import SimulatedDrone
from aeroexec.engine.clock import SimulatedClock
from aeroexec.engine.engine import Engine
from aeroexec.trees import read_mission_tree
from aeroexec.trees.runtime.nodes.registry import BUILT_IN
from aeroexec.trees.runtime.runner import TreeMission
from aeroexec.trees.runtime.ticking import status_name
from aeroexec.trees.runtime.tree_state import TreeState, TreeStateError, capture, restore_mission

COUNT = '<Script code="n := n + 1"/>'
SLEEP = '<Sleep msec="150"/>'


def switches() -> str:
    """Switch2..Switch6, each choosing its second case (v is 2) or, with no case matching, its last child."""
    made = []
    for cases in range(2, 7):
        ports = " ".join(f'case_{i}="{i}"' for i in range(1, cases + 1))
        chosen = 1 if cases < 4 else cases
        children = "".join(SLEEP if i == chosen else "<AlwaysFailure/>" for i in range(cases + 1))
        made.append(f'<Switch{cases} variable="{{v}}" {ports}>{children}</Switch{cases}>' if cases < 4 else
                    f'<Switch{cases} variable="x" {ports}>{children}</Switch{cases}>')
    return "".join(made)


TREES = {
    "sequences": f"""<Sequence><Script code="n := 0; q := '1;2;3'"/>
        <SequenceWithMemory>{COUNT}{SLEEP}<Inverter><AlwaysFailure/></Inverter>{SLEEP}</SequenceWithMemory>
        <AsyncSequence>{COUNT}{SLEEP}{COUNT}</AsyncSequence>
        <Fallback><AlwaysFailure/>{SLEEP}</Fallback><AsyncFallback><ForceFailure>{SLEEP}</ForceFailure>{COUNT}</AsyncFallback>
        <ReactiveSequence><ScriptCondition code="n &lt; 100"/>{SLEEP}</ReactiveSequence>
        <ReactiveFallback><ScriptCondition code="n &gt; 100"/>{SLEEP}</ReactiveFallback></Sequence>""",
    "parallels": f"""<Sequence><Script code="n := 0"/>
        <Parallel success_count="2" failure_count="2">{SLEEP}<Sleep msec="300"/><Sleep msec="450"/></Parallel>
        <ParallelAll max_failures="2"><Sleep msec="100"/><ForceFailure>{SLEEP}</ForceFailure>{SLEEP}</ParallelAll>
        </Sequence>""",
    "branches": f"""<Sequence><Script code="n := 0; v := 2"/>
        <IfThenElse><Sleep msec="100"/>{SLEEP}<AlwaysFailure/></IfThenElse>
        <WhileDoElse><ScriptCondition code="n &lt; 3"/><Sequence>{COUNT}{SLEEP}</Sequence>{SLEEP}</WhileDoElse>
        {switches()}
        <ForceSuccess><TryCatch>{SLEEP}<AlwaysFailure/>{SLEEP}</TryCatch></ForceSuccess></Sequence>""",
    "decorators": f"""<Sequence><Script code="n := 0; q := '1;2;3'; f := 0"/>
        <Repeat num_cycles="3"><Sequence>{COUNT}{SLEEP}</Sequence></Repeat>
        <RetryUntilSuccessful num_attempts="4"><Sequence><Script code="f := f + 1"/>{SLEEP}
            <ScriptCondition code="f &gt;= 3"/></Sequence></RetryUntilSuccessful>
        <RunOnce>{SLEEP}</RunOnce><RunOnce then_skip="false">{COUNT}</RunOnce>
        <Timeout msec="1000">{SLEEP}</Timeout><Delay delay_msec="200">{COUNT}</Delay>
        <Precondition if="n &gt; 0">{SLEEP}</Precondition>
        <LoopInt queue="1;2;3" value="{{i}}"><Sequence>{COUNT}{SLEEP}</Sequence></LoopInt>
        <LoopDouble queue="1.5;2.5" value="{{d}}">{SLEEP}</LoopDouble>
        <LoopString queue="a;b" value="{{s}}">{SLEEP}</LoopString>
        <LoopBool queue="true;false" value="{{b}}">{SLEEP}</LoopBool>
        <ForceSuccess><KeepRunningUntilFailure><Sequence>{COUNT}{SLEEP}<ScriptCondition code="n &lt; 12"/></Sequence>
            </KeepRunningUntilFailure></ForceSuccess>
        <SetBlackboard value="7" output_key="w"/><SkipUnlessUpdated entry="w">{SLEEP}</SkipUnlessUpdated>
        <WaitValueUpdate entry="w">{SLEEP}</WaitValueUpdate>
        <WasEntryUpdated entry="w"/><UnsetBlackboard key="w"/><AlwaysSuccess/>
        <SubTree ID="Inner" m="{{n}}"/></Sequence>""",
}
INNER = f'<BehaviorTree ID="Inner"><Sequence><Script code="m := m + 10"/>{SLEEP}</Sequence></BehaviorTree>'
ENGINE_LEAVES = {"AskBehavior", "CheckBelief", "Condition", "QueryBelief", "AddBelief", "RemoveBelief", "AddRule"}


def document(body: str):
    return read_mission_tree(f'<root BTCPP_format="4" main_tree_to_execute="T"><BehaviorTree ID="T">{body}'
                             f'</BehaviorTree>{INNER}</root>', "state.xml")


def mission(body: str, start: float = 0.0) -> tuple[Engine, TreeMission]:
    engine = Engine(SimulatedDrone(start_time=start), clock=SimulatedClock(start))
    run = TreeMission(document(body), engine)
    return engine, run


def seen(run: TreeMission) -> tuple:
    return tuple(status_name(node) for _, node in run.nodes), tuple(sorted(run.blackboard.items()))


def test_every_built_in_node_kind_is_exercised_here():
    used = set(re.findall(r"<(\w+)", "".join(TREES.values())))
    assert set(BUILT_IN) - ENGINE_LEAVES <= used, set(BUILT_IN) - ENGINE_LEAVES - used


def length(body: str) -> int:
    """How many ticks the tree runs."""
    engine, run = mission(body)
    run.start()
    for tick in range(1, 1000):
        engine.step(engine.period)
        if run.done:
            return tick
    raise AssertionError("the tree does not end")


@pytest.mark.parametrize("name", list(TREES))
@pytest.mark.parametrize("part", [0.1, 0.35, 0.6, 0.85])
def test_a_restored_tree_goes_on_as_the_original(name, part):
    ticks = max(1, int(length(TREES[name]) * part))
    engine, original = mission(TREES[name])
    original.start()
    for _ in range(ticks):
        engine.step(engine.period)
    assert not original.done
    text = capture(original.root, original.blackboard).to_json()
    again_engine, again = mission(TREES[name], start=engine.now())
    restore_mission(again, TreeState.from_json(text))
    assert capture(again.root, again.blackboard).to_json() == text
    again.start()
    for tick in range(200):
        engine.step(engine.period)
        again_engine.step(again_engine.period)
        assert seen(again) == seen(original), f"tick {ticks + tick + 1} after the restore"
        if original.done:
            break
    assert original.done and again.done and again.status == original.status


def test_a_state_does_not_go_into_another_tree():
    _, one = mission(TREES["decorators"])
    _, other = mission(TREES["sequences"])
    state = capture(one.root, one.blackboard)
    with pytest.raises(TreeStateError, match=r"state.xml:\d+: the tree has"):
        restore_mission(other, state)
    compact = state.to_json(shape=False)
    assert TreeState.from_json(compact, state.shape()).to_json() == state.to_json()
    with pytest.raises(TreeStateError, match="without the shape"):
        TreeState.from_json(compact)
