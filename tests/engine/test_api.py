"""The Python mission API (Table 8) against a running engine on the simulated clock, with scripted behaviors."""

import textwrap

import aeroexec.engine.api as api
import pytest
from aeroexec.drones.sim import SimulatedDrone
from aeroexec.engine.catalog import parse_catalog
from aeroexec.engine.engine import Engine
from aeroexec.engine.events import Outcome
from aeroexec.engine.execution.process import BehaviorLibrary, BehaviorProcess

CATALOG = """
predicates:
- {predicate: flight_state, arity: 2}
- {predicate: charge, arity: 2}
- {predicate: position, arity: 2}
- {predicate: visited, arity: 2}
behavior_descriptors:
- behavior: GO
  timeout: 10
  incompatible_lists: [motion]
  arguments:
    - {argument: COORDINATES, allowed_values: [-100, 100], dimensions: 3, required: yes}
- behavior: HOVER
  category: recurrent
  incompatible_lists: [motion]
- behavior: PLAN
  category: deliberative
- behavior: GUARDED
  preconditions: flight_state(self, hovering)
behavior_lists:
- {list: motion, behaviors: [GO, HOVER]}
"""


class Go(BehaviorProcess):
    """Arrives after one second per meter from the origin, and remembers where it went."""

    def on_run(self):
        target = self.arguments["COORDINATES"]
        if self.elapsed >= sum(abs(v) for v in target):
            self.memory.add(f"visited(self, {tuple(float(v) for v in target)})")
            return Outcome.GOAL_ACHIEVED
        return None


class Plan(BehaviorProcess):
    def on_run(self):
        self.result = [[0.0, 0.0, 1.0], [2.0, 0.0, 1.0]]
        return Outcome.GOAL_ACHIEVED


def make_engine():
    library = BehaviorLibrary()
    for name, cls in {"GO": Go, "HOVER": BehaviorProcess, "PLAN": Plan, "GUARDED": BehaviorProcess}.items():
        library.register(cls, name)
    catalog = parse_catalog(textwrap.dedent(CATALOG), "test.yaml")
    return Engine(SimulatedDrone(), catalog=catalog, library=library)


def fly(mission, max_time=120.0):
    engine = make_engine()
    try:
        engine.run(mission, max_time=max_time)
    finally:
        engine.stop()
    return engine


def test_execute_behavior_waits_for_the_goal_and_returns_it():
    seen = {}

    def mission():
        seen["start"] = api.now()
        seen["result"] = api.execute_behavior("GO", coordinates=[1, 2, 0])  # case-insensitive names
        seen["end"] = api.now()
        seen["visited"] = api.consult_belief("visited(self, ?P)")

    engine = fly(mission)
    assert seen["result"] == Outcome.GOAL_ACHIEVED == "GOAL_ACHIEVED"
    assert seen["end"] - seen["start"] == pytest.approx(3.0, abs=0.11)  # three simulated seconds
    success, unification = seen["visited"]
    assert success and unification["?P"] == (1.0, 2.0, 0.0) and unification["P"] == (1.0, 2.0, 0.0)
    assert engine.log.events(kind="mission_completed")


def test_activate_inhibit_and_is_active():
    seen = []

    def mission():
        seen.append(api.activateBehavior("HOVER"))
        seen.append(api.isActiveBehavior("HOVER"))
        api.wait(1.0)
        seen.append(api.inhibitBehavior("HOVER"))
        seen.append(api.is_active_behavior("HOVER"))

    engine = fly(mission)
    assert seen == ["OK", True, True, False]
    assert [e.kind for e in engine.log.events(behavior="HOVER")] == ["activated", "INTERRUPTED"]


def test_failed_preconditions_are_returned_and_a_wrong_value_raises_in_the_mission():
    seen = []

    def mission():
        seen.append(api.execute_behavior("GUARDED"))
        seen.append(api.activate_behavior("GUARDED"))
        try:
            api.execute_behavior("GO", coordinates=(1, 2))  # WRONG_VALUE: what verify would refuse
        except api.RequestRejected as error:
            seen.append((error.kind, error.behavior))

    engine = fly(mission)
    assert seen == [Outcome.FAILED_PRECONDITIONS, "FAILED_PRECONDITIONS", ("WRONG_VALUE", "GO")]
    explained = engine.log.events(kind="failed_preconditions", behavior="GUARDED")[0].detail
    assert "flight_state(self, hovering)" in explained and "the memory holds flight_state(self, landed)" in explained
    assert "The value (1, 2) of argument COORDINATES for behavior GO is not correct" in \
        engine.log.events(kind="rejected", behavior="GO")[0].detail


def test_ask_behavior_returns_the_deliberative_result():
    seen = []
    fly(lambda: seen.append(api.askBehavior("PLAN")))
    assert seen == [[[0.0, 0.0, 1.0], [2.0, 0.0, 1.0]]]


def test_beliefs_from_the_mission():
    seen = []

    def mission():
        seen.append(api.addBelief("visited(self, home)"))
        seen.append(api.trueBelief("visited(self, home)"))
        seen.append(api.queryBelief("charge(battery, ?X), ?X > 50"))
        seen.append(api.removeBelief("visited(self, ?)"))
        seen.append(api.true_belief("visited(self, home)"))

    fly(mission)
    assert seen[0:2] == [True, True]
    assert seen[2][0] is True and seen[2][1]["X"] == 100
    assert seen[3:] == [1, False]


def test_a_failing_mission_is_reported_with_its_line():
    def mission():
        api.execute_behavior("GO", coordinates=[1, 0, 0])
        raise ValueError("the operator's code is wrong")

    engine = fly(mission)
    failed = engine.log.events(kind="mission_failed")[0].detail
    assert "ValueError: the operator's code is wrong" in failed and "test_api.py:" in failed
    assert engine.log.events(kind="GOAL_ACHIEVED", behavior="GO")


def test_a_malformed_belief_expression_raises_in_the_mission():
    errors = []

    def mission():
        try:
            api.consult_belief("charge(battery, ?X")
        except ValueError as exc:
            errors.append(str(exc))

    fly(mission)
    assert errors and errors[0].startswith("The format of the belief expression charge(battery, ?X is not correct")


def test_executing_a_recurrent_behavior_needs_a_timeout():
    seen = []

    def mission():
        try:
            api.execute_behavior("HOVER")
        except ValueError as exc:
            seen.append(str(exc))
        seen.append(api.execute_behavior("HOVER", timeout=2))

    fly(mission)
    assert "is recurrent" in seen[0] and seen[1] == Outcome.TIME_OUT


def test_same_mission_same_event_log():
    def mission():
        api.activate_behavior("HOVER")
        for point in ([1, 0, 0], [0, 2, 0], [1, 1, 1]):
            api.execute_behavior("GO", coordinates=point)
        api.wait(0.5)

    logs = [[(round(e.time, 6), e.kind, e.behavior, e.detail) for e in fly(mission).log.events()] for _ in range(2)]
    assert logs[0] == logs[1] and len(logs[0]) > 10


def test_the_engine_time_limit_stops_a_mission_that_never_ends():
    def mission():
        while True:
            api.wait(1.0)

    engine = fly(mission, max_time=5.0)
    assert engine.log.events(kind="engine_time_limit")
    assert engine.now() == pytest.approx(5.0, abs=0.1)


def test_api_outside_a_mission_says_how_to_run_one():
    with pytest.raises(RuntimeError, match="aeroexec run"):
        api.execute_behavior("TAKE_OFF")
