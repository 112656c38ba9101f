"""How a run ended, in one word shared by the summary line, the live view, ``--plain``, the report and the event
log, and the exit status ``aeroexec run`` returns for it.

- completed: the mission finished and every request it made was accepted (exit 0);
- completed with refused requests: the mission finished, but a request of it was refused on the way
  (FAILED_PRECONDITIONS, a rejected request the mission caught, a paused behavior the resume could not
  restart) (exit 3);
- failed: the mission raised, a tree ended in FAILURE, or the time limit stopped it (exit 1);
- aborted: the operator aborted the run (``ctl abort``, the ``a`` key, Ctrl-C) (exit 4).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any

from aeroexec.engine.events import EngineEvent
from aeroexec.engine.supervision.flight_log import event_record

COMPLETED = "completed"
REFUSED = "completed with refused requests"
FAILED = "failed"
ABORTED = "aborted"
#: The exit status of ``aeroexec run`` for each way a run ends.
EXIT_STATUS = {COMPLETED: 0, FAILED: 1, REFUSED: 3, ABORTED: 4}
#: The event that records the run's end (its ``detail`` is the word) in the event log.
RUN_ENDED = "run_ended"
#: Event kinds that are a request of the mission refused (with ``source`` mission).
REFUSAL_KINDS = ("failed_preconditions", "rejected")
#: Event kinds that make a run fail (the mission raised or its tree failed, the time limit stopped it).
FAILURE_KINDS = ("mission_failed", "engine_time_limit")


@dataclass(frozen=True)
class RunStatus:
    """How a run ended: the word, the exit status, and why (the refusals or the failure)."""

    word: str
    reasons: list[str] = field(default_factory=list)

    @property
    def exit_status(self) -> int:
        return EXIT_STATUS[self.word]

    def __str__(self) -> str:
        return self.word


def _record(item: dict[str, Any] | EngineEvent) -> dict[str, Any]:
    return event_record(item) if isinstance(item, EngineEvent) else item


def run_status(events: Iterable[dict[str, Any] | EngineEvent]) -> RunStatus:
    """The status of a run from its events (engine events, or the records of an event log)."""
    records = [_record(e) for e in events]
    for record in records:  # a log that already says how it ended
        if record.get("kind") == RUN_ENDED and record.get("detail") in EXIT_STATUS:
            return RunStatus(record["detail"], list((record.get("data") or {}).get("reasons", [])))
    aborted = [r.get("detail", "") for r in records if r.get("kind") == "operator_interrupt" or (
        r.get("kind") == "operator_command" and (r.get("data") or {}).get("command") == "abort"
        and (r.get("data") or {}).get("ok"))]
    if aborted:
        return RunStatus(ABORTED, aborted)
    failed = [r.get("detail", "") for r in records if r.get("kind") in FAILURE_KINDS]
    if failed or not any(r.get("kind") == "mission_completed" for r in records):
        return RunStatus(FAILED, failed or ["the mission did not finish"])
    refused = [f"{r.get('behavior', '')}: {r.get('detail', '')}" for r in records
               if r.get("kind") in REFUSAL_KINDS and (r.get("data") or {}).get("source") == "mission"]
    return RunStatus(REFUSED, refused) if refused else RunStatus(COMPLETED)


def record_run_status(log: Any, status: RunStatus) -> None:
    """Write the run's end to the event log (``run_ended``, detail the word)."""
    log.record(RUN_ENDED, detail=status.word, exit_status=status.exit_status, reasons=list(status.reasons))


__all__ = ["ABORTED", "COMPLETED", "EXIT_STATUS", "FAILED", "FAILURE_KINDS", "REFUSAL_KINDS", "REFUSED", "RunStatus",
           "record_run_status", "run_status"]
