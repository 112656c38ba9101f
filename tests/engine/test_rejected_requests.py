"""A request ``verify`` would have refused, found at run time in a Python mission, raises in the mission at its
line (issue 18, point 2); FAILED_PRECONDITIONS stays a return value; the run's status tells them apart."""

from __future__ import annotations

import json
import textwrap
from pathlib import Path

import pytest
from aeroexec.cli.main import main
from aeroexec.flight.run_status import EXIT_STATUS, FAILED, REFUSED

HEADER = "import aeroexec.engine.api as api\n\n"

# Each mission computes what verify cannot see: the error is on the line marked HERE.
COMPUTED = {
    "unknown behavior": ('''
        def mission():
            api.execute_behavior("TAKE_OFF", altitude=3)
            name = "GO_TO_" + "POINTS"
            api.execute_behavior(name, coordinates=(1, 0, 3))  # HERE
            api.execute_behavior("LAND")
        ''', "WRONG_FORMAT", "GO_TO_POINTS"),
    "value out of range": ('''
        def mission():
            api.execute_behavior("TAKE_OFF", altitude=3)
            x = 3000 * 3
            api.execute_behavior("GO_TO_POINT", coordinates=(x, 0, 3))  # HERE
            api.execute_behavior("LAND")
        ''', "WRONG_VALUE", "(9000, 0, 3)"),
    "no implementation": ('''
        def mission():
            api.execute_behavior("TAKE_OFF", altitude=3)
            name = "SPIN_" + "AROUND"  # computed: verify cannot see it, so the engine refuses it in flight
            api.execute_behavior(name)  # HERE
            api.execute_behavior("LAND")
        ''', "WRONG_FORMAT", "no implementation is registered"),
}

EXTRA_CATALOG = """
behavior_descriptors:
- behavior: SPIN_AROUND
  description: a behavior this robot has no class for
"""


def write_mission(tmp_path: Path, body: str) -> tuple[Path, int]:
    text = HEADER + textwrap.dedent(body)
    path = tmp_path / "computed.py"
    path.write_text(text)
    line = next((i for i, row in enumerate(text.splitlines(), 1) if "# HERE" in row), 0)
    return path, line


def fly(tmp_path: Path, path: Path, capsys, *extra: str) -> tuple[int, str, list[dict]]:
    out = tmp_path / "out"
    status = main(["run", str(path), "--plain", "--output", str(out), *extra])
    records = [json.loads(line) for line in (out / "events.jsonl").read_text().splitlines()]
    return status, capsys.readouterr().err, records


def catalog_with_extra(tmp_path: Path) -> Path:
    aerial = (Path(__file__).parents[2] / "catalogs" / "aerial.yaml").read_text()
    merged = aerial.replace("behavior_descriptors:\n", EXTRA_CATALOG.strip() + "\n", 1)
    assert merged != aerial
    path = tmp_path / "extra.yaml"
    path.write_text(merged)
    return path


@pytest.mark.parametrize("case", sorted(COMPUTED))
def test_a_request_verify_would_refuse_raises_in_the_mission_at_its_line(tmp_path, capsys, case):
    body, kind, named = COMPUTED[case]
    path, line = write_mission(tmp_path, body)
    extra = ("--catalog", str(catalog_with_extra(tmp_path))) if case == "no implementation" else ()
    status, err, records = fly(tmp_path, path, capsys, *extra)
    assert status == EXIT_STATUS[FAILED] == 1, err
    failed = [r for r in records if r["kind"] == "mission_failed"]
    assert len(failed) == 1 and "RequestRejected" in failed[0]["detail"] and named in failed[0]["detail"]
    assert f"computed.py:{line}" in failed[0]["detail"] and kind in failed[0]["detail"]
    rejected = [r for r in records if r["kind"] == "rejected"]
    assert rejected and rejected[0]["data"]["where"] == f"computed.py:{line}"
    assert "computed.py: failed at" in err
    ended = [r for r in records if r["kind"] == "run_ended"]
    assert [r["detail"] for r in ended] == [FAILED]
    assert not any(r["kind"] == "activated" and r.get("behavior") == "LAND" and
                   r["data"].get("source") == "mission" for r in records)  # the mission did not go on


def test_a_caught_rejection_ends_completed_with_refused_requests(tmp_path, capsys):
    path, _ = write_mission(tmp_path, '''
        def mission():
            api.execute_behavior("TAKE_OFF", altitude=3)
            try:
                api.execute_behavior("GO_TO_POINT", coordinates=(30 * 5, 0, 3))  # HERE
            except api.RequestRejected as error:
                assert error.behavior == "GO_TO_POINT" and error.kind == "WRONG_VALUE"
            api.execute_behavior("LAND")
        ''')
    status, err, records = fly(tmp_path, path, capsys)
    assert status == EXIT_STATUS[REFUSED] == 3, err
    assert "computed.py: completed with refused requests at" in err and "GO_TO_POINT" in err
    assert [r["detail"] for r in records if r["kind"] == "run_ended"] == [REFUSED]


def test_failed_preconditions_stay_a_return_value_but_the_run_says_so(tmp_path, capsys):
    path, _ = write_mission(tmp_path, '''
        def mission():
            land = "LA" + "ND"  # computed, so verify cannot see the landed drone asked to land
            assert api.execute_behavior(land) == api.FAILED_PRECONDITIONS  # refused on the ground; no raise
        ''')
    status, err, _ = fly(tmp_path, path, capsys)
    assert status == 3 and "completed with refused requests" in err and "LAND" in err


def test_a_failed_runs_summary_names_the_first_refused_request(tmp_path, capsys):
    """A mission that gives up after a refusal failed; its summary named only the failure, and the refusal that led
    to it was in the event log alone."""
    path, _ = write_mission(tmp_path, '''
        def mission():
            api.execute_behavior("TAKE_OFF", altitude=3)
            reached = api.execute_behavior("GO_TO_POINT", coordinates=(30 * 5, 0, 3))  # HERE
            api.execute_behavior("LAND")
            if reached != "GOAL_ACHIEVED":
                raise RuntimeError("the survey point is out of reach")
        ''')
    status, err, records = fly(tmp_path, path, capsys)
    assert status == EXIT_STATUS[FAILED] == 1, err
    ended = [r for r in records if r["kind"] == "run_ended"][-1]
    first = "the first request refused: GO_TO_POINT: Behavior GO_TO_POINT cannot be executed because its " \
            "preconditions are not satisfied. The destination is too far"
    assert ended["detail"] == FAILED and any(first in reason for reason in ended["data"]["reasons"])
    assert first in err.split("computed.py: failed at")[1]  # the summary's lines under its last one
