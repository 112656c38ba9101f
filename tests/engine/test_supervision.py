"""The operator's commands on the engine (engine/supervision.py), in lockstep on simulated time: pause holds the
drone and the mission, resume asks again for what the pause stopped, abort lands, answer reaches ASK_OPERATOR."""

from __future__ import annotations

import math
import time

import pytest
from aeroexec.drones import LandedState
from aeroexec.drones.sim import SimulatedDrone, default_world
from aeroexec.engine import api
from aeroexec.engine.engine import Engine
from aeroexec.engine.events import Outcome
from aeroexec.engine.supervision.operator import LoggingOperator, RemoteOperator
from aeroexec.trees.model import TreeDocument, TreeNode
from aeroexec.trees.runtime.runner import TreeMission
from py_trees.common import Status

FAR = (12.0, 0.0, 3.0)


@pytest.fixture
def engine():
    world = default_world()
    engine = Engine(SimulatedDrone(world), obstacles=world, operator=RemoteOperator())
    yield engine
    engine.stop()


def flight(results: list, steps: list) -> callable:
    def mission() -> None:
        results.append(api.execute_behavior("TAKE_OFF", altitude=3))
        steps.append("took off")
        results.append(api.execute_behavior("GO_TO_POINT", coordinates=FAR))
        steps.append("arrived")
        results.append(api.execute_behavior("LAND"))
        steps.append("landed")

    return mission


def flying_east(engine: Engine) -> tuple[list, list]:
    """Start the flight and tick until it is on its way to FAR: the mission's results and steps so far."""
    results: list = []
    steps: list = []
    engine.start_mission(flight(results, steps))
    assert engine.run_until(lambda: engine.coordinator.is_active("GO_TO_POINT"), 60)
    return results, steps


def commands(engine: Engine) -> list[tuple[str, bool]]:
    return [(e.data["command"], e.data["ok"]) for e in engine.log.events(kind="operator_command")]


def test_pause_holds_the_drone_and_the_mission_and_resume_goes_on(engine):
    results, steps = flying_east(engine)
    engine.step(1.0)
    result = engine.supervisor.execute("pause", origin="test")
    assert result.ok and "GO_TO_POINT" in result.message
    assert engine.coordinator.active()["KEEP_HOVERING"].source == "operator"
    engine.step(4.0)  # brakes, then holds
    held = engine.drone.telemetry().position
    engine.step(10.0)
    telemetry = engine.drone.telemetry()
    assert math.dist(held, telemetry.position) < 0.3 and telemetry.speed < 0.2
    assert steps == ["took off"] and not engine.coordinator.is_active("GO_TO_POINT")
    assert not engine.supervisor.execute("pause").ok  # already paused
    assert engine.supervisor.execute("resume").ok
    assert engine.coordinator.is_active("GO_TO_POINT") and not engine.coordinator.is_active("KEEP_HOVERING")
    assert engine.run_until(lambda: len(steps) == 3, 120)
    assert results == [Outcome.GOAL_ACHIEVED] * 3  # the mission never saw the pause's INTERRUPTED
    assert engine.drone.telemetry().position[0] == pytest.approx(FAR[0], abs=0.5)
    assert commands(engine) == [("pause", True), ("pause", False), ("resume", True)]
    assert engine.log.events(kind="INTERRUPTED", behavior="GO_TO_POINT")[0].detail == "paused by the operator"


def test_a_pause_while_hovering_by_reaction_lets_the_next_request_go_after_resume(engine):
    """A pause that comes as TAKE_OFF ends finds KEEP_HOVERING already hovering by reaction: the pause raised it to
    its own priority and resume left it there, so the mission's next GO_TO_POINT was refused ("KEEP_HOVERING has a
    higher priority") and the mission failed (the browser test hit it on a loaded machine)."""
    results: list = []

    def mission() -> None:
        results.append(api.execute_behavior("TAKE_OFF", altitude=3))
        api.wait(1.0)
        results.append(api.execute_behavior("GO_TO_POINT", coordinates=FAR))

    engine.start_mission(mission)
    hovering = engine.coordinator.active
    assert engine.run_until(lambda: getattr(hovering().get("KEEP_HOVERING"), "source", None) == "reactive", 60)
    assert engine.supervisor.execute("pause", origin="test").ok
    engine.step(2.0)
    assert engine.supervisor.execute("resume").ok
    assert engine.run_until(lambda: len(results) == 2, 120)
    assert results == [Outcome.GOAL_ACHIEVED] * 2
    assert not engine.log.events(kind="rejected", behavior="GO_TO_POINT")


def test_a_paused_python_mission_does_not_call_the_engine(engine):
    calls = []

    def mission() -> None:
        for _ in range(100):
            calls.append(api.now())
            api.wait(0.5)

    engine.start_mission(mission)
    engine.step(2.0)
    engine.supervisor.execute("pause")
    engine.step(0.2)
    deadline = time.monotonic() + 30  # a wait that ended as the pause began lets the mission reach its next call
    while not engine.bridge.queued and time.monotonic() < deadline:
        time.sleep(0.01)
    before = len(calls)
    engine.step(5.0)
    assert len(calls) == before
    engine.supervisor.execute("resume")
    engine.step(2.0)
    assert len(calls) > before


def test_abort_stops_the_mission_and_lands(engine):
    results, steps = flying_east(engine)
    engine.step(1.0)
    result = engine.supervisor.execute("abort", origin="test")
    assert result.ok and "landing" in result.message
    assert set(engine.coordinator.active()) <= {"LAND", "SELF_LOCALIZE_BY_ODOMETRY"}
    assert engine.run_until(lambda: engine.drone.telemetry().landed_state is LandedState.ON_GROUND, 60)
    assert engine.run_until(lambda: engine.bridge.state == "done", 5)
    assert steps == ["took off"]  # the mission never went on
    assert engine.drone.telemetry().position[0] < FAR[0] - 3
    assert not engine.supervisor.execute("resume").ok


def test_abort_while_paused_ends_the_waiting_call_and_lands(engine):
    results, steps = flying_east(engine)
    engine.supervisor.execute("pause")
    engine.step(1.0)
    engine.supervisor.execute("abort")
    assert engine.run_until(lambda: engine.bridge.state == "done", 5)
    assert engine.run_until(lambda: engine.drone.telemetry().landed_state is LandedState.ON_GROUND, 60)
    assert steps == ["took off"]


def test_answer_reaches_ask_operator(engine):
    answers = []

    def mission() -> None:
        answers.append(api.ask_behavior("ASK_OPERATOR", question="Go on?", possible_answers=["yes", "no"]))

    assert not engine.supervisor.execute("answer", "yes").ok  # nothing asked yet
    engine.start_mission(mission)
    assert engine.run_until(lambda: engine.context.operator.pending_questions(), 10)
    engine.step(3.0)
    assert not answers  # the question waits for the operator
    result = engine.supervisor.execute("answer", "2")  # the second possible answer
    assert result.ok and "'no'" in result.message
    assert engine.run_until(lambda: answers, 5)
    assert answers == ["no"] and engine.memory.holds("answer('Go on?', no)")


def test_inhibit_add_remove_and_unknown_commands(engine):
    engine.step(1.0)
    assert engine.coordinator.is_active("SELF_LOCALIZE_BY_ODOMETRY")
    assert engine.supervisor.execute("inhibit", "self_localize_by_odometry").ok
    engine.step(1.0)
    assert not engine.coordinator.is_active("SELF_LOCALIZE_BY_ODOMETRY")  # reactions do not start it again
    assert not engine.supervisor.execute("inhibit", "FLY_AWAY").ok
    assert engine.supervisor.execute("add", "visible(marker_3)").ok
    assert engine.memory.holds("visible(marker_3)")
    assert "1 belief" in engine.supervisor.execute("remove", "visible(?x)").message
    assert not engine.memory.holds("visible(?x)")
    assert not engine.supervisor.execute("add", "visible(").ok
    assert not engine.supervisor.execute("warp").ok
    status = engine.supervisor.execute("status")
    assert status.data["state"] == "running" and status.data["landed_state"] == "on_ground"
    assert [c for c, _ in commands(engine)] == ["inhibit", "inhibit", "add", "remove", "add", "warp"]


def test_commands_submitted_from_another_thread_run_on_the_tick(engine):
    ticket = engine.supervisor.submit("add", "visible(marker_1)", origin="test")
    assert ticket.wait(0.05) is None  # nothing runs it until the engine ticks
    engine.step(0.1)
    assert ticket.wait(1.0).ok and engine.memory.holds("visible(marker_1)")


def N(kind: str, *children: TreeNode, **ports: str) -> TreeNode:  # noqa: N802
    return TreeNode(kind, "", dict(ports), list(children), "mission.xml", 0)


def test_a_paused_tree_stops_ticking_and_its_leaf_resumes_with_the_behavior():
    world = default_world()
    engine = Engine(SimulatedDrone(world), obstacles=world, operator=LoggingOperator())
    try:
        tree = TreeMission(TreeDocument({"Main": N("Sequence", N("TAKE_OFF", ALTITUDE="3"),
                                                   N("GO_TO_POINT", COORDINATES="12, 0, 3"), N("LAND"))},
                                        "Main", "mission.xml"), engine)
        tree.start()
        assert engine.supervisor.missions == (tree,)
        assert engine.run_until(lambda: engine.coordinator.is_active("GO_TO_POINT"), 60)
        engine.supervisor.execute("pause")
        engine.step(5.0)
        assert tree.paused and not engine.coordinator.is_active("GO_TO_POINT")
        assert "[RUNNING] GO_TO_POINT" in tree.display()  # the leaf still waits for its behavior
        engine.supervisor.execute("resume")
        assert engine.run_until(lambda: tree.done, 120)
        assert tree.status == Status.SUCCESS and engine.supervisor.missions == ()
        assert [e.behavior for e in engine.log.events(kind="GOAL_ACHIEVED")][-2:] == ["GO_TO_POINT", "LAND"]
    finally:
        engine.stop()


def test_abort_halts_a_tree_and_lands():
    world = default_world()
    engine = Engine(SimulatedDrone(world), obstacles=world)
    try:
        tree = TreeMission(TreeDocument({"Main": N("Sequence", N("TAKE_OFF", ALTITUDE="3"),
                                                   N("GO_TO_POINT", COORDINATES="12, 0, 3"))},
                                        "Main", "mission.xml"), engine)
        tree.start()
        assert engine.run_until(lambda: engine.coordinator.is_active("GO_TO_POINT"), 60)
        engine.supervisor.execute("abort")
        assert tree.done and engine.log.events(kind="mission_failed")
        assert engine.run_until(lambda: engine.drone.telemetry().landed_state is LandedState.ON_GROUND, 60)
    finally:
        engine.stop()


# -- resume: continue what was paused, refuse what the situation now refuses (issue 18, point 1) -------------
RESUME_CATALOG = """
predicates:
- {predicate: cleared, arity: 2}
behavior_descriptors:
- behavior: MOVE
  timeout: 60
  incompatible_lists: [motion]
  preconditions: cleared(path, yes)
- behavior: CLIMB
  timeout: 60
  incompatible_lists: [motion]
  preconditions: cleared(ground, yes)
- behavior: KEEP_HOVERING
  category: recurrent
  incompatible_lists: [motion]
behavior_lists:
- {list: motion, behaviors: [MOVE, CLIMB, KEEP_HOVERING]}
"""


def resume_engine():
    import textwrap

    from aeroexec.engine.catalog import parse_catalog
    from aeroexec.engine.execution.process import BehaviorLibrary, BehaviorProcess

    class Timed(BehaviorProcess):
        """Achieved after 4 s of running in all; a resumed one goes on from where the paused one was."""

        done = ran = 0.0

        def resume_from(self, paused):
            self.done = paused.ran

        def on_stop(self, outcome):
            self.ran = self.done + self.elapsed

        def on_start(self):
            if self.name == "CLIMB":  # its own progress falsifies its precondition, as TAKE_OFF's
                self.memory.remove("cleared(ground, ?x)")

        def on_run(self):
            return Outcome.GOAL_ACHIEVED if self.done + self.elapsed >= 4.0 else None

    library = BehaviorLibrary()
    for name in ("MOVE", "CLIMB", "KEEP_HOVERING"):
        library.register(Timed if name != "KEEP_HOVERING" else BehaviorProcess, name)
    catalog = parse_catalog(textwrap.dedent(RESUME_CATALOG), "resume.yaml")
    return Engine(SimulatedDrone(), catalog=catalog, library=library)


@pytest.mark.parametrize("behavior, belief, falsified_during_pause, expected", [
    ("CLIMB", "cleared(ground, yes)", False, Outcome.GOAL_ACHIEVED),  # its own progress: continues
    ("MOVE", "cleared(path, yes)", True, Outcome.FAILED_PRECONDITIONS),  # the situation changed: refused
])
def test_a_resumed_behavior_continues_unless_the_situation_now_refuses_it(behavior, belief, falsified_during_pause,
                                                                          expected):
    from aeroexec.flight.run_status import COMPLETED, REFUSED, run_status

    engine = resume_engine()
    results = []

    def mission() -> None:
        api.add_belief(belief)
        results.append(api.execute_behavior(behavior))

    try:
        engine.start_mission(mission)
        engine.step(2.0)
        assert engine.supervisor.execute("pause").ok and not engine.coordinator.is_active(behavior)
        if falsified_during_pause:
            engine.supervisor.execute("remove", belief)
        engine.step(3.0)
        resumed = engine.supervisor.execute("resume")
        assert ("refused now" in resumed.message) == (expected is Outcome.FAILED_PRECONDITIONS)
        engine.run_until(lambda: engine.bridge.state == "done", 30)
        assert results == [expected]
        if expected is Outcome.GOAL_ACHIEVED:  # 2 s before the pause + 2 s after: it went on, not again
            achieved = engine.log.events(kind="GOAL_ACHIEVED", behavior=behavior)[0].time
            assert achieved == pytest.approx(5.0 + 2.0, abs=0.2)
        engine.log.record("mission_completed")  # the bridge ended it: how the run would be summed up
        assert run_status(engine.log.events()).word == (COMPLETED if expected is Outcome.GOAL_ACHIEVED
                                                         else REFUSED)
    finally:
        engine.stop()
