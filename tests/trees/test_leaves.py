"""Leaves on the engine: behaviors, beliefs, the blackboard from QueryBelief to ports, SubTree remapping, halting."""

from __future__ import annotations

import pytest
from aeroexec.drones.sim import SimulatedDrone, default_world
from aeroexec.engine.engine import Engine
from aeroexec.trees.model import TreeDocument, TreeNode
from aeroexec.trees.runtime.blackboard import Blackboard
from aeroexec.trees.runtime.runner import TreeMission
from py_trees.common import Status


def N(kind: str, *children: TreeNode, name: str = "", line: int = 0, **ports: str) -> TreeNode:  # noqa: N802
    return TreeNode(kind, name, dict(ports), list(children), "mission.xml", line)


@pytest.fixture
def engine():
    world = default_world()
    engine = Engine(SimulatedDrone(world), obstacles=world)
    yield engine
    engine.stop()


def run(engine: Engine, root: TreeNode, max_time: float = 120.0, **trees: TreeNode) -> TreeMission:
    mission = TreeMission(TreeDocument({"Main": root, **trees}, "Main", "mission.xml"), engine)
    mission.run(max_time)
    return mission


def statuses(engine: Engine, node: str) -> list[str]:
    return [e.data["new"] for e in engine.log.events(kind="node_status") if e.data["node"] == node]


def activated(engine: Engine, behavior: str) -> list[str]:
    return [e.detail for e in engine.log.events(kind="activated", behavior=behavior)]


def test_take_off_go_to_point_land_runs_to_success(engine):
    mission = run(engine, N("Sequence", N("TAKE_OFF", ALTITUDE="2"), N("GO_TO_POINT", COORDINATES="2, -1, 2"),
                            N("LAND")))
    assert mission.status == Status.SUCCESS
    assert engine.log.events(kind="mission_completed")
    assert statuses(engine, "GO_TO_POINT") == ["RUNNING", "SUCCESS"]
    assert [e.behavior for e in engine.log.events(kind="GOAL_ACHIEVED")] == ["TAKE_OFF", "GO_TO_POINT", "LAND"]
    x, y, z = engine.drone.telemetry().position
    assert (x, y, z) == pytest.approx((2, -1, 0), abs=0.3)
    assert "[SUCCESS] LAND" in mission.display()


def test_query_belief_variables_flow_to_a_behavior_port(engine):
    for belief in ("object(pad, marker)", "code(pad, 3)", "position(pad, (2, -1, 2))"):
        engine.memory.add(belief)
    mission = run(engine, N("Sequence", N("TAKE_OFF"),
                            N("QueryBelief", belief="object(?X, marker), code(?X, 3), position(?X, ?P)"),
                            N("GO_TO_POINT", COORDINATES="{P}")))
    assert mission.status == Status.SUCCESS
    assert mission.blackboard["X"] == "pad" and mission.blackboard["P"] == (2, -1, 2)
    assert "COORDINATES=(2, -1, 2)" in activated(engine, "GO_TO_POINT")[0]


def test_subtree_ports_remap_keys_and_set_literals(engine):
    engine.memory.add("position(pad, (2, -1, 2))")
    fly = N("Sequence", N("TAKE_OFF", ALTITUDE="{height}"), N("GO_TO_POINT", COORDINATES="{target}"),
            N("QueryBelief", belief="position(pad, ?Inner)"))
    mission = run(engine, N("Sequence", N("QueryBelief", belief="position(pad, ?P)"),
                            N("SubTree", ID="Fly", target="{P}", height="2.5")), Fly=fly)
    assert mission.status == Status.SUCCESS
    assert "ALTITUDE=2.5" in activated(engine, "TAKE_OFF")[0]
    assert "COORDINATES=(2, -1, 2)" in activated(engine, "GO_TO_POINT")[0]
    assert set(mission.blackboard) == {"P"}  # the subtree's own keys stay in its blackboard


def test_blackboard_remapping_and_autoremap():
    parent = Blackboard(values={"goal": (1, 2, 3), "shared": 1})
    isolated = Blackboard.for_subtree(parent, {"ID": "X", "target": "{goal}", "speed": "1.5"})
    assert isolated["target"] == (1, 2, 3) and isolated["speed"] == 1.5 and "shared" not in isolated  # 4.10: a number
    isolated["target"] = (4, 5, 6)
    isolated["local"] = True
    assert parent["goal"] == (4, 5, 6) and "local" not in parent
    shared = Blackboard.for_subtree(parent, {"ID": "X", "_autoremap": "true"})
    shared["result"] = 42
    assert shared["shared"] == 1 and parent["result"] == 42
    shared["_private"] = 7  # BT.CPP: an underscore-prefixed key stays the subtree's own under _autoremap
    assert "_private" not in parent and shared["_private"] == 7 and list(shared) == ["_private", "goal", "result",
                                                                                      "shared"]


def test_ask_behavior_puts_a_deliberative_result_on_the_blackboard(engine):
    mission = run(engine, N("Sequence", N("TAKE_OFF"),
                            N("AskBehavior", behavior="GENERATE_PATH_FREE_OF_OBSTACLES", DESTINATION="2, -1, 2",
                              result="{path}"),
                            N("FOLLOW_PATH", PATH="{path}")))
    assert mission.status == Status.SUCCESS
    assert mission.blackboard["path"][-1] == pytest.approx([2, -1, 2], abs=0.01)
    assert engine.log.events(kind="GOAL_ACHIEVED", behavior="FOLLOW_PATH")


def test_beliefs_conditions_and_skip_if(engine):
    mission = run(engine, N("Sequence", N("AddBelief", belief="code(box, 7)"), N("Condition", belief="code(box, 7)"),
                            N("TAKE_OFF", _skipIf="code(box, 7)"), N("RemoveBelief", belief="code(box, ?C)"),
                            N("Inverter", N("Condition", belief="code(box, ?C)"))))
    assert mission.status == Status.SUCCESS
    assert not engine.log.events(kind="activated", behavior="TAKE_OFF")
    assert statuses(engine, "TAKE_OFF") == ["SKIPPED"]


def test_a_refused_activation_fails_the_leaf(engine):
    mission = run(engine, N("Sequence", N("LAND")))
    assert mission.status == Status.FAILURE
    assert statuses(engine, "LAND") == ["FAILURE"]
    assert engine.log.events(kind="failed_preconditions", behavior="LAND")
    assert engine.log.events(kind="mission_failed")


def test_timeout_halts_the_running_behavior_which_is_interrupted(engine):
    mission = run(engine, N("Sequence", N("TAKE_OFF"),
                            N("Timeout", N("GO_TO_POINT", COORDINATES="8, -1, 2", line=7), msec="1000")))
    assert mission.status == Status.FAILURE
    interrupted = engine.log.events(kind="INTERRUPTED", behavior="GO_TO_POINT")
    assert interrupted and interrupted[0].detail == "halted by the behavior tree (mission.xml:7)"
    assert statuses(engine, "Timeout") == ["RUNNING", "FAILURE"]
    assert statuses(engine, "GO_TO_POINT") == ["RUNNING", "IDLE"]


def test_halting_the_tree_stops_every_behavior_it_started(engine):
    tree = N("Sequence", N("TAKE_OFF"),
             N("Parallel", N("KEEP_MOVING", DIRECTION="FORWARD", SPEED="0.5"),
               N("PAY_ATTENTION_TO_VISUAL_MARKERS")))
    mission = run(engine, tree, max_time=5.0)
    assert mission.done and mission.status == Status.RUNNING  # it was still running when halted
    stopped = {e.behavior for e in engine.log.events(kind="INTERRUPTED")}
    assert {"KEEP_MOVING", "PAY_ATTENTION_TO_VISUAL_MARKERS"} <= stopped
    assert not engine.coordinator.is_active("KEEP_MOVING")
    assert engine.log.events(kind="mission_failed")[-1].detail == "Main: halted (time limit)"


def test_a_tree_halted_while_it_waits_for_a_belief_names_it(engine):
    wait = N("KeepRunningUntilFailure", N("Inverter", N("CheckBelief", belief="cleared(runway)", line=4), line=4),
             line=3)
    mission = run(engine, N("Sequence", wait, N("TAKE_OFF")), max_time=5.0)
    assert mission.done and not engine.log.events(kind="activated", behavior="TAKE_OFF")
    assert engine.log.events(kind="mission_failed")[-1].detail == (
        "Main: halted (time limit); it was waiting for the belief cleared(runway) (mission.xml:3), which nothing "
        "added (aeroexec ctl add gives it; aeroexec run --event or --alert at launch)")


def test_a_recurrent_behavior_node_succeeds_once_active_without_waiting(engine):
    tree = N("Sequence", N("TAKE_OFF"), N("PAY_ATTENTION_TO_VISUAL_MARKERS", _wait_for_completion="false"),
             N("GO_TO_POINT", COORDINATES="2, -1, 2"))
    mission = run(engine, tree)
    assert mission.status == Status.SUCCESS
    assert statuses(engine, "PAY_ATTENTION_TO_VISUAL_MARKERS") == ["SUCCESS"]
    ended = engine.log.events(kind="INTERRUPTED", behavior="PAY_ATTENTION_TO_VISUAL_MARKERS")
    assert ended and ended[0].time >= engine.log.events(kind="GOAL_ACHIEVED", behavior="GO_TO_POINT")[0].time


def test_a_missing_blackboard_key_fails_the_leaf_with_an_explanation(engine):
    mission = run(engine, N("Sequence", N("TAKE_OFF"), N("GO_TO_POINT", COORDINATES="{nowhere}")))
    assert mission.status == Status.FAILURE
    errors = engine.log.events(kind="tree_error")
    assert errors and "the blackboard has no value for {nowhere}" in errors[0].detail


def test_an_aerostack_flat_yaml_mission_verifies_and_runs(engine):
    from pathlib import Path

    from aeroexec.trees.mission_file import load_mission_tree
    from aeroexec.trees.verify import verify_document

    document = load_mission_tree(Path(__file__).parent / "data" / "aerostack_tower_inspection.yaml")
    assert verify_document(document, engine.catalog) == []
    mission = TreeMission(document, engine)
    assert mission.run(300.0) == Status.SUCCESS
    assert [e.behavior for e in engine.log.events(kind="GOAL_ACHIEVED")][-1] == "LAND"


def test_check_belief_and_scripts_consult_the_belief_memory(engine):
    engine.memory.add("code(box, 7)")
    mission = run(engine, N("Sequence", N("CheckBelief", belief="code(box, 7)"),
                            N("ScriptCondition", code='belief("code(box, ?C), ?C > 5") && !belief("code(box, 1)")'),
                            N("TAKE_OFF", _skipIf='belief("code(box, 7)")', _onSuccess="took := 1"),
                            N("Script", code="done := true")))
    assert mission.status == Status.SUCCESS
    assert mission.blackboard["done"] == 1 and "took" not in mission.blackboard
    assert not engine.log.events(kind="activated", behavior="TAKE_OFF")  # skipped: the belief holds


def test_a_script_failing_in_flight_fails_the_mission_naming_its_node_and_line(engine):
    mission = run(engine, N("Fallback", N("Script", code="y := missing + 1", line=3), N("Script", code="handled := 1")))
    assert mission.status != Status.SUCCESS and "handled" not in mission.blackboard  # BT.CPP throws: no fallback
    assert [e.detail for e in engine.log.events(kind="tree_error")] == [
        "mission.xml:3: Script: Error in script [y := missing + 1]: Variable not found: missing"]
    [failed] = engine.log.events(kind="mission_failed")
    assert "Script failed at mission.xml:3" in failed.detail and "Variable not found: missing" in failed.detail


def test_a_script_failing_in_a_try_block_fails_the_mission_as_btcpp_4_10_lets_it_escape(engine):
    """BT.CPP 4.10's TryCatch catches a child's FAILURE, not an exception: the error escapes the tick."""
    mission = run(engine, N("Fallback", N("TryCatch", N("Precondition", N("AlwaysSuccess"), line=4,
                                                        **{"if": "nothing > 1"}),
                                          N("Script", code="caught := 1")),
                            N("Script", code="handled := 1")))
    assert mission.status != Status.SUCCESS
    assert "caught" not in mission.blackboard and "handled" not in mission.blackboard
    assert [e.detail for e in engine.log.events(kind="tree_error")] == [
        "mission.xml:4: Precondition: Error in script [nothing > 1]: Variable not found: nothing"]
    [failed] = engine.log.events(kind="mission_failed")
    assert "Precondition failed at mission.xml:4" in failed.detail


def test_a_script_failing_while_a_node_is_halted_is_recorded_and_the_halt_goes_on(engine):
    mission = run(engine, N("Sequence", N("Script", code="n := 0"),
                            N("ReactiveSequence", N("ScriptCondition", code="n := n + 1; n < 3"),
                              N("Sleep", msec="10000", line=7, _onHalted="x := missing"))))
    assert mission.status == Status.FAILURE  # the condition failed on the third tick: the tree ended there
    [error] = [e.detail for e in engine.log.events(kind="tree_error")]
    assert error.startswith("mission.xml:7: Sleep: _onHalted: Error in script [x := missing]")


def test_a_condition_is_asked_again_only_when_the_memory_changed(engine, monkeypatch):
    """A CheckBelief ticked while nothing changed answers from its last answer; a change is seen at the next tick."""
    asked = []
    ask = engine.memory.holds_standing
    monkeypatch.setattr(engine.memory, "holds_standing", lambda text: asked.append(text) or ask(text))
    engine.memory.add("code(box, 7)")
    engine.tick_callbacks.append(lambda: engine.clock.now() > 1.0 and engine.memory.add("code(box, 3)"))
    mission = run(engine, N("KeepRunningUntilFailure", N("CheckBelief", belief="code(box, 7)")), max_time=5.0)
    assert mission.status == Status.FAILURE and "mission_failed" in [e.kind for e in engine.log.events()]
    assert statuses(engine, "CheckBelief") == ["SUCCESS", "FAILURE"]
    assert len(asked) <= 4  # ~20 ticks before the change: asked once, again once kept, and after the change


def test_a_condition_on_a_belief_that_expires_fails_when_it_expires(engine):
    """``visible`` lasts 2 s: the condition fails when the belief goes, though no belief was added or removed."""
    engine.memory.add("visible(box)")
    mission = run(engine, N("KeepRunningUntilFailure", N("CheckBelief", belief="visible(box)")), max_time=10.0)
    [failed] = engine.log.events(kind="mission_failed")
    assert mission.status == Status.FAILURE and "time limit" not in failed.detail
    assert 1.5 < failed.time < 3.0


def test_a_condition_on_a_computed_predicate_is_asked_at_every_tick(engine):
    """``mission_time`` is computed: its answer changes with no belief changing."""
    late = N("CheckBelief", belief="mission_time(?T), ?T > 1")
    mission = run(engine, N("KeepRunningUntilFailure", N("Inverter", late)), max_time=10.0)
    [failed] = engine.log.events(kind="mission_failed")
    assert mission.status == Status.FAILURE and "time limit" not in failed.detail
