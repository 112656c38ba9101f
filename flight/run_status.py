"""How a run ended, in one word shared by the summary line, the live view, ``--plain``, the report and the event
log, and the exit status ``aeroexec run`` returns for it.

- completed: the mission finished and every request it made was accepted (exit 0);
- completed with refused requests: the mission finished, but a request of it was refused on the way
  (FAILED_PRECONDITIONS, a rejected request the mission caught, a paused behavior the resume could not
  restart) (exit 3);
- failed: the mission raised, a tree ended in FAILURE, a task it waited for ended without its goal (Aerostack's
  ``executeTask``: ``task_failed``), or the time limit stopped it (the reasons add the first request of the
  mission refused, when there was one); or a safety rule was broken
  (its contingency took the drone over: the reasons name the rule, when, and what it did); or the vehicle had a
  fault (the link was lost in flight, the landing failed, the drone was left armed or in the air) (exit 1);
- aborted: the operator aborted the run (``ctl abort``, the ``a`` key, Ctrl-C, SIGTERM, SIGHUP) (exit 4);
- suspended: a safety reaction (a reactive behavior of the higher priority, such as LAND on low battery) took
  the drone over before the mission finished, and the mission could not do all it asked, or the operator
  suspended it (``aeroexec ctl suspend``) (exit 5); the reasons name the reaction and when (``LAND on low battery
  at t=95.2 s``). ``aeroexec run --resume`` goes on from there.

A resumed run's log goes on after the interrupted run's: its status is that of its last part (from the last
``log_resumed`` line).

Whatever the word, a run whose event log or journal could not be written whole, or whose photos could not all be
saved (a full disk) exits 6 unless it failed or was aborted: its record is incomplete (:data:`LOG_INCOMPLETE`).
The exit status is decided once, before the run's end is recorded: ``run_ended`` states it, the summary's last line
says it, the process returns it.

A flight's :class:`FlightOutcome` is its status (:func:`flight_status`: a suspended tree says how many of its goals
were not reached) with the vehicle's faults and whether its event log is whole.
"""

from __future__ import annotations

from collections.abc import Collection, Iterable
from dataclasses import dataclass, field
from pathlib import Path

from aeroexec.engine.events import EngineEvent
from aeroexec.flight.flight_log import event_record

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

COMPLETED = "completed"
REFUSED = "completed with refused requests"
FAILED = "failed"
ABORTED = "aborted"
SUSPENDED = "suspended"
#: The exit status of ``aeroexec run`` for each way a run ends.
EXIT_STATUS = {COMPLETED: 0, FAILED: 1, REFUSED: 3, ABORTED: 4, SUSPENDED: 5}
#: The exit status of a run whose event log is incomplete (unless it failed or was aborted).
LOG_INCOMPLETE = 6
#: The event that records the run's end (its ``detail`` is the word) in the event log.
RUN_ENDED = "run_ended"
#: Event kinds that are a request of the mission refused (with ``source`` mission).
REFUSAL_KINDS = ("failed_preconditions", "rejected")
#: Event kinds that make a run fail (the mission raised or its tree failed, the time limit stopped it, a task it
#: waited for ended without its goal: Aerostack's executeTask).
FAILURE_KINDS = ("mission_failed", "engine_time_limit", "task_failed")
#: Event kinds that are a safety rule broken (or a ``within`` obligation opened), its contingency taken.
SAFETY_KINDS = ("safety_violated", "safety_triggered")
#: The operator suspended the mission (``ctl suspend``): the event says where (``mission_stopped``, data ``suspend``).
SUSPENSION = "mission_suspended"
#: A safety reaction: a reactive behavior of the higher priority, which takes the drone over (``reactive``).
REACTION = "reactive"
HIGHER = "higher priority"
#: Plain words for what a reaction's condition watches, by the predicate it reads.
WATCHED = {"charge": "on low battery", "link": "on link loss", "wind": "in strong wind"}


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


def last_part(records: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The records of a log's last part: from its last ``log_resumed`` line (a resumed run), else all."""
    start = max((i for i, r in enumerate(records) if r.get("kind") == "log_resumed"), default=0)
    return records[start:]


def run_status(events: Iterable[dict[str, Any] | EngineEvent]) -> RunStatus:
    """The status of a run from its events (engine events, or the records of an event log)."""
    records = last_part([_record(e) for e in events])
    for record in records:  # a log that already says how it ended
        if record.get("kind") == RUN_ENDED and record.get("detail") in EXIT_STATUS:
            return RunStatus(record["detail"], list((record.get("data") or {}).get("reasons", [])))
    suspended = [r.get("detail", "") for r in records if r.get("kind") == SUSPENSION]
    if suspended:
        return RunStatus(SUSPENDED, suspended)
    aborted = [r.get("detail", "") for r in records if r.get("kind") == "operator_interrupt" or (
        r.get("kind") == "operator_command" and (r.get("data") or {}).get("command") == "abort"
        and (r.get("data") or {}).get("ok"))]
    if aborted:
        return RunStatus(ABORTED, aborted)
    failed = [r.get("detail", "") for r in records if r.get("kind") in FAILURE_KINDS]
    broken = [safety_reason(r) for r in records if r.get("kind") in SAFETY_KINDS]
    if broken:  # the run did not do what was asked: a contingency took the drone over
        return RunStatus(FAILED, broken + failed)
    refused = [f"{r.get('behavior', '')}: {r.get('detail', '')}" for r in records
               if r.get("kind") in REFUSAL_KINDS and (r.get("data") or {}).get("source") == "mission"]
    completed = any(r.get("kind") == "mission_completed" for r in records)
    reaction = safety_reaction(records)
    if reaction is not None and (failed or refused or not completed):
        cut = len(refused) + len(failed)
        return RunStatus(SUSPENDED, [reaction] + ([f"{cut} request{'s' if cut != 1 else ''} of the mission "
                                                   f"refused or failed after it"] if cut else []))
    if failed or not completed:
        return RunStatus(FAILED, (failed or ["the mission did not finish"]) + _first_refused(records, failed))
    return RunStatus(REFUSED, refused) if refused else RunStatus(COMPLETED)


def _first_refused(records: list[dict[str, Any]], failed: list[str]) -> list[str]:
    """A failed run's first refused request of the mission, as a reason (the failure often follows from it: a
    script that exits when a request was refused), unless a failure's reason already says it."""
    first = next((r for r in records if r.get("kind") in REFUSAL_KINDS
                  and (r.get("data") or {}).get("source") == "mission"), None)
    if first is None or any(str(first.get("detail", "")) in reason for reason in failed):
        return []
    return [f"the first request refused: {first.get('behavior', '')}: {first.get('detail', '')}"]


def safety_reason(record: dict[str, Any]) -> str:
    """A safety rule's violation (or ``within`` trigger) in words: ``safety rule fence broken at t=12.3 s: hold
    (holding at (18.9, 0.0, 5.0))``."""
    data = record.get("data") or {}
    what = "triggered" if record.get("kind") == "safety_triggered" else "broken"
    action = f" ({data['action']})" if data.get("action") else ""
    return (f"safety rule {data.get('rule', '?')} {what} at t={float(record.get('time', 0.0)):.1f} s: "
            f"{data.get('contingency', '')}{action}")


def safety_reaction(records: list[dict[str, Any]]) -> str | None:
    """The first reaction of the higher priority while the mission ran, in words (``LAND on low battery at
    t=95.2 s (charge(battery, ?X), less_than(?X, 10))``), or None."""
    ended = ("mission_completed", "mission_failed")
    for record in records:
        if record.get("kind") in ended:
            return None
        if record.get("kind") == REACTION and HIGHER in str(record.get("detail", "")):
            condition = str(record.get("detail", "")).partition(": ")[2]
            words = next((w for name, w in WATCHED.items() if f"{name}(" in condition), "by reaction")
            return (f"{record.get('behavior', '')} {words} at t={float(record.get('time', 0.0)):.1f} s"
                    + (f" ({condition})" if condition else ""))
    return None


def exit_status(status: RunStatus, log_incomplete: bool = False) -> int:
    """The exit status of a run that ended with ``status`` (:data:`LOG_INCOMPLETE` when its event log could not
    be written whole and it neither failed nor was aborted)."""
    if log_incomplete and status.word not in (FAILED, ABORTED):
        return LOG_INCOMPLETE
    return status.exit_status


def record_run_status(log: Any, status: RunStatus, code: int | None = None) -> None:
    """Write the run's end to the event log (``run_ended``, detail the word, and the exit status ``code`` the
    process returns: by default the word's)."""
    log.record(RUN_ENDED, detail=status.word, exit_status=status.exit_status if code is None else code,
               reasons=list(status.reasons))


@dataclass
class FlightOutcome:
    """How a flight ended: its status (the word and why), the vehicle's faults, whether the event log is whole,
    and the exit status ``aeroexec run`` returns for it."""

    status: RunStatus
    faults: list[str] = field(default_factory=list)
    log_incomplete: str | None = None  # why the event log stopped short (a full disk), None when whole
    folder: Path | None = None
    photos_not_saved: str | None = None  # why photos could not be saved (a full disk), None when all were
    recorded: int | None = None  # the exit status ``run_ended`` states, when the event log holds it

    @property
    def exit_status(self) -> int:
        if self.recorded is not None:
            return self.recorded
        return exit_status(self.status, self.log_incomplete is not None or self.photos_not_saved is not None)


def flight_status(log: Any, faults: list[str], tree: Any = None, catalog: Any = None,
                  reached_before: Collection[int] = ()) -> RunStatus:
    """How a flight ended: failed by the vehicle's ``faults``, else as its event ``log`` says; a suspended tree's
    reason says how many of its goals were not reached (``reached_before``: those a resumed run's earlier parts
    reached)."""
    status = RunStatus(FAILED, faults) if faults else run_status(log.events())
    if status.word == SUSPENDED and tree is not None:
        reached = {e.data.get("uid") for e in log.events("node_status") if e.data.get("new") == "SUCCESS"}
        reached |= set(reached_before)
        left, total = goals_left(tree, catalog, reached)
        status = RunStatus(SUSPENDED, [f"{status.reasons[0]}; {left} of {total} goals not reached"])
    return status


def goals_left(tree: Any, catalog: Any, reached: Collection[int] = ()) -> tuple[int, int]:
    """How many of a tree's behavior leaves did not reach their goal, of how many (``reached``: the places, from 1,
    of the nodes that succeeded before, though a halt has reset them since)."""
    leaves = [(uid, node) for uid, (_, node) in enumerate(tree.nodes, 1) if _behavior_of(node) in catalog]
    done = sum(node.status.name == "SUCCESS" or uid in reached for uid, node in leaves)
    return len(leaves) - done, len(leaves)


def _behavior_of(node: Any) -> str:
    from aeroexec.trees.runtime.builder import model_of

    model = model_of(node)
    return getattr(model, "type", "") if model is not None else ""


__all__ = ["ABORTED", "COMPLETED", "EXIT_STATUS", "FAILED", "FAILURE_KINDS", "LOG_INCOMPLETE", "REFUSAL_KINDS",
           "REFUSED", "SAFETY_KINDS", "SUSPENDED", "SUSPENSION", "FlightOutcome", "RunStatus", "exit_status",
           "flight_status", "goals_left", "last_part", "record_run_status", "run_status", "safety_reaction",
           "safety_reason"]
