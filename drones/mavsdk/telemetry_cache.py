"""The MAVSDK adapter's latest-value telemetry cache and link watchdog.

MAVSDK subscriptions write the newest value of each stream under a lock (nothing queues, so nothing goes
stale); the engine reads a :class:`Telemetry` snapshot in ENU from home. The cache also turns link loss and
recovery, disarming, touchdown and autopilot warnings into :class:`DroneEvent` s.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable

from aeroexec.drones.interface import DroneEvent, LandedState, Telemetry
from aeroexec.drones.mavsdk.frames import geodetic_to_enu, heading_to_yaw, ned_to_enu

_EVENT_SEVERITIES = ("WARNING", "ERROR", "CRITICAL", "ALERT", "EMERGENCY")
_MAX_EVENTS = 1000


class TelemetryCache:
    """Latest values of the vehicle's telemetry; every method is thread-safe and returns at once."""

    def __init__(self, clock: Callable[[], float], silence_limit: float = 1.5) -> None:
        self._clock = clock  # the owner's time, stamped on snapshots and events
        self.silence_limit = silence_limit  # s without telemetry before the link counts as lost
        self._lock = threading.Lock()
        self.position: tuple[float, float, float] | None = None  # lat, lon, altitude AMSL
        self.position_time: float | None = None  # the owner's time when the position last came
        self.velocity_ned = (0.0, 0.0, 0.0)
        self.heading = 90.0  # degrees, 0 = north, clockwise (ATTITUDE yaw)
        self.battery = (100.0, 16.8)  # percent, volts
        self.armed = False
        self.landed_state = LandedState.UNKNOWN
        self.flight_mode = "UNKNOWN"
        self.camera_component: int | None = None  # the MAVLink component id of the vehicle's camera, once heard
        self.home: tuple[float, float, float] | None = None
        self.position_accuracy: float | None = None  # m, horizontal (GPS_RAW_INT h_acc)
        self.armable = False
        self.global_position_ok = False
        self.home_position_ok = False
        self.restores = 0  # times the link came back after a loss
        self.health_seen = False  # a health report (SYS_STATUS) came: MAVSDK's health is the vehicle's
        self.connected = False
        self.link_ok = False
        self.status_text = ""
        self._status_time = -1e9
        self._last_rx: float | None = None
        self._deaf = 0.0  # s since the last telemetry during which the adapter's loop was held up, not listening
        self._linked_once = False
        self._events: list[DroneEvent] = []

    # --- writers (MAVSDK subscriptions, on the adapter's event loop) ----------------------------------
    def set(self, **values) -> None:
        """Store new values; any of them proves the link is alive."""
        now = time.monotonic()
        measured = self._clock() if "position" in values else None
        with self._lock:
            if measured is not None:
                self.position_time = measured
            for name, value in values.items():
                old = getattr(self, name)
                setattr(self, name, value)
                if name == "armed" and old and not value:
                    self._event("disarmed")
                elif (
                    name == "landed_state"
                    and value == LandedState.ON_GROUND
                    and old in (LandedState.IN_AIR, LandedState.LANDING)
                ):
                    self._event("landed")
            self._last_rx, self._deaf = now, 0.0
            if not self.link_ok and self.connected:
                self._restore()

    def set_status_text(self, severity: str, text: str) -> None:
        with self._lock:
            self.status_text = text
            self._status_time = time.monotonic()
            self._last_rx, self._deaf = self._status_time, 0.0
            if severity in _EVENT_SEVERITIES:
                self._event("status_text", text, {"severity": severity})

    def set_connected(self, connected: bool, detail: str = "") -> bool:
        """MAVSDK's own view of the link (heartbeats within its timeout); True when this loses the link.

        MAVSDK says "disconnected" only after its own, longer timeout: when telemetry came within the silence
        limit, that report is about a drop the watchdog already counted (and saw end), not a new one."""
        with self._lock:
            self.connected = connected
            recent = self._last_rx is not None and time.monotonic() - self._last_rx - self._deaf <= self.silence_limit
            if not connected and self.link_ok and not recent:
                self._lose(detail or "MAVSDK reports the vehicle disconnected")
                return True
            if connected and not self.link_ok and self._last_rx is not None:
                self._restore()
            return False

    def not_listening(self, seconds: float) -> None:
        """The adapter's loop was held up for ``seconds`` (a loaded machine): no telemetry could be read then, so
        that time does not count as the vehicle's silence."""
        with self._lock:
            self._deaf += seconds

    def check_link(self, silence_limit: float) -> bool:
        """The watchdog: declare the link lost once no telemetry came for ``silence_limit`` seconds of listening.

        True when this call declared it lost.
        """
        with self._lock:
            if self.link_ok and self._last_rx is not None:
                age = time.monotonic() - self._last_rx - self._deaf
                if age > silence_limit:
                    self._lose(f"no telemetry for {age:.1f} s")
                    return True
            return False

    def add_event(self, kind: str, detail: str = "", data: dict | None = None) -> None:
        with self._lock:
            self._event(kind, detail, data)

    def _lose(self, detail: str) -> None:
        self.link_ok = False
        self._event("link_lost", detail, self._where())

    def _where(self) -> dict:
        """Where the vehicle was last seen: height above home (m) and whether it was in the air."""
        height = None
        if self.position is not None and self.home is not None:
            height = round(self.position[2] - self.home[2], 2)
        in_air = self.landed_state in (LandedState.IN_AIR, LandedState.TAKING_OFF, LandedState.LANDING)
        return {"altitude": height, "in_air": bool(in_air or (self.armed and height is not None and height > 0.5))}

    def _restore(self) -> None:
        self.link_ok = True
        if self._linked_once:  # the first link is a connection, not a recovery
            self._event("link_restored")
            self.restores += 1
        self._linked_once = True

    def _event(self, kind: str, detail: str = "", data: dict | None = None) -> None:
        if len(self._events) < _MAX_EVENTS:
            self._events.append(DroneEvent(self._clock(), kind, detail, data or {}))

    def retime(self, owner_time: Callable[[float], float]) -> None:
        """Restamp the events not yet read, and when the position came, with ``owner_time(stamp)`` (when the owner's
        clock starts: what came before it was stamped with the monotonic clock)."""
        with self._lock:
            self._events = [DroneEvent(owner_time(e.time), e.kind, e.detail, e.data) for e in self._events]
            if self.position_time is not None:
                self.position_time = owner_time(self.position_time)

    # --- readers --------------------------------------------------------------------------------------
    def events(self) -> list[DroneEvent]:
        with self._lock:
            events, self._events = self._events, []
        return events

    def recent_status_text(self, within: float = 2.0) -> str:
        with self._lock:
            return self.status_text if time.monotonic() - self._status_time <= within else ""

    def ready(self) -> bool:
        return not self.missing()

    def missing(self) -> list[str]:
        """What the vehicle still lacks before it can be flown, in words (empty when ready)."""
        with self._lock:
            if not self.health_seen:  # MAVSDK's health flags mean nothing yet
                gaps = ["no health report (SYS_STATUS) from the vehicle: is its stream rate requested?"]
                gaps += ["no position"] if self.position is None else []
                return gaps + (["no home position"] if self.home is None else [])
            gaps = []
            if not self.global_position_ok or self.position is None:
                gaps.append("no global position")
            if not self.home_position_ok or self.home is None:
                gaps.append("no home position")
            if not (self.armable or self.armed):
                gaps.append("pre-arm checks failing (not armable)")
            return gaps

    def snapshot(self) -> Telemetry:
        with self._lock:
            position = (0.0, 0.0, 0.0)
            if self.position is not None and self.home is not None:
                position = geodetic_to_enu(self.position, self.home)
            return Telemetry(
                time=self._clock(),
                position=position,
                velocity=ned_to_enu(*self.velocity_ned),
                yaw=heading_to_yaw(self.heading),
                battery_percent=self.battery[0],
                battery_voltage=self.battery[1],
                armed=self.armed,
                landed_state=self.landed_state,
                flight_mode=self.flight_mode,
                link_ok=self.link_ok,
                home=self.home,
                position_accuracy=self.position_accuracy,
                position_time=self.position_time,
            )
