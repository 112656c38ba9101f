"""What a fleet tells of its flights: each drone's events as lines prefixed by its name, how each flight ended (a
summary line), ``fleet_status.json`` in the fleet's output folder (the fleet's status, its exit status and each
drone's), and the fleet's exit status."""

from __future__ import annotations

import json
import logging
from collections.abc import Mapping
from pathlib import Path
from typing import Any

logger = logging.getLogger(__name__)

STATUS_FILE = "fleet_status.json"  # how the fleet and each drone ended, in the fleet's output folder


def event_line(drone: str, event: Any) -> str | None:
    """The line that shows ``drone``'s event (None for a node's status: the views show those)."""
    return None if event.kind == "node_status" else f"{drone:>4} | {event}"


def drone_status(outcome: Any) -> dict[str, Any]:
    """One drone's record of :data:`STATUS_FILE`, from its :class:`~aeroexec.flight.run_status.FlightOutcome`."""
    return {"status": outcome.status.word, "reasons": outcome.status.reasons, "faults": outcome.faults,
            "exit_status": outcome.exit_status, "log_incomplete": outcome.log_incomplete}


def summary_line(member: Any, outcome: Any) -> str:
    """The line that says how one drone's flight ended (:class:`~aeroexec.flight.fleet.fleet_flight.Member`)."""
    from aeroexec.engine.events import Outcome
    from aeroexec.engine.supervision.supervisor import is_flying

    engine = member.engine
    t = engine.drone.telemetry()
    goals = sum(e.kind == Outcome.GOAL_ACHIEVED.value for e in engine.log.events())
    silent = sorted(member.link.silent)
    why = f" ({'; '.join(outcome.faults or outcome.status.reasons[:1])})" if outcome.exit_status else ""
    return (f"{member.name}: {member.session.spec.name} {outcome.status.word}{why} at t={engine.now():.1f} s, "
            f"{goals} goal{'' if goals == 1 else 's'} achieved, {'in the air' if is_flying(engine) else 'landed'} at "
            f"({t.position[0]:.1f}, {t.position[1]:.1f}), battery {t.battery_percent:.0f} %"
            + (f"; silent: {', '.join(silent)}" if silent else ""))


def fleet_exit_status(drones: Mapping[str, Mapping[str, Any]]) -> int:
    """The fleet's exit status from its drones' records: 0 when every drone's flight completed (exit status 0),
    else 1; each drone's own status is in its log, its summary line and :data:`STATUS_FILE`."""
    return 0 if drones and all(d["exit_status"] == 0 for d in drones.values()) else 1


def write_status(output: Path, fleet: str, drones: Mapping[str, Mapping[str, Any]],
                 extra: Mapping[str, Any] | None = None) -> None:
    """Write :data:`STATUS_FILE` of ``fleet`` in ``output``: its drones' records (:func:`drone_status`) and
    ``extra`` (how it was flown)."""
    words = sorted({d["status"] for d in drones.values()})
    record = {"fleet": fleet, "status": words[0] if len(words) == 1 else "mixed",
              "exit_status": fleet_exit_status(drones), **(extra or {}), "drones": dict(drones)}
    try:
        (Path(output) / STATUS_FILE).write_text(json.dumps(record, indent=2) + "\n", encoding="utf-8")
    except OSError as error:
        logger.error("%s cannot be written: %s", Path(output) / STATUS_FILE, error.strerror or error)


__all__ = ["STATUS_FILE", "drone_status", "event_line", "fleet_exit_status", "summary_line", "write_status"]
