"""The coordinator and the resource manager (Algorithms 1-5) with scripted behaviors on the simulated clock."""

import textwrap

import pytest
from aeroexec.drones.sim import SimConfig, SimulatedDrone
from aeroexec.engine.catalog import parse_catalog
from aeroexec.engine.engine import Engine
from aeroexec.engine.events import Outcome
from aeroexec.engine.execution.process import BehaviorLibrary, BehaviorProcess, Situation
from aeroexec.engine.execution.resources import Process, ProcessRegistry, ResourceError

CATALOG = """
default_behavior_values: {timeout: 5, category: goal_based}
predicates:
- {predicate: flight_state, arity: 2}
- {predicate: charge, arity: 2}
- {predicate: flag, arity: 2}
- {predicate: position, arity: 2}
behavior_descriptors:
- {behavior: MOVE, incompatible_lists: [motion], capabilities: [CONTROL]}
- {behavior: OTHER_MOVE, incompatible_lists: [motion], capabilities: [CONTROL]}
- {behavior: HOVER, category: recurrent, incompatible_lists: [motion], capabilities: [CONTROL]}
- {behavior: EMERGENCY, incompatible_lists: [motion], capabilities: [CONTROL]}
- {behavior: SLOW, timeout: 1}
- {behavior: BROKEN}
- {behavior: STALLS}
- {behavior: GUARDED, preconditions: "flag(ready, yes), flight_state(self, hovering)"}
- {behavior: DONE_ALREADY}
- {behavior: FILM, category: recurrent, capabilities: [CAMERA]}
- {behavior: PHOTO, capabilities: [CAMERA]}
- {behavior: TRACK, category: recurrent, capabilities: [SERVO]}
- {behavior: LOOK, category: deliberative}
behavior_lists:
- {list: motion, behaviors: [MOVE, OTHER_MOVE, HOVER, EMERGENCY]}
reactive_activation:
- {behavior: HOVER, condition: "flag(hover, yes)", priority: lower}
- {behavior: EMERGENCY, condition: "charge(battery, ?X), ?X < 10", priority: higher}
capability_descriptors:
- {capability: CONTROL, process_sequence: [controller], incompatible_capabilities: [SERVO]}
- {capability: CAMERA, process_sequence: [camera, encoder]}
- {capability: SERVO, process_sequence: [tracker], alternative_processes: {tracker: backup_tracker}}
- {capability: ODOMETRY, process_sequence: [odometry], permanent_active: yes}
"""


class Finishes(BehaviorProcess):
    """Reaches its goal after ``duration`` seconds (a DURATION-like scripted behavior)."""

    duration = 2.0

    def on_run(self):
        return Outcome.GOAL_ACHIEVED if self.elapsed >= self.duration else None


class Forever(BehaviorProcess):
    pass


class Raises(BehaviorProcess):
    def on_run(self):
        raise RuntimeError("sensor exploded")


class Stalls(BehaviorProcess):
    def on_run(self):
        return self.fail("no progress toward the goal") if self.elapsed > 0.5 else None


class AlreadyDone(BehaviorProcess):
    def check_situation(self):
        return Situation(Outcome.GOAL_ACHIEVED, "the drone is already there")


class Looks(BehaviorProcess):
    def on_run(self):
        self.result = [[1.0, 2.0, 3.0]]
        return Outcome.GOAL_ACHIEVED


class FlakyTracker(Process):
    def __init__(self, name):
        super().__init__(name)
        self.steps = 0

    def step(self, now):
        self.steps += 1

    def healthy(self):
        return self.steps < 3


def library():
    classes = {"MOVE": Finishes, "OTHER_MOVE": Finishes, "HOVER": Forever, "EMERGENCY": Finishes, "SLOW": Forever,
               "BROKEN": Raises, "STALLS": Stalls, "GUARDED": Finishes, "DONE_ALREADY": AlreadyDone,
               "FILM": Forever, "PHOTO": Finishes, "TRACK": Forever, "LOOK": Looks}
    lib = BehaviorLibrary()
    for name, cls in classes.items():
        lib.register(cls, name)
    return lib


@pytest.fixture
def engine():
    catalog = parse_catalog(textwrap.dedent(CATALOG), "test.yaml")
    processes = ProcessRegistry({"tracker": FlakyTracker})
    eng = Engine(SimulatedDrone(config=SimConfig(initial_battery_percent=60)), catalog=catalog, library=library(),
                 processes=processes, capability_grace=1.0)
    eng.step(0.1)
    yield eng
    eng.stop()


def kinds(engine, behavior):
    return [e.kind for e in engine.log.events(behavior=behavior) if e.kind != "reactive"]


# -- Algorithm 4 ------------------------------------------------------------------------------
def test_activation_then_goal_achieved(engine):
    assert engine.coordinator.activate("MOVE").accepted
    engine.step(3.0)
    assert kinds(engine, "MOVE") == ["activated", "GOAL_ACHIEVED"]
    assert not engine.coordinator.is_active("MOVE")


def test_equal_priority_recency_stops_the_older_one(engine):
    engine.coordinator.activate("MOVE")
    result = engine.coordinator.activate("OTHER_MOVE")
    assert result.accepted
    assert kinds(engine, "MOVE") == ["activated", "INTERRUPTED"]
    assert "stopped for OTHER_MOVE" in engine.log.events(kind="INTERRUPTED")[0].detail
    assert engine.coordinator.is_active("OTHER_MOVE")


def test_deliberative_request_preempts_a_lower_priority_reaction(engine):
    engine.memory.add("flag(hover, yes)")
    engine.step(0.2)
    assert engine.coordinator.active()["HOVER"].source == "reactive"
    assert engine.coordinator.activate("MOVE").accepted
    assert kinds(engine, "HOVER")[-1] == "INTERRUPTED"


def test_higher_priority_reaction_rejects_a_deliberative_request(engine):
    engine.coordinator.activate("EMERGENCY", priority="higher", source="reactive")
    result = engine.coordinator.activate("MOVE")
    assert not result.accepted and result.outcome is Outcome.FAILED_PRECONDITIONS
    assert "The active behavior EMERGENCY has a higher priority" in result.message
    assert engine.log.events(kind="rejected", behavior="MOVE")


def test_compatible_behaviors_run_together(engine):
    engine.coordinator.activate("MOVE")
    engine.coordinator.activate("FILM")
    assert set(engine.coordinator.active()) == {"MOVE", "FILM"}


# -- Algorithm 5 and reactive rules ---------------------------------------------------------------
def test_lower_priority_reaction_waits_for_the_active_motion_to_finish(engine):
    engine.coordinator.activate("MOVE")
    engine.memory.add("flag(hover, yes)")
    engine.step(0.5)
    assert not engine.coordinator.is_active("HOVER")  # incompatible with MOVE, lower priority
    engine.step(2.0)
    assert kinds(engine, "MOVE")[-1] == "GOAL_ACHIEVED"
    assert engine.coordinator.is_active("HOVER")  # Algorithm 5 after the event
    assert engine.log.events(kind="reactive", behavior="HOVER")


def test_a_reaction_is_activated_in_the_period_its_belief_changes_once_the_rules_have_run(engine):
    engine.step(1.0)  # the rules have run: what they read is known, and only those changes reach them
    assert not engine.coordinator.is_active("HOVER")
    engine.memory.add("position(self, (1.0, 2.0, 3.0))")  # a belief no rule reads: nothing to react to
    engine.step(0.05)
    assert not engine.coordinator.is_active("HOVER")
    engine.memory.add("flag(hover, yes)")
    changed = engine.now()
    engine.step(0.05)  # one period
    assert engine.coordinator.is_active("HOVER")
    assert [e.time for e in engine.log.events(kind="reactive", behavior="HOVER")] == [changed]


def test_a_reaction_over_a_derived_belief_wakes_on_the_stored_belief_it_is_derived_from():
    text = textwrap.dedent(CATALOG)
    old = '{behavior: HOVER, condition: "flag(hover, yes)"'
    assert old in text
    text = text.replace(old, '{behavior: HOVER, condition: "hovering_wanted"')
    text += "rules: |\n  hovering_wanted :- flag(hover, yes).\n"
    catalog = parse_catalog(text, "test.yaml")
    engine = Engine(SimulatedDrone(), catalog=catalog, library=library())
    engine.step(1.0)
    assert not engine.coordinator.is_active("HOVER")
    engine.memory.add("flag(hover, yes)")  # not what the rule names: what its condition is derived from
    changed = engine.now()
    engine.step(0.05)
    assert [e.time for e in engine.log.events(kind="reactive", behavior="HOVER")] == [changed]
    engine.stop()


def test_battery_below_10_preempts_the_mission():
    catalog = parse_catalog(textwrap.dedent(CATALOG), "test.yaml")
    drone = SimulatedDrone(config=SimConfig(initial_battery_percent=10.2))
    engine = Engine(drone, catalog=catalog, library=library())
    drone.takeoff(2.0)  # flying drains the battery: below 10 % within a few seconds
    engine.step(0.1)
    assert engine.coordinator.activate("HOVER").accepted  # the mission's, deliberative
    assert engine.run_until(lambda: engine.coordinator.is_active("EMERGENCY"), 30.0)
    assert engine.memory.query("charge(battery, ?X)")["?X"] < 10
    assert kinds(engine, "HOVER") == ["activated", "INTERRUPTED"]
    assert engine.coordinator.active()["EMERGENCY"].source == "reactive"
    assert not engine.coordinator.activate("MOVE").accepted  # the mission cannot take over again
    engine.stop()


def test_inhibit_interrupts_and_keeps_reactions_away(engine):
    engine.memory.add("flag(hover, yes)")
    engine.step(0.2)
    assert engine.coordinator.inhibit("HOVER")
    engine.step(0.5)
    assert kinds(engine, "HOVER") == ["activated", "INTERRUPTED"]
    assert not engine.coordinator.is_active("HOVER")
    engine.coordinator.activate("HOVER")  # asking again lifts the inhibition
    assert engine.coordinator.is_active("HOVER")


# -- Algorithm 2: events -------------------------------------------------------------------------
def test_time_out(engine):
    engine.coordinator.activate("SLOW")
    engine.step(1.5)
    event = engine.log.events(kind="TIME_OUT", behavior="SLOW")[0]
    assert event.detail == "The goal of behavior SLOW has not been reached in the expected time (1 seconds)"


@pytest.mark.parametrize("name, answer", [("SLOW", None), ("HOVER", Outcome.GOAL_ACHIEVED)],
                         ids=["going-on-until-its-time-is-out", "recurrent-goal-achieved-goes-on"])
def test_the_monitors_end_a_behavior_at_the_tick_judging_it_would(engine, name, answer):
    """The tick's monitoring skips judging an answer that goes on (None, within the timeout): the behavior ends at
    the very tick at which judging its process's answer ends it, and not before."""
    assert engine.coordinator.activate(name, timeout=1.0).accepted
    activation = engine.coordinator.active()[name]
    activation.process.on_run = lambda: answer
    ticks = 0
    while ticks < 60:  # 1 s of timeout at 20 Hz
        judged, _ = engine.coordinator._judged(activation, answer, engine.now())  # at the next tick's time
        engine.step(engine.period)
        ticks += 1
        assert engine.coordinator.is_active(name) == (judged is None)
        if judged is not None:
            break
    assert ticks > 10 and kinds(engine, name)[-1] == "TIME_OUT"


def test_timeout_overridden_per_request(engine):
    engine.coordinator.activate("MOVE", timeout=0.5)
    engine.step(1.0)
    assert kinds(engine, "MOVE")[-1] == "TIME_OUT"


def test_wrong_progress(engine):
    engine.coordinator.activate("STALLS")
    engine.step(1.0)
    event = engine.log.events(kind="WRONG_PROGRESS", behavior="STALLS")[0]
    assert event.detail == "The behavior STALLS does not progress correctly (no progress toward the goal)"


def test_a_raising_behavior_does_not_kill_the_engine(engine):
    engine.coordinator.activate("BROKEN")
    engine.coordinator.activate("MOVE")
    engine.step(3.0)
    assert "it raised RuntimeError: sensor exploded" in engine.log.events(kind="WRONG_PROGRESS")[0].detail
    assert kinds(engine, "MOVE")[-1] == "GOAL_ACHIEVED"


def test_failed_preconditions_are_explained(engine):
    engine.memory.add("flag(ready, yes)")
    result = engine.coordinator.activate("GUARDED")
    assert result.outcome is Outcome.FAILED_PRECONDITIONS
    assert result.message.startswith("Behavior GUARDED cannot be executed because its preconditions are not "
                                     "satisfied.")
    assert "flight_state(self, hovering) does not hold; the memory holds flight_state(self, landed)" in result.message


def test_goal_already_achieved(engine):
    result = engine.coordinator.activate("DONE_ALREADY")
    assert not result.accepted and result.outcome is Outcome.GOAL_ACHIEVED
    assert result.message == ("The goal of behavior DONE_ALREADY has already been achieved "
                              "(the drone is already there)")


def test_deliberative_result_reaches_the_listener(engine):
    seen = []
    engine.coordinator.activate("LOOK", on_end=lambda outcome, message, result: seen.append((outcome, result)))
    engine.step(0.1)
    assert seen == [(Outcome.GOAL_ACHIEVED, [[1.0, 2.0, 3.0]])]


# -- resource manager -----------------------------------------------------------------------------
def test_permanent_capabilities_run_from_the_start(engine):
    assert "ODOMETRY" in engine.resources.running()


def test_capabilities_are_reference_counted_and_stopped_after_the_grace_period(engine):
    engine.coordinator.activate("FILM")
    engine.coordinator.activate("PHOTO")
    assert engine.resources.users("CAMERA") == {"FILM", "PHOTO"}
    engine.step(2.5)  # PHOTO achieved its goal; FILM still uses the camera
    assert engine.resources.users("CAMERA") == {"FILM"}
    engine.coordinator.inhibit("FILM")
    engine.step(0.5)
    assert "CAMERA" in engine.resources.running()  # kept for the next behavior
    engine.coordinator.activate("PHOTO")  # reuses the running processes
    engine.step(2.5)
    assert [e.detail for e in engine.log.events(kind="capability_started")].count("CAMERA") == 1
    engine.step(1.2)
    assert "CAMERA" not in engine.resources.running()
    stopped = [e.detail for e in engine.log.events(kind="capability_stopped")]
    assert "CAMERA (unused for 1 s)" in stopped


def test_incompatible_capabilities_never_run_together(engine):
    engine.coordinator.activate("HOVER")  # CONTROL
    assert engine.coordinator.activate("TRACK").accepted  # SERVO clashes with CONTROL: HOVER is stopped
    assert kinds(engine, "HOVER")[-1] == "INTERRUPTED"
    assert "CONTROL" not in engine.resources.running()  # stopped at once, not after the grace period
    with pytest.raises(ResourceError, match="cannot run together with SERVO \\(used by TRACK\\)"):
        engine.resources.acquire("SOMEONE", ["CONTROL"])
    assert engine.resources.running() == {"ODOMETRY", "SERVO"}


def test_a_capability_started_in_flight_is_stepped_and_a_replaced_process_no_longer_is():
    """What a tick steps is made again when a capability starts or a process is replaced: the tracker started after
    the first ticks is stepped until it fails, then only its alternative runs (one replacement, never again)."""
    made = []

    def tracker(name):
        made.append(FlakyTracker(name))
        return made[-1]

    catalog = parse_catalog(textwrap.dedent(CATALOG), "test.yaml")
    eng = Engine(SimulatedDrone(), catalog=catalog, library=library(),
                 processes=ProcessRegistry({"tracker": tracker}), capability_grace=1.0)
    try:
        eng.step(0.5)
        assert eng.coordinator.activate("TRACK").accepted
        eng.step(1.0)
        assert [p.steps for p in made] == [3]  # failed at its third step's check, then stepped no more
        assert len(eng.log.events(kind="process_replaced")) == 1
        assert [p.name for p in eng.resources.processes("SERVO")] == ["backup_tracker"]
    finally:
        eng.stop()


def test_a_failed_process_is_replaced_by_its_alternative(engine):
    engine.coordinator.activate("TRACK")
    engine.step(0.5)
    replaced = engine.log.events(kind="process_replaced")
    assert replaced and "tracker failed; backup_tracker runs instead" in replaced[0].detail
    assert [p.name for p in engine.resources.processes("SERVO")] == ["backup_tracker"]
    assert engine.coordinator.is_active("TRACK")
