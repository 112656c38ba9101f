"""A behavior's timing and motion are catalog fields (issue 41): ``motion:`` (climb, fly_to, descend, follow_path,
hover), ``duration:`` (seconds in place, or the argument that says so) and ``beside: yes``. The route estimate, the
safety checks' contingencies and a resumed run read them, so a catalog's own behaviors are costed and flown by what
it says, and a catalog in the paper's format (without them) keeps the aerial behaviors' timing."""

from __future__ import annotations

import textwrap

import pytest
from aeroexec.engine.catalog import default_catalog, parse_catalog
from aeroexec.engine.catalog.behavior_catalog import default_catalog_path
from aeroexec.engine.catalog.safety_rules import read_safety_rules_text, rule_vocabulary
from aeroexec.engine.errors import CatalogError
from aeroexec.engine.safety.contingency import Contingencies
from aeroexec.trees.loaders.xml_loader import read_xml
from aeroexec.trees.route import estimate_route

AERIAL = default_catalog_path().read_text()
SPRAY = """
- behavior: SPRAY
  description: spray the crop below for DURATION seconds
  arguments:
    - argument: DURATION
      allowed_values: [1, 600]
  duration: DURATION

- behavior: SNIFF
  category: recurrent
  description: sample the air beside the flight
  beside: yes
"""


def with_behaviors(text: str) -> str:
    """The aerial catalog with ``text``'s behavior descriptors added to its own."""
    return AERIAL.replace("behavior_descriptors:\n", "behavior_descriptors:\n" + textwrap.dedent(text) + "\n", 1)


def tree(body: str):
    return read_xml(f'<root BTCPP_format="4"><BehaviorTree ID="M"><Sequence><TAKE_OFF ALTITUDE="5"/>{body}<LAND/>'
                    f'</Sequence></BehaviorTree></root>', "route.xml")


def test_a_catalog_behavior_s_duration_and_running_beside_are_on_the_route():
    catalog = parse_catalog(with_behaviors(SPRAY), "crop.yaml")
    plain = estimate_route(tree('<GO_TO_POINT COORDINATES="20,0,5"/>'), catalog=catalog)
    sprayed = estimate_route(tree('<GO_TO_POINT COORDINATES="20,0,5"/><SPRAY DURATION="45"/>'), catalog=catalog)
    assert sprayed is not None and plain is not None
    assert sprayed.duration == pytest.approx(plain.duration + 45.0)
    assert sprayed.battery < plain.battery  # hovering while it sprays
    beside = estimate_route(tree('<Parallel success_count="1"><GO_TO_POINT COORDINATES="20,0,5"/><SNIFF/>'
                                 '</Parallel>'), catalog=catalog)
    assert beside is not None and beside.duration == pytest.approx(plain.duration)
    assert estimate_route(tree("<SPRAY/>"), catalog=catalog) is None  # how long: its DURATION, not given


def test_a_behavior_that_says_nothing_of_its_timing_has_no_route():
    catalog = parse_catalog(with_behaviors("- behavior: SPRAY\n  description: spray\n"), "crop.yaml")
    assert estimate_route(tree("<SPRAY/>"), catalog=catalog) is None


def test_a_catalog_in_the_paper_s_format_keeps_the_aerial_behaviors_timing():
    paper = parse_catalog(textwrap.dedent("""
        default_behavior_values:
          timeout: 15
          category: goal_based
        behavior_descriptors:
        - behavior: TAKE_OFF
        - behavior: LAND
        - behavior: GO_TO_POINT
          arguments:
            - argument: COORDINATES
              allowed_values: [-100, 100]
              dimensions: 3
        - behavior: TAKE_PHOTO
        """), "paper.yaml")
    body = '<GO_TO_POINT COORDINATES="20,0,5"/><TAKE_PHOTO/>'
    estimate = estimate_route(tree(body), catalog=paper)
    assert estimate is not None
    assert estimate.duration == pytest.approx(estimate_route(tree(body), catalog=default_catalog()).duration)


@pytest.mark.parametrize(("field", "message"), [
    ("motion: teleport", "the motion of SPRAY must be one of climb, fly_to, descend, follow_path, hover, not "
                         "'teleport'"),
    ("duration: SPEED", "the duration of SPRAY must be seconds or one of its arguments, not 'SPEED'"),
    ("duration: -3", "the duration of SPRAY must be at least 0 seconds, not -3"),
    ("beside: sometimes", "beside of SPRAY must be yes or no, not 'sometimes'"),
])
def test_a_wrong_timing_field_is_refused_at_its_line(field, message):
    text = with_behaviors(f"- behavior: SPRAY\n  description: spray\n  {field}\n")
    with pytest.raises(CatalogError) as info:
        parse_catalog(text, "crop.yaml")
    line = text.splitlines().index(f"  {field}") + 1
    assert [(p.file, p.line, p.message) for p in info.value.errors] == [("crop.yaml", line, message)]


class Coordinator:
    """What a contingency asks of the behavior coordinator: the catalog, and the behaviors it activates."""

    def __init__(self, catalog) -> None:
        self.catalog, self.activated, self.preempted_by = catalog, [], None

    def activate(self, behavior, arguments=None, **_):
        self.activated.append(behavior)
        return type("Result", (), {"accepted": True, "outcome": None, "message": ""})()

    def active(self):
        return {}


def test_a_contingency_lands_and_flies_with_the_catalog_s_behaviors_of_those_motions():
    """A catalog whose flight and landing behaviors have other names than the aerial catalog's: a contingency asks
    for the behavior of the motion (the aerial names would be refused, and nothing would land the drone)."""
    rover_like = parse_catalog(textwrap.dedent("""
        behavior_descriptors:
        - behavior: TOUCH_DOWN
          motion: descend
        - behavior: HEAD_TO
          motion: fly_to
          arguments:
            - argument: COORDINATES
              allowed_values: [-100, 100]
              dimensions: 3
        - behavior: STAY
          category: recurrent
          motion: hover
        """), "field.yaml")
    for contingency, expected in (("land", ["TOUCH_DOWN"]), ("return", ["HEAD_TO"])):
        coordinator = Coordinator(rover_like)
        log = type("Log", (), {"record": lambda *a, **k: None})()
        contingencies = Contingencies(coordinator, log, lambda: (30.0, 0.0, 5.0), lambda here, home: (0.0, 0.0, 5.0),
                                      5.0)
        rule = read_safety_rules_text(f"- rule: fence\n  always: position(self, (?x, ?y, ?z)), ?x < 10\n"
                                      f"  contingency: {contingency}\n", "field.yaml",
                                      rule_vocabulary({"position": 2})).rules[0]
        contingencies.take(rule)
        assert coordinator.activated == expected, contingency
