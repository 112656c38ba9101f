"""What an event log says about a run: the path flown, each behavior's activation span and outcome, the beliefs'
spans, failures with their reasons, duration, distance flown and battery used (for ``aeroexec report``).

It reads the records of :mod:`aeroexec.flight.flight_log` and knows nothing of drawing.
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass, field
from typing import Any

from aeroexec.engine.events import Outcome
from aeroexec.engine.safety.compliance import Compliance, compliance
from aeroexec.flight.run_status import last_part, run_status

OUTCOMES = {o.value for o in Outcome}
#: Event kinds that are failures worth an operator's attention (INTERRUPTED is how behaviors normally make way).
FAILURE_KINDS = {"TIME_OUT", "WRONG_PROGRESS", "failed_preconditions", "rejected", "mission_failed",
                 "process_failed", "engine_time_limit", "operator_interrupt"}
Point = tuple[float, float, float]


@dataclass
class BehaviorSpan:
    """One activation of a behavior: from ``activated`` to the event that ended it (``RUNNING`` if none did)."""

    behavior: str
    start: float
    end: float
    outcome: str = "RUNNING"
    reason: str = ""
    arguments: dict[str, Any] = field(default_factory=dict)
    source: str = ""
    start_position: Point | None = None
    end_position: Point | None = None


@dataclass
class BeliefSpan:
    """A belief held from ``start`` to ``end`` (the end of the log when it was never removed)."""

    belief: str
    start: float
    end: float
    removed: bool = False

    @property
    def predicate(self) -> str:
        return self.belief.split("(", 1)[0].strip()


@dataclass
class Failure:
    time: float
    kind: str
    behavior: str
    reason: str


@dataclass
class MissionChangeRecord:
    """A change of the running mission the operator asked for: taken (what it did) or refused (why)."""

    time: float
    command: str
    argument: str
    origin: str
    taken: bool
    said: str  # what it did, or why it was refused
    problems: list[str] = field(default_factory=list)


@dataclass
class FlightSummary:
    """The report's numbers and spans, from one event log."""

    meta: dict[str, Any]
    samples: list[dict[str, Any]]
    behaviors: list[BehaviorSpan]
    beliefs: list[BeliefSpan]
    failures: list[Failure]
    start: float
    end: float
    outcome: str  # the run's status word (run_status), or incomplete (the log ends without log_closed: a crash)
    refusals: list[Failure] = field(default_factory=list)  # requests refused before they started
    flight_states: list[tuple[float, str]] = field(default_factory=list)  # (time, state) at each change
    safety: list[Compliance] = field(default_factory=list)  # each safety rule watched: held or violated, when
    changes: list[MissionChangeRecord] = field(default_factory=list)  # the mission changed while it flew

    @property
    def duration(self) -> float:
        return self.end - self.start

    @property
    def path(self) -> list[Point]:
        return [tuple(s["position"]) for s in self.samples]  # type: ignore[misc]

    @property
    def distance(self) -> float:
        """Meters flown, along the sampled path."""
        points = self.path
        return sum(math.dist(a, b) for a, b in zip(points, points[1:], strict=False))

    @property
    def battery_used(self) -> float | None:
        """Percentage points of battery used between the first and the last sample."""
        if not self.samples:
            return None
        return round(self.samples[0]["battery"] - self.samples[-1]["battery"], 2)

    def outcome_counts(self) -> dict[str, dict[str, int]]:
        """behavior -> outcome -> how many times; requests refused before starting count as FAILED_PRECONDITIONS."""
        counts: dict[str, dict[str, int]] = {}
        for behavior, outcome in [*((s.behavior, s.outcome) for s in self.behaviors),
                                  *((r.behavior, Outcome.FAILED_PRECONDITIONS.value) for r in self.refusals)]:
            per = counts.setdefault(behavior, {})
            per[outcome] = per.get(outcome, 0) + 1
        return counts

    def series(self) -> dict[str, list[float]]:
        """The drone's samples as series: time, altitude (m), speed (m/s), battery (%)."""
        return {"time": [float(s["time"]) for s in self.samples],
                "altitude": [float(s["position"][2]) for s in self.samples],
                "speed": [math.hypot(*s["velocity"]) if s.get("velocity") else 0.0 for s in self.samples],
                "battery": [float(s["battery"]) for s in self.samples]}

    def homeward_sample(self) -> int:
        """The index of the sample where the way home begins: the last sample after which the drone only came
        nearer home (a survey's last transect end, an out-and-back's far point). Wobbles of a hover or a noisy
        estimate, smaller than 2 m or 0.5 % of the distance, do not end the way home."""
        if not self.samples:
            return 0
        distances = [math.hypot(p[0], p[1]) for p in self.path]
        turn = farthest = len(distances) - 1
        for i in range(len(distances) - 1, -1, -1):  # backwards from the end, the distance grows along the way home
            if distances[i] >= distances[farthest]:
                farthest = turn = i
            elif distances[i] < distances[farthest] - max(2.0, 0.005 * distances[farthest]):
                break
        return turn

    def position_at(self, t: float) -> Point | None:
        """The drone's position at ``t``, interpolated between the state samples."""
        if not self.samples:
            return None
        i = bisect.bisect_left([s["time"] for s in self.samples], t)
        if i == 0 or i == len(self.samples):
            return tuple(self.samples[min(i, len(self.samples) - 1)]["position"])  # type: ignore[return-value]
        before, after = self.samples[i - 1], self.samples[i]
        w = (t - before["time"]) / (after["time"] - before["time"]) if after["time"] > before["time"] else 1.0
        return tuple(a + w * (b - a) for a, b in zip(before["position"], after["position"], strict=True))


def summarize(records: list[dict[str, Any]]) -> FlightSummary:
    """The summary of a log's records (as :func:`~.flight_log.read_flight_log` returns them)."""
    meta = next((r for r in records if r.get("kind") == "log_started"), {})
    samples = [r for r in records if r.get("kind") == "state" and r.get("position")]
    times = [float(r["time"]) for r in records if isinstance(r.get("time"), int | float)]
    start, end = (min(times), max(times)) if times else (0.0, 0.0)
    open_spans: dict[str, BehaviorSpan] = {}
    spans: list[BehaviorSpan] = []
    held: dict[str, float] = {}
    beliefs: list[BeliefSpan] = []
    failures: list[Failure] = []
    refusals: list[Failure] = []
    flight_states: list[tuple[float, str]] = []
    changes: list[MissionChangeRecord] = []
    for record in records:
        kind, t, behavior = record.get("kind", ""), float(record.get("time", 0.0)), record.get("behavior", "")
        if kind == "activated":
            data = record.get("data", {})
            span = BehaviorSpan(behavior, t, end, arguments=dict(record.get("arguments") or {}),
                                source=str(data.get("source", "")))
            open_spans[behavior] = span
            spans.append(span)
        elif kind in OUTCOMES and behavior in open_spans:
            span = open_spans.pop(behavior)
            span.end, span.outcome, span.reason = t, kind, record.get("reason", record.get("detail", ""))
        elif kind == "belief_added":
            held.setdefault(record["belief"], t)
        elif kind == "belief_removed" and record["belief"] in held:
            beliefs.append(BeliefSpan(record["belief"], held.pop(record["belief"]), t, removed=True))
        if kind in FAILURE_KINDS:
            failures.append(Failure(t, kind, behavior, record.get("reason", record.get("detail", ""))))
        if kind in ("failed_preconditions", "rejected") and behavior:
            refusals.append(Failure(t, kind, behavior, record.get("reason", record.get("detail", ""))))
        if kind == "belief_added" and str(record.get("belief", "")).startswith("flight_state(self,"):
            flight_states.append((t, record["belief"].split(",", 1)[1].strip(" )")))
        if kind == "mission_change":
            changes.append(_change(record, t))
    outcome = run_status(records).word
    beliefs.extend(BeliefSpan(b, t, end) for b, t in held.items())
    beliefs.sort(key=lambda b: (b.start, b.belief))
    if not any(r.get("kind") == "log_closed" for r in last_part(records)):
        outcome = "incomplete"
    summary = FlightSummary(meta, samples, spans, beliefs, failures, start, end, outcome, refusals, flight_states,
                            compliance(records), changes)
    for span in spans:
        span.start_position, span.end_position = summary.position_at(span.start), summary.position_at(span.end)
    return summary


def _change(record: dict[str, Any], t: float) -> MissionChangeRecord:
    data = record.get("data") or {}
    said = str(record.get("detail", "")).partition(": ")[2]
    taken = bool(data.get("ok"))
    return MissionChangeRecord(t, str(data.get("command", "")), str(data.get("argument", "")),
                               str(data.get("origin", "")), taken, said.removeprefix("refused: "),
                               [str(p) for p in data.get("problems") or []])


def final_beliefs(records: list[dict[str, Any]]) -> list[str]:
    """The beliefs held at the end of a log, in the order they were added."""
    held: dict[str, None] = {}
    for record in records:
        if record.get("kind") == "belief_added":
            held[record["belief"]] = None
        elif record.get("kind") == "belief_removed":
            held.pop(record["belief"], None)
    return list(held)
