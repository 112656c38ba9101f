"""A behavior tree changed while it flies (tests/changes/data/patrol.xml: items 1-6 of a SequenceWithMemory, item 4
a Repeat of two laps): jump back to item 2, replace a subtree, skip the running behavior, modify the running one,
changes made while paused; what cannot be changed says why; and after every change the tree is the one its
document builds (what a flight journal captured after it resumes into)."""

from __future__ import annotations

import pytest
from aeroexec.trees import load_mission_tree
from aeroexec.trees.loaders.fragment import read_fragment
from aeroexec.trees.runtime.blackboard import Blackboard
from aeroexec.trees.runtime.builder import build_tree
from aeroexec.trees.runtime.changes import replay_edits
from aeroexec.trees.runtime.context import TreeContext
from changing import DATA, MISSIONS, ChangedFlight, changes, ended, statuses

PATROL = DATA / "patrol.xml"
A, B, C = (6.0, 0.0, 3.0), (14.0, 2.0, 3.0), (2.0, 4.0, 3.0)
SOUTH = (4.0, -14.0, 3.0)


def patrol_at(tmp_path, node: str, seconds: float = 0.0) -> ChangedFlight:
    """The patrol flown until ``node`` has run ``seconds``."""
    flight = ChangedFlight(PATROL, tmp_path / "run")
    flight.until(lambda: flight.running(node))
    flight.engine.step(seconds)
    return flight


def shape(root) -> list[tuple[str, str]]:
    return [(type(node).__name__, node.name) for node in root.iterate()]


def built_again(flight: ChangedFlight) -> list[tuple[str, str]]:
    """The tree the mission's (changed) document builds."""
    tree = flight.session.tree
    return shape(build_tree(tree.document, TreeContext(flight.engine), Blackboard()))


def test_a_jump_back_to_item_2_flies_corner_a_again(tmp_path):
    flight = patrol_at(tmp_path, "corner B", 2.0)
    now = flight.engine.now()
    result = flight.change("jump", "2")
    assert result.ok and result.message == "the mission goes on from corner A (line 8)"
    records = flight.finish()
    back = flight.reached_at(A, after=now)
    assert back is not None and flight.reached_at(B, after=back) is not None  # A again, then B again
    assert statuses(records, "corner A") == ["RUNNING", "SUCCESS", "RUNNING", "SUCCESS"]
    assert ended(records) == "completed"


def test_a_subtree_replaced_while_it_runs_flies_the_new_one_in_its_place(tmp_path):
    flight = patrol_at(tmp_path, "lap west")
    now = flight.engine.now()
    result = flight.change("replace", "laps '<Sequence name=\"look around\"><GO_TO_POINT name=\"spot\" "
                                      "COORDINATES=\"-4, -2, 4\"/><ROTATE ANGLE=\"90\"/></Sequence>'")
    assert result.ok and result.message == "laps replaced by look around"
    assert [i["name"] for i in flight.items()] == ["take off", "corner A", "corner B", "look around", "corner C",
                                                   "land"]
    assert shape(flight.session.tree.root) == built_again(flight)  # the tree is its document's
    records = flight.finish()
    assert flight.reached_at((-4.0, -2.0, 4.0), after=now) is not None
    assert flight.closest(SOUTH, after=now) > 5.0  # the laps were not flown on
    assert "SUCCESS" not in statuses(records, "lap west")
    assert flight.reached_at(C, after=now) is not None and ended(records) == "completed"


def test_skip_ends_the_running_behavior_skipped_and_modify_restarts_one_with_its_new_values(tmp_path):
    flight = patrol_at(tmp_path, "corner A")
    now = flight.engine.now()
    result = flight.change("skip")
    assert result.ok and result.message == "corner A (line 8) skipped; the mission goes on with corner B (line 9)"
    assert flight.running("corner B")
    moved = flight.change("modify", "'corner B' COORDINATES='12, -2, 4'")
    assert moved.ok and moved.message == "corner B: COORDINATES=12, -2, 4"
    assert shape(flight.session.tree.root) == built_again(flight)
    records = flight.finish()
    assert flight.closest(A, after=now + 0.1) > 1.0
    assert flight.reached_at((12.0, -2.0, 4.0), after=now) is not None and flight.closest(B, after=now) > 2.0
    assert statuses(records, "corner A")[-2:] == ["RUNNING", "SKIPPED"]
    assert ended(records) == "completed"


@pytest.mark.parametrize("within, resumed", [
    (4.0, "mission resumed (requested again: GO_TO_POINT)"),  # on its way: asked again, it flies on to corner A
    (0.6, "mission resumed (already achieved, the mission goes on: GO_TO_POINT)"),  # held where it arrives
])
def test_pause_and_resume_say_what_becomes_of_the_running_go_to_point(tmp_path, within, resumed):
    import math

    flight = ChangedFlight(PATROL, tmp_path / "run")
    flight.until(lambda: flight.running("corner A") and
                 math.dist(flight.engine.drone.telemetry().position, A) < within)
    paused = flight.change("pause")
    assert paused.message == "mission paused (stopped GO_TO_POINT until resume, which asks for it again; " \
                             "KEEP_HOVERING holds the drone)"
    flight.engine.step(3.0)
    assert flight.change("resume").message == resumed  # never "refused now" for a request that then succeeds
    records = flight.finish()
    assert statuses(records, "corner A") == ["RUNNING", "SUCCESS"] and ended(records) == "completed"
    assert flight.reached_at(A, within=0.5) is not None


def test_changes_made_while_paused_take_effect_on_resume_and_the_skipped_behavior_is_not_asked_again(tmp_path):
    flight = patrol_at(tmp_path, "corner B")
    assert flight.change("pause").ok
    assert flight.change("insert", "after 3 'GO_TO_POINT COORDINATES=\"9, -3, 4\" name=detour'").ok
    assert flight.change("skip").ok
    resumed = flight.engine.now()
    assert flight.change("resume").message == "mission resumed"  # nothing the pause stopped is asked again
    records = flight.finish()
    assert flight.reached_at((9.0, -3.0, 4.0), after=resumed) is not None and flight.closest(B, after=resumed) > 2
    assert statuses(records, "detour") == ["RUNNING", "SUCCESS"]
    assert ended(records) == "completed"


def test_a_take_off_is_not_cut_short_and_what_cannot_be_changed_says_why(tmp_path):
    flight = patrol_at(tmp_path, "take off")
    said = {f"{command} {argument}".strip(): flight.change(command, argument).message for command, argument in [
        ("skip", ""), ("jump", "3"), ("delete", "1")]}
    assert set(said.values()) == {"TAKE_OFF is running, and a change does not cut it short (it takes flight from or "
                                  "to landed): change the mission once it ends"}
    flight.until(lambda: flight.running("corner A"))
    refused = [(command, argument, flight.change(command, argument)) for command, argument in [
        ("jump", "9"), ("jump", "'corner D'"), ("delete", "lap"), ("insert", "before lap 'WAIT DURATION=1'"),
        ("insert", "before 'lap west' 'FLY_AWAY SPEED=3'"), ("insert", "after 2 '<GO_TO_POINT'"),
        ("modify", "2 SPEED=90"), ("replace", "patrol '<LAND/>'"), ("insert", "after 2 LAND"),
        ("insert", "after 2 'GO_TO_POINT COORDINATES=\"30, 0, 3\"'")]]
    messages = [result.message for _, _, result in refused]
    assert [result.ok for _, _, result in refused] == [False] * len(refused), messages
    assert messages[0] == "the mission has items 1 to 6, not 9"
    assert messages[1] == "the mission has no node named 'corner D' (aeroexec ctl items lists its items)"
    assert messages[2] == "items are deleted from sequences; lap (line 11) is in laps (line 10) (Repeat): replace " \
                          "laps (line 10) instead"
    assert messages[3] == "items are inserted into sequences; lap (line 11) is in laps (line 10) (Repeat): replace " \
                          "laps (line 10) instead"
    assert messages[4].startswith("change 8:1: The behavior FLY_AWAY does not exist")
    assert messages[5].startswith("the fragment cannot be read: change 9:1:")
    assert messages[6].endswith("patrol.xml:8: The value 90 of argument SPEED for behavior GO_TO_POINT is not "
                                "correct (a number between 0.1 and 12 is expected)")
    assert messages[7] == "'patrol' is the mission's root: load a new mission to change all of it"
    assert "The execution of behavior GO_TO_POINT cannot be done after the execution of LAND" in messages[8]
    assert "outside the world's bounds" in messages[9]
    records = flight.finish()
    assert ended(records) == "completed" and all(not c["ok"] for c in changes(records))


@pytest.mark.parametrize("command, argument", [
    ("insert", "after 3 'GO_TO_POINT COORDINATES=\"9, -3, 4\"'"), ("delete", "5"), ("modify", "'lap south' SPEED=2"),
    ("replace", "laps '<ROTATE ANGLE=\"45\"/>'")])
def test_after_a_change_the_running_tree_is_the_one_its_document_builds(tmp_path, command, argument):
    flight = patrol_at(tmp_path, "lap west")
    assert flight.change(command, argument).ok
    assert shape(flight.session.tree.root) == built_again(flight)
    records = flight.finish()
    assert ended(records) == "completed"


def test_the_edits_recorded_in_the_event_log_make_the_changed_tree_again_from_the_mission_file(tmp_path):
    flight = patrol_at(tmp_path, "lap west")
    for command, argument in [("insert", "after 3 'GO_TO_POINT COORDINATES=\"9, -3, 4\" name=detour'"),
                              ("modify", "detour SPEED=2 name=\"slow detour\""), ("delete", "6"),
                              ("replace", "'lap south' '<Sequence><ROTATE ANGLE=\"45\"/><WAIT DURATION=\"1\"/>"
                                          "</Sequence>'"), ("skip", "")]:
        assert flight.change(command, argument).ok
    running = shape(flight.session.tree.root)
    edits = [edit for record in flight.records() if record["kind"] == "mission_change"
             for edit in record["data"].get("edits", [])]
    assert len(edits) == 4  # skip edits no document
    document = load_mission_tree(PATROL)  # as a resumed run reads it
    replay_edits(document, edits, read_fragment)
    assert shape(build_tree(document, TreeContext(flight.engine), Blackboard())) == running
    flight.finish()


def test_an_item_inserted_before_the_running_one_flies_first_and_a_deleted_running_item_gives_way(tmp_path):
    flight = patrol_at(tmp_path, "corner B", 1.0)
    now = flight.engine.now()
    result = flight.change("insert", "before 3 'GO_TO_POINT COORDINATES=\"9, -3, 4\" name=detour'")
    assert result.message == "detour inserted before corner B (it is running: it flies again after detour)"
    flight.until(lambda: flight.running("corner B"))
    again = flight.engine.now()
    assert flight.change("delete", "'corner B'").message == "corner B deleted"
    records = flight.finish()
    assert flight.reached_at((9.0, -3.0, 4.0), after=now) < again  # the detour first, then corner B again
    assert flight.closest(B, after=again) > 2.0  # deleted while it ran: the laps came next
    assert statuses(records, "detour") == ["RUNNING", "SUCCESS"]
    assert flight.reached_at((0.0, -4.0, 3.0), after=again) is not None and ended(records) == "completed"


def test_a_tml_mission_takes_skip_of_the_task_it_waits_for_and_is_edited_by_loading_a_new_one(tmp_path):
    flight = ChangedFlight(MISSIONS / "search_for_object.tml.xml", tmp_path / "run")
    flight.until(lambda: flight.active("ROTATE"))
    skipped = flight.change("skip")  # the task waited for, not SELF_LOCALIZE_BY_ODOMETRY running beside it
    assert skipped.message.startswith("Face the search area (line 28) skipped; the mission goes on with")
    assert flight.change("insert", "after 1 LAND").message == (
        "a TML mission's tasks compile into a tree of their own: it takes skip; load a new mission to change its "
        "tasks")
    assert ended(flight.finish()) == "completed"


LANDED_LAP = ("patrol.xml:12: The execution of behavior GO_TO_POINT cannot be done after the execution of LAND "
              "(flight is landed; GO_TO_POINT needs hovering or moving)")
LANDED_C = LANDED_LAP.replace(":12:", ":16:")
LANDED_LAND = ("patrol.xml:17: The execution of behavior LAND cannot be done after the execution of LAND (flight is "
               "landed; LAND needs hovering or moving)")


@pytest.mark.parametrize("moment, command, argument, refusal", [
    # at the running item (the laps, a Repeat): checked as before a future item, from the drone's state now
    ("lap west", "insert", "before 4 LAND", LANDED_LAP),
    ("lap west", "insert", "after 4 LAND", LANDED_C),
    ("lap west", "replace", "4 LAND", LANDED_C),
    ("lap west", "delete", "4", None),
    # at a future item
    ("corner A", "insert", "before 4 LAND", LANDED_LAP),
    ("lap west", "insert", "before 5 LAND", LANDED_C),
    ("lap west", "insert", "after 5 LAND", LANDED_LAND),
    ("lap west", "replace", "5 LAND", LANDED_LAND),
    ("lap west", "delete", "5", None),
    # at the end of the mission
    ("lap west", "insert", "before 6 LAND", LANDED_LAND),
    ("lap west", "insert", "after 6 LAND", "change 1:1: The execution of behavior LAND cannot be done after the "
                                          "execution of LAND (flight is landed; LAND needs hovering or moving)"),
    ("lap west", "replace", "6 LAND", None),
    ("lap west", "delete", "6", None),  # the mission ends without its LAND: the run lands the drone
])
def test_an_edit_at_the_running_item_is_checked_as_one_at_a_future_item_and_the_drone_lands(tmp_path, moment, command,
                                                                                           argument, refusal):
    flight = patrol_at(tmp_path, moment)
    result = flight.change(command, argument)
    if refusal is None:
        assert result.ok, result.message
    else:
        assert not result.ok and result.message.endswith(refusal), result.message
    records = flight.finish()
    assert ended(records) == "completed"  # a refused edit leaves the mission as it was; a taken one keeps it flyable
    assert flight.engine.drone.telemetry().landed_state.name == "ON_GROUND"
    if refusal is not None:  # nothing of the refused edit flew
        assert statuses(records, "laps")[-1] == "SUCCESS" and statuses(records, "land") == ["RUNNING", "SUCCESS"]


FRAGMENTS = ["LAND", "TAKE_OFF ALTITUDE=2", "'GO_TO_POINT COORDINATES=\"3, 2, 3\"'", "'WAIT DURATION=1'",
             "'<Repeat num_cycles=\"2\"><GO_TO_POINT COORDINATES=\"2, 2, 3\"/></Repeat>'", "'<LAND/><TAKE_OFF/>'"]


def random_edit(rng, items: list[dict]) -> tuple[str, str]:
    """One live edit as an operator (or the campaign) sends it: at the running item, a future one, the end, past it."""
    running = [i for i, item in enumerate(items, 1) if item["status"] == "running"] or [1]
    target = str(rng.choice([running[0], running[0], running[0] + 1, len(items), len(items) + 1,
                             rng.randint(1, len(items)), "\u00b2"]))
    command = rng.choice(["insert", "replace", "delete", "jump", "skip", "modify", "update", "pause", "resume"])
    if command == "insert":
        return command, f"{rng.choice(['before', 'after'])} {target} {rng.choice(FRAGMENTS)}"
    if command == "replace":
        return command, f"{target} {rng.choice(FRAGMENTS)}"
    if command == "modify":
        return command, f"{target} {rng.choice(['SPEED=2', 'num_cycles=1', 'name=renamed'])}"
    if command == "update":
        return command, rng.choice([f"INSERT {target} LAND", f"REMOVE {target}", "NEXT_ITEM", "INSERT", "MODIFY 1"])
    return command, target if command in ("delete", "jump") else ""


@pytest.mark.parametrize("seed", range(8))
def test_live_edits_at_random_times_never_fail_inside_and_the_drone_always_lands(tmp_path, caplog, seed):
    import random

    rng = random.Random(seed)
    flight = ChangedFlight(PATROL, tmp_path / "run")
    said = []
    for _ in range(5):
        flight.engine.run_until(lambda: flight.session.mission_done, rng.uniform(0.5, 12.0))
        command, argument = random_edit(rng, flight.items() or [{"status": "done"}])
        said.append((command, argument, flight.change(command, argument).message))
    if flight.engine.supervisor.paused:
        flight.change("resume")
    records = flight.finish()
    internal = [record.getMessage() for record in caplog.records if record.levelname in ("ERROR", "CRITICAL")]
    assert not internal and not [s for s in said if " failed: " in s[2] or "please report" in s[2]], said
    assert flight.engine.drone.telemetry().landed_state.name == "ON_GROUND", said
    assert ended(records) == "completed", said  # what a taken edit left to fly was checked flyable
