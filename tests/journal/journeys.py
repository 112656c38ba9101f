"""Flights for the journal's tests, in this process: flown until a condition, then crashed as ``kill -9`` leaves a
run's files (what was handed to the journal's thread is written, nothing more: no run_ended, no log_closed), and
resumed; the goals achieved counted from the journal."""

from __future__ import annotations

import json
import math
import os
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any

from aeroexec.flight.journal import Journal
from aeroexec.flight.run_status import FlightOutcome
from aeroexec.flight.session import FlightSession
from aeroexec.flight.spec import FlightSpec

ROOT = Path(__file__).parents[2]
MISSIONS = ROOT / "missions"
LIMIT = 600.0  # s of engine time any flight below may take


def spec(mission: Path | str, output: Path, **options: Any) -> FlightSpec:
    return FlightSpec(mission=Path(mission), output=str(output), register=False, **options)


def fly(flight: FlightSpec, **session: Any) -> tuple[FlightSession, FlightOutcome]:
    """A whole flight."""
    run = FlightSession(flight, notify=lambda text: None, **session)
    return run, run.fly()


def fly_until(flight: FlightSpec, condition: Callable[[FlightSession], bool], **session: Any) -> FlightSession:
    """A flight flown until ``condition(session)`` holds (checked every engine period), left as it is."""
    run = FlightSession(flight, notify=lambda text: None, **session).open()
    run.start_mission()
    engine = run.engine
    if not engine.run_until(lambda: condition(run) or run.mission_done, LIMIT):
        raise AssertionError("the condition never held")
    if run.mission_done:
        events = "\n".join(str(e) for e in run.engine.log.events() if not e.kind.startswith("capability"))
        raise AssertionError(f"the mission ended before the crash:\n{events}")
    return run


def crash(run: FlightSession) -> None:
    """End a flight as ``kill -9`` would: the journal keeps what it committed, the logs stop where they are."""
    run.journal.abandon()
    for writer in (run.flight_log, run.btlog):
        if writer is not None:
            fd, writer._fd = writer._fd, None
            os.close(fd)
    run.journal = run.flight_log = run.btlog = None
    run.close()


def goals_after(count: int, behavior: str | None = None) -> Callable[[FlightSession], bool]:
    """A crash point: once ``count`` goals (of ``behavior``) were achieved in this flight."""
    def reached(run: FlightSession) -> bool:
        events = run.engine.log.events("GOAL_ACHIEVED", behavior)
        return sum(e.data.get("source") == "mission" for e in events) >= count

    return reached


def active(behavior: str, seconds: float = 0.0) -> Callable[[FlightSession], bool]:
    """A crash point: ``behavior`` has been running ``seconds`` for the mission."""
    def running(run: FlightSession) -> bool:
        activation = run.engine.coordinator.active().get(behavior)
        return (activation is not None and activation.source == "mission"
                and run.engine.now() - activation.started_at >= seconds)

    return running


def resume(folder: Path, **options: Any) -> tuple[FlightSession, FlightOutcome]:
    from aeroexec.flight.journal import resume_spec

    return fly(replace(resume_spec(folder), register=False, **options))


def achieved(folder: Path) -> list[tuple[str, dict]]:
    """The mission's goals achieved, over every part of the run, in order: (behavior, arguments)."""
    with Journal(folder) as journal:
        rows = journal.rows("SELECT behavior, arguments FROM behaviors WHERE source = 'mission' AND "
                            "outcome = 'GOAL_ACHIEVED' ORDER BY ended_seq")
    return [(r["behavior"], json.loads(r["arguments"])) for r in rows]


def same_goals(resumed: list[tuple[str, dict]], whole: list[tuple[str, dict]], tolerance: float = 0.6) -> str | None:
    """Where two lists of goals differ (behaviors in order, arguments equal, numbers within ``tolerance``: a
    position the mission read from the world), or None."""
    if [b for b, _ in resumed] != [b for b, _ in whole]:
        return f"behaviors differ:\n  resumed {[b for b, _ in resumed]}\n  whole   {[b for b, _ in whole]}"
    for n, ((behavior, one), (_, other)) in enumerate(zip(resumed, whole, strict=True)):
        if not _close(one, other, tolerance):
            return f"goal {n + 1} ({behavior}): {one} != {other}"
    return None


def _close(one: Any, other: Any, tolerance: float) -> bool:
    if isinstance(one, int | float) and isinstance(other, int | float) and not isinstance(one, bool):
        return math.isclose(one, other, abs_tol=tolerance)
    if isinstance(one, dict) and isinstance(other, dict):
        return one.keys() == other.keys() and all(_close(one[k], other[k], tolerance) for k in one)
    if isinstance(one, list | tuple) and isinstance(other, list | tuple):
        return len(one) == len(other) and all(_close(a, b, tolerance) for a, b in zip(one, other, strict=True))
    return one == other


def final_state(folder: Path) -> dict[str, Any]:
    """The drone's last journaled state."""
    with Journal(folder) as journal:
        return journal.last_state()


def photos(folder: Path, behavior: str = "TAKE_PHOTO") -> int:
    """Photos taken by ``behavior`` over every part of the run (as the journal says), checked against the files."""
    with Journal(folder) as journal:
        taken = journal.rows("SELECT detail FROM events WHERE kind = 'photo_taken' AND behavior = ?", (behavior,))
    assert all(Path(r["detail"]).is_file() for r in taken)
    return len(taken)
