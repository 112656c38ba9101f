"""The live view of a fleet in a terminal: one line per drone (mission, state, active behaviors, battery,
position) and the last events of all, prefixed by drone; refreshed in place."""

from __future__ import annotations

import contextlib
import threading
from collections import deque
from typing import Any

from rich.console import Console, Group, RenderableType
from rich.live import Live
from rich.panel import Panel
from rich.table import Table
from rich.text import Text

EVENTS = 15  # lines of events shown
QUIET_KINDS = {"node_status", "belief_added", "belief_removed", "reactive"}


class FleetView:
    """Watches the engines of a fleet run (``{drone: engine}``) and draws them."""

    def __init__(self, fleet: str, engines: dict[str, Any], links: dict[str, Any], console: Console | None = None):
        self.fleet, self.engines, self.links = fleet, engines, links
        self.console = console or Console()
        self._rows: dict[str, tuple] = {}
        self._events: deque[str] = deque(maxlen=EVENTS)
        self._lock = threading.Lock()
        self._live: Live | None = None
        self._undo: list[Any] = []
        for name, engine in engines.items():
            self._undo.append(engine.log.subscribe(lambda event, name=name: self._event(name, event)))
            engine.tick_callbacks.append(self._ticker(name, engine))

    def _event(self, name: str, event: Any) -> None:
        if event.kind not in QUIET_KINDS:
            self._events.append(f"{name:>4} | {event}")

    def _ticker(self, name: str, engine: Any) -> Any:
        def tick() -> None:  # on the loop's thread: read the engine where it is safe
            t = engine.drone.telemetry()
            link = self.links.get(name)
            active = ", ".join(sorted(engine.coordinator.active()))
            row = (getattr(link, "mission", ""), engine.supervisor.state, active, t.battery_percent, t.position,
                   engine.now(), ", ".join(sorted(getattr(link, "silent", ()))))
            with self._lock:
                self._rows[name] = row

        return tick

    def render(self) -> RenderableType:
        table = Table("drone", "mission", "state", "active behaviors", "battery", "position", "silent",
                      expand=True, box=None)
        with self._lock:
            rows = dict(self._rows)
        now = max((row[5] for row in rows.values()), default=0.0)
        for name in self.engines:
            if name not in rows:
                table.add_row(name, "", "starting", "", "", "", "")
                continue
            mission, state, active, battery, (x, y, z), _, silent = rows[name]
            table.add_row(name, mission, state, active or "-",
                          Text(f"{battery:.0f} %", "red" if battery < 30 else ""), f"({x:.1f}, {y:.1f}, {z:.1f})",
                          silent)
        title = Text.assemble(("aeroexec fleet ", "bold"), (self.fleet, "bold cyan"), f"  t={now:.1f} s  ",
                              (f"{len(self.engines)} drones", "dim"))
        events = Text("\n".join(self._events), no_wrap=True, overflow="ellipsis")
        return Group(title, Panel(table, title="drones", title_align="left"),
                     Panel(events, title="events", title_align="left"),
                     Text("Ctrl-C stops the fleet; aeroexec ctl --fleet " + self.fleet + " pause|resume|abort", "dim"))

    def start(self) -> FleetView:
        self._live = Live(get_renderable=self.render, console=self.console, refresh_per_second=4,
                          redirect_stdout=True, redirect_stderr=True)
        self._live.start()
        return self

    def stop(self) -> None:
        for unsubscribe in self._undo:
            with contextlib.suppress(Exception):
                unsubscribe()
        if self._live is not None:
            self._live.stop()
            self._live = None
