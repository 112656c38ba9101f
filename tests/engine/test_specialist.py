"""The behavior specialist: Table 1's messages for bad requests, compatibility, and sequence verification."""

import pytest
from aeroexec.engine.catalog.specialist import BehaviorSpecialist, Request
from aeroexec.engine.errors import SpecificationError


@pytest.fixture(scope="module")
def specialist():
    return BehaviorSpecialist()


def error_of(specialist, name, arguments=None) -> SpecificationError:
    with pytest.raises(SpecificationError) as info:
        specialist.check_request(name, arguments)
    return info.value


# -- Table 1: WRONG_FORMAT and WRONG_VALUE ------------------------------------------------
def test_a_correct_request_returns_the_descriptor(specialist):
    descriptor = specialist.check_request("GO_TO_POINT", {"COORDINATES": (1.0, 2.0, 3)})
    assert descriptor.name == "GO_TO_POINT" and descriptor.timeout == 120
    assert specialist.check_request("LAND").name == "LAND"


def test_unknown_behavior(specialist):
    error = error_of(specialist, "GO_TO_PONT", {"COORDINATES": (1, 2, 3)})
    assert error.kind == "WRONG_FORMAT"
    assert error.message == "The behavior GO_TO_PONT does not exist (did you mean GO_TO_POINT?)"


def test_unknown_argument(specialist):
    error = error_of(specialist, "GO_TO_POINT", {"COORDINATES": (1, 2, 3), "SPEEED": 2})
    assert error.kind == "WRONG_FORMAT"
    assert error.message == "The argument SPEEED of behavior GO_TO_POINT does not exist (did you mean SPEED?)"
    error = error_of(specialist, "LAND", {"ALTITUDE": 3})
    assert error.message == "The argument ALTITUDE of behavior LAND does not exist (it takes no arguments)"


def test_out_of_range_value(specialist):
    error = error_of(specialist, "TAKE_OFF", {"ALTITUDE": 800})
    assert error.kind == "WRONG_VALUE"
    assert error.message == ("The value 800 of argument ALTITUDE for behavior TAKE_OFF is not correct "
                             "(a number between 0.5 and 500 is expected)")


def test_wrong_dimensions(specialist):
    error = error_of(specialist, "GO_TO_POINT", {"COORDINATES": (1, 2)})
    assert error.kind == "WRONG_VALUE"
    assert error.message == ("The value (1, 2) of argument COORDINATES for behavior GO_TO_POINT is not correct "
                             "(a point (x, y, z) or geo:LAT,LON,ALT in the world (x and y within 5000 m of "
                             "home, z within 500 m) is expected)")
    assert error_of(specialist, "GO_TO_POINT", {"COORDINATES": 5}).kind == "WRONG_VALUE"
    assert error_of(specialist, "GO_TO_POINT", {"COORDINATES": (1, 2, "up")}).kind == "WRONG_VALUE"


def test_value_outside_an_enumeration(specialist):
    error = error_of(specialist, "KEEP_MOVING", {"DIRECTION": "UP"})
    assert error.message == ("The value UP of argument DIRECTION for behavior KEEP_MOVING is not correct "
                             "(one of FORWARD, BACKWARD, LEFT, RIGHT, UPWARD, DOWNWARD is expected)")


def test_value_of_the_wrong_type(specialist):
    error = error_of(specialist, "SAY", {"SENTENCE": 42})
    assert error.message == "The value 42 of argument SENTENCE for behavior SAY is not correct (a text is expected)"
    assert error_of(specialist, "TAKE_OFF", {"ALTITUDE": True}).kind == "WRONG_VALUE"  # a bool is not a number
    assert error_of(specialist, "TAKE_OFF", {"ALTITUDE": float("nan")}).kind == "WRONG_VALUE"
    path_error = error_of(specialist, "FOLLOW_PATH", {"PATH": [(0, 0, 2), (5, 0)]})
    assert "a list of points (x, y, z) or geo:LAT,LON,ALT in the world (x and y within 5000 m" in path_error.message


def test_missing_required_arguments(specialist):
    error = error_of(specialist, "TURN_LIGHTS", {})
    assert error.message == "The argument MODE of behavior TURN_LIGHTS is missing (one of ON, OFF is expected)"
    error = error_of(specialist, "GO_TO_POINT", {})
    assert error.message == "The behavior GO_TO_POINT needs one of the arguments COORDINATES, RELATIVE_COORDINATES"
    error = error_of(specialist, "GO_TO_POINT", {"COORDINATES": (1, 2, 3), "RELATIVE_COORDINATES": (0, 0, 1)})
    assert "cannot be given together" in error.message


def test_every_error_of_a_request_is_reported(specialist):
    errors = specialist.request_errors("KEEP_MOVING", {"DIRECTON": "FORWARD", "SPEED": -1})
    assert [e.kind for e in errors] == ["WRONG_FORMAT", "WRONG_VALUE", "WRONG_FORMAT"]
    assert "DIRECTON" in errors[0].message and "SPEED" in errors[1].message and "DIRECTION" in errors[2].message
    with pytest.raises(SpecificationError) as info:
        specialist.check_request("KEEP_MOVING", {"DIRECTON": "FORWARD", "SPEED": -1})
    assert len(info.value.others) == 2


def test_defaults_are_filled_in(specialist):
    assert specialist.resolve_arguments("KEEP_MOVING", {"DIRECTION": "FORWARD"}) == {"DIRECTION": "FORWARD",
                                                                                     "SPEED": 1.0}


def test_belief_expressions_are_checked_against_the_vocabulary(specialist):
    assert specialist.check_expression("object(?X, marker), code(?X, 3)") is not None
    with pytest.raises(SpecificationError) as info:
        specialist.check_expression("objet(?X, marker)")
    assert info.value.kind == "WRONG_FORMAT"
    assert info.value.message == "The predicate objet of the belief expression objet(?X, marker) does not exist"
    with pytest.raises(SpecificationError, match="The format of the belief expression code"):
        specialist.check_expression("code(?X, 3")


# -- compatibility ---------------------------------------------------------------------
def test_motion_behaviors_are_incompatible_with_each_other(specialist):
    assert not specialist.compatible("GO_TO_POINT", "KEEP_HOVERING")
    assert not specialist.compatible("KEEP_HOVERING", "GO_TO_POINT")
    assert not specialist.compatible("TAKE_OFF", "LAND")
    assert specialist.compatible("GO_TO_POINT", "TAKE_PHOTO")
    assert specialist.compatible("GO_TO_POINT", "PAY_ATTENTION_TO_VISUAL_MARKERS")
    assert not specialist.compatible("SELF_LOCALIZE_BY_ODOMETRY", "SLAM_BY_VISUAL_MARKERS")


def test_conflicts_with_active_behaviors(specialist):
    active = ["KEEP_HOVERING", "RECORD_VIDEO", "SELF_LOCALIZE_BY_ODOMETRY"]
    assert specialist.conflicts("GO_TO_POINT", active) == {"KEEP_HOVERING"}
    assert specialist.conflicts("SLAM_BY_VISUAL_MARKERS", active) == {"SELF_LOCALIZE_BY_ODOMETRY"}
    assert specialist.conflicts("TAKE_PHOTO", active) == set()


# -- WRONG_SEQUENCE --------------------------------------------------------------------
def test_take_off_go_to_point_land_is_accepted(specialist):
    plan = ["TAKE_OFF", ("GO_TO_POINT", {"COORDINATES": (4, 0, 2)}), "LAND"]
    assert specialist.check_sequence(plan) == []
    assert specialist.check_plan(plan) == []


def test_land_after_land(specialist):
    errors = specialist.check_sequence(["TAKE_OFF", "LAND", "LAND"])
    assert len(errors) == 1
    assert errors[0].kind == "WRONG_SEQUENCE" and errors[0].step == 2
    assert errors[0].message.startswith("The execution of behavior LAND cannot be done after the execution of LAND")


def test_motion_before_take_off(specialist):
    errors = specialist.check_sequence([("GO_TO_POINT", {"COORDINATES": (1, 1, 1)}), "LAND"])
    assert [e.step for e in errors] == [0]  # reported once, then taken as done
    assert errors[0].message.startswith("The execution of behavior GO_TO_POINT cannot be done at the start")
    assert "flight is landed" in errors[0].message
    errors = specialist.check_sequence(["TAKE_OFF", "LAND", Request("KEEP_MOVING", {"DIRECTION": "FORWARD"})])
    assert errors[0].message.startswith(
        "The execution of behavior KEEP_MOVING cannot be done after the execution of LAND")


def test_lights_on_twice(specialist):
    on = ("TURN_LIGHTS", {"MODE": "ON"})
    errors = specialist.check_sequence([on, on])
    assert len(errors) == 1 and errors[0].step == 1
    assert errors[0].message.startswith(
        "The execution of behavior TURN_LIGHTS cannot be done after the execution of TURN_LIGHTS")
    assert specialist.check_sequence([on, ("TURN_LIGHTS", {"MODE": "OFF"}), on]) == []


def test_sequences_from_another_initial_state(specialist):
    assert specialist.check_sequence(["LAND"], initial={"flight": "hovering"}) == []
    assert specialist.check_sequence([{"behavior": "TAKE_OFF"}], initial={"flight": "hovering"})[0].step == 0


def test_check_plan_reports_request_and_sequence_errors_in_step_order(specialist):
    errors = specialist.check_plan(["TAKE_OFF", ("TAKE_OFF", {"ALTITUDE": 999}), "LANDD"])
    assert [(e.step, e.kind) for e in errors] == [(1, "WRONG_VALUE"), (1, "WRONG_SEQUENCE"), (2, "WRONG_FORMAT")]
