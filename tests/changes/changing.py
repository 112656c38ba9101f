"""A flight whose mission is changed while it flies, as the operator changes it: the flight session of ``aeroexec
run`` on the simulated drone, stepped on its simulated clock until the moment chosen, the change submitted to the
supervisor as ``aeroexec ctl`` submits it, then flown to its end; the event log read back, and the drone's path as
it flew (every engine period)."""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path
from typing import Any

from aeroexec.drones.geodesy import geo_to_enu, parse_geo
from aeroexec.flight import FlightSession, FlightSpec
from aeroexec.flight.ending import end_flight

ROOT = Path(__file__).parents[2]
MISSIONS = ROOT / "missions"
DATA = Path(__file__).with_name("data")
sys.path.insert(0, str(ROOT / "tests" / "flight"))  # runs of aeroexec in a subprocess: flight_runs.Command


class ChangedFlight:
    """One flight of ``mission``; :meth:`until` flies it to a moment, :meth:`change` changes it, :meth:`finish`
    flies it to its end."""

    def __init__(self, mission: Path, folder: Path, **spec: Any) -> None:
        self.session = FlightSession(FlightSpec(mission=mission, output=str(folder), register=False, **spec),
                                     notify=lambda text: None).open()
        self.engine = self.session.engine
        self.path: list[tuple[float, tuple[float, float, float]]] = []
        self.engine.tick_callbacks.append(self._sample)
        self.session.start_mission()
        self.outcome: Any = None

    def _sample(self) -> None:
        self.path.append((self.engine.now(), tuple(self.engine.drone.telemetry().position)))

    # -- flying ----------------------------------------------------------------------------------------------
    def until(self, condition: Any, timeout: float = 300.0) -> None:
        assert self.engine.run_until(condition, timeout), "the moment never came"

    def running(self, name: str) -> bool:
        """True while the tree node ``name`` runs."""
        return any(n.name == name and n.status.name == "RUNNING" for _, n in self.session.tree.nodes)

    def active(self, behavior: str) -> bool:
        return self.engine.coordinator.is_active(behavior)

    def change(self, command: str, argument: str = "") -> Any:
        """Submit a command as ``aeroexec ctl`` does (from another thread's point of view) and let the engine run
        it at its next tick; its result."""
        ticket = self.engine.supervisor.submit(command, argument, origin="test")
        self.engine.step(self.engine.period)
        assert ticket.result is not None, "the engine did not run the command"
        return ticket.result

    def items(self) -> list[dict]:
        return self.engine.supervisor.execute("items").data.get("items", [])

    def finish(self, timeout: float = 600.0) -> list[dict]:
        """Fly to the end of the mission, land, and read the event log back."""
        self.engine.run_until(lambda: self.session.mission_done, timeout)
        self.outcome = self.session.finish(end_flight(self.engine))
        return self.records()

    def records(self) -> list[dict]:
        text = (Path(self.session.folder) / "events.jsonl").read_text(encoding="utf-8")
        return [json.loads(line) for line in text.splitlines()]

    # -- what was flown --------------------------------------------------------------------------------------
    def closest(self, point: tuple[float, float, float], after: float = 0.0) -> float:
        """How close the drone came to ``point`` (ENU m) after engine time ``after``."""
        return min((math.dist(p, point) for t, p in self.path if t >= after), default=math.inf)

    def reached_at(self, point: tuple[float, float, float], within: float = 1.0, after: float = 0.0) -> float | None:
        """When the drone first came within ``within`` m of ``point`` after ``after`` (None: never)."""
        return next((t for t, p in self.path if t >= after and math.dist(p, point) <= within), None)

    def enu(self, geo: str) -> tuple[float, float, float]:
        """A ``geo:`` point of the plan in the world's frame (the drone's, in the simulator)."""
        return geo_to_enu(parse_geo(geo), self.session.world.home)


def changes(records: list[dict]) -> list[dict]:
    """The ``mission_change`` records: command, argument, ok, and what was said."""
    return [{"command": r["data"]["command"], "argument": r["data"]["argument"], "ok": r["data"]["ok"],
             "detail": r["detail"], "problems": r["data"].get("problems", [])}
            for r in records if r["kind"] == "mission_change"]


def statuses(records: list[dict], node: str) -> list[str]:
    """Every status a tree node went through, in order."""
    return [r["data"]["new"] for r in records if r["kind"] == "node_status" and r["data"]["node"] == node]


def ended(records: list[dict]) -> str:
    return next(r["detail"] for r in records if r["kind"] == "run_ended")
