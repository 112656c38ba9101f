"""What the console shows of one engine, taken as plain JSON-ready data on the engine's thread.

A :class:`ConsoleFeed` subscribes to an engine's events and takes a snapshot a few times a wall second (a tick
callback); each snapshot, with the events since the last one, goes to the feed's sinks. The engine's thread only
copies plain data; the web server's thread sends it, so the console never slows a tick.
"""

from __future__ import annotations

import contextlib
import linecache
import os
import sys
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from aeroexec.engine.supervision.operator import operator_of

SNAPSHOT_PERIOD = 0.2  # wall seconds between two snapshots
MAX_BELIEFS = 400  # beliefs sent per snapshot (the rest are counted)
MAX_EVENTS = 200  # events kept for a page that connects late
PRIORITIES = {2: "higher", 1: "deliberative", 0: "lower"}

Sink = Callable[[dict[str, Any]], None]


def mission_line(mission_file: str) -> str | None:
    """``file.py:LINE  code`` where the Python mission is now: the innermost frame of any thread in that file."""
    for frame in sys._current_frames().values():
        found = None
        while frame is not None:
            if frame.f_code.co_filename == mission_file or \
                    os.path.abspath(frame.f_code.co_filename) == mission_file:
                found = frame
                break
            frame = frame.f_back
        if found is not None:
            code = linecache.getline(mission_file, found.f_lineno).strip()
            return f"{Path(mission_file).name}:{found.f_lineno}  {code}  (in {found.f_code.co_name})"
    return None


def event_data(event: Any) -> dict[str, Any]:
    """An engine event as JSON-ready data."""
    data = {k: v if isinstance(v, str | int | float | bool) or v is None else str(v)
            for k, v in event.data.items()}
    return {"time": round(event.time, 3), "kind": event.kind, "behavior": event.behavior, "detail": event.detail,
            "data": data}


def _point(value: Any) -> list[float] | None:
    try:
        x, y, *rest = value
        return [round(float(x), 2), round(float(y), 2), round(float(rest[0]) if rest else 0.0, 2)]
    except (TypeError, ValueError):
        return None


class ConsoleFeed:
    """Snapshots and events of one engine (a drone named ``name``) for the console's pages."""

    def __init__(self, engine: Any, name: str, mission_file: str | Path | None = None) -> None:
        self.engine, self.name = engine, name
        self.mission_file = str(Path(mission_file).resolve()) if mission_file is not None else None
        self.tree: Any = None
        self._sinks: list[Sink] = []
        self._lock = threading.Lock()
        self._pending: list[dict[str, Any]] = []
        self.recent: list[dict[str, Any]] = []  # for a page that connects late
        self.latest: dict[str, Any] | None = None
        self._taken_at = 0.0
        self._unsubscribe = engine.log.subscribe(self._on_event)
        engine.tick_callbacks.append(self._tick)

    def subscribe(self, sink: Sink) -> Callable[[], None]:
        """Call ``sink(message)`` (from the engine's thread) for every snapshot from now on."""
        with self._lock:
            self._sinks.append(sink)
        return lambda: self._sinks.remove(sink) if sink in self._sinks else None

    # -- on the engine's thread ---------------------------------------------------------------------
    def _on_event(self, event: Any) -> None:
        data = event_data(event)
        with self._lock:
            self._pending.append(data)
            self.recent.append(data)
            del self.recent[:-MAX_EVENTS]

    def _tick(self) -> None:
        if time.monotonic() - self._taken_at >= SNAPSHOT_PERIOD:
            self.publish()

    def publish(self) -> None:
        """Take a snapshot now and send it with the events since the last one (engine thread, or loop stopped)."""
        self._taken_at = time.monotonic()
        snapshot = self.snapshot()
        with self._lock:
            events, self._pending = self._pending, []
            self.latest = snapshot
            sinks = list(self._sinks)
        message = {"type": "update", "drone": self.name, "snapshot": snapshot, "events": events}
        for sink in sinks:
            sink(message)

    def snapshot(self) -> dict[str, Any]:
        engine = self.engine
        now = engine.now()
        t = engine.drone.telemetry()
        active = []
        for a in sorted(engine.coordinator.active().values(), key=lambda a: a.order):
            path = getattr(a.process, "route", None) or getattr(a.process, "points", None) or []
            active.append({"name": a.name, "priority": PRIORITIES.get(a.priority, "?"), "source": a.source,
                           "elapsed": round(now - a.started_at, 1),
                           "left": round(a.started_at + a.timeout - now, 1) if a.timeout else None,
                           "path": [p for p in (_point(q) for q in path) if p is not None]})
        beliefs = sorted(str(b) for b in engine.memory.beliefs())
        questions = [{"question": p.question, "answers": list(p.answers)}
                     for p in operator_of(engine.context).pending_questions()]
        return {"time": round(now, 2), "state": engine.supervisor.state, "mission": self._mission(),
                "telemetry": {"position": _point(t.position), "yaw": round(t.yaw, 1), "speed": round(t.speed, 2),
                              "battery": round(t.battery_percent, 1), "landed": t.landed_state.value,
                              "mode": t.flight_mode, "armed": t.armed},
                "active": active, "beliefs": beliefs[:MAX_BELIEFS], "belief_count": len(beliefs),
                "questions": questions, "safety": self._safety()}

    def _safety(self) -> dict[str, Any] | None:
        monitor = getattr(self.engine, "safety", None)
        return monitor.status().as_dict() if monitor is not None else None

    def _mission(self) -> dict[str, Any]:
        attached = next((m for m in self.engine.supervisor.missions if hasattr(m, "nodes")), None)
        if attached is not None:  # a tree mission attaches itself to the supervisor when it starts (a loaded one too)
            self.tree = attached
        elif self.tree is not None and self.tree.done and self.engine.bridge.state != "done":
            self.tree = None  # a Python mission was loaded in its place
        if self.tree is not None:
            from aeroexec.trees.runtime.ticking import status_name

            return {"kind": "tree", "name": self.tree.name,
                    "nodes": [{"uid": uid, "depth": depth, "name": node.name, "status": status_name(node)}
                              for uid, (depth, node) in enumerate(self.tree.nodes, 1)]}
        line = mission_line(self.mission_file) if self.mission_file else None
        return {"kind": "python", "line": line or "(the mission is not running code of its own right now)"}

    def close(self) -> None:
        """Send the last state and stop following the engine."""
        with contextlib.suppress(ValueError):
            self.engine.tick_callbacks.remove(self._tick)
        self.publish()
        self._unsubscribe()
