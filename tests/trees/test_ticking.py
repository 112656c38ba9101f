"""How a tree ticks (trees/runtime/ticking.py): one call per node, the status changes reported as they happen.

The runner reports only the nodes that recorded a change (no scan of the tree), and a control node starting again
shows IDLE the children it did not reach only once the tick ends: what the terminal, the console and Groot2 show
must still be every node's true status after every tick."""

from __future__ import annotations

import pytest
from aeroexec.drones.sim import SimulatedDrone
from aeroexec.engine.engine import Engine
from aeroexec.trees import read_mission_tree
from aeroexec.trees.runtime.runner import TreeMission
from aeroexec.trees.runtime.ticking import status_name
from py_trees.common import Status

TREE = """<root BTCPP_format="4"><BehaviorTree ID="Main">
<KeepRunningUntilFailure>
 <Sequence name="each tick">
  <Script code="n := n + 1"/>
  <Fallback name="either">
   <ScriptCondition name="shortcut" code="n == 2 || n == 5 || n == 9"/>
   <Sequence name="the long way">
    <ScriptCondition code="n != 3 &amp;&amp; n != 7"/>
    <Inverter><ScriptCondition code="n == 4"/></Inverter>
    <Switch2 variable="{n}" case_1="6" case_2="8"><AlwaysFailure/><Sleep msec="200"/><AlwaysSuccess/></Switch2>
   </Sequence>
   <AlwaysSuccess name="otherwise"/>
  </Fallback>
  <ReactiveSequence><ScriptCondition code="n &lt; 12"/><AlwaysSuccess _skipIf="n == 10"/></ReactiveSequence>
 </Sequence>
</KeepRunningUntilFailure>
</BehaviorTree></root>"""


@pytest.fixture
def engine():
    engine = Engine(SimulatedDrone())
    yield engine
    engine.stop()


def reported(engine: Engine) -> dict[int, str]:
    """Every node's status as the node_status events told it, by uid."""
    shown: dict[int, str] = {}
    for event in engine.log.events(kind="node_status"):
        assert shown.get(event.data["uid"], "IDLE") == event.data["old"]  # each event starts where the last ended
        shown[event.data["uid"]] = event.data["new"]
    return shown


def test_the_status_reported_for_every_node_is_its_status_after_every_tick(engine):
    mission = TreeMission(read_mission_tree(TREE, "ticking.xml"), engine, blackboard={"n": 0})
    mission.start()
    names = {node.name: uid for uid, (_, node) in enumerate(mission.nodes, 1)}
    seen: list[tuple[int, str, str]] = []
    for _ in range(100):  # 12 runs of the tree, four ticks of Sleep
        if mission.done:
            break
        engine.step(engine.period)
        shown = reported(engine)
        truth = {uid: status_name(node) for uid, (_, node) in enumerate(mission.nodes, 1)}
        assert {uid: shown.get(uid, "IDLE") for uid in truth} == truth
        n = mission.blackboard["n"]
        seen.append((n, truth[names["shortcut"]], truth[names["the long way"]]))
    assert mission.status == Status.FAILURE and mission.blackboard["n"] == 12  # ``n < 12`` failed at last
    # n == 2: the shortcut succeeds and the long way, which ran at n == 1, is not reached: shown IDLE again
    assert (1, "FAILURE", "SUCCESS") in seen and (2, "SUCCESS", "IDLE") in seen
    # n == 3 and 4: the long way fails, at its first and then its second child; n == 8: Sleep keeps it RUNNING
    assert (3, "FAILURE", "FAILURE") in seen and (4, "FAILURE", "FAILURE") in seen
    assert any(n == 8 and long == "RUNNING" for n, _, long in seen)


def test_py_trees_tick_still_yields_every_node_ticked_with_its_status(engine):
    mission = TreeMission(read_mission_tree(TREE, "ticking.xml"), engine, blackboard={"n": 0})
    ticked = [(node.name, status_name(node)) for node in mission.root.tick()]  # py_trees' own way of ticking
    assert ticked[-1] == ("KeepRunningUntilFailure", "RUNNING")
    assert ("shortcut", "FAILURE") in ticked and ("the long way", "SUCCESS") in ticked
    assert "otherwise" not in [name for name, _ in ticked]  # the Fallback did not reach it
