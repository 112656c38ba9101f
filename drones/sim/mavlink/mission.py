"""The MAVLink mission protocol of the simulated vehicle and a small AUTO.MISSION executor.

Upload (MISSION_COUNT, MISSION_REQUEST_INT, MISSION_ITEM_INT, MISSION_ACK), download, clear and
set-current for the mission, geofence and rally lists, with retries on wall time (as ArduCopter, item 0 is home
and a mission starts at item 1). A mission runs
NAV_TAKEOFF, NAV_WAYPOINT, NAV_LAND, NAV_RETURN_TO_LAUNCH and DO_CHANGE_SPEED items on the simulated
drone; other items are skipped.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from dataclasses import dataclass, field

from aeroexec.drones.interface import CommandHandle, Failure, LandedState, Telemetry
from aeroexec.drones.sim.mavlink.telemetry import heading_to_yaw
from pymavlink.dialects.v20 import common as mavlink

logger = logging.getLogger(__name__)

_RETRY_S = 0.5  # wall seconds without the next item before asking again
_RETRIES = 5
_GLOBAL_FRAMES = (mavlink.MAV_FRAME_GLOBAL, mavlink.MAV_FRAME_GLOBAL_INT)
_RELATIVE_FRAMES = (
    mavlink.MAV_FRAME_GLOBAL_RELATIVE_ALT,
    mavlink.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT,
    mavlink.MAV_FRAME_GLOBAL_TERRAIN_ALT,
    mavlink.MAV_FRAME_GLOBAL_TERRAIN_ALT_INT,
)


@dataclass(frozen=True, slots=True)
class MissionItem:
    """One stored item, in MISSION_ITEM_INT form (latitude and longitude in degrees * 1e7)."""

    seq: int
    frame: int
    command: int
    autocontinue: int
    params: tuple[float, float, float, float]
    x: int
    y: int
    z: float

    @classmethod
    def from_message(cls, msg) -> MissionItem:
        x, y = msg.x, msg.y
        if msg.get_type() == "MISSION_ITEM" and msg.frame in _GLOBAL_FRAMES + _RELATIVE_FRAMES:
            x, y = int(round(x * 1e7)), int(round(y * 1e7))
        return cls(
            msg.seq,
            msg.frame,
            msg.command,
            msg.autocontinue,
            (msg.param1, msg.param2, msg.param3, msg.param4),
            int(x),
            int(y),
            float(msg.z),
        )


@dataclass(slots=True)
class _Upload:
    partner: tuple[int, int]
    mission_type: int
    items: list[MissionItem] = field(default_factory=list)
    count: int = 0
    asked_at: float = 0.0
    retries: int = 0


class MissionManager:
    """Stores the uploaded lists and runs the mission when the vehicle is put in AUTO.MISSION."""

    def __init__(self, mav: mavlink.MAVLink, statustext: Callable[[int, str], None], first: int = 0) -> None:
        self._mav = mav
        self.first = first  # the first item flown: ArduPilot's item 0 is home, never flown
        self._statustext = statustext
        self._lists: dict[int, list[MissionItem]] = {0: [], 1: [], 2: []}
        self._upload: _Upload | None = None
        self.active = False
        self.current = 0
        self._started = False
        self._hold_until: float | None = None
        self._kind = ""  # what the started item waits for: "climb", "goto" or "ground"
        self._goal: tuple[float, float, float] = (0.0, 0.0, 0.0)

    @property
    def items(self) -> list[MissionItem]:
        return list(self._lists[mavlink.MAV_MISSION_TYPE_MISSION])

    # --- transfer protocol -------------------------------------------------------------------------
    def handle(self, msg, wall_now: float) -> bool:
        """Answer a mission-protocol message; False when ``msg`` is not one."""
        kind = msg.get_type()
        partner = (msg.get_srcSystem(), msg.get_srcComponent())
        mission_type = getattr(msg, "mission_type", 0)
        if kind == "MISSION_COUNT":
            self._begin_upload(partner, mission_type, msg.count, wall_now)
        elif kind in ("MISSION_ITEM_INT", "MISSION_ITEM"):
            self._receive_item(partner, msg, wall_now)
        elif kind == "MISSION_REQUEST_LIST":
            self._mav.mission_count_send(*partner, len(self._lists.get(mission_type, [])), mission_type)
        elif kind in ("MISSION_REQUEST_INT", "MISSION_REQUEST"):
            self._send_item(partner, msg.seq, mission_type, as_int=kind == "MISSION_REQUEST_INT")
        elif kind == "MISSION_CLEAR_ALL":
            types = list(self._lists) if mission_type == mavlink.MAV_MISSION_TYPE_ALL else [mission_type]
            for each in types:
                self._replace(each, [])
            self._mav.mission_ack_send(*partner, mavlink.MAV_MISSION_ACCEPTED, mission_type)
        elif kind == "MISSION_SET_CURRENT":
            self.set_current(msg.seq)
        elif kind == "MISSION_ACK":
            pass  # the end of a download
        else:
            return False
        return True

    def poll(self, wall_now: float) -> None:
        """Ask again for an item that did not come; give the upload up after a few tries."""
        up = self._upload
        if up is None or wall_now - up.asked_at < _RETRY_S:
            return
        if up.retries >= _RETRIES:
            self._upload = None
            self._mav.mission_ack_send(*up.partner, mavlink.MAV_MISSION_OPERATION_CANCELLED, up.mission_type)
            self._statustext(mavlink.MAV_SEVERITY_WARNING, "Mission upload timed out")
            return
        up.retries += 1
        self._request(up, wall_now)

    def _begin_upload(self, partner: tuple[int, int], mission_type: int, count: int, wall_now: float) -> None:
        if mission_type not in self._lists:
            self._mav.mission_ack_send(*partner, mavlink.MAV_MISSION_UNSUPPORTED, mission_type)
            return
        if self._upload is not None and self._upload.partner != partner:
            self._mav.mission_ack_send(*partner, mavlink.MAV_MISSION_DENIED, mission_type)
            return
        if count == 0:
            self._upload = None
            self._replace(mission_type, [])
            self._mav.mission_ack_send(*partner, mavlink.MAV_MISSION_ACCEPTED, mission_type)
            return
        self._upload = _Upload(partner, mission_type, count=count)
        self._request(self._upload, wall_now)

    def _receive_item(self, partner: tuple[int, int], msg, wall_now: float) -> None:
        up = self._upload
        if up is None or up.partner != partner or getattr(msg, "mission_type", 0) != up.mission_type:
            return
        if msg.seq == len(up.items):
            up.items.append(MissionItem.from_message(msg))
            up.retries = 0
        if len(up.items) < up.count:
            self._request(up, wall_now)
            return
        self._upload = None
        self._replace(up.mission_type, up.items)
        self._mav.mission_ack_send(*partner, mavlink.MAV_MISSION_ACCEPTED, up.mission_type)
        logger.info("mission upload (type %d): %d items", up.mission_type, len(up.items))

    def _request(self, up: _Upload, wall_now: float) -> None:
        up.asked_at = wall_now
        self._mav.mission_request_int_send(*up.partner, len(up.items), up.mission_type)

    def _send_item(self, partner: tuple[int, int], seq: int, mission_type: int, as_int: bool) -> None:
        items = self._lists.get(mission_type, [])
        if not 0 <= seq < len(items):
            self._mav.mission_ack_send(*partner, mavlink.MAV_MISSION_INVALID_SEQUENCE, mission_type)
            return
        it = items[seq]
        current = int(mission_type == 0 and seq == self.current)
        if as_int:
            self._mav.mission_item_int_send(
                *partner,
                seq,
                it.frame,
                it.command,
                current,
                it.autocontinue,
                *it.params,
                it.x,
                it.y,
                it.z,
                mission_type,
            )
        else:
            scale = 1e-7 if it.frame in _GLOBAL_FRAMES + _RELATIVE_FRAMES else 1.0
            self._mav.mission_item_send(
                *partner,
                seq,
                it.frame,
                it.command,
                current,
                it.autocontinue,
                *it.params,
                it.x * scale,
                it.y * scale,
                it.z,
                mission_type,
            )

    def _replace(self, mission_type: int, items: list[MissionItem]) -> None:
        self._lists[mission_type] = list(items)
        if mission_type == mavlink.MAV_MISSION_TYPE_MISSION:
            if self.active:
                self.abort("mission replaced")
            self.current = 0

    # --- execution ---------------------------------------------------------------------------------
    def set_current(self, seq: int) -> bool:
        if not 0 <= seq < max(len(self.items), 1):
            return False
        self.current = seq
        self._started = False
        self._mav.mission_current_send(self.current, len(self.items))
        return True

    def start(self, first: int | None = None) -> CommandHandle:
        if not self.items:
            return CommandHandle.failed("mission", Failure.DENIED, "mission denied: no mission uploaded")
        if first is not None and not self.set_current(first):
            return CommandHandle.failed("mission", Failure.DENIED, f"mission denied: no item {first}")
        if self.current >= len(self.items) or self.current < self.first:
            self.current = min(self.first, len(self.items) - 1)
        self.active = True
        self._started = False
        return CommandHandle.succeeded("mission")

    def abort(self, why: str) -> None:
        if self.active:
            logger.info("mission stopped at item %d: %s", self.current, why)
        self.active = False
        self._started = False

    def step(self, drone, tel: Telemetry, home_alt: float, acceptance: float, cruise: float | None) -> None:
        """Advance the running mission by what the simulated drone has done since the last step."""
        if not self.active:
            return
        items = self.items
        if self.current >= len(items):
            self.active = False
            self._statustext(mavlink.MAV_SEVERITY_INFO, "Mission finished")
            if tel.landed_state == LandedState.IN_AIR:
                drone.hold()
            return
        item = items[self.current]
        if not self._started:
            if not tel.armed:
                return  # as PX4: a mission waits on the ground for arming
            handle = self._begin(drone, tel, item, home_alt, cruise)
            if handle is None:
                self._advance()
            elif not handle.ok:
                self._statustext(mavlink.MAV_SEVERITY_WARNING, f"Mission item {item.seq} rejected: {handle.reason}")
                self.abort(handle.reason)
            else:
                self._started = True
            return
        if self._reached(tel, item, acceptance):
            self._advance()

    def _advance(self) -> None:
        self._mav.mission_item_reached_send(self.current)
        self.current += 1
        self._started = False

    def _target(self, tel: Telemetry, item: MissionItem, home_alt: float, world) -> tuple[float, float, float]:
        """The item's ENU position; latitude and longitude 0 mean "here", altitude 0 of a landing "here"."""
        if item.x or item.y:
            alt = item.z if item.frame in _GLOBAL_FRAMES else home_alt + item.z
            return tuple(world.to_enu(item.x * 1e-7, item.y * 1e-7, alt))
        alt_rel = item.z - home_alt if item.frame in _GLOBAL_FRAMES else item.z
        return (tel.position[0], tel.position[1], alt_rel)

    def _begin(self, drone, tel, item: MissionItem, home_alt: float, cruise: float | None) -> CommandHandle | None:
        cmd = item.command
        on_ground = tel.landed_state in (LandedState.ON_GROUND, LandedState.UNKNOWN)
        self._hold_until = None
        if cmd in (mavlink.MAV_CMD_NAV_TAKEOFF, mavlink.MAV_CMD_NAV_WAYPOINT) and on_ground:
            # A take-off, or a first waypoint from the ground: climb first (a waypoint then starts again).
            self._kind = "climb"
            self._goal = (0.0, 0.0, max(self._target(tel, item, home_alt, drone.world)[2], 1.0))
            return drone.takeoff(self._goal[2])
        if cmd in (mavlink.MAV_CMD_NAV_TAKEOFF, mavlink.MAV_CMD_NAV_WAYPOINT):
            self._kind = "goto"
            self._goal = self._target(tel, item, home_alt, drone.world)
            yaw = item.params[3] if cmd == mavlink.MAV_CMD_NAV_WAYPOINT else math.nan
            return drone.goto(self._goal, heading_to_yaw(yaw) if math.isfinite(yaw) else None, cruise)
        if cmd in (mavlink.MAV_CMD_NAV_LAND, mavlink.MAV_CMD_NAV_RETURN_TO_LAUNCH):
            self._kind = "ground"
            return drone.land() if cmd == mavlink.MAV_CMD_NAV_LAND else drone.return_to_launch()
        if cmd != mavlink.MAV_CMD_DO_CHANGE_SPEED:
            logger.debug("mission item %d: command %d skipped", item.seq, cmd)
        return None

    def _reached(self, tel: Telemetry, item: MissionItem, acceptance: float) -> bool:
        if self._kind == "ground":
            return tel.landed_state == LandedState.ON_GROUND
        if self._kind == "climb":
            climbed = tel.landed_state == LandedState.IN_AIR and tel.position[2] >= self._goal[2] - 0.3
            if climbed and item.command == mavlink.MAV_CMD_NAV_WAYPOINT:
                self._started = False  # now fly to it
                return False
            return climbed
        radius = item.params[1] if item.command == mavlink.MAV_CMD_NAV_WAYPOINT and item.params[1] > 0 else acceptance
        gx, gy, gz = self._goal
        x, y, z = tel.position
        if math.hypot(gx - x, gy - y) > radius or abs(gz - z) > max(1.0, radius / 2):
            return False
        if self._hold_until is None:
            hold = item.params[0] if item.command == mavlink.MAV_CMD_NAV_WAYPOINT else 0.0
            self._hold_until = tel.time + max(hold, 0.0)
        return tel.time >= self._hold_until
