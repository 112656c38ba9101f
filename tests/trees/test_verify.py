"""Verification before flight: every problem with the paper's words and its line; WRONG_SEQUENCE never falsely."""

from __future__ import annotations

import pytest
from aeroexec.trees.mission_file import read_mission_tree
from aeroexec.trees.model import TreeDocument, TreeNode
from aeroexec.trees.verify import verify_document

BAD = """<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence>
      <LAND/>
      <TAKE_OF/>
      <TAKE_OFF ALTITUDE="800"/>
      <GO_TO_POINT COORDINATE="1, 2, 3"/>
      <GO_TO_POINT COORDINATES="1, 2"/>
      <Condition belief="flight_state(self, "/>
      <Condition belief="colour(box, red)"/>
      <GO_TO_POINT COORDINATES="{target}"/>
      <Inverter/>
      <Repeat num_cycles="many"><AlwaysSuccess/></Repeat>
      <SubTree ID="Mising"/>
      <SubTree ID="Loop"/>
      <Parallel success_count="3"><AlwaysSuccess/><AlwaysSuccess/></Parallel>
      <Timeout msecs="100"><AlwaysSuccess/></Timeout>
      <KEEP_MOVING DIRECTION="SIDEWAYS"/>
      <TAKE_OFF _skipIf="not(flying(self)"/>
      <QueryBelief belief="position(?X, ?P)"/>
      <AskBehavior behavior="GENERATE_PATH_FREE_OF_OBSTACLES" DESTINATION="{P}" result="{path}"/>
      <FOLLOW_PATH PATH="{path}"/>
    </Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Missing"><AlwaysSuccess/></BehaviorTree>
  <BehaviorTree ID="Loop">
    <SubTree ID="Loop"/>
  </BehaviorTree>
</root>
"""

EXPECTED = [
    (4, "WRONG_SEQUENCE", "The execution of behavior LAND cannot be done at the start of the mission (flight is "
                          "landed; LAND needs hovering or moving)"),
    (5, "WRONG_FORMAT", "The behavior TAKE_OF does not exist (did you mean TAKE_OFF?)"),
    (6, "WRONG_VALUE", "The value 800 of argument ALTITUDE for behavior TAKE_OFF is not correct (a number between "
                       "0.5 and 500 is expected)"),
    (7, "WRONG_FORMAT", "The argument COORDINATE of behavior GO_TO_POINT does not exist (did you mean COORDINATES?)"),
    (8, "WRONG_VALUE", "The value (1, 2) of argument COORDINATES for behavior GO_TO_POINT is not correct (a point "
                       "(x, y, z) or geo:LAT,LON,ALT in the world (x and y within 5000 m of home, z within 500 m) is "
                       "expected)"),
    (10, "WRONG_FORMAT", "The predicate colour of the belief expression colour(box, red) does not exist"),
    (11, "WRONG_FORMAT", "The blackboard key target is read before any node writes it"),
    (12, "WRONG_FORMAT", "The node Inverter must have exactly one child, not 0"),
    (13, "WRONG_VALUE", "The value many of port num_cycles of node Repeat is not correct (an integer (-1: forever) "
                        "is expected)"),
    (14, "WRONG_FORMAT", "The tree Mising does not exist (did you mean Missing?)"),
    (16, "WRONG_VALUE", "The value 3 of port success_count of node Parallel is not correct (it has 2 children)"),
    (17, "WRONG_FORMAT", "The port msecs of node Timeout does not exist (did you mean msec?)"),
    (17, "WRONG_FORMAT", "The node Timeout needs the port msec"),
    (18, "WRONG_VALUE", "The value SIDEWAYS of argument DIRECTION for behavior KEEP_MOVING is not correct (one of "
                        "FORWARD, BACKWARD, LEFT, RIGHT, UPWARD, DOWNWARD is expected)"),
    (19, "WRONG_SEQUENCE", "The execution of behavior TAKE_OFF cannot be done after the execution of KEEP_MOVING "
                           "(flight is moving; TAKE_OFF needs landed)"),
    (27, "WRONG_FORMAT", "The tree Loop includes itself (Loop -> Loop)"),
]


def test_every_problem_is_reported_with_its_message_and_line():
    problems = verify_document(read_mission_tree(BAD, "bad.xml"))
    found = [(p.line, p.kind, p.message) for p in problems]
    for expected in EXPECTED:
        assert expected in found
    assert all(p.file == "bad.xml" for p in problems)
    syntax = [p for p in problems if p.line == 9 and p.severity == "error"]  # the other: <Condition belief>
    assert len(syntax) == 1 and syntax[0].message.startswith("The format of the belief expression "
                                                              "flight_state(self,  is not correct")
    assert any(p.line == 19 and p.message.startswith("The format of the belief expression not(flying(self)")
               for p in problems)
    assert not [p for p in problems if p.line in (20, 21, 22)]  # keys written by QueryBelief and AskBehavior
    assert len({(p.line, p.message) for p in problems}) >= 18
    assert str(problems[0]).startswith("bad.xml:4: error: WRONG_SEQUENCE: The execution of behavior LAND")


def N(kind: str, *children: TreeNode, line: int = 0, **ports: str) -> TreeNode:  # noqa: N802
    return TreeNode(kind, "", dict(ports), list(children), "m.xml", line)


def sequence_problems(root: TreeNode, **trees: TreeNode) -> list[tuple[int, str]]:
    problems = [p for p in verify_document(TreeDocument({"Main": root, **trees}, "Main", "m.xml"))
                if p.severity == "error" or p.kind == "WRONG_SEQUENCE"]  # not the old belief-expression spelling
    assert all(p.kind == "WRONG_SEQUENCE" for p in problems), problems
    return [(p.line, p.message) for p in problems]


def test_land_after_land_is_a_wrong_sequence():
    found = sequence_problems(N("Sequence", N("TAKE_OFF", line=1), N("LAND", line=2), N("LAND", line=3)))
    assert found == [(3, "The execution of behavior LAND cannot be done after the execution of LAND (flight is "
                         "landed; LAND needs hovering or moving)")]


@pytest.mark.parametrize("loop", ["Repeat", "RetryUntilSuccessful", "KeepRunningUntilFailure"])
def test_a_loop_entered_after_landing_is_checked_from_the_ground_on_its_first_pass(loop):
    # a later pass could start hovering (the body's GO_TO_POINT would have flown): the first starts landed
    ports = {"num_cycles": "2"} if loop == "Repeat" else {"num_attempts": "2"} if loop == "RetryUntilSuccessful" \
        else {}
    body = N("Sequence", N("GO_TO_POINT", COORDINATES="0, -4, 3", line=5), N("GO_TO_POINT", COORDINATES="4, -4, 3",
                                                                             line=6))
    found = sequence_problems(N("Sequence", N("TAKE_OFF", line=2), N("LAND", line=3), N(loop, body, **ports)))
    assert found == [(5, "The execution of behavior GO_TO_POINT cannot be done after the execution of LAND (flight "
                         "is landed; GO_TO_POINT needs hovering or moving)")]


def test_nested_loops_are_walked_a_bounded_number_of_times(monkeypatch):
    from aeroexec.trees.sequence_check import SequenceChecker

    walked = []
    behavior = SequenceChecker.behavior
    monkeypatch.setattr(SequenceChecker, "behavior", lambda self, *args: walked.append(1) or behavior(self, *args))
    body = N("GO_TO_POINT", COORDINATES="1, 1, 3", line=9)
    for _ in range(16):  # each pass of a loop walked its body twice more: 2^16 walks of the GO_TO_POINT, 25 s
        body = N("Repeat", N("Sequence", body, N("LAND"), N("TAKE_OFF")), num_cycles="2")
    found = sequence_problems(N("Sequence", N("TAKE_OFF"), N("LAND"), body, N("LAND")))
    assert found == [(9, "The execution of behavior GO_TO_POINT cannot be done after the execution of LAND (flight "
                         "is landed; GO_TO_POINT needs hovering or moving)")]
    assert len(walked) < 2000, len(walked)


def test_each_branch_is_checked_from_the_state_it_starts_in():
    root = N("Sequence", N("IfThenElse", N("Condition", belief="code(box, 1)"), N("TAKE_OFF", line=2),
                           N("LAND", line=3)))
    assert sequence_problems(root) == [(3, "The execution of behavior LAND cannot be done at the start of the "
                                           "mission (flight is landed; LAND needs hovering or moving)")]


@pytest.mark.parametrize("root", [
    # the alternative may start after TAKE_OFF succeeded and GO_TO_POINT failed
    N("Fallback", N("Sequence", N("TAKE_OFF"), N("GO_TO_POINT", COORDINATES="1, 1, 2")), N("LAND")),
    # another branch of the Parallel changes the flight while this one waits
    N("Parallel", N("Sequence", N("TAKE_OFF"), N("GO_TO_POINT", COORDINATES="1, 1, 2")),
      N("Delay", N("LAND"), delay_msec="5000")),
    # a condition on the flight state: the memory may know better than the state machine
    N("Sequence", N("TAKE_OFF"), N("Condition", belief="flight_state(self, landed)"), N("TAKE_OFF")),
    # a loop: the second pass starts after the first
    N("Repeat", N("Sequence", N("TAKE_OFF"), N("LAND")), num_cycles="3"),
    # a skipped node may leave the flight as it was
    N("Sequence", N("TAKE_OFF", _skipIf="code(box, 1)"), N("LAND")),
    # a reactive sequence ticks its children again while one runs
    N("ReactiveSequence", N("Condition", belief="code(box, 1)"), N("SubTree", ID="Fly")),
])
def test_no_wrong_sequence_where_a_run_could_avoid_it(root):
    fly = N("Sequence", N("TAKE_OFF"), N("GO_TO_POINT", COORDINATES="1, 1, 2"), N("LAND"))
    assert sequence_problems(root, Fly=fly) == []


def test_a_subtree_is_checked_where_it_is_used():
    land = N("Sequence", N("LAND", line=9))
    found = sequence_problems(N("Sequence", N("TAKE_OFF"), N("SubTree", ID="Land"), N("SubTree", ID="Land")),
                              Land=land)
    assert found == [(9, "The execution of behavior LAND cannot be done after the execution of LAND (flight is "
                         "landed; LAND needs hovering or moving)")]


def test_blackboard_keys_through_subtree_remapping_and_loops():
    inner = N("Sequence", N("GO_TO_POINT", COORDINATES="{goal}", line=5),
              N("QueryBelief", belief="position(self, ?Here)"))
    ok = N("Sequence", N("TAKE_OFF"), N("QueryBelief", belief="position(pad, ?P)"),
           N("SubTree", ID="Go", goal="{P}"),
           N("Repeat", N("Sequence", N("CheckBelief", belief="position(self, {Last})",
                                       _skipIf="belief('code(first, 1)')"),
                         N("QueryBelief", belief="position(self, ?Last)")), num_cycles="2"))
    problems = verify_document(TreeDocument({"Main": ok, "Go": inner}, "Main", "m.xml"), known_keys=())
    assert problems == []
    unmapped = N("Sequence", N("TAKE_OFF"), N("QueryBelief", belief="position(pad, ?P)"), N("SubTree", ID="Go"))
    problems = verify_document(TreeDocument({"Main": unmapped, "Go": inner}, "Main", "m.xml"))
    assert [(p.line, p.message) for p in problems] == [(5, "The blackboard key goal is read before any node "
                                                           "writes it")]
    remapped = N("Sequence", N("TAKE_OFF"), N("SubTree", ID="Go", goal="{target}"))
    problems = verify_document(TreeDocument({"Main": remapped, "Go": inner}, "Main", "m.xml"),
                               known_keys=["target"])
    assert problems == []


def test_the_main_tree_must_exist_and_ask_behavior_is_checked_against_the_catalog():
    ask = N("AskBehavior", behavior="GENERATE_PATH_FREE_OF_OBSTACLE", result="{p}", line=3)
    document = TreeDocument({"Main": ask}, "Mian", "m.xml")
    messages = [p.message for p in verify_document(document)]
    assert messages[0] == "The main tree Mian does not exist (did you mean Main?)"
    document.main = "Main"
    assert [(p.line, p.message) for p in verify_document(document)] == [
        (3, "The behavior GENERATE_PATH_FREE_OF_OBSTACLE does not exist (did you mean "
            "GENERATE_PATH_FREE_OF_OBSTACLES?)")]


def test_add_belief_declares_new_predicates_for_the_rest_of_the_mission():
    root = N("Sequence", N("AddBelief", belief="inspected(wing)", multivalued="true"),
             N("Condition", belief="inspected(?X)"), N("Condition", belief="inspectd(?X)", line=4))
    problems = verify_document(TreeDocument({"Main": root}, "Main", "m.xml"))
    assert [(p.line, p.message) for p in problems] == [
        (4, "The predicate inspectd of the belief expression inspectd(?X) does not exist")]


LEG = """<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence><TAKE_OFF/><SubTree ID="Leg" target="3, 0, 2"/><SubTree ID="Leg"/><LAND/></Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Leg"><GO_TO_POINT COORDINATES="{target}"/></BehaviorTree>
  <TreeNodesModel><SubTree ID="Leg"><input_port name="target" default="1, 1, 2"/></SubTree></TreeNodesModel>
</root>"""


def test_a_subtree_port_given_a_literal_or_a_palette_default_is_written_for_the_subtree():
    assert verify_document(read_mission_tree(LEG, "leg.xml")) == []
    document = read_mission_tree(LEG, "leg.xml")
    uses = [n for n in document.root.walk() if n.type == "SubTree"]
    assert [u.ports.get("target") for u in uses] == ["3, 0, 2", "1, 1, 2"]


def test_scripts_are_checked_and_a_repeat_count_may_come_from_the_blackboard():
    text = """<root BTCPP_format="4"><BehaviorTree>
      <Sequence><Script code="n := 2"/><Repeat num_cycles="{n}"><AlwaysSuccess _onSuccess="k := := 1"/></Repeat>
        <ScriptCondition code="n == 2" _skipIf="n &gt; 3"/></Sequence></BehaviorTree></root>"""
    problems = verify_document(read_mission_tree(text, "s.xml"))
    assert [p.message.split(":")[0] for p in problems] == ["The _onSuccess of node AlwaysSuccess is not a script"]


def test_status_and_integer_ports_of_the_v4_nodes_are_checked():
    text = """<root BTCPP_format="4"><BehaviorTree><Sequence>
      <Precondition if="true" else="MAYBE"><AlwaysSuccess/></Precondition>
      <LoopInt queue="1;2" value="{v}" if_empty="RUNNING"><AlwaysSuccess/></LoopInt>
      <Sleep msec="{t}"/>
      <ParallelAll max_failures="x"><AlwaysSuccess/></ParallelAll>
    </Sequence></BehaviorTree></root>"""
    messages = [(p.line, p.message) for p in verify_document(read_mission_tree(text, "v.xml"))]
    assert messages == [
        (2, "The value MAYBE of port else of node Precondition is not correct (SUCCESS, FAILURE, SKIPPED, RUNNING "
            "is expected)"),
        (3, "The value RUNNING of port if_empty of node LoopInt is not correct (SUCCESS, FAILURE, SKIPPED is "
            "expected)"),
        (4, "The blackboard key t is read before any node writes it"),
        (5, "The value x of port max_failures of node ParallelAll is not correct (an integer is expected)"),
    ]


def test_ports_are_converted_as_btcpp_converts_them_when_it_loads_the_tree():
    text = """<root BTCPP_format="4"><BehaviorTree><Sequence>
      <Repeat num_cycles="2.5"><AlwaysSuccess/></Repeat><Repeat num_cycles="-2"><AlwaysSuccess/></Repeat>
      <LoopInt queue="" value="{v}"><AlwaysSuccess/></LoopInt><LoopInt queue="1;x" value="{v}">
        <AlwaysSuccess/></LoopInt>
      <Script code="a := true"/><RunOnce then_skip="{a}"><Repeat num_cycles="{a}"><AlwaysSuccess/></Repeat></RunOnce>
      <Timeout msec=" 5"><AlwaysSuccess/></Timeout><Sleep msec="{a}"/>
    </Sequence></BehaviorTree></root>"""
    messages = [(p.line, p.severity, p.message) for p in verify_document(read_mission_tree(text, "v.xml"))]
    assert messages == [
        (2, "warning", "The value 2.5 of port num_cycles of node Repeat is read as 2 (BehaviorTree.CPP reads the "
                       "integer the text starts with)"),
        (2, "error", "The value -2 of port num_cycles of node Repeat is not correct (an integer (-1: forever) is "
                     "expected)"),
        (3, "error", "The value 1;x of port queue of node LoopInt is not correct (int items separated by ; are "
                     "expected: Can't convert string [x] to integer)"),  # queue="" is an empty queue
        (5, "error", "The creation of the tree failed because the port [a] was initially created with type [bool] "
                     "and, later type [int] was used somewhere else."),
        (6, "error", "The value  5 of port msec of node Timeout is not correct (an integer of at least 0 is "
                     "expected)"),
        (6, "error", "The creation of the tree failed because the port [a] was initially created with type [bool] "
                     "and, later type [unsigned] was used somewhere else."),
    ]


def test_a_script_variable_nothing_writes_is_a_warning():
    text = """<root BTCPP_format="4"><BehaviorTree><Sequence>
      <Script code="total := 0"/>
      <Repeat num_cycles="3"><Script code="total += step; seen := @origin"/></Repeat>
      <AlwaysSuccess _skipIf="total &gt; limit"/>
    </Sequence></BehaviorTree></root>"""
    problems = verify_document(read_mission_tree(text, "w.xml"), known_keys=["limit"])
    assert [(p.line, p.severity, p.message) for p in problems] == [
        (3, "warning", 'The script variable step is read but no node writes it (the run fails there: "Variable not '
                       'found: step")'),
        (3, "warning", 'The script variable @origin is read but no node writes it (the run fails there: "Variable '
                       'not found: @origin")'),
    ]
