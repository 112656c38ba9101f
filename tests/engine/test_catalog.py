"""Loading behavior catalogs: the default aerial catalog, the paper's Appendix B, malformed files with their lines."""

import textwrap
from pathlib import Path

import pytest
from aeroexec.beliefs import BeliefMemory
from aeroexec.engine.catalog import BehaviorCatalog, default_catalog, load_catalog, parse_catalog
from aeroexec.engine.errors import CatalogError

DATA = Path(__file__).parent / "data"

# Appendix A: Tables A.2 and A.3, plus WAIT, SELF_LOCALIZE_BY_ODOMETRY and SLAM_BY_VISUAL_MARKERS (Appendix B)
APPENDIX_A = [
    "TAKE_OFF", "LAND", "KEEP_HOVERING", "KEEP_MOVING", "ROTATE", "GO_TO_POINT", "FLIP", "FOLLOW_OBJECT_IMAGE",
    "FOLLOW_PATH", "LOOK_AT_A_POINT", "KEEP_LOITERING", "TRACK_OBJECT_IMAGE", "ALIGN_OVER_IMAGE",
    "LAND_ON_MOVING_PLATFORM", "TOUCH_MOVING_OBJECT", "TAKE_OFF_FROM_MOVING_PLATFORM",
    "SELF_LOCALIZE_BY_VISUAL_MARKERS", "PAY_ATTENTION_TO_VISUAL_MARKERS", "PAY_ATTENTION_TO_COLORS",
    "PAY_ATTENTION_TO_SHAPES", "VERIFY", "GENERATE_PATH_FREE_OF_OBSTACLES", "GENERATE_NEXT_POINT_TO_EXPLORE",
    "BROADCAST_MESSAGE", "NOTIFY_OPERATOR", "ASK_OPERATOR", "ASK_FOR_OBJECT_IMAGE", "DISPLAY_CAMERA_IMAGE",
    "SPEAK_UP", "SAY", "BUILD_MAP", "RECORD_VIDEO", "TAKE_PHOTO", "TURN_LIGHTS", "DROP_ITEM", "WAIT",
    "SELF_LOCALIZE_BY_ODOMETRY", "SLAM_BY_VISUAL_MARKERS",
]


def catalog(text: str, **kwargs) -> BehaviorCatalog:
    return parse_catalog(textwrap.dedent(text).lstrip("\n"), "test.yaml", **kwargs)


def problems(text: str) -> list[str]:
    with pytest.raises(CatalogError) as info:
        catalog(text)
    return [str(p) for p in info.value.errors]


# -- the default aerial catalog -------------------------------------------------------
def test_default_catalog_has_every_behavior_of_appendix_a_and_no_warnings():
    aerial = default_catalog()
    assert set(APPENDIX_A) <= set(aerial.behaviors)  # the paper's library; more behaviors may be added
    assert aerial.warnings == []


def test_every_catalog_behavior_has_an_implementation_and_every_implementation_an_entry():
    from aeroexec.engine.library import default_library

    assert default_library().names() == set(default_catalog().behaviors)


def test_default_catalog_categories_timeouts_and_arguments():
    aerial = default_catalog()
    assert aerial.behaviors["KEEP_HOVERING"].category == "recurrent"
    assert aerial.behaviors["KEEP_HOVERING"].timeout is None
    assert aerial.behaviors["GENERATE_PATH_FREE_OF_OBSTACLES"].category == "deliberative"
    assert aerial.behaviors["GO_TO_POINT"].timeout == 120
    assert aerial.behaviors["TAKE_OFF"].timeout == aerial.default_timeout
    coordinates = aerial.behaviors["GO_TO_POINT"].arguments["COORDINATES"]
    assert (coordinates.in_world, coordinates.reach, coordinates.dimensions) == (True, (5000, 500), 3)  # limits
    assert aerial.behaviors["KEEP_MOVING"].arguments["DIRECTION"].choices == (
        "FORWARD", "BACKWARD", "LEFT", "RIGHT", "UPWARD", "DOWNWARD")
    # YAML 1.1 would read ON/OFF as booleans; enumerations keep the text as written
    assert aerial.behaviors["TURN_LIGHTS"].arguments["MODE"].choices == ("ON", "OFF")
    assert aerial.behaviors["GO_TO_POINT"].arguments["SPLINE"].default == "no"


def test_default_catalog_preconditions_and_reactive_rules():
    aerial = default_catalog()
    assert "belong(?x1, [moving, hovering])" in aerial.behaviors["GO_TO_POINT"].precondition_text
    assert aerial.behaviors["LAND"].preconditions is not None
    rules = {r.behavior: r for r in aerial.reactive_rules}
    assert rules["LAND"].priority == "higher"
    assert rules["LAND"].condition_text == "charge(battery, ?X), less_than(?X, 10)"
    assert rules["KEEP_HOVERING"].priority == "lower" and rules["KEEP_HOVERING"].condition is not None
    assert rules["SELF_LOCALIZE_BY_ODOMETRY"].condition is None


def test_default_catalog_capabilities_and_phenomena():
    aerial = default_catalog()
    assert aerial.capabilities["SELF_LOCALIZATION_BY_ODOMETRY"].permanent
    assert aerial.capabilities["VISUAL_SERVOING"].incompatible == ("SETPOINT_BASED_FLIGHT_CONTROL",)
    assert aerial.phenomena["flight"].states == ("landed", "taking_off", "hovering", "moving", "landing")
    assert aerial.phenomena["flight"].initial_state == "landed"
    assert aerial.phenomena["light"].initial_state == "off"


def test_default_vocabulary_configures_a_belief_memory():
    memory = BeliefMemory()
    default_catalog().declare_vocabulary(memory)
    memory.add("charge(battery, 80)")
    memory.add("charge(battery, 15)")  # exclusive: replaces 80
    assert memory.query("charge(battery, ?X)") == {"?X": 15}
    memory.add("carry(self, box)")
    memory.add("carry(self, rope)")  # multi-valued: both kept
    assert len(memory.query_all("carry(self, ?X)")) == 2
    with pytest.raises(Exception, match="The predicate chrage of the belief expression"):
        memory.query("chrage(battery, ?X)")


# -- the paper's Appendix B -------------------------------------------------------------
def test_appendix_b_catalog_loads_with_warnings_for_its_inconsistencies():
    paper = load_catalog(DATA / "appendix_b.yaml")
    assert len(paper) == 15
    warnings = [str(w) for w in paper.warnings]
    assert any("START_MOVING" in w and ":126:" in w for w in warnings)
    assert any("START_HOVERING" in w and ":127:" in w for w in warnings)
    assert any("MISSION_PLANNING" in w and "not supported by the architecture" in w for w in warnings)
    assert any("dimension" in w for w in warnings)
    assert paper.behaviors["PAY_ATTENTION_TO_VISUAL_MARKERS"].category == "recurrent"
    assert paper.behaviors["GENERATE_PATH_FREE_OF_OBSTACLES"].arguments["DESTINATION"].dimensions == 3
    assert paper.behaviors["BROADCAST_MESSAGE"].arguments["TEXT"].value_type == "TEXT"
    assert paper.behaviors["WAIT"].arguments["UNTIL_OBSERVED_VISUAL_MARKER"].maximum == 1023
    assert paper.behaviors["GO_TO_POINT"].timeout == 120 and paper.behaviors["LAND"].timeout == 15
    assert paper.incompatible("GO_TO_POINT", "KEEP_HOVERING")
    assert paper.incompatible("FOLLOW_OBJECT_IMAGE", "ROTATE")  # by list, and by VISUAL_SERVOING capability


def test_architecture_processes_missing_give_warnings():
    paper = load_catalog(DATA / "appendix_b.yaml", processes={"droneTrajectoryController"})
    warnings = [str(w) for w in paper.warnings]
    assert any("PATH_PLANNING is not supported by the architecture" in w and "droneTrajectoryPlanner" in w
               for w in warnings)
    assert not any("SETPOINT_BASED_FLIGHT_CONTROL is not supported" in w for w in warnings)


def test_figure_8_transitions_with_both_spellings_of_phenomenon():
    text = """
        behavior_descriptors:
        - behavior: TURN_LIGHT
          arguments:
            - argument: MODE
              allowed_values: [ON, OFF]
        behavior_transitions:
        - behavior: TAKE_OFF
          physical_phenomenon: flight
          initial_state: landed
          final_state: hovering
        - behavior: TURN_LIGHT
          argument: MODE
          argument_value: ON
          phenomenon: light
          initial_state: off
          final_state: on
        """
    loaded = catalog(text)
    assert loaded.phenomena["light"].initial_state == "off"
    assert loaded.phenomena["flight"].initial_state == "landed"
    assert loaded.transitions[1].argument_value == "ON"
    assert any("TAKE_OFF" in str(w) and "not described" in str(w) for w in loaded.warnings)


# -- malformed catalogs, each reported at its line ------------------------------------
MALFORMED = [
    ("unknown top-level key",
     """
     behavior_descriptors: []
     behaviour_lists: []
     """, 2, "unknown key behaviour_lists (did you mean behavior_lists?)"),
    ("unknown behavior key",
     """
     behavior_descriptors:
     - behavior: TAKE_OFF
       timout: 10
     """, 3, "unknown key timout (did you mean timeout?)"),
    ("wrong type for timeout",
     """
     behavior_descriptors:
     - behavior: TAKE_OFF
       timeout: soon
     """, 3, "the timeout of TAKE_OFF must be a number, not 'soon'"),
    ("range with min above max",
     """
     behavior_descriptors:
     - behavior: ROTATE
       arguments:
         - argument: ANGLE
           allowed_values: [360, -360]
     """, 5, "minimum 360 above its maximum -360"),
    ("reference to a list that does not exist",
     """
     behavior_lists:
     - list: motion_behaviors
       behaviors: [LAND]
     behavior_descriptors:
     - behavior: LAND
       incompatible_lists: [motion_behavior]
     """, 6, "the behavior list motion_behavior does not exist (did you mean motion_behaviors?)"),
    ("reactive rule for a behavior that does not exist",
     """
     behavior_descriptors:
     - behavior: LAND
     reactive_activation:
     - behavior: LANDING
       priority: higher
     """, 4, "the behavior LANDING does not exist (did you mean LAND?)"),
    ("malformed belief expression in a condition",
     """
     behavior_descriptors:
     - behavior: LAND
     reactive_activation:
     - behavior: LAND
       condition: charge(battery, ?X), ?X <
       priority: higher
     """, 5, "The format of the belief expression charge(battery, ?X), ?X < is not correct"),
    ("unknown predicate in a precondition",
     """
     predicates:
     - {predicate: flight_state, arity: 2}
     behavior_descriptors:
     - behavior: LAND
       preconditions: flight_stat(self, hovering)
     """, 5, "The predicate flight_stat of the belief expression flight_stat(self, hovering) does not exist"),
    ("duplicate behavior",
     """
     behavior_descriptors:
     - behavior: LAND
     - behavior: TAKE_OFF
     - behavior: LAND
     """, 4, "the behavior LAND is described twice (first at line 2)"),
    ("bad priority",
     """
     behavior_descriptors:
     - behavior: LAND
     reactive_activation:
     - behavior: LAND
       priority: highest
     """, 5, "must be lower or higher, not highest"),
    ("bad category",
     """
     behavior_descriptors:
     - behavior: KEEP_HOVERING
       category: recurent
     """, 3, "the category recurent is not one of goal_based, recurrent, deliberative (did you mean recurrent?)"),
    ("YAML syntax error",
     """
     behavior_descriptors:
     - behavior: LAND
       arguments: [
     """, 4, "not valid YAML"),
    ("default outside the allowed values",
     """
     behavior_descriptors:
     - behavior: TAKE_OFF
       arguments:
         - argument: ALTITUDE
           allowed_values: [1, 10]
           default: 20
     """, 6, "the default 20 of argument ALTITUDE of TAKE_OFF is not allowed (a number between 1 and 10 is expected)"),
    ("transition state outside the declared states",
     """
     behavior_descriptors:
     - behavior: LAND
     phenomena:
     - phenomenon: flight
       states: [landed, hovering]
       initial_state: landed
     behavior_transitions:
     - behavior: LAND
       physical_phenomenon: flight
       initial_state: [hovering, flying]
       final_state: landed
     """, 8, "the state flying is not a state of flight (landed, hovering)"),
    ("transition for an argument the behavior does not have",
     """
     behavior_descriptors:
     - behavior: TURN_LIGHTS
       arguments:
         - argument: MODE
           allowed_values: [ON, OFF]
     behavior_transitions:
     - behavior: TURN_LIGHTS
       argument: VALUE
       argument_value: ON
       physical_phenomenon: light
       initial_state: off
       final_state: on
     """, 7, "the transition names the argument VALUE, which behavior TURN_LIGHTS does not have"),
    ("duplicate key",
     """
     behavior_descriptors:
     - behavior: LAND
       timeout: 10
       timeout: 20
     """, 4, "key timeout is given twice (first at line 3)"),
    ("section of the wrong shape",
     """
     behavior_descriptors:
       behavior: LAND
     """, 2, "behavior_descriptors must be a list"),
]


@pytest.mark.parametrize("text,line,message", [m[1:] for m in MALFORMED], ids=[m[0] for m in MALFORMED])
def test_malformed_catalog_is_reported_with_its_line(text, line, message):
    found = problems(text)
    assert any(f"test.yaml:{line}: error: " in p and message in p for p in found), found


def test_every_problem_is_reported_not_just_the_first():
    found = problems("""
        behavior_descriptors:
        - behavior: LAND
          timout: 10
        - behavior: ROTATE
          category: sometimes
        """)
    assert [p.split(": error")[0] for p in found] == ["test.yaml:3", "test.yaml:5"]


def test_missing_or_unreadable_file(tmp_path):
    with pytest.raises(CatalogError, match="cannot read the file"):
        load_catalog(tmp_path / "nope.yaml")
    empty = tmp_path / "empty.yaml"
    empty.write_text("")
    with pytest.raises(CatalogError, match="the catalog is empty"):
        load_catalog(empty)
    binary = tmp_path / "binary.yaml"
    binary.write_bytes(b"\xff\xfe\x00garbage")
    with pytest.raises(CatalogError):
        load_catalog(binary)
