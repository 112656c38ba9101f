"""A QGroundControl survey (missions/survey.plan: a take-off, a lawnmower of items 8-17 with the camera triggered,
a loiter, a landing, inside a geofence) changed while it flies, by item number as QGroundControl numbers them: a
waypoint inserted mid-survey is flown, the next one deleted is not, a jump back flies the survey again, skip goes
on with the next item; a change that leaves the fence, breaks the flight order or needs more battery than is left
is refused with the reason and the mission flies on unchanged; the event log and the report show each change."""

from __future__ import annotations

from aeroexec.cli.reporting.html import write_html
from aeroexec.flight.summary import summarize
from changing import MISSIONS, ChangedFlight, changes, ended, statuses

SURVEY = MISSIONS / "survey.plan"
ITEM_9 = "geo:47.39765206,8.54572646,15"
ITEM_10 = "geo:47.39769703,8.54572646,15"
ITEM_11 = "geo:47.39769703,8.54546154,15"
INSIDE = "geo:47.39777000,8.54562000,15"  # inside the survey's fence, off its lawnmower


def survey_at_item_9(tmp_path) -> ChangedFlight:
    flight = ChangedFlight(SURVEY, tmp_path / "run")
    flight.until(lambda: flight.running("item 9 WAYPOINT"))
    return flight


def test_a_waypoint_inserted_mid_survey_is_flown_between_the_items_it_was_put_between(tmp_path):
    flight = survey_at_item_9(tmp_path)
    now = flight.engine.now()
    result = flight.change("insert", f"after 10 'GO_TO_POINT COORDINATES={INSIDE} SPEED=4 name=\"extra look\"'")
    assert result.ok, result.message
    assert result.message == "extra look inserted after item 10 WAYPOINT"
    assert [i["name"] for i in flight.items()][7:10] == ["item 10 WAYPOINT", "extra look", "item 11 WAYPOINT"]
    records = flight.finish()
    at_10, at_extra = flight.reached_at(flight.enu(ITEM_10), after=now), flight.reached_at(flight.enu(INSIDE),
                                                                                          after=now)
    at_11 = flight.reached_at(flight.enu(ITEM_11), after=now)
    assert at_10 is not None and at_extra is not None and at_11 is not None
    assert at_10 < at_extra < at_11
    assert statuses(records, "extra look") == ["RUNNING", "SUCCESS"]
    assert ended(records) == "completed"


def test_the_next_waypoint_deleted_is_not_flown(tmp_path):
    flight = survey_at_item_9(tmp_path)
    now = flight.engine.now()
    result = flight.change("delete", "10")
    assert result.ok and result.message == "item 10 WAYPOINT deleted"
    records = flight.finish()
    assert flight.closest(flight.enu(ITEM_10), after=now) > 2.0  # from item 9 straight on to item 11
    assert flight.reached_at(flight.enu(ITEM_11), after=now) is not None
    assert "RUNNING" not in statuses(records, "item 10 WAYPOINT")
    assert ended(records) == "completed"


def test_a_jump_back_to_item_4_flies_the_survey_again_and_skip_goes_on_with_the_next_item(tmp_path):
    flight = survey_at_item_9(tmp_path)
    jumped = flight.engine.now()
    assert flight.change("jump", "4").message == "the mission goes on from item 4 WAYPOINT"
    flight.until(lambda: flight.running("item 8 WAYPOINT"))
    skipped = flight.engine.now()
    result = flight.change("skip")
    assert result.ok and result.message == "item 8 WAYPOINT skipped; the mission goes on with item 9 WAYPOINT"
    records = flight.finish()
    item_4 = flight.enu("geo:47.39763407,8.54559400,15")
    assert flight.reached_at(item_4, after=jumped) is not None  # flown a second time
    assert statuses(records, "item 4 WAYPOINT") == ["RUNNING", "SUCCESS", "RUNNING", "SUCCESS"]
    assert "SKIPPED" in statuses(records, "item 8 WAYPOINT")
    assert flight.reached_at(flight.enu(ITEM_9), after=skipped) is not None
    assert ended(records) == "completed"


def test_changes_that_leave_the_fence_break_the_order_or_outlast_the_battery_are_refused_and_nothing_changes(
        tmp_path):
    flight = survey_at_item_9(tmp_path)
    before = flight.items()
    outside = flight.change("insert", "after 10 'GO_TO_POINT COORDINATES=geo:47.39790,8.54600,15'")
    order = flight.change("insert", "after 10 TAKE_OFF")
    battery = flight.change("insert", "after 10 '<WAIT DURATION=\"900\"/><WAIT DURATION=\"900\"/>'")
    modified = flight.change("modify", "11 COORDINATES=geo:47.39740,8.54546154,15")
    assert not outside.ok and "geofence" in outside.message and outside.message.startswith("change 1:1: ")
    assert not order.ok and order.message == (
        "change 2:1: The execution of behavior TAKE_OFF cannot be done after the execution of GO_TO_POINT "
        "(flight is hovering; TAKE_OFF needs landed)")
    assert not battery.ok and "the battery runs down to its 7% failsafe here" in battery.message
    assert "more than the drone has" in battery.message
    assert not modified.ok and "geofence" in modified.message  # item 11 moved out of the fence
    assert flight.items() == before  # the mission flies on unchanged
    records = flight.finish()
    assert [c["ok"] for c in changes(records)] == [False, False, False, False]
    assert all(statuses(records, f"item {n} WAYPOINT")[-1] == "SUCCESS" for n in range(8, 18))
    assert ended(records) == "completed"
    assert sorted(p.name for p in flight.session.folder.glob("*.btlog")) == ["mission.btlog"]


def test_the_event_log_and_the_report_show_each_change_taken_or_refused(tmp_path):
    flight = survey_at_item_9(tmp_path)
    flight.change("insert", f"after 10 'GO_TO_POINT COORDINATES={INSIDE}'")
    flight.change("delete", "99")
    flight.change("skip")
    records = flight.finish()
    said = changes(records)
    assert [(c["command"], c["ok"]) for c in said] == [("insert", True), ("delete", False), ("skip", True)]
    assert said[1]["detail"] == ("delete 99: refused: the plan has no item 99 (items with behaviors: 1, 3-4, 6-17, "
                                 "19-20)")
    summary = summarize(records)
    assert [(c.command, c.taken, c.origin) for c in summary.changes] == [
        ("insert", True, "test"), ("delete", False, "test"), ("skip", True, "test")]
    page = write_html(summary, [], tmp_path / "report.html", "test", "now", tmp_path / "events.jsonl").read_text(
        encoding="utf-8")
    assert "<h2>Mission changes</h2>" in page
    assert "the plan has no item 99" in page and "item 9 WAYPOINT skipped" in page
    assert page.count("<b>refused</b>") == 1
    # a changed tree goes on in its own .btlog file, whose header is the changed tree
    assert sorted(p.name for p in flight.session.folder.glob("*.btlog")) == ["mission.btlog",
                                                                             "mission.change-1.btlog"]


def test_a_loiter_without_end_goes_on_when_the_operator_skips_it(tmp_path):
    plan = tmp_path / "survey_loiter_unlim.plan"  # the survey with its loiter (item 19) held until moved on
    plan.write_text(SURVEY.read_text().replace('"command": 19,', '"command": 17,', 1))
    flight = ChangedFlight(plan, tmp_path / "run")
    flight.until(lambda: flight.running("item 19 loiter"))
    flight.engine.step(5.0)
    assert flight.running("item 19 loiter")  # KEEP_HOVERING: it holds there until the operator says
    result = flight.change("skip")
    assert result.message == "item 19 loiter skipped; the mission goes on with item 20 land"
    records = flight.finish()
    assert statuses(records, "item 20 land") == ["RUNNING", "SUCCESS"] and ended(records) == "completed"
