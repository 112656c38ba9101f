"""The simulated drone exposed over MAVLink as a PX4 or ArduCopter multicopter, so MAVSDK scripts and
QGroundControl can fly it.

:class:`MavlinkVehicle` owns a thread that advances the simulated drone on wall time x ``speed``, answers
commands, parameters, missions and offboard setpoints, and streams telemetry at rates a client may change
(SET_MESSAGE_INTERVAL, REQUEST_MESSAGE; REQUEST_DATA_STREAM as ArduPilot). As PX4 it streams at once; as
ArduPilot (``autopilot="ardupilot"``, :mod:`.ardupilot`) only what it is asked for. Streams and every timer
that waits on a client (offboard loss, mission retries) run on wall time,
so a fast simulation does not make a client look slow.
"""

from __future__ import annotations

import contextlib
import logging
import math
import threading
import time
from pathlib import Path

from aeroexec.drones.interface import LandedState, Telemetry
from aeroexec.drones.sim.mavlink.ardupilot import (
    COPTER_MODES,
    EKF_STATUS_REPORT,
    GUIDED_TIMEOUT_S,
    NEEDS_ORIGIN,
    ArduCopter,
    streamed_messages,
)
from aeroexec.drones.sim.mavlink.camera import COMPONENT as CAMERA
from aeroexec.drones.sim.mavlink.camera import CameraComponent
from aeroexec.drones.sim.mavlink.commands import CommandHandler
from aeroexec.drones.sim.mavlink.mission import MissionManager
from aeroexec.drones.sim.mavlink.offboard import OffboardControl, setpoint_from_global_int, setpoint_from_local_ned
from aeroexec.drones.sim.mavlink.onboard_log import OnboardLog, Sample, ned
from aeroexec.drones.sim.mavlink.params import ParameterServer, px4_parameters
from aeroexec.drones.sim.mavlink.streams import StreamScheduler
from aeroexec.drones.sim.mavlink.telemetry import DEFAULT_RATES_HZ, TelemetryEncoder, VehicleState, yaw_to_heading
from pymavlink import mavutil
from pymavlink.dialects.v20 import ardupilotmega
from pymavlink.dialects.v20 import common as mavlink

logger = logging.getLogger(__name__)

_LOOP_S = 0.01  # longest wait for input between two rounds of the vehicle's loop
AUTOPILOTS = ("px4", "ardupilot")
_SEVERITY = {
    "collision": mavlink.MAV_SEVERITY_CRITICAL,
    "failsafe": mavlink.MAV_SEVERITY_CRITICAL,
    "out_of_bounds": mavlink.MAV_SEVERITY_WARNING,
}


class MavlinkVehicleError(RuntimeError):
    """The vehicle cannot open its link (bad URL, port in use, unreachable TCP peer)."""


def normalize_url(url: str) -> str:
    """A pymavlink device string from a MAVSDK-style URL: ``udpout://127.0.0.1:14540`` -> ``udpout:127.0.0.1:14540``.

    Accepts udpout, udpin, tcpin and tcp/tcpout, with or without ``//``.
    """
    scheme, sep, rest = url.strip().partition(":")
    rest = rest[2:] if rest.startswith("//") else rest
    scheme = {"tcpout": "tcp", "udp": "udpin"}.get(scheme.lower(), scheme.lower())
    host, _, port = rest.rpartition(":")
    if not sep or scheme not in ("udpout", "udpin", "tcpin", "tcp") or not host or not port.isdigit():
        raise MavlinkVehicleError(
            f"bad MAVLink URL {url!r}: expected e.g. udpout://127.0.0.1:14540, udpin://0.0.0.0:14550, "
            "tcpin://0.0.0.0:5760 or tcpout://127.0.0.1:5760"
        )
    if not 0 < int(port) < 65536:
        raise MavlinkVehicleError(f"bad MAVLink URL {url!r}: port {port} out of range")
    return f"{scheme}:{host}:{port}"


class _GatedWriter:
    """The file pymavlink's encoder writes to: the link, unless the vehicle's link is cut."""

    def __init__(self, vehicle: MavlinkVehicle) -> None:
        self._vehicle = vehicle

    def write(self, buf: bytes) -> None:
        link = self._vehicle._link
        if link is not None and not self._vehicle.link_cut:
            link.write(buf)


class MavlinkVehicle:
    """A simulated drone behind a PX4- or ArduCopter-like MAVLink endpoint. ``start()`` it, ``stop()`` it.

    ``autopilot`` is ``px4`` or ``ardupilot``; ``ekf`` the simulated seconds after start at which an ArduCopter
    passes its pre-arm checks and then gets its GPS origin and home. With ``log_folder``, the vehicle writes its own
    flight log there from each arming to disarming, as the autopilot would (:mod:`.onboard_log`).
    """

    def __init__(
        self,
        drone,
        connect: str = "udpout:127.0.0.1:14540",
        speed: float = 1.0,
        system_id: int = 1,
        component_id: int = 1,
        autopilot: str = "px4",
        ekf: tuple[float, float] = (2.0, 5.0),
        log_folder: Path | None = None,
        camera: bool = False,
        camera_folder: Path | None = None,
    ) -> None:
        if not speed > 0 or not math.isfinite(speed):
            raise ValueError(f"the simulation speed must be a positive number, not {speed}")
        if autopilot not in AUTOPILOTS:
            raise ValueError(f"unknown autopilot {autopilot!r}: expected one of {', '.join(AUTOPILOTS)}")
        self.autopilot = autopilot
        self.copter = ArduCopter(*ekf) if autopilot == "ardupilot" else None
        self.drone = drone
        self.url = normalize_url(connect)
        self.speed = float(speed)
        self.system_id = system_id
        self.component_id = component_id
        self.link_cut = False
        dialect = mavlink if self.copter is None else ardupilotmega  # ArduPilot's has EKF_STATUS_REPORT too
        self.mav = dialect.MAVLink(_GatedWriter(self), srcSystem=system_id, srcComponent=component_id)
        self.mav.robust_parsing = True
        self.encoder = TelemetryEncoder(self.mav)
        config = drone.config
        self.params = ParameterServer(
            self.mav,
            px4_parameters(config.default_takeoff_altitude, config.cruise_speed, config.max_speed, system_id),
            statustext=self.statustext,
        )
        # ArduCopter streams nothing by default (every SRn_ rate is 0); PX4 streams its defaults.
        defaults = DEFAULT_RATES_HZ
        if self.copter is not None:
            defaults = dict.fromkeys([*DEFAULT_RATES_HZ, EKF_STATUS_REPORT], 0.0)
        self.streams = StreamScheduler(defaults)
        self.offboard = OffboardControl()
        self.mission = MissionManager(self.mav, self.statustext, first=1 if self.copter is not None else 0)
        self.commands = CommandHandler(self)
        #: the camera component (``camera``: the vehicle has one; photos saved in ``camera_folder`` when given)
        self.camera = CameraComponent(self, _GatedWriter(self), camera_folder) if camera else None
        self.speed_override: float | None = None  # DO_CHANGE_SPEED / DO_REPOSITION speed
        self.last_goto: tuple[tuple[float, float, float], float | None] | None = None
        self.latest: Telemetry = drone.telemetry()
        self._link = None
        self._thread: threading.Thread | None = None
        self._stop = threading.Event()
        self._snapshot = self.latest
        self._last_yaw = (self.latest.time, self.latest.yaw)
        self._yaw_rate = 0.0
        self._last_flags: tuple | None = None
        self._next_heartbeat = 0.0
        self._boot_utc = 0.0  # the GPS's UTC when the vehicle's clock read 0 (set as the loop starts)
        self.onboard_log: OnboardLog | None = None
        if log_folder is not None:
            from aeroexec import __version__

            name = "aeroexec sim (PX4 personality)" if self.copter is None else "aeroexec sim (ArduCopter personality)"
            self.onboard_log = OnboardLog(log_folder, autopilot, name, __version__)

    # --- public API --------------------------------------------------------------------------------
    def start(self) -> None:
        """Open the link and start the vehicle's thread."""
        if self._thread is not None:
            return
        try:
            self._link = mavutil.mavlink_connection(
                self.url, source_system=self.system_id, source_component=self.component_id, retries=1
            )
        except Exception as exc:  # pymavlink raises many kinds (OSError, ValueError, socket errors)
            raise MavlinkVehicleError(f"cannot open the MAVLink link {self.url}: {exc}") from exc
        self._stop.clear()
        self._thread = threading.Thread(target=self._run, name="aeroexec-mavlink-vehicle", daemon=True)
        self._thread.start()
        name = "PX4" if self.copter is None else "ArduCopter"
        logger.info("simulated %s vehicle %d on %s at %gx real time", name, self.system_id, self.url, self.speed)

    def stop(self, timeout: float = 2.0) -> None:
        """Stop the thread and close the link; returns within about ``timeout`` seconds."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout)
            if self._thread.is_alive():
                logger.warning("the simulated vehicle's thread did not stop within %.1f s", timeout)
            self._thread = None
        if self._link is not None:
            with contextlib.suppress(OSError):
                self._link.close()
            self._link = None
        if self.onboard_log is not None:
            self.onboard_log.close(self.latest.time)

    def cut_link(self) -> None:
        """Go silent and deaf, as if the radio link dropped (for tests)."""
        self.link_cut = True

    def restore_link(self) -> None:
        self.link_cut = False

    def telemetry(self) -> Telemetry:
        """The simulated drone's state as last sent (readable from any thread)."""
        return self._snapshot

    @property
    def running(self) -> bool:
        return self._thread is not None and self._thread.is_alive()

    def __enter__(self) -> MavlinkVehicle:
        self.start()
        return self

    def __exit__(self, *exc) -> None:
        self.stop()

    # --- used by the protocol handlers ---------------------------------------------------------------
    def wall_now(self) -> float:
        return time.monotonic()

    def home(self) -> tuple[float, float, float]:
        return self.latest.home or tuple(self.drone.world.to_geodetic((0.0, 0.0, 0.0)))

    def cruise_speed(self) -> float:
        return self.speed_override if self.speed_override is not None else self.params.get("MPC_XY_CRUISE")

    def statustext(self, severity: int, text: str) -> None:
        self.encoder.statustext(severity, text)

    def send_message(self, msg_id: int) -> None:
        state = self._state()
        if self._withheld(msg_id, state):
            return
        self.encoder.send(msg_id, state)

    def _withheld(self, msg_id: int, state: VehicleState) -> bool:
        """ArduCopter says nothing of where it is before its EKF has an origin."""
        return self.copter is not None and not state.position_ok and msg_id in NEEDS_ORIGIN

    # --- the loop ------------------------------------------------------------------------------------
    def _run(self) -> None:
        wall_start = time.monotonic()
        sim_start = self.latest.time
        self._boot_utc = time.time() - sim_start  # the simulated GPS's clock runs with the simulation's
        while not self._stop.is_set():
            try:
                wall = time.monotonic()
                self.drone.update(sim_start + (wall - wall_start) * self.speed)
                self.latest = self.drone.telemetry()
                self._receive(wall)
                self.latest = self.drone.telemetry()
                self._step(wall)
                self._send(wall)
            except Exception:  # keep flying: a broken message or a bug must not silence the vehicle
                logger.exception("simulated vehicle loop error")
                self._stop.wait(0.1)
            self._wait()

    def _wait(self) -> None:
        """Until input arrives or the loop period ends."""
        try:
            self._link.select(_LOOP_S)
        except (OSError, ValueError, AttributeError):
            self._stop.wait(_LOOP_S)

    def _receive(self, wall: float) -> None:
        link = self._link
        for _ in range(200):  # bounded: a flood of input must not starve the simulation
            data = link.recv(4096)
            if not data:
                return
            if self.link_cut:
                continue
            for msg in (
                self.mav.parse_buffer(bytearray(data.encode("latin-1") if isinstance(data, str) else data)) or []
            ):
                if msg.get_type() != "BAD_DATA" and self._for_us(msg):
                    self._dispatch(msg, wall)

    def _for_us(self, msg) -> bool:
        target_system = getattr(msg, "target_system", 0)
        target_component = getattr(msg, "target_component", 0)
        components = (0, self.component_id, CAMERA) if self.camera is not None else (0, self.component_id)
        return target_system in (0, self.system_id) and target_component in components

    def _dispatch(self, msg, wall: float) -> None:
        kind = msg.get_type()
        if self.camera is not None and getattr(msg, "target_component", 0) == CAMERA and self.camera.handle(msg):
            return
        if kind in ("COMMAND_LONG", "COMMAND_INT"):
            self.commands.handle(msg)
        elif kind == "SET_POSITION_TARGET_LOCAL_NED":
            self._setpoint(setpoint_from_local_ned(msg, self.latest), wall)
        elif kind == "SET_POSITION_TARGET_GLOBAL_INT":
            self._setpoint(setpoint_from_global_int(msg, self.latest, self.drone.world), wall)
        elif kind == "REQUEST_DATA_STREAM":
            self._data_stream(msg)
        elif self.params.handle(msg) or self.mission.handle(msg, wall):
            return
        elif kind not in ("HEARTBEAT", "TIMESYNC", "PING", "SYSTEM_TIME"):
            logger.debug("ignored %s from %d/%d", kind, msg.get_srcSystem(), msg.get_srcComponent())

    def _setpoint(self, setpoint, wall: float) -> None:
        if setpoint is None:
            logger.debug("offboard setpoint with an unsupported frame or mask ignored")
            return
        self.offboard.receive(setpoint, wall)
        tel = self.latest
        if (self.copter is not None and self.copter.mode == "GUIDED" and tel.flight_mode != "OFFBOARD"
                and tel.armed and tel.landed_state == LandedState.IN_AIR):
            self.offboard.engage(self.drone, tel, wall, GUIDED_TIMEOUT_S)  # GUIDED follows setpoints at once

    def _data_stream(self, msg) -> None:
        """REQUEST_DATA_STREAM, as ArduPilot reads it (PX4 ignores it): a group of messages at one rate."""
        if self.copter is None:
            logger.debug("REQUEST_DATA_STREAM ignored: PX4 uses SET_MESSAGE_INTERVAL")
            return
        hz = float(msg.req_message_rate) if msg.start_stop else 0.0
        for msg_id in streamed_messages(msg.req_stream_id):
            self.streams.set_interval(msg_id, 1e6 / hz if hz > 0 else -1)

    def _step(self, wall: float) -> None:
        self.commands.poll()
        self.mission.poll(wall)
        loss_s = GUIDED_TIMEOUT_S if self.copter is not None else self.params.get("COM_OF_LOSS_T")
        lost = self.offboard.step(self.drone, self.latest, wall, loss_s)
        if lost is not None:
            if self.copter is None:
                self.statustext(mavlink.MAV_SEVERITY_CRITICAL, f"Failsafe: {lost}, holding position")
            self.drone.hold()  # ArduCopter: GUIDED stops where it is, silently
        if self.copter is not None:
            self._ekf_news()
        self.mission.step(self.drone, self.latest, self.home()[2], self.params.get("NAV_ACC_RAD"), self.cruise_speed())
        for event in self.drone.events():
            if event.kind in ("failsafe", "collision"):
                self.mission.abort(event.kind)
            text = event.kind.replace("_", " ").capitalize() + (f": {event.detail}" if event.detail else "")
            self.statustext(_SEVERITY.get(event.kind, mavlink.MAV_SEVERITY_INFO), text)
        self.latest = self.drone.telemetry()

    def _ekf_news(self) -> None:
        """ArduCopter's EKF gets its origin once: say so, and send the new home unasked (as ArduPilot does)."""
        copter = self.copter
        if copter.origin_announced or not copter.position_ok(self.latest.time):
            return
        copter.origin_announced = True
        self.statustext(mavlink.MAV_SEVERITY_INFO, "EKF3 IMU0 origin set")
        self.statustext(mavlink.MAV_SEVERITY_INFO, "EKF3 IMU0 is using GPS")
        self.send_message(mavlink.MAVLINK_MSG_ID_HOME_POSITION)

    def _state(self) -> VehicleState:
        tel = self.latest
        t0, yaw0 = self._last_yaw
        if tel.time > t0:
            self._yaw_rate = ((tel.yaw - yaw0 + 180.0) % 360.0 - 180.0) / (tel.time - t0)
            self._last_yaw = (tel.time, tel.yaw)
        mission = self.mission
        mode = "MISSION" if mission.active else tel.flight_mode
        heartbeat, position_ok, ekf = None, True, 0
        if self.copter is not None:
            mode = self.copter.reported(tel.flight_mode, mission.active)
            heartbeat = self.copter.heartbeat_fields(mode, tel.armed)
            position_ok = self.copter.position_ok(tel.time)
            ekf = self.copter.ekf_flags(tel.time)
        return VehicleState(
            telemetry=tel,
            geodetic=tuple(self.drone.world.to_geodetic(tel.position)),
            home=self.home(),
            mode=mode,
            armable=self._armable(tel),
            yaw_rate=self._yaw_rate,
            mission_seq=mission.current,
            mission_total=len(mission.items),
            position_ok=position_ok,
            heartbeat=heartbeat,
            ekf_flags=ekf,
        )

    def _log(self, state: VehicleState) -> None:
        """The autopilot's own flight log: its estimate, its setpoint, its mode, on its boot clock."""
        tel = state.telemetry
        if not tel.armed and not self.onboard_log.recording:
            return  # on the ground, disarmed: nothing to log
        setpoint = self.drone.setpoint() if hasattr(self.drone, "setpoint") else None
        mode_number = COPTER_MODES.get(state.mode, 0) if self.copter is not None else 0
        self.onboard_log.record(Sample(
            boot_s=tel.time, utc_s=self._boot_utc + tel.time, position=ned(tel.position), velocity=ned(tel.velocity),
            heading=math.radians(yaw_to_heading(tel.yaw)), setpoint=None if setpoint is None else ned(setpoint),
            geodetic=state.geodetic, battery_remaining=tel.battery_percent / 100.0,
            battery_voltage=tel.battery_voltage, mode=state.mode), tel.armed, mode_number)

    def _armable(self, tel: Telemetry) -> bool:
        """The pre-arm check: what the simulated drone's arm() would accept (battery above failsafe, not crashed)."""
        if getattr(self.drone, "crashed", None):
            return False
        if self.copter is not None and not self.copter.prearm_ok(tel.time):
            return False
        return tel.battery_percent > getattr(self.drone.config, "failsafe_battery_percent", 7.0)

    def _send(self, wall: float) -> None:
        state = self._state()
        self._snapshot = state.telemetry
        tel = state.telemetry
        flags = (tel.armed, state.mode, tel.landed_state)
        if flags != self._last_flags or wall >= self._next_heartbeat:
            self.encoder.heartbeat(state)
            if self.camera is not None:
                self.camera.heartbeat()
            self._next_heartbeat = wall + 1.0
            if self._last_flags is not None and flags != self._last_flags:
                # State changed: tell now, not at the next stream slot (ArduCopter: only if it is streamed).
                if self.copter is None or self.streams.interval_us(mavlink.MAVLINK_MSG_ID_EXTENDED_SYS_STATE) != -1:
                    self.encoder.send(mavlink.MAVLINK_MSG_ID_EXTENDED_SYS_STATE, state)
                if flags[2] != self._last_flags[2] and tel.landed_state == LandedState.ON_GROUND:
                    self.statustext(mavlink.MAV_SEVERITY_INFO, "Landing detected")
            self._last_flags = flags
        if self.onboard_log is not None:
            self._log(state)
        for msg_id in self.streams.due(wall):
            if msg_id == mavlink.MAVLINK_MSG_ID_MISSION_CURRENT and not state.mission_total:
                continue
            if self._withheld(msg_id, state):
                continue
            self.encoder.send(msg_id, state)
