"""The MAVSDK adapter: a PX4, ArduPilot or ``aeroexec sim`` vehicle behind the drone interface (mavsdk 4.1).

Commands return at once; their handles complete when the autopilot accepts or refuses them. Telemetry is a
latest-value cache converted to local ENU meters from the vehicle's home position.
"""

from __future__ import annotations

import asyncio
import json
import logging
import math
import threading
import time

from aeroexec.drones.interface import (
    CAMERA_NONE,
    CAMERA_VEHICLE,
    CommandHandle,
    Drone,
    DroneEvent,
    Failure,
    Telemetry,
    Vector,
)
from aeroexec.drones.mavsdk.connection import COPTER_MODE_NUMBERS, TelemetryRates
from aeroexec.drones.mavsdk.errors import AdapterError
from aeroexec.drones.mavsdk.frames import enu_to_geodetic, enu_to_ned, yaw_to_heading
from aeroexec.drones.mavsdk.session import MavsdkSession
from mavsdk.asyncio.plugins.mavlink_direct import MavlinkMessage
from mavsdk.asyncio.plugins.offboard import VelocityNedYaw

logger = logging.getLogger(__name__)

_YAW_STEP = 0.1  # s between two heading updates of a velocity setpoint with a yaw rate
#: ArduCopter modes aeroexec arms in: GUIDED (its take-off, go-tos and setpoints), LOITER. After a landing the copter
#: is in LAND, and MAVSDK's arm first switches it to Hold, which is BRAKE on ArduCopter, where it refuses to arm
#: (``Arm: Brake mode not armable``): the adapter sets GUIDED before arming.
ARDUCOPTER_ARMS_IN = ("GUIDED", "LOITER")
#: The mode an ArduCopter holds in (docs/real-vehicles.md): MAVSDK's hold would put it in BRAKE.
ARDUCOPTER_HOLD = "LOITER"
_DO_SET_MODE = 176  # MAV_CMD_DO_SET_MODE
_IMAGE_START_CAPTURE = 2000  # MAV_CMD_IMAGE_START_CAPTURE
_CUSTOM_MODE_ENABLED = 1  # MAV_MODE_FLAG_CUSTOM_MODE_ENABLED


def _said(cache) -> str:
    """The autopilot's last words, when it said why (``: Flight mode change failed: ...``)."""
    text = getattr(cache, "status_text", None)
    return f": {text}" if text else ""


class MavsdkDrone(Drone):
    """A MAVLink vehicle reached through MAVSDK.

    ``url`` is a MAVSDK connection URL: ``udpin://0.0.0.0:14540`` (PX4 SITL, ``aeroexec sim``),
    ``tcpout://127.0.0.1:5760`` (ArduPilot SITL), ``serial:///dev/ttyUSB0:57600``. The adapter connects in
    the background; :meth:`wait_ready` blocks until the vehicle can be flown, and ``arm``/``takeoff`` wait
    for that themselves (up to ``ready_timeout``). The link counts as lost after ``link_timeout`` seconds
    without telemetry. ArduPilot's GUIDED mode, which MAVSDK reports as OFFBOARD, is named GUIDED here.
    """

    def __init__(
        self,
        url: str,
        *,
        command_timeout: float = 15.0,
        ready_timeout: float = 30.0,
        link_timeout: float = 1.5,
        rates: TelemetryRates | None = None,
        close_timeout: float = 3.0,
    ) -> None:
        self.command_timeout = command_timeout
        self.ready_timeout = ready_timeout
        self.close_timeout = close_timeout
        self._time_lock = threading.Lock()
        self._owner_time: tuple[float, float] | None = None  # (owner's now, monotonic) at the last update()
        self._session = MavsdkSession(url, clock=self._now, rates=rates or TelemetryRates(), link_timeout=link_timeout)
        self._yaw_task: asyncio.Task | None = None
        self._offboard = False  # we started offboard control and stream velocity setpoints
        self._photos = 0  # photos asked of the vehicle's camera
        self._session.start()

    # --- state -------------------------------------------------------------------------------------
    @property
    def url(self) -> str:
        return self._session.url

    @property
    def connection_error(self) -> str | None:
        """Why the connection could not be opened (bad port, missing serial device), None otherwise."""
        return self._session.error

    @property
    def autopilot(self) -> str:
        return "ardupilot" if self._session.ardupilot else "px4"

    def wait_ready(self, timeout: float) -> bool:
        """Block until connected, armable, with global and home positions (for scripts and tests, not ticks)."""
        return self._session.wait_ready(timeout)

    def not_ready_because(self) -> list[str]:
        """What the vehicle lacks before it can be flown, in words; empty when ready."""
        if self._session.error is not None:
            return [self._session.error]
        if not self._session.cache.connected:
            return ["no vehicle connected"]
        return self._session.cache.missing()

    def _now(self) -> float:
        """The owner's clock, extrapolated on wall time from the last ``update(now)``."""
        with self._time_lock:
            if self._owner_time is None:
                return time.monotonic()
            owner, wall = self._owner_time
        return owner + (time.monotonic() - wall)

    def update(self, now: float) -> None:
        wall = time.monotonic()
        with self._time_lock:
            first = self._owner_time is None
            self._owner_time = (now, wall)
        if first:  # what happened before the owner's clock started keeps its time, before ``now``
            self._session.cache.retime(lambda stamp: now - (wall - stamp))

    def telemetry(self) -> Telemetry:
        return self._session.cache.snapshot()

    def events(self) -> list[DroneEvent]:
        return self._session.cache.events()

    def close(self) -> None:
        self._session.close(self.close_timeout)

    def __enter__(self) -> MavsdkDrone:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    # --- commands ----------------------------------------------------------------------------------
    def arm(self) -> CommandHandle:
        return self._submit("arm", self._arm)

    def disarm(self) -> CommandHandle:
        return self._submit("disarm", lambda: self._session.call(self._session.action.disarm()))

    def takeoff(self, altitude: float) -> CommandHandle:
        if not (math.isfinite(altitude) and altitude > 0.0):
            return CommandHandle.failed(
                "takeoff", Failure.DENIED, f"takeoff denied: altitude {altitude} m is not above home"
            )

        async def body() -> None:
            s = self._session
            await self._leave_offboard()
            await s.call(s.action.set_takeoff_altitude(float(altitude)))
            if not s.cache.armed:
                await self._arm()
            await s.call(s.action.takeoff())

        return self._submit("takeoff", body, self.ready_timeout + self.command_timeout)

    def photo_source(self) -> str:
        """The vehicle's camera (a MAVLink camera component heard on the link: PX4's, ArduPilot's, ``aeroexec sim
        --camera``), else none."""
        return CAMERA_VEHICLE if self._session.cache.camera_component is not None else CAMERA_NONE

    def wait_camera(self, timeout: float) -> bool:
        """Block until the vehicle's camera has been heard (its heartbeat comes once a second), False on timeout."""
        deadline = time.monotonic() + timeout
        while self._session.cache.camera_component is None and time.monotonic() < deadline:
            time.sleep(0.05)
        return self._session.cache.camera_component is not None

    def take_photo(self) -> CommandHandle:
        """One photo by the vehicle's camera: MAV_CMD_IMAGE_START_CAPTURE (one image) to its component, through
        MAVLink direct; done when the camera acknowledges it."""
        component = self._session.cache.camera_component
        if component is None:
            return CommandHandle.failed("take_photo", Failure.UNSUPPORTED, "the vehicle has no camera")
        self._photos += 1
        sequence = self._photos

        async def body() -> None:
            s = self._session
            command = MavlinkMessage(message_name="COMMAND_LONG", system_id=0, component_id=0,
                                     target_system_id=s.system_id, target_component_id=component,
                                     fields_json=json.dumps({
                                         "target_system": s.system_id, "target_component": component,
                                         "command": _IMAGE_START_CAPTURE, "confirmation": 0, "param1": 0,
                                         "param2": 0, "param3": 1, "param4": sequence, "param5": 0, "param6": 0,
                                         "param7": 0}))
            ack = await s.call(s.direct.send_command(command))
            result = json.loads(ack.fields_json or "{}").get("result")
            if result != 0:
                raise AdapterError(Failure.DENIED, f"the vehicle's camera did not take photo {sequence} "
                                                   f"(MAV_RESULT {result}{_said(s.cache)})")

        return self._submit("take_photo", body)

    def land(self) -> CommandHandle:
        return self._submit("land", self._simple("land"))

    def return_to_launch(self) -> CommandHandle:
        return self._submit("return_to_launch", self._simple("return_to_launch"))

    def hold(self) -> CommandHandle:
        async def body() -> None:
            left = await self._leave_offboard()  # leaving offboard puts the vehicle in HOLD (ArduCopter: BRAKE)
            if self._session.ardupilot:  # ArduCopter holds in LOITER (MAVSDK's hold is BRAKE: it cannot arm there)
                await self._copter_mode(ARDUCOPTER_HOLD, "to hold")
            elif not left:
                await self._session.call(self._session.action.hold())

        return self._submit("hold", body)

    def goto(self, position: Vector, yaw: float | None = None, speed: float | None = None) -> CommandHandle:
        if len(position) != 3 or not all(math.isfinite(v) for v in position):
            return CommandHandle.failed("goto", Failure.DENIED, f"goto denied: bad position {position!r}")
        if speed is not None and not (math.isfinite(speed) and speed > 0.0):
            return CommandHandle.failed("goto", Failure.DENIED, f"goto denied: bad speed {speed!r}")
        target = tuple(float(v) for v in position)

        async def body() -> None:
            s = self._session
            home = s.cache.home
            if home is None:
                raise AdapterError(Failure.DENIED, "the vehicle has no home position yet")
            lat, lon, alt = enu_to_geodetic(target, home)
            heading = yaw_to_heading(yaw) if yaw is not None else math.nan
            await self._leave_offboard()
            await s.call(s.action.goto_location(lat, lon, alt, heading))
            if speed is not None:
                await s.call(s.action.set_current_speed(float(speed)))

        return self._submit("goto", body)

    def set_velocity(self, velocity: Vector, yaw_rate: float = 0.0) -> CommandHandle:
        if len(velocity) != 3 or not all(math.isfinite(v) for v in (*velocity, yaw_rate)):
            return CommandHandle.failed(
                "set_velocity", Failure.DENIED, f"set_velocity denied: bad velocity {velocity!r}"
            )
        north, east, down = enu_to_ned(tuple(float(v) for v in velocity))

        async def body() -> None:
            s = self._session
            self._stop_yaw()
            heading = s.cache.heading
            await s.call(s.offboard.set_velocity_ned(VelocityNedYaw(north, east, down, heading)))
            if not (self._offboard and s.cache.flight_mode in ("OFFBOARD", "GUIDED")):
                await s.call(s.offboard.start())  # MAVSDK streams the setpoint from now on
                self._offboard = True
            if yaw_rate:
                self._yaw_task = s.spawn(self._turn(north, east, down, heading, yaw_rate))

        return self._submit("set_velocity", body)

    # --- helpers (on the adapter's loop) -------------------------------------------------------------
    def _submit(self, name: str, body, timeout: float | None = None) -> CommandHandle:
        return self._session.submit(name, body, timeout or self.command_timeout)

    def _simple(self, action: str):
        async def body() -> None:
            await self._leave_offboard()
            await self._session.call(getattr(self._session.action, action)())

        return body

    async def _arm(self) -> None:
        s = self._session
        if not await s.wait_until(lambda: s.cache.ready() or s.cache.armed, self.ready_timeout):
            missing = ", ".join(s.cache.missing()) or "not ready"
            raise AdapterError(Failure.DENIED, f"the vehicle is not ready after {self.ready_timeout:g} s: {missing}")
        if s.ardupilot and not s.cache.armed and s.cache.flight_mode not in ARDUCOPTER_ARMS_IN:
            await self._copter_mode("GUIDED", "to arm")
        await s.call(s.action.arm())

    async def _copter_mode(self, name: str, why: str) -> None:
        """Put an ArduCopter in mode ``name`` (DO_SET_MODE through MAVLink direct), and wait until it says so."""
        s = self._session
        before = s.cache.flight_mode
        command = MavlinkMessage(message_name="COMMAND_LONG", system_id=0, component_id=0,
                                 target_system_id=s.system_id, target_component_id=1,
                                 fields_json=json.dumps({
                                     "target_system": s.system_id, "target_component": 1, "command": _DO_SET_MODE,
                                     "confirmation": 0, "param1": _CUSTOM_MODE_ENABLED,
                                     "param2": COPTER_MODE_NUMBERS[name], "param3": 0, "param4": 0, "param5": 0,
                                     "param6": 0, "param7": 0}))
        ack = await s.call(s.direct.send_command(command))
        result = json.loads(ack.fields_json or "{}").get("result")
        if result != 0:
            raise AdapterError(Failure.DENIED, f"the vehicle did not switch from {before} to {name} {why} "
                                               f"(MAV_RESULT {result}{_said(s.cache)})")
        if not await s.wait_until(lambda: s.cache.flight_mode == name, self.command_timeout):
            raise AdapterError(Failure.DENIED, f"the vehicle still says {s.cache.flight_mode} after switching to "
                                               f"{name} {why}")
        logger.info("%s: switched from %s to %s %s", s.url, before, name, why)

    async def _leave_offboard(self) -> bool:
        """Stop streaming velocity setpoints (the vehicle goes to HOLD); True when offboard was active."""
        s = self._session
        self._stop_yaw()
        if not self._offboard:
            return False
        await s.call(s.offboard.stop())
        self._offboard = False
        return True

    def _stop_yaw(self) -> None:
        if self._yaw_task is not None:
            self._yaw_task.cancel()
            self._yaw_task = None

    async def _turn(self, north: float, east: float, down: float, heading: float, yaw_rate: float) -> None:
        """Advance the setpoint's heading at ``yaw_rate`` (deg/s, counterclockwise) while the velocity holds."""
        s = self._session
        loop = asyncio.get_running_loop()
        start = loop.time()
        while True:
            await asyncio.sleep(_YAW_STEP)
            target = (heading - yaw_rate * (loop.time() - start)) % 360.0
            try:
                await s.call(s.offboard.set_velocity_ned(VelocityNedYaw(north, east, down, target)))
            except Exception as exc:
                logger.info("velocity setpoint update failed: %s", exc)
                return
