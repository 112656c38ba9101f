"""TML missions: reading, verification with lines, and runs on the simulated drone (termination modes, recurrent
behaviors, +VAR substitution, a low-battery event preempting GO_TO_POINT, the example mission from the CLI)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from aeroexec.dialects.tml.compiler import TmlDocument, read_tml_document
from aeroexec.dialects.tml.verify import verify_tml
from aeroexec.drones.sim import SimConfig, SimulatedDrone, default_world
from aeroexec.engine.catalog import default_catalog
from aeroexec.engine.engine import Engine
from aeroexec.flight.missions import check_mission
from aeroexec.trees import TreeFormatError, load_mission_tree, read_mission_tree
from aeroexec.trees.runtime.runner import TreeMission
from py_trees.common import Status

ROOT = Path(__file__).parents[2]
EXAMPLE = ROOT / "missions" / "search_for_object.tml.xml"


def mission(main: str, *trees: str, events: str = "", root: str = "Main") -> str:
    """A TML mission: the main task's body, other task trees (whole <task> elements) and <event> elements."""
    others = "".join(f"  <task_tree>\n{tree}\n  </task_tree>\n" for tree in trees)
    handling = f"  <event_handling>\n{events}\n  </event_handling>\n" if events else ""
    return (f'<mission root_task="{root}">\n  <task_tree>\n    <task name="Main">\n{main}\n    </task>\n'
            f"  </task_tree>\n{others}{handling}</mission>\n")


def task(name: str, behavior: str, **arguments: str) -> str:
    args = "".join(f'<argument name="{k}" value="{v}"/>' for k, v in arguments.items())
    return f'<task name="{name}"><behavior name="{behavior}">{args}</behavior></task>'


def event(name: str, condition: str, mode: str, call: str | None = None) -> str:
    called = f'<call root_task="{call}"/>' if call else ""
    return f'<event name="{name}"><condition belief="{condition}"/>{called}<termination mode="{mode}"/></event>'


def line_of(text: str, fragment: str) -> int:
    return text[:text.index(fragment)].count("\n") + 1


FLY = "\n".join([task("Take off", "TAKE_OFF", altitude="2"), task("Go east", "GO_TO_POINT", coordinates="[8, 0, 2]"),
                 task("Land", "LAND")])
PASSED = "position(self, (?PX, ?, ?)), ?PX > 3"  # true once the drone has flown 3 m east
PAUSE = '<task name="Pause">' + task("Wait", "WAIT", timeout="1") + "</task>"


@pytest.fixture
def engine():
    world = default_world()
    engine = Engine(SimulatedDrone(world), obstacles=world)
    yield engine
    engine.stop()


def fly(engine: Engine, text: str, max_time: float = 120.0) -> TreeMission:
    document = read_tml_document(text, "mission.xml")
    errors = [p for p in verify_tml(document) if p.severity == "error"]
    assert not errors, "\n".join(map(str, errors))
    run = TreeMission(document, engine)
    run.run(max_time)
    return run


def kinds(engine: Engine, kind: str, behavior: str = "") -> list:
    return [e for e in engine.log.events(kind=kind) if not behavior or e.behavior == behavior]


def position(engine: Engine) -> tuple[float, float, float]:
    return engine.drone.telemetry().position


# -- termination modes --------------------------------------------------------------------------------------
def test_repeat_task_runs_the_interrupted_task_again_then_goes_on(engine):
    run = fly(engine, mission(FLY, PAUSE, events=event("Passed", PASSED, "REPEAT_TASK", "Pause")))
    assert run.status == Status.SUCCESS
    assert len(kinds(engine, "activated", "GO_TO_POINT")) == 2  # interrupted, then started again
    assert len(kinds(engine, "INTERRUPTED", "GO_TO_POINT")) == 1
    assert len(kinds(engine, "GOAL_ACHIEVED", "WAIT")) == 1
    assert len(kinds(engine, "tml_event")) == 1  # edge-triggered: still true after the repeat, not fired again
    assert kinds(engine, "tml_event")[0].data["task"] == "Go east"
    assert position(engine) == pytest.approx((8, 0, 0), abs=0.4)


def test_next_task_drops_the_interrupted_task(engine):
    run = fly(engine, mission(FLY, PAUSE, events=event("Passed", PASSED, "NEXT_TASK", "Pause")))
    assert run.status == Status.SUCCESS
    assert len(kinds(engine, "activated", "GO_TO_POINT")) == 1
    assert len(kinds(engine, "GOAL_ACHIEVED", "LAND")) == 1
    x, _, z = position(engine)
    assert 3 < x < 7 and z == pytest.approx(0, abs=0.2)  # landed on the way, not at x = 8


def test_next_task_after_the_last_task_completes_the_mission(engine):
    body = "\n".join([task("Take off", "TAKE_OFF", altitude="2"),
                      task("Go east", "GO_TO_POINT", coordinates="[8, 0, 2]")])
    run = fly(engine, mission(body, events=event("Passed", PASSED, "NEXT_TASK")))
    assert run.status == Status.SUCCESS and kinds(engine, "mission_completed")
    assert len(kinds(engine, "INTERRUPTED", "GO_TO_POINT")) == 1


def test_end_mission_completes_after_the_called_tree(engine):
    land = '<task name="Land here"><behavior name="LAND"/></task>'
    run = fly(engine, mission(FLY, land, events=event("Passed", PASSED, "END_MISSION", "Land here")))
    assert run.status == Status.SUCCESS and kinds(engine, "mission_completed")
    assert len(kinds(engine, "activated", "LAND")) == 1  # the handler's, never the main tree's
    assert "END_MISSION" in kinds(engine, "tml_termination")[0].detail


def test_abort_mission_fails_the_mission(engine):
    land = '<task name="Land here"><behavior name="LAND"/></task>'
    run = fly(engine, mission(FLY, land, events=event("Passed", PASSED, "ABORT_MISSION", "Land here")))
    assert run.status == Status.FAILURE and kinds(engine, "mission_failed")
    assert len(kinds(engine, "GOAL_ACHIEVED", "LAND")) == 1
    assert position(engine)[2] == pytest.approx(0, abs=0.2)


def test_a_failing_handler_fails_the_mission_without_its_termination(engine):
    bad = '<task name="Take off again"><behavior name="TAKE_OFF"/></task>'  # refused: already flying
    run = fly(engine, mission(FLY, bad, events=event("Passed", PASSED, "NEXT_TASK", "Take off again")))
    assert run.status == Status.FAILURE
    assert kinds(engine, "tml_handler_failed") and not kinds(engine, "tml_termination")


# -- recurrent behaviors -------------------------------------------------------------------------------------
def test_recurrent_behaviors_are_on_exactly_while_their_task_runs(engine):
    body = f"""
      <task name="Up">
        <recurrent_behavior name="PAY_ATTENTION_TO_COLORS"/>
        <task name="Take off"><behavior name="TAKE_OFF"><argument name="altitude" value="2"/></behavior></task>
      </task>
      <task name="Survey">
        <recurrent_behavior name="PAY_ATTENTION_TO_VISUAL_MARKERS"/>
        {task("Go east", "GO_TO_POINT", coordinates="[4, 0, 2]")}
        <task name="Look"><behavior name="WAIT"><argument name="timeout" value="1"/></behavior></task>
      </task>
      <task name="Land"><behavior name="LAND"/></task>"""
    seen: list[set[str]] = []
    engine.tick_callbacks.append(lambda: seen.append(set(engine.coordinator.active())))
    assert fly(engine, mission(body)).status == Status.SUCCESS
    colors, markers = "PAY_ATTENTION_TO_COLORS", "PAY_ATTENTION_TO_VISUAL_MARKERS"
    during = {b: [s for s in seen if b in s] for b in ("TAKE_OFF", "GO_TO_POINT", "WAIT", "LAND")}
    assert all(colors in s and markers not in s for s in during["TAKE_OFF"])
    assert all(markers in s and colors not in s for s in during["GO_TO_POINT"] + during["WAIT"])
    assert all(markers not in s and colors not in s for s in during["LAND"])
    assert len(kinds(engine, "activated", markers)) == 1  # on through both subtasks, not once per subtask


def test_recurrent_behaviors_go_off_during_a_handler_and_on_again_after_repeat_task(engine):
    body = f"""{task("Take off", "TAKE_OFF", altitude="2")}
      <task name="Search">
        <recurrent_behavior name="PAY_ATTENTION_TO_COLORS"/>
        {task("Go east", "GO_TO_POINT", coordinates="[8, 0, 2]")}
      </task>
      {task("Land", "LAND")}"""
    seen: list[set[str]] = []
    engine.tick_callbacks.append(lambda: seen.append(set(engine.coordinator.active())))
    assert fly(engine, mission(body, PAUSE, events=event("Passed", PASSED, "REPEAT_TASK", "Pause"))).status \
        == Status.SUCCESS
    assert all("PAY_ATTENTION_TO_COLORS" not in s for s in seen if "WAIT" in s)
    assert len(kinds(engine, "activated", "PAY_ATTENTION_TO_COLORS")) == 2


# -- variables ---------------------------------------------------------------------------------------------
def test_consulted_variables_are_substituted_in_arguments_beliefs_and_called_trees(engine):
    body = f"""<task name="Home"><consult belief="position(self, (?HX, ?HY, ?))"/></task>
      {task("Take off", "TAKE_OFF", altitude="2")}
      {task("Go east", "GO_TO_POINT", coordinates="[8, 0, 2]")}
      {task("Land", "LAND")}"""
    back = f"""<task name="Back">
        <task name="Note"><add belief="turned_at(self, +PX)"/></task>
        {task("Home again", "GO_TO_POINT", coordinates="[+HX, +HY, 2]")}
        {task("Sideways", "GO_TO_POINT", relative_coordinates="[0, 2, 0]")}
      </task>"""
    fly(engine, mission(body, back, events=event("Passed", PASSED, "NEXT_TASK", "Back")))
    targets = [e.detail for e in kinds(engine, "activated", "GO_TO_POINT")]
    assert "COORDINATES=(0.0, 0.0, 2)" in targets[1]
    found = engine.memory.query("turned_at(self, ?X)")
    assert found is not None and 3 < found["?X"] < 8
    assert position(engine)[:2] == pytest.approx((0, 2), abs=0.4)


# -- the low-battery event -------------------------------------------------------------------------------------
def test_low_battery_preempts_a_running_go_to_point_lands_and_aborts():
    world = default_world()
    drone = SimulatedDrone(world, config=SimConfig(initial_battery_percent=22.0, battery_hover_minutes=3.0))
    engine = Engine(drone, obstacles=world)
    try:
        body = "\n".join([task("Take off", "TAKE_OFF", altitude="2"),
                          task("Far away", "GO_TO_POINT", coordinates="[15, -15, 2]"), task("Land", "LAND")])
        land = '<task name="Emergency land"><behavior name="LAND"/></task>'
        run = fly(engine, mission(body, land, events=event("Low battery", "battery_level(self, low)",
                                                          "ABORT_MISSION", "Emergency land")))
        assert run.status == Status.FAILURE
        fired = kinds(engine, "tml_event")
        assert len(fired) == 1 and fired[0].data["task"] == "Far away"
        interrupted = kinds(engine, "INTERRUPTED", "GO_TO_POINT")
        assert interrupted and interrupted[0].time == pytest.approx(fired[0].time)
        assert not kinds(engine, "GOAL_ACHIEVED", "GO_TO_POINT")
        assert len(kinds(engine, "GOAL_ACHIEVED", "LAND")) == 1
        x, y, z = position(engine)
        assert z == pytest.approx(0, abs=0.2) and (x, y) != pytest.approx((15, -15), abs=1)
    finally:
        engine.stop()


# -- malformed missions ------------------------------------------------------------------------------------
def problems_of(text: str) -> list[tuple[int, str]]:
    """(line, message) of every error: those found reading the file, else those of verification."""
    try:
        document = read_mission_tree(text, "bad.xml")
    except TreeFormatError as error:
        return [(line, message) for _, line, message in error.problems]
    assert isinstance(document, TmlDocument)
    return [(p.line, p.message) for p in verify_tml(document, default_catalog()) if p.severity == "error"]


TAKE_OFF = task("Take off", "TAKE_OFF")
MALFORMED = {
    "unknown element": (mission(TAKE_OFF + '\n<task name="X"><behaviour name="LAND"/></task>'),
                        "<behaviour", "unknown element <behaviour> in <task>"),
    "behavior in a complex task": (mission(TAKE_OFF + '\n<behavior name="LAND"/>'), '<behavior name="LAND"',
                                   "the task 'Main' has subtasks, so it is a complex task"),
    "two behaviors in a leaf": (mission('<task name="A"><behavior name="TAKE_OFF"/>\n<behavior name="LAND"/></task>'),
                                '<behavior name="LAND"', "a leaf task has exactly one"),
    "unknown behavior": (mission(TAKE_OFF + "\n" + task("Go", "GO_TO_PIONT", coordinates="[1, 1, 2]")),
                         "GO_TO_PIONT", "The behavior GO_TO_PIONT does not exist (did you mean GO_TO_POINT?)"),
    "bad argument value": (mission(TAKE_OFF + "\n" + task("Go", "GO_TO_POINT", coordinates="[1, 2]")),
                           'value="[1, 2]"', "The value"),
    "unbound +VAR": (mission(TAKE_OFF + "\n" + task("Go", "GO_TO_POINT", coordinates="[+X, 1, 2]")),
                     'value="[+X', "+X is not bound"),
    "+VAR unbound wherever an event fires": (
        mission(TAKE_OFF + "\n" + task("Go", "GO_TO_POINT", coordinates="[3, 0, 2]")
                + '\n<task name="Home"><consult belief="position(self, ?H)"/></task>',
                task("Back", "GO_TO_POINT", coordinates="+H"), events=event("E", "visible(red_box)", "END_MISSION",
                                                                            "Back")),
        'value="+H"', "+H is not bound when the event 'E' fires: no <consult> binds ?H before any task it can fire "
                      "during"),
    "missing call target": (mission(TAKE_OFF, events=event("E", "visible(red_box)", "END_MISSION", "Rescue")),
                            "<call", "the event 'E' calls 'Rescue', but no task tree has that root task"),
    "LAND before TAKE_OFF": (mission(task("Land", "LAND") + "\n" + TAKE_OFF), '<behavior name="LAND"', "LAND"),
    "malformed XML": (mission(TAKE_OFF + '\n<task name="X"><behavior name="LAND"></task>'), '<task name="X">',
                      "not well-formed XML"),
    "unknown termination mode": (mission(TAKE_OFF, events=event("E", "visible(red_box)", "STOP")), "<termination",
                                 "unknown termination mode 'STOP'"),
    "bad condition": (mission(TAKE_OFF, events=event("E", "visible(red_box", "END_MISSION")), "<condition", ""),
    "unknown attribute": (mission('<task name="A" repeat="2"><behavior name="TAKE_OFF"/></task>'), 'repeat="2"',
                          "unknown attribute repeat of <task>"),
    "goal-based recurrent": (mission('<recurrent_behavior name="GO_TO_POINT"/>' + TAKE_OFF),
                             "<recurrent_behavior", "GO_TO_POINT is not a recurrent behavior"),
    "missing root task": (mission(TAKE_OFF, root="Start"), "<mission", "root_task names 'Start'"),
}


@pytest.mark.parametrize("case", MALFORMED)
def test_malformed_tml_is_refused_with_the_message_and_line(case):
    text, fragment, message = MALFORMED[case]
    found = problems_of(text)
    line = line_of(text, fragment)
    assert any(at == line and message in text_ for at, text_ in found), f"{found} (expected line {line})"


def test_land_before_take_off_is_a_wrong_sequence():
    document = read_tml_document(mission(task("Land", "LAND") + "\n" + TAKE_OFF), "bad.xml")
    assert any(p.kind == "WRONG_SEQUENCE" for p in verify_tml(document))


def test_the_gregale_dialect_is_refused_by_name():
    text = '<mission name="Old">\n  <task name="Initial"><action name="TAKE_OFF"/></task>\n</mission>\n'
    with pytest.raises(TreeFormatError, match="Gregale dialect"):
        read_mission_tree(text, "old.xml")


def test_behavior_trees_in_xml_still_load_as_trees(tmp_path):
    path = tmp_path / "tree.xml"
    path.write_text('<root BTCPP_format="4"><BehaviorTree ID="M"><TAKE_OFF/></BehaviorTree></root>')
    document = load_mission_tree(path)
    assert not isinstance(document, TmlDocument) and document.root.type == "TAKE_OFF"


def test_check_mission_recognises_tml_by_its_root_element(tmp_path):
    path = tmp_path / "mission.xml"
    text = mission(TAKE_OFF + "\n" + task("Go", "GO_TO_POINT", coordinates="[1, 2]"))
    path.write_text(text)
    checked = check_mission(path, default_catalog())
    assert isinstance(checked.tree, TmlDocument)
    assert [p.line for p in checked.errors] == [line_of(text, 'value="[1, 2]"')]


# -- the example mission -------------------------------------------------------------------------------------
def test_the_example_mission_verifies_cleanly():
    assert verify_tml(load_mission_tree(EXAMPLE)) == []


def test_the_example_mission_runs_to_completion_from_the_command_line(tmp_path):
    result = subprocess.run([sys.executable, "-m", "aeroexec.cli.main", "run", str(EXAMPLE), "--output",
                             str(tmp_path)], capture_output=True, text=True, timeout=120, cwd=ROOT)
    assert result.returncode == 0, result.stderr + result.stdout
    assert "search_for_object.tml.xml: completed" in result.stderr
    assert "tml_event: Object found" in result.stdout
    assert "tml_termination: Object found: END_MISSION" in result.stdout
    assert "mission_completed" in result.stdout
