"""``QGC WPL 110`` waypoint files (Mission Planner's ``.waypoints``, MAVProxy's and ArduPilot's autotest ``.txt``)
into the item model.

The first line is ``QGC WPL 110``; each other line is one item, tab (or space) separated::

    INDEX  CURRENT  FRAME  COMMAND  PARAM1  PARAM2  PARAM3  PARAM4  LATITUDE  LONGITUDE  ALTITUDE  AUTOCONTINUE

A first line of index 0 that is a NAV_WAYPOINT (or all zeros) is home (an AMSL altitude), as Mission Planner and
MAVProxy write it; any other first line is an item (MAVSDK's sample starts with its NAV_TAKEOFF as line 0). Items
are numbered in file order, as an autopilot receives them. Blank lines and lines starting with ``#`` are skipped.
These files come from ArduPilot's tools: latitude and longitude 0 mean "where the drone is" and a waypoint's
altitude 0 "the altitude it flies at", as ArduPilot reads them.
"""

from __future__ import annotations

import math

from aeroexec.drones.geodesy import valid_latitude_longitude
from aeroexec.engine.errors import WRONG_VALUE
from aeroexec.trees.items.model import ItemMission, MissionItem
from aeroexec.trees.model import TreeFormatError

HEADER = "QGC WPL 110"
FIELDS = 12


def is_wpl(text: str) -> bool:
    """Whether ``text`` starts like a QGC WPL file (its header, whatever the version)."""
    return text.lstrip("\ufeff").lstrip()[:7].upper() == "QGC WPL"


def _numbers(fields: list[str]) -> list[float] | None:
    try:
        values = [float(f) for f in fields]
    except ValueError:
        return None
    return values if all(math.isfinite(v) for v in values) else None


def read_wpl(text: str, file: str) -> ItemMission:
    """A QGC WPL 110 file as an item mission; a line that is no item is an error at its line."""
    lines = text.lstrip("\ufeff").splitlines()
    first = next((i for i, line in enumerate(lines) if line.strip()), None)
    if first is None or not is_wpl(lines[first]):
        raise TreeFormatError([(file, 1, f"not a waypoint file: the first line must be \"{HEADER}\"")])
    if lines[first].split() != HEADER.split():
        raise TreeFormatError([(file, first + 1, f"a waypoint file of version {lines[first].strip()!r}: aeroexec "
                                                 f"reads \"{HEADER}\"")])
    mission = ItemMission(file, line=first + 1, ardupilot=True)  # the header line: no item's
    seq, previous = 1, None
    for number, line in enumerate(lines[first + 1:], start=first + 2):
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        fields = line.split()
        values = _numbers(fields) if len(fields) == FIELDS else None
        if values is None:
            why = (f"{len(fields)} fields" if len(fields) != FIELDS else "a field that is no finite number")
            mission.problem(number, f"a waypoint line has {FIELDS} numbers (index, current, frame, command, "
                                    f"4 params, latitude, longitude, altitude, autocontinue), not {why}")
            continue
        index, _, frame, command = (int(v) if v.is_integer() else -1 for v in values[:4])
        if frame < 0 or command < 0:
            mission.problem(number, "the frame and command of a waypoint line are integers")
            continue
        params = tuple(values[4:11])
        if previous is None and index == 0 and command in (0, 16):  # the home line (a waypoint numbered 0)
            lat, lon, alt = params[4:7]
            if not (lat == 0.0 and lon == 0.0):
                why = valid_latitude_longitude(lat, lon)
                if why:
                    mission.problem(number, f"home is no place on Earth: {why}", kind=WRONG_VALUE)
                else:
                    mission.home, mission.home_line = (lat, lon, alt), number
            previous = index
            continue
        if previous is not None and index != previous + 1:
            mission.problem(number, f"item {seq}: the line says index {index} after {previous}: the items are "
                                    f"numbered in file order, as an autopilot receives them", severity="warning")
        previous = index
        mission.items.append(MissionItem(seq, command, frame, params, number, bool(values[11])))
        seq += 1
    if not mission.items and not mission.errors:
        mission.problem(first + 1, "the waypoint file has no items after its home line: nothing to fly")
    return mission
