"""A fleet in one process: every drone's engine in one world, ticked in lockstep on one simulated time, each
with its own mission (Python or behavior tree), all linked over one Zenoh session.

The loop ticks every engine, serves every Python mission until it waits, then moves time one period on (paced
to ``speed`` times real time when given). A drone whose mission ended lands; the run ends when every drone
is done and on the ground, or at ``max_time``.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from aeroexec.drones.sim import Airspace, SimConfig, SimulatedDrone
from aeroexec.engine.clock import SimulatedClock
from aeroexec.engine.engine import Engine
from aeroexec.engine.missions.bridge import DONE, RUNNING
from aeroexec.engine.supervision.flight_log import FlightLogWriter
from aeroexec.engine.supervision.supervisor import LAND_BEHAVIOR, is_flying, start_landing
from aeroexec.fleet.fleet_file import DroneSpec
from aeroexec.fleet.link import FleetLink
from aeroexec.fleet.node import FleetNode
from aeroexec.trees import TreeDocument
from aeroexec.trees.runtime.runner import TreeMission

logger = logging.getLogger(__name__)

RATE = 20.0  # Hz, as a single engine
LANDING_TIME = 180.0  # engine seconds a drone is given to land after its mission
HAND_OVER = 0.0002  # wall seconds between two looks at missions still computing
STALL_WARNING = 30.0  # wall seconds of missions computing before saying so


@dataclass
class Member:
    """One drone of the run: its engine, link, mission and how it ended."""

    spec: DroneSpec
    engine: Engine
    link: FleetLink
    mission: Callable[[], Any] | TreeDocument
    tree: TreeMission | None = None
    flight_log: FlightLogWriter | None = None
    ended_at: float | None = None  # engine time the mission ended
    landed: bool = False
    extra: dict[str, Any] = field(default_factory=dict)

    @property
    def name(self) -> str:
        return self.spec.name

    def mission_done(self) -> bool:
        return self.tree.done if self.tree is not None else self.engine.bridge.state == DONE

    def outcome(self) -> str:
        log = self.engine.log
        if log.events(kind="mission_failed"):
            return "failed"
        return "completed" if log.events(kind="mission_completed") else "stopped"


class FleetRun:
    """The drones of ``node``'s fleet flying ``missions`` (by drone name) in ``world`` on one simulated clock."""

    def __init__(self, node: FleetNode, drones: list[DroneSpec], missions: dict[str, Any], *, world: Any,
                 catalog: Any = None, speed: float | None = None, output: Path | None = None,
                 telemetry_rate: float = 5.0, operator: Callable[[], Any] | None = None) -> None:
        self.node, self.world, self.speed = node, world, speed
        self.airspace = Airspace()
        self.members: list[Member] = []
        self.clock = SimulatedClock()
        self.period = 1.0 / RATE
        self._stop = threading.Event()
        self._closed = False
        for spec in drones:
            drone = SimulatedDrone(world, seed=spec.seed, config=SimConfig(start=spec.home))
            drone.join(self.airspace, spec.name)
            folder = output / spec.name if output is not None else None
            if folder is not None:
                folder.mkdir(parents=True, exist_ok=True)
            engine = Engine(drone, catalog=catalog, clock=SimulatedClock(), rate=RATE, obstacles=world,
                            operator=operator() if operator else None, output_dir=folder)
            link = FleetLink(node, spec.name, engine, spec.share, telemetry_rate).join()
            link.mission = spec.mission.name
            member = Member(spec, engine, link, missions[spec.name])
            if folder is not None:
                member.flight_log = FlightLogWriter(engine, folder / "events.jsonl",
                                                    meta={"mission": str(spec.mission), "drone": spec.name,
                                                          "fleet": node.fleet, "seed": spec.seed})
            self.members.append(member)

    @property
    def engines(self) -> dict[str, Engine]:
        """The engines by drone name (for a console that shows several)."""
        return {m.name: m.engine for m in self.members}

    def stop(self) -> None:
        """End the run at the next period (another thread, or a signal handler)."""
        self._stop.set()

    def run(self, max_time: float = 1800.0) -> dict[str, str]:
        """Fly every mission; the outcome of each drone (completed, failed or stopped)."""
        for m in self.members:
            if isinstance(m.mission, TreeDocument):
                m.tree = TreeMission(m.mission, m.engine, name=m.spec.mission.name)
                m.tree.start()
            else:
                m.engine.start_mission(m.mission, m.spec.mission.name)
        wall0, end = time.monotonic(), max_time
        try:
            while not self._stop.is_set() and not all(m.landed for m in self.members):
                now = self.clock.now()
                if now >= end:
                    for m in self.members:
                        if not m.mission_done():
                            m.engine.log.record("engine_time_limit", detail=f"{max_time:g} s of engine time")
                            self._halt(m, "time limit")
                    break
                self._period(now)
                deadline = now + self.period
                if self.speed is not None:
                    delay = wall0 + deadline / self.speed - time.monotonic()
                    if delay > 0:
                        self._stop.wait(delay)
                self.clock.sleep_until(deadline)
                for m in self.members:
                    m.engine.clock.sleep_until(deadline)
        finally:
            self.close()
        return {m.name: m.outcome() for m in self.members}

    def _period(self, now: float) -> None:
        for m in self.members:
            m.engine.tick()  # a landed drone is still heard (telemetry) and still hears
        self._serve([m for m in self.members if not m.landed])
        for m in self.members:
            if m.landed:
                continue
            if m.mission_done():
                if m.ended_at is None:
                    m.ended_at = now
                    m.engine.bridge.close()
                    if is_flying(m.engine):
                        start_landing(m.engine, "the mission ended with the drone in the air")
                landing = m.engine.coordinator.is_active(LAND_BEHAVIOR)
                if not landing and not is_flying(m.engine) or now - m.ended_at > LANDING_TIME:
                    m.landed = True
                    m.link.state = m.outcome()

    def _serve(self, members: list[Member]) -> None:
        """Serve every Python mission until each waits on its engine (lockstep, as ``Engine.step``); the
        mission threads run side by side meanwhile, so N missions cost about one hand-over, not N."""
        waiting = members
        warned_at = time.monotonic() + STALL_WARNING
        while waiting:
            busy = []
            for m in waiting:
                m.engine.bridge.serve(lockstep=False)  # what is queued now; returns when the queue is empty
                if m.engine.bridge.state == RUNNING and not m.engine.supervisor.paused and not m.engine.stopped:
                    busy.append(m)
            waiting = busy
            if waiting:
                time.sleep(HAND_OVER)
                if time.monotonic() > warned_at:
                    logger.warning("the missions of %s have been busy for %.0f s of wall time without calling "
                                   "their engines; simulated time waits for them",
                                   ", ".join(m.name for m in waiting), STALL_WARNING)
                    warned_at = time.monotonic() + STALL_WARNING

    def _halt(self, m: Member, reason: str) -> None:
        if m.tree is not None:
            m.tree.halt(reason)
        m.engine.bridge.close()

    def close(self) -> None:
        """Halt what still runs, stop every engine and drone (again: nothing happens)."""
        if self._closed:
            return
        self._closed = True
        for m in self.members:
            if not m.mission_done():
                self._halt(m, "fleet stopped")
            m.link.leave()
            m.engine.stop()
            if m.flight_log is not None:
                m.flight_log.close()
            m.engine.drone.close()
