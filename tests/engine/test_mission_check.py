"""The static check of Python missions: Table 1's messages with line numbers, and no false WRONG_SEQUENCE."""

from pathlib import Path
from textwrap import dedent

import pytest
from aeroexec.engine.missions.check import MissionProblem, check_mission_file, check_mission_source

DATA = Path(__file__).parent / "data" / "missions"
HEADER = "import aeroexec.engine.api as api\n\n\ndef mission():\n"  # the body starts on line 5


def problems(source: str, header: str = HEADER) -> list[tuple[int, str]]:
    """(line, message) of every problem of a mission, ``source`` being its indented body or a whole program."""
    text = header + "    " + dedent(source).strip("\n").replace("\n", "\n    ") if header else dedent(source)
    return [(p.line, p.message) for p in check_mission_source(text, "mission.py")]


def messages(source: str) -> list[str]:
    return [message for _, message in problems(source)]


SEQUENCE_LAND = "The execution of behavior LAND cannot be done after the execution of LAND " \
                "(flight is landed; LAND needs hovering or moving)"


# -- the three example failing inputs ---------------------------------------------------
def test_a_misspelt_behavior_a_wrong_argument_and_a_malformed_belief_are_all_reported():
    found = check_mission_file(DATA / "three_mistakes.py")
    assert [(p.severity, p.line, p.message) for p in found] == [
        ("error", 8, "The behavior GO_TO_PONT does not exist (did you mean GO_TO_POINT?)"),
        ("error", 9, "The argument SPEEED of behavior GO_TO_POINT does not exist (did you mean SPEED?)"),
        ("error", 10, "The format of the belief expression position(self, (?x, ?y, ?z) is not correct "
                      "(the expression ends too early; expected ')' or ',')"),
    ]
    assert [p.kind for p in found] == ["WRONG_FORMAT"] * 3
    assert str(found[0]) == (f"{DATA / 'three_mistakes.py'}:8:26: error: WRONG_FORMAT: The behavior GO_TO_PONT "
                             f"does not exist (did you mean GO_TO_POINT?)")


def test_misspelt_behavior_file():
    found = check_mission_file(DATA / "misspelt_behavior.py")
    assert [(p.line, p.column, p.message) for p in found] == [
        (8, 21, "The behavior LANDING does not exist (did you mean LAND?)")]


def test_wrong_argument_file():
    found = check_mission_file(DATA / "wrong_argument.py")
    assert [(p.line, p.kind, p.message) for p in found] == [
        (7, "WRONG_VALUE", "The value 800 of argument ALTITUDE for behavior TAKE_OFF is not correct "
                           "(a number between 0.5 and 500 is expected)"),
        (8, "WRONG_VALUE", "The value (4, 2) of argument COORDINATES for behavior GO_TO_POINT is not correct "
                           "(a point (x, y, z) or geo:LAT,LON,ALT in the world (x and y within 5000 m of home, z "
                           "within 500 m) is expected)"),
    ]


def test_malformed_belief_file():
    found = check_mission_file(DATA / "malformed_belief.py")
    assert [(p.line, p.message) for p in found] == [
        (11, "The format of the belief expression object(?x, marker), position(?x, ?p is not correct "
             "(the expression ends too early; expected ')' or ',')"),
        (12, "The predicate objet of the belief expression objet(?x, marker) does not exist"),
    ]


# -- correct missions pass ----------------------------------------------------------------
FIGURE_10 = '''\
import aeroexec.engine.api as api


def runMission():
    api.executeBehavior("TAKE_OFF")

    api.activateBehavior("PAY_ATTENTION_TO_VISUAL_MARKERS")

    success, unification = api.consultBelief("position(self, (?x,?y,?z))")
    if success:
        x, y, z = unification["x"], unification["y"], unification["z"]
    else:
        print("Position unknown")

    api.executeBehavior("GO_TO_POINT", coordinates=[2, 5, 1.3])
    api.executeBehavior("GO_TO_POINT", coordinates=[x, y, z])

    api.inhibitBehavior("PAY_ATTENTION_TO_VISUAL_MARKERS")

    api.executeBehavior("LAND")
'''


def test_figure_10_passes():
    assert check_mission_source(FIGURE_10, "figure10.py") == []


def test_a_patrol_with_loops_branches_and_helpers_passes():
    assert problems("""
        if api.execute_behavior("TAKE_OFF", altitude=3) != api.GOAL_ACHIEVED:
            return
        api.activate_behavior("PAY_ATTENTION_TO_VISUAL_MARKERS")
        for lap in range(2):
            for corner in [(-4, -6, 3), (4, -6, 3)]:
                result = api.execute_behavior("GO_TO_POINT", coordinates=corner, timeout=60)
                if result != api.GOAL_ACHIEVED:
                    print(f"lap {lap}: {result}")
            if api.true_belief("charge(battery, ?p), ?p < 30"):
                break
        found, marker = api.consult_belief(f"object(?m, marker), code(?m, {3})")
        api.add_belief("visible(marker_1)")
        api.remove_belief("visible(?x)")
        api.execute_behavior("KEEP_HOVERING", timeout=2)
        api.execute_behavior("LAND")
    """) == []


# -- requests -----------------------------------------------------------------------------
def test_unknown_argument_name_out_of_range_value_and_a_point_with_two_numbers():
    assert problems("""
        api.execute_behavior("TAKE_OFF", altitud=3)
        api.execute_behavior("GO_TO_POINT", coordinates=[1, 2, 3], speed=-2)
        api.execute_behavior("GO_TO_POINT", coordinates=[1, 2])
    """) == [
        (5, "The argument ALTITUD of behavior TAKE_OFF does not exist (did you mean ALTITUDE?)"),
        (6, "The value -2 of argument SPEED for behavior GO_TO_POINT is not correct "
            "(a number between 0.1 and 12 is expected)"),
        (7, "The value (1, 2) of argument COORDINATES for behavior GO_TO_POINT is not correct "
            "(a point (x, y, z) or geo:LAT,LON,ALT in the world (x and y within 5000 m of home, z within 500 m) "
            "is expected)"),
    ]


def test_argument_errors_name_the_line_of_the_argument():
    assert problems("""
        api.execute_behavior("TAKE_OFF")
        api.execute_behavior(
            "GO_TO_POINT",
            coordinates=[1, 2, 3],
            speed=99,
        )
    """) == [(9, "The value 99 of argument SPEED for behavior GO_TO_POINT is not correct "
                 "(a number between 0.1 and 12 is expected)")]


def test_missing_arguments_and_enumerations():
    assert messages("""
        api.activate_behavior("TURN_LIGHTS")
        api.activate_behavior("TURN_LIGHTS", mode="DIM")
    """) == ["The argument MODE of behavior TURN_LIGHTS is missing (one of ON, OFF is expected)",
             "The value DIM of argument MODE for behavior TURN_LIGHTS is not correct (one of ON, OFF is expected)"]


def test_values_that_are_not_literals_are_not_judged():
    assert problems("""
        api.execute_behavior("TAKE_OFF", altitude=height())
        api.execute_behavior("GO_TO_POINT", coordinates=[x, y, z], speed=s)
        api.execute_behavior("GO_TO_POINT", **where)
        api.activate_behavior("TURN_LIGHTS", mode=mode)
        api.consult_belief(f"position(self, {p}")
        api.true_belief(expression)
        api.execute_behavior("LAND")
    """) == []


def test_reserved_keywords_recurrent_behaviors_and_timeouts():
    assert problems("""
        api.execute_behavior("TAKE_OFF", timeout=0)
        api.execute_behavior("KEEP_HOVERING")
        api.executeBehavior("KEEP_MOVING", direction="FORWARD", timeout=3)
        api.activate_behavior("KEEP_HOVERING", activation_delay=2)
        api.wait(-1)
    """) == [
        (5, "The value 0 of argument timeout for behavior TAKE_OFF is not correct "
            "(a positive number of seconds is expected)"),
        (6, "The behavior KEEP_HOVERING is recurrent: it has no goal to wait for "
            "(use activate_behavior, or give timeout=)"),
        (9, "The value -1 of wait is not correct (a number of seconds, 0 or more, is expected)"),
    ]


def test_behavior_names_are_matched_without_regard_to_case():
    assert problems('api.execute_behavior("take_off")\napi.inhibit_behavior("land")\n'
                    'api.is_active_behavior("GO_TO_PIONT")') == [
        (7, "The behavior GO_TO_PIONT does not exist (did you mean GO_TO_POINT?)")]


def test_belief_expressions():
    assert problems("""
        api.true_belief("flight_state(self, flying")
        api.consultBelief("objet(?x, marker)")
        api.add_belief("visible(?x)")
        api.remove_belief("visible(?x), visible(?y)")
        api.add_belief("distance_to((1, 2, 3), 4)")
        api.queryBelief(42)
    """) == [
        (5, "The format of the belief expression flight_state(self, flying is not correct "
            "(the expression ends too early; expected ')' or ',')"),
        (6, "The predicate objet of the belief expression objet(?x, marker) does not exist"),
        (7, "The format of the belief expression visible(?x) is not correct (a belief cannot hold variables)"),
        (8, "The format of the belief expression visible(?x), visible(?y) is not correct "
            "(expected a single predicate such as visible(?X))"),
        (9, "distance_to is computed by the engine and cannot be stored as a belief"),
        (10, "The format of the belief expression 42 is not correct (a belief expression is text)"),
    ]


def test_a_computed_behavior_name_is_one_warning():
    found = check_mission_source(HEADER + '    for b in ["TAKE_OFF"]:\n        api.execute_behavior(b, x=1)\n',
                                 "mission.py")
    assert [(p.severity, p.line, p.message) for p in found] == [
        ("warning", 6, "The behavior name is computed (b): the behavior and its arguments are checked only "
                       "when the mission runs")]


@pytest.mark.parametrize("header, call", [
    ("import aeroexec.engine.api as api\n", 'api.executeTask("LANDD")'),
    ("from aeroexec.engine import api as drone\n", 'drone.startTask("LANDD")'),
    ("from aeroexec.engine.api import executeBehavior as go\n", 'go("LANDD")'),
    ("from aeroexec.engine.api import *\n", 'askBehavior("LANDD")'),
    ("import aeroexec.engine.api\n", 'aeroexec.engine.api.activate_behavior("LANDD")'),
    ("from aeroexec import engine\n", 'engine.api.deactivateBehavior("LANDD")'),
    ("def mission():\n    from aeroexec.engine.api import stopTask\n", 'stopTask("LANDD")'),
])
def test_every_import_form_and_alias_is_followed(header, call):
    source = header + ("" if "def mission" in header else "\n\ndef mission():\n") + "    " + call + "\n"
    found = check_mission_source(source, "m.py")
    assert [p.message for p in found] == ["The behavior LANDD does not exist (did you mean LAND?)"]
    assert found[0].line == source.count("\n")


def test_other_modules_are_not_the_api():
    assert problems('import string as api\n\ndef mission():\n    api.execute_behavior("NOPE")\n', header="") == []


def test_unknown_api_functions():
    assert problems("""
        api.executeBehaviour("TAKE_OFF")
    """) == [(5, "The function executeBehaviour does not exist in the mission API (did you mean executeBehavior?)")]
    assert problems("from aeroexec.engine.api import consult_beleif\n\ndef mission():\n    pass\n", header="") == [
        (1, "The function consult_beleif does not exist in the mission API (did you mean consult_belief?)")]


def test_a_syntax_error_is_one_error_with_its_line():
    found = check_mission_source(HEADER + '    api.execute_behavior("TAKE_OFF"\n    api.wait(1)\n', "m.py")
    assert len(found) == 1 and found[0].line == 5 and found[0].severity == "error"
    assert found[0].message.startswith("The mission is not valid Python: ")


def test_a_missing_mission_function():
    found = check_mission_source('import aeroexec.engine.api as api\n\ndef main():\n    api.execute_behavior("LAN")\n',
                                 "m.py")
    assert [(p.line, p.message) for p in found] == [
        (0, "The mission has no mission() or runMission() function"),
        (4, "The behavior LAN does not exist (did you mean LAND?)")]
    assert str(found[0]) == "m.py: error: WRONG_FORMAT: The mission has no mission() or runMission() function"
    assert [p.message for p in check_mission_source("def mission(speed):\n    pass\n", "m.py")] == [
        "The function mission() is called without arguments: it cannot require any"]


def test_a_program_for_other_software_says_so_with_its_missing_modules(tmp_path):
    """project_pegasus_isaac_sim's Isaac Sim launcher: no mission function and no mission API; the first error says
    it is another software's program and names the modules it needs, not only that mission() is missing."""
    program = tmp_path / "launcher.py"
    program.write_text("import argparse\nimport carb\nfrom omni.isaac.core.world import World\n\nWorld()\n")
    found = check_mission_source(program.read_text(), str(program))
    assert [(p.line, p.message) for p in found] == [
        (0, "The mission has no mission() or runMission() function, and imports no mission API that runs scripts "
            "whole: a program for other software, whose modules carb, omni cannot be found here"),
        (2, "The module carb cannot be found: the mission would stop at this import"),
        (3, "The module omni cannot be found: the mission would stop at this import")]


def test_an_unreadable_file(tmp_path):
    found = check_mission_file(tmp_path / "none.py")
    assert len(found) == 1 and found[0].message.startswith("The mission cannot be read: ")
    assert isinstance(found[0], MissionProblem)


# -- WRONG_SEQUENCE -------------------------------------------------------------------------
def test_land_after_land_and_motion_before_take_off():
    assert problems("""
        api.execute_behavior("GO_TO_POINT", coordinates=[1, 1, 1])
        api.execute_behavior("TAKE_OFF")
        api.execute_behavior("LAND")
        api.execute_behavior("LAND")
    """) == [
        (5, "The execution of behavior GO_TO_POINT cannot be done at the start of the mission "
            "(flight is landed; GO_TO_POINT needs hovering or moving)"),
        # the specialist takes a wrong request as done, so the take-off comes after GO_TO_POINT
        (6, "The execution of behavior TAKE_OFF cannot be done after the execution of GO_TO_POINT "
            "(flight is hovering; TAKE_OFF needs landed)"),
        (8, SEQUENCE_LAND),
    ]


def test_the_lights_follow_their_literal_mode():
    assert messages("""
        api.execute_behavior("TURN_LIGHTS", mode="ON")
        api.execute_behavior("TURN_LIGHTS", mode=on_or_off)
        api.execute_behavior("TURN_LIGHTS", mode="ON")
        api.execute_behavior("TURN_LIGHTS", mode="ON")
    """) == ["The execution of behavior TURN_LIGHTS cannot be done after the execution of TURN_LIGHTS "
             "(light is on; TURN_LIGHTS needs off)"]


def test_errors_inside_a_branch_are_reported_and_disagreeing_branches_are_not_judged_after():
    assert problems("""
        api.execute_behavior("TAKE_OFF")
        if api.true_belief("charge(battery, ?c), ?c < 30"):
            api.execute_behavior("LAND")
            api.execute_behavior("LAND")
        api.execute_behavior("LAND")
        api.execute_behavior("TAKE_OFF")
    """) == [(8, SEQUENCE_LAND)]


def test_branches_that_agree_keep_the_state():
    assert problems("""
        if ready:
            api.execute_behavior("TAKE_OFF", altitude=2)
        else:
            api.execute_behavior("TAKE_OFF", altitude=4)
        api.execute_behavior("LAND")
        api.execute_behavior("LAND")
    """) == [(10, "The execution of behavior LAND cannot be done after the execution of LAND "
                  "(flight is landed; LAND needs hovering or moving)")]


@pytest.mark.parametrize("body", [
    # a branch that returns does not reach what follows
    'api.execute_behavior("TAKE_OFF")\nif low:\n    api.execute_behavior("LAND")\n    return\n'
    'api.execute_behavior("LAND")',
    # a loop body that changes the flight may have run or not
    'api.execute_behavior("TAKE_OFF")\nfor i in range(n):\n    api.execute_behavior("LAND")\n'
    'api.execute_behavior("LAND")',
    'api.execute_behavior("TAKE_OFF")\nwhile not done():\n    api.execute_behavior("LAND")\n'
    '    api.execute_behavior("TAKE_OFF")\napi.execute_behavior("LAND")',
    # a later iteration may break from another state
    'while True:\n    if done():\n        break\n    api.execute_behavior("TAKE_OFF")\n'
    '    api.execute_behavior("GO_TO_POINT", coordinates=[1, 1, 1])\napi.execute_behavior("TAKE_OFF")',
    # an exception may come before or after the landing
    'api.execute_behavior("TAKE_OFF")\ntry:\n    api.execute_behavior("LAND")\nexcept Exception:\n'
    '    api.execute_behavior("LAND")',
    'api.execute_behavior("TAKE_OFF")\ntry:\n    api.execute_behavior("GO_TO_POINT", coordinates=[1, 1, 1])\n'
    'finally:\n    api.execute_behavior("LAND")\napi.execute_behavior("TAKE_OFF")',
    # behaviors run by a local function, by a variable, by reference, or conditionally
    'fly()\napi.execute_behavior("LAND")',
    'api.execute_behavior(first)\napi.execute_behavior("LAND")',
    'run = api.execute_behavior\nrun("TAKE_OFF")\napi.execute_behavior("LAND")',
    'ok = started or api.execute_behavior("TAKE_OFF")\napi.execute_behavior("LAND")',
    'api.execute_behavior("TAKE_OFF") if go else None\napi.execute_behavior("LAND")',
    # stopping a take-off half way
    'api.activate_behavior("TAKE_OFF")\napi.inhibit_behavior("TAKE_OFF")\napi.execute_behavior("TAKE_OFF")',
    # a dead branch is never run
    'if False:\n    api.execute_behavior("LAND")\napi.execute_behavior("TAKE_OFF")',
    'match command:\n    case "up":\n        api.execute_behavior("TAKE_OFF")\n    case _:\n        pass\n'
    'api.execute_behavior("LAND")',
])
def test_branches_never_give_false_sequence_reports(body):
    source = "import aeroexec.engine.api as api\n\n\ndef fly():\n    api.execute_behavior('TAKE_OFF')\n\n\n" \
             "def mission():\n    " + body.replace("\n", "\n    ") + "\n"
    assert [p.message for p in check_mission_source(source, "m.py") if p.kind == "WRONG_SEQUENCE"] == []


def test_loops_that_leave_the_flight_as_it_was_are_checked_after():
    assert problems("""
        api.execute_behavior("TAKE_OFF")
        for corner in corners:
            api.execute_behavior("GO_TO_POINT", coordinates=corner)
            if lost():
                continue
        while True:
            if api.execute_behavior("LAND") == api.GOAL_ACHIEVED:
                break
        api.execute_behavior("LAND")
    """) == [(13, "The execution of behavior LAND cannot be done after the execution of LAND "
                  "(flight is landed; LAND needs hovering or moving)")]


def test_a_loop_body_is_checked_for_every_iteration():
    # TAKE_OFF, LAND, LAND in a loop: wrong at every iteration; TAKE_OFF alone: wrong only from the second on
    assert problems("""
        for i in range(3):
            api.execute_behavior("TAKE_OFF")
            api.execute_behavior("LAND")
            api.execute_behavior("LAND")
        for i in range(3):
            api.execute_behavior("TAKE_OFF")
    """) == [(8, SEQUENCE_LAND)]


def test_unreachable_code_is_not_checked():
    assert problems("""
        return
        api.execute_behavior("LAND")
    """) == []
