"""The live view of ``aeroexec run`` on a terminal: what the drone does and why, refreshed in place (rich).

Sections: the safety rules' line when the run has some (held; or the rule violated, the contingency in effect,
an obligation due), the mission (the tree with node statuses, or the Python mission's current line), the active
behaviors (priority, source, elapsed time, timeout), the drone (position, altitude, speed, battery), the
beliefs (recently changed ones highlighted, removed ones struck through), the last events with their reasons,
and a waiting question. On a terminal the view fits its size (80 x 24 included): the panels shrink, the
newest events and the key line stay, and explanations wrap rather than being cut. When the run ends, the
header shows how (completed, completed with refused requests, failed, aborted). The engine thread only
takes a snapshot of plain data now and then (a tick
callback, a few times a wall second); rich's own thread draws it, so the view never slows a tick.

:class:`KeyReader` turns keys into the operator's commands (p pause, r resume, n next item (skip), j jump to
an item, a/q abort, i inhibit NAME, t answer TEXT, Esc cancels a prompt) from a daemon thread reading the terminal
in cbreak mode.
"""

from __future__ import annotations

import contextlib
import os
import select
import shlex
import sys
import threading
import time
from collections import deque
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, TextIO

from aeroexec.cli.views.choice import wanted  # noqa: F401  # by its old place
from aeroexec.console.feed import mission_line
from aeroexec.engine.events import EngineEvent
from aeroexec.engine.supervision.operator import operator_of
from aeroexec.flight.run_status import ABORTED, COMPLETED, FAILED, REFUSED, RUN_ENDED

if TYPE_CHECKING:  # rich is imported when a view is drawn: a run with --plain never loads it
    from rich.console import Console, RenderableType
    from rich.live import Live
    from rich.text import Text

SNAPSHOT_PERIOD = 0.2  # wall seconds between two snapshots
RECENT = 2.0  # engine seconds a changed belief stays highlighted
EVENTS_SHOWN = 10
BELIEFS_SHOWN = 14
STATUS_STYLE = {"RUNNING": "bold yellow", "SUCCESS": "green", "FAILURE": "bold red", "IDLE": "dim",
                "INVALID": "dim", "SKIPPED": "dim cyan"}
EVENT_STYLE = {"GOAL_ACHIEVED": "green", "TIME_OUT": "red", "WRONG_PROGRESS": "red", "INTERRUPTED": "yellow",
               "failed_preconditions": "red", "rejected": "red", "mission_failed": "bold red",
               "mission_completed": "bold green", "operator_command": "bold magenta", "operator": "cyan",
               "mission_change": "bold magenta", "mission_replaced": "bold magenta"}
KEYS_HELP = "p pause  r resume  n next item  j jump  a/q abort+land  i inhibit  t answer"
FINAL_STYLE = {COMPLETED: "bold green", REFUSED: "bold yellow", FAILED: "bold red", ABORTED: "bold red"}
SAFETY_STYLE = {"held": "green", "due": "bold yellow", "violated": "bold white on red"}
FLIGHT_CAPABILITY = "FLIGHT_CONTROL"  # the behaviors holding it command the drone's flight mode


@dataclass
class Snapshot:
    """What the view shows, as plain data taken on the engine's thread."""

    time: float = 0.0
    state: str = "running"
    mission: list[tuple[int, str, str]] = field(default_factory=list)  # (depth, status, text)
    active: list[tuple[str, str, str, float, float | None]] = field(default_factory=list)
    drone: dict[str, Any] = field(default_factory=dict)
    beliefs: list[tuple[str, str]] = field(default_factory=list)  # (text, style)
    events: list[tuple[str, str]] = field(default_factory=list)
    questions: list[str] = field(default_factory=list)
    safety: tuple[str, str] | None = None  # the safety rules' line and its level (held, due, violated)


class LiveView:
    """Watches one engine; :meth:`render` draws its latest snapshot, :meth:`start` shows it in place."""

    def __init__(self, engine: Any, name: str, tree: Any = None, mission_file: str | Path | None = None,
                 console: Console | None = None) -> None:
        self.engine, self.name, self.tree = engine, name, tree
        self.mission_file = str(Path(mission_file).resolve()) if mission_file is not None else None
        if console is None:
            from rich.console import Console

            console = Console()
        self.console = console
        self.prompt = ""  # the key reader's prompt line, shown at the bottom
        self.message = ""  # the last command's answer
        self._events: deque[EngineEvent] = deque(maxlen=EVENTS_SHOWN)
        self._changed: dict[str, tuple[float, str]] = {}  # belief text -> (time, "added"/"removed")
        self._snapshot = Snapshot()
        self._taken_at = 0.0
        self._final = ""  # how the run ended, once it has
        self._live: Live | None = None
        self._unsubscribe = [engine.log.subscribe(self._event), engine.memory.subscribe(self._belief)]
        engine.tick_callbacks.append(self._tick)

    # -- on the engine's thread -------------------------------------------------------------
    def _event(self, event: EngineEvent) -> None:
        if event.kind == RUN_ENDED:
            self._final = event.detail
        if event.kind not in ("node_status",):
            self._events.append(event)

    def _belief(self, change: Any) -> None:
        if change.kind == "removed" and change.reason == "replaced":
            return  # an exclusive value changed: the new one is shown as added
        self._changed[str(change.belief)] = (self.engine.now(), change.kind)

    def _tick(self) -> None:
        if time.monotonic() - self._taken_at >= SNAPSHOT_PERIOD:
            self.refresh()

    def refresh(self) -> None:
        """Take a snapshot now (on the engine's thread, or while the loop does not run)."""
        self._taken_at = time.monotonic()
        self._snapshot = self.snapshot()

    def snapshot(self) -> Snapshot:
        engine = self.engine
        now = engine.now()
        telemetry = engine.drone.telemetry()
        active = [(a.name, {2: "higher", 1: "deliberative", 0: "lower"}.get(a.priority, "?"), a.source,
                   now - a.started_at, a.timeout)
                  for a in sorted(engine.coordinator.active().values(), key=lambda a: a.order)]
        flying = [a.name for a in sorted(engine.coordinator.active().values(), key=lambda a: -a.order)
                  if any(FLIGHT_CAPABILITY in c for c in a.process.descriptor.capabilities)]  # newest first
        drone = {"position": telemetry.position, "altitude": telemetry.altitude, "speed": telemetry.speed,
                 "battery": telemetry.battery_percent, "landed": telemetry.landed_state.value,
                 "mode": telemetry.flight_mode, "by": flying[0] if flying else ""}
        monitor = getattr(engine, "safety", None)
        status = monitor.status() if monitor is not None else None
        return Snapshot(now, self._final or engine.supervisor.state, self._mission_lines(), active, drone,
                        self._beliefs(now),
                        [(_event_line(e), EVENT_STYLE.get(e.kind, "")) for e in self._events],
                        [_question(p) for p in operator_of(engine.context).pending_questions()],
                        (status.summary(), status.level) if status is not None else None)

    def _mission_lines(self) -> list[tuple[int, str, str]]:
        attached = next((m for m in self.engine.supervisor.missions if hasattr(m, "nodes")), None)
        if attached is not None:  # a tree mission attaches itself to the supervisor when it starts (a loaded one too)
            self.tree = attached
        elif self.tree is not None and self.tree.done and self.engine.bridge.state != "done":
            self.tree = None  # a Python mission was loaded in its place
        if self.tree is not None:
            from aeroexec.trees.runtime.ticking import status_name

            return [(depth, status_name(node), node.name) for depth, node in self.tree.nodes]
        line = mission_line(self.mission_file) if self.mission_file else None
        if line is None:
            return [(0, "", "(the mission is not running Python code of its own right now)")]
        return [(0, "RUNNING", line)]

    def _beliefs(self, now: float) -> list[tuple[str, str]]:
        present = [str(b) for b in self.engine.memory.beliefs()]
        for text, (when, _) in list(self._changed.items()):
            if now - when > RECENT:
                del self._changed[text]
        recent = [t for t, (_, kind) in sorted(self._changed.items(), key=lambda i: -i[1][0]) if kind == "added"]
        removed = [t for t, (_, kind) in self._changed.items() if kind == "removed" and t not in present]
        shown = [(t, "bold green") for t in recent if t in present]
        shown += [(t, "strike dim red") for t in removed]
        shown += [(t, "") for t in present if t not in self._changed]
        return shown[:BELIEFS_SHOWN] + ([(f"... {len(shown) - BELIEFS_SHOWN} more", "dim")]
                                        if len(shown) > BELIEFS_SHOWN else [])

    # -- drawing (any thread) --------------------------------------------------------------------
    def render(self) -> RenderableType:
        """The view of the latest snapshot; on a terminal, sized to fit it (the key line always shows)."""
        size = self.console.size if self.console.is_terminal else None
        return self.draw(size)

    def draw(self, size: tuple[int, int] | None = None) -> RenderableType:
        """The view for a ``(width, height)`` terminal, or everything when ``size`` is None."""
        from aeroexec.cli.views.live_layout import behavior_table, newest, rows, share, window
        from rich.console import Group
        from rich.panel import Panel
        from rich.table import Table
        from rich.text import Text

        s = self._snapshot
        width = size[0] if size else 10_000
        state_style = FINAL_STYLE.get(s.state) or {"paused": "bold yellow", "aborted": "bold red",
                                                    "suspended": "bold yellow"}.get(s.state, "bold green")
        title = Text.assemble(("aeroexec ", "bold"), (self.name, "bold cyan"), f"  t={s.time:.1f} s  ",
                              (s.state.upper(), state_style), no_wrap=True, overflow="ellipsis")
        footer = Text(self.prompt, style="bold") if self.prompt else Text(KEYS_HELP, style="dim")
        if self.message and not self.prompt:
            footer = Text.assemble((self.message, "magenta"), "   ", footer)
        footer.no_wrap, footer.overflow = True, "ellipsis"
        questions = [Text(f"the drone asks: {q}  (press t to answer)", style="bold cyan") for q in s.questions]
        safety = [Text(s.safety[0], style=SAFETY_STYLE.get(s.safety[1], ""))] if s.safety else []
        drone = self._drone_text(s.drone)
        # rows left for the panels' contents: title, footer, safety, questions, four panels' borders, table header
        budget = None if size is None else size[1] - 2 - sum(rows(q, width) for q in (*safety, *questions)) \
            - rows(drone, width - 4) - 2 - 2 - 3 - 2
        mission_rows, behavior_rows, event_rows = share(budget, len(s.mission), len(s.active))
        mission = Text(no_wrap=True, overflow="ellipsis")
        for depth, status, text in window(s.mission, mission_rows):
            if mission:
                mission.append("\n")
            if status and self.tree is not None:
                mission.append(f"{'  ' * depth}[{status}] ", STATUS_STYLE.get(status, ""))
                mission.append(text)
            else:
                mission.append(text, "yellow" if status else "dim")
        behaviors = behavior_table(s.active, behavior_rows, compact=width < 110)
        left_rows = None if budget is None else (mission_rows or 0) + (behavior_rows or 0) + 3
        shown_beliefs = s.beliefs if left_rows is None else s.beliefs[:max(1, left_rows)]
        beliefs = Text("\n").join(Text(text, style) for text, style in shown_beliefs)
        beliefs.no_wrap, beliefs.overflow = True, "ellipsis"
        events = Text("\n").join(Text(line, style) for line, style in newest(s.events, event_rows, width - 4))
        events.overflow = "fold"  # explanations wrap, never cut
        top = Table.grid(expand=True)
        top.add_column(ratio=3)
        top.add_column(ratio=2)
        top.add_row(Group(Panel(mission, title="mission", title_align="left"),
                          Panel(behaviors, title="active behaviors", title_align="left")),
                    Panel(beliefs, title="beliefs", title_align="left"))
        parts: list[RenderableType] = [title, *safety, Panel(drone, title="drone", title_align="left"), top,
                                       Panel(events, title="events", title_align="left"), *questions, footer]
        return Group(*parts)

    @staticmethod
    def _drone_text(d: dict[str, Any]) -> Text:
        from rich.text import Text

        drone = Text()
        if d:
            x, y, z = d["position"]
            drone.append(f"position ({x:.1f}, {y:.1f}, {z:.1f}) m  altitude {d['altitude']:.1f} m  "
                         f"speed {d['speed']:.1f} m/s  ")
            drone.append(f"battery {d['battery']:.0f} %", "red" if d["battery"] < 30 else "")
            drone.append(f"\n{d['landed']}, flight mode {d['mode']}", "dim")
            if d.get("by"):
                drone.append(f" (commanded by {d['by']})", "dim")
        return drone

    def start(self) -> LiveView:
        from rich.live import Live

        self.refresh()
        self._live = Live(get_renderable=self.render, console=self.console, refresh_per_second=4,
                          redirect_stdout=True, redirect_stderr=True)
        self._live.start()
        return self

    def stop(self) -> None:
        """Draw the last state and give the terminal back."""
        with contextlib.suppress(ValueError):
            self.engine.tick_callbacks.remove(self._tick)
        for unsubscribe in self._unsubscribe:
            unsubscribe()
        if self._live is not None:
            self.refresh()
            self._live.stop()
            self._live = None


def _event_line(event: EngineEvent) -> str:
    who = f" {event.behavior}" if event.behavior else ""
    why = f": {event.detail}" if event.detail else ""
    return f"[{event.time:7.1f}] {event.kind}{who}{why}"


def _question(pending: Any) -> str:
    choices = f" [{' / '.join(f'{i}) {a}' for i, a in enumerate(pending.answers, 1))}]" if pending.answers else ""
    return f"{pending.question}{choices}"


class KeyReader:
    """Reads single keys from a terminal in a daemon thread and submits the operator's commands."""

    PROMPTS = {"i": ("inhibit", "inhibit behavior: "), "t": ("answer", "answer: "),
               "j": ("jump", "jump to item (number or name): ")}
    SINGLE = {"p": "pause", "r": "resume", "a": "abort", "q": "abort", "n": "skip"}

    def __init__(self, supervisor: Any, view: LiveView | None = None, stream: TextIO | None = None) -> None:
        self.supervisor, self.view = supervisor, view
        self.stream = stream if stream is not None else sys.stdin
        self._prompt: tuple[str, str] | None = None
        self._buffer = ""
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._saved: Any = None

    def start(self) -> KeyReader:
        """Start reading when the stream is a terminal (cbreak mode: Ctrl-C still interrupts)."""
        try:
            if not self.stream.isatty():
                return self
            import termios
            import tty

            fd = self.stream.fileno()
            self._saved = termios.tcgetattr(fd)
            tty.setcbreak(fd)
        except (OSError, ValueError, ImportError, AttributeError):
            return self
        self._thread = threading.Thread(target=self._read, args=(fd,), name="aeroexec-keys", daemon=True)
        self._thread.start()
        return self

    def stop(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=0.5)
        if self._saved is not None:
            import termios

            with contextlib.suppress(OSError, ValueError):
                termios.tcsetattr(self.stream.fileno(), termios.TCSADRAIN, self._saved)
            self._saved = None

    def _read(self, fd: int) -> None:
        while not self._stop.is_set():
            try:
                ready, _, _ = select.select([fd], [], [], 0.2)
                if not ready:
                    continue
                data = os.read(fd, 32)
            except (OSError, ValueError):
                return
            if not data:
                return
            for key in data.decode(errors="ignore"):
                self.press(key)

    def press(self, key: str) -> None:
        """One key: a command, or a character of the prompt being typed (Enter sends it, Esc cancels)."""
        if self._prompt is not None:
            command, label = self._prompt
            if key in ("\r", "\n"):
                self._prompt = None
                self._submit(command, self._buffer.strip())
            elif key == "\x1b":
                self._prompt = None
            elif key in ("\x7f", "\b"):
                self._buffer = self._buffer[:-1]
            elif key.isprintable():
                self._buffer += key
            self._show(f"{label}{self._buffer}_" if self._prompt else "")
            return
        key = key.lower()
        if key in self.SINGLE:
            self._submit(self.SINGLE[key], "")
        elif key in self.PROMPTS:
            self._prompt, self._buffer = self.PROMPTS[key], ""
            self._show(self._prompt[1] + "_")

    def _submit(self, command: str, argument: str) -> None:
        if command in ("inhibit", "answer", "jump") and not argument:
            return
        if command == "jump":  # the target as typed: a name with spaces is one word
            argument = shlex.quote(argument)
        ticket = self.supervisor.submit(command, argument, origin="keyboard")

        def report() -> None:  # the answer shows up in the footer, without blocking the reader
            result = ticket.wait(5.0)
            if self.view is not None and result is not None:
                self.view.message = result.message

        threading.Thread(target=report, daemon=True).start()

    def _show(self, prompt: str) -> None:
        if self.view is not None:
            self.view.prompt = prompt


class LiveConsole:
    """The live view of one engine with its keys, for a person at a terminal; a context manager (closed on the
    way out, Ctrl-C included)."""

    def __init__(self, engine: Any, name: str, mission: Any = None) -> None:
        self.engine, self.name, self.mission = engine, name, mission
        self.view: LiveView | None = None
        self.keys: KeyReader | None = None

    def __enter__(self) -> LiveConsole:
        code = getattr(self.mission, "__code__", None)
        mission_file = code.co_filename if code is not None else None
        self.view = LiveView(self.engine, self.name, mission_file=mission_file).start()
        self.keys = KeyReader(self.engine.supervisor, self.view).start()
        return self

    def __exit__(self, *exc: object) -> None:
        if self.keys is not None:
            self.keys.stop()
        if self.view is not None:
            self.view.stop()
