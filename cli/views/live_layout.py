"""How the live view fits a terminal: rows for each panel out of the height, the newest events that fit when
wrapped whole, a window of the mission around what runs, a compact behavior table on a narrow terminal."""

from __future__ import annotations

import textwrap

from rich.table import Table
from rich.text import Text


def behavior_table(active: list[tuple[str, str, str, float, float | None]], rows: int | None,
                    compact: bool) -> Table:
    """The active behaviors, the newest last; ``compact`` (a narrow terminal) folds the times into one column."""
    shown = active if rows is None or len(active) <= rows else active[-(rows - 1):] if rows > 1 else []
    columns = ("behavior", "priority", "time") if compact else ("behavior", "priority", "source", "elapsed",
                                                                "timeout")
    table = Table(*columns, expand=True, box=None)
    if len(shown) < len(active):
        table.add_row(f"... {len(active) - len(shown)} more", *[""] * (len(columns) - 1), style="dim")
    for name, priority, source, elapsed, timeout in shown:
        limit = f"{timeout:g} s" if timeout else "-"
        if compact:
            table.add_row(name, priority, f"{elapsed:.1f}/{limit}" if timeout else f"{elapsed:.1f} s")
        else:
            table.add_row(name, priority, source, f"{elapsed:.1f} s", limit)
    return table


def wrapped(line: str, width: int) -> int:
    """How many rows ``line`` takes wrapped at word boundaries to ``width`` columns."""
    return max(1, len(textwrap.wrap(line, max(1, width), break_long_words=True, break_on_hyphens=False)))


def rows(text: Text, width: int) -> int:
    """How many terminal rows ``text`` takes at ``width`` columns when wrapped."""
    return sum(wrapped(line, width) for line in text.plain.rstrip("\n").split("\n"))


def share(budget: int | None, missions: int, active: int) -> tuple[int | None, int | None, int | None]:
    """Rows for the mission, the active behaviors and the events out of ``budget`` (None: no limit)."""
    if budget is None:
        return None, None, None
    budget = max(budget, 5)
    events = max(3, budget // 3)
    behaviors = max(1, min(active, (budget - events) // 2))
    mission = max(1, min(missions, budget - events - behaviors))
    events = max(2, budget - mission - behaviors)
    return mission, behaviors, events


def window(lines: list[tuple[int, str, str]], rows: int | None) -> list[tuple[int, str, str]]:
    """At most ``rows`` lines of the mission, around the deepest running node."""
    if rows is None or len(lines) <= rows:
        return lines
    running = [i for i, (_, status, _) in enumerate(lines) if status == "RUNNING"]
    focus = running[-1] if running else 0
    start = min(max(0, focus - rows // 2), len(lines) - rows)
    return lines[start:start + rows]


def newest(events: list[tuple[str, str]], rows: int | None, width: int) -> list[tuple[str, str]]:
    """The newest events that fit in ``rows`` rows of ``width`` columns, each wrapped whole, oldest first."""
    if rows is None:
        return events
    shown: list[tuple[str, str]] = []
    used = 0
    for line, style in reversed(events):
        need = wrapped(line, width)
        if shown and used + need > rows:
            break
        shown.append((line, style))
        used += need
    return shown[::-1]
