"""The simulated autopilot's own flight log, as the real ones write it: a PX4 ULog (``.ulg``) or an ArduPilot
DataFlash log (``.BIN``), from arming to disarming, on the autopilot's boot clock.

The files follow the published formats (PX4's ULog file format, version 1; ArduPilot's DataFlash binary log with
self-describing FMT records), so `pyulog`, pymavlink's ``DFReader``, PX4 Flight Review and MAVExplorer read them.
The topics are the ones the real autopilots log under the same names and fields, a subset of them: the estimate
(``vehicle_local_position`` / ``XKF1``), the position controller's setpoint (``vehicle_local_position_setpoint`` /
``PSCN``, ``PSCE``, ``PSCD``), the global position, the battery, the arming state and the flight mode, and GPS
time (``vehicle_gps_position.time_utc_usec`` / ``GPS.GWk``, ``GMS``). The simulator's name is written where the
autopilot writes its own (``sys_name``, the first ``MSG``), so no tool mistakes the file for a flight of PX4 or
ArduPilot itself.
"""

from __future__ import annotations

import datetime
import logging
import math
import struct
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import BinaryIO

logger = logging.getLogger(__name__)

#: Seconds GPS time is ahead of UTC (leap seconds since 1980, as of 2017 and still).
GPS_LEAP_S = 18
_GPS_EPOCH = datetime.datetime(1980, 1, 6, tzinfo=datetime.UTC)
SAMPLE_S = 0.04  # simulated seconds between two samples of the estimate and the setpoint (25 Hz)

#: PX4's vehicle_status.nav_state numbers (PX4-Autopilot msg/VehicleStatus.msg) of the simulated drone's modes.
PX4_NAV_STATES = {"MANUAL": 0, "ALTCTL": 1, "POSCTL": 2, "MISSION": 3, "HOLD": 4, "RETURN": 5, "OFFBOARD": 14,
                  "TAKEOFF": 17, "LAND": 18}
PX4_ARMED, PX4_DISARMED = 2, 1  # vehicle_status.arming_state
AP_EVENT_ARMED, AP_EVENT_DISARMED = 10, 11  # ArduPilot's EV ids (AP_Logger LogEvent)


@dataclass(frozen=True)
class Sample:
    """What the autopilot logs at one instant: times on its boot clock, positions in NED metres from home."""

    boot_s: float  # seconds since the autopilot started
    utc_s: float  # the GPS's UTC time, seconds since 1970
    position: tuple[float, float, float]  # estimate, NED
    velocity: tuple[float, float, float]  # NED
    heading: float  # radians, 0 = north, clockwise
    setpoint: tuple[float, float, float] | None  # the position controller's target, NED (None: not controlled)
    geodetic: tuple[float, float, float]  # latitude, longitude, altitude AMSL
    battery_remaining: float  # 0..1
    battery_voltage: float
    mode: str  # the autopilot's mode name (PX4 nav state or Copter mode)


class ULogWriter:
    """A PX4 ULog file (version 1): definitions first, then data and logged strings."""

    TOPICS = {
        "vehicle_local_position": "uint64_t timestamp;float x;float y;float z;float vx;float vy;float vz;"
                                  "float heading;bool xy_valid;bool z_valid",
        "vehicle_local_position_setpoint": "uint64_t timestamp;float x;float y;float z;float vx;float vy;float vz;"
                                           "float yaw",
        "vehicle_global_position": "uint64_t timestamp;double lat;double lon;float alt",
        "vehicle_gps_position": "uint64_t timestamp;uint64_t time_utc_usec;double latitude_deg;double longitude_deg;"
                                "double altitude_msl_m;uint8_t fix_type",
        "battery_status": "uint64_t timestamp;float voltage_v;float remaining",
        "vehicle_status": "uint64_t timestamp;uint8_t arming_state;uint8_t nav_state",
    }
    _PACK = {
        "vehicle_local_position": struct.Struct("<Q7f??"),
        "vehicle_local_position_setpoint": struct.Struct("<Q7f"),
        "vehicle_global_position": struct.Struct("<Qddf"),
        "vehicle_gps_position": struct.Struct("<QQdddB"),
        "battery_status": struct.Struct("<Qff"),
        "vehicle_status": struct.Struct("<QBB"),
    }

    def __init__(self, file: BinaryIO, boot_us: int, info: dict[str, str]) -> None:
        self._file = file
        file.write(b"ULog\x01\x12\x35" + bytes([1]) + struct.pack("<Q", boot_us))
        self._message(b"B", bytes(16) + struct.pack("<3Q", 0, 0, 0))  # flag bits: nothing appended, nothing new
        for name, fields in self.TOPICS.items():
            self._message(b"F", f"{name}:{fields}".encode())
        for key, value in info.items():
            encoded = value.encode()
            field = f"char[{len(encoded)}] {key}".encode()
            self._message(b"I", bytes([len(field)]) + field + encoded)
        self._ids = {}
        for msg_id, name in enumerate(self.TOPICS):
            self._ids[name] = msg_id
            self._message(b"A", struct.pack("<BH", 0, msg_id) + name.encode())

    def _message(self, kind: bytes, payload: bytes) -> None:
        self._file.write(struct.pack("<H", len(payload)) + kind + payload)

    def data(self, topic: str, *values: float | int | bool) -> None:
        self._message(b"D", struct.pack("<H", self._ids[topic]) + self._PACK[topic].pack(*values))

    def text(self, boot_us: int, level: int, message: str) -> None:
        """A logged string ('L'); ``level`` as syslog (6 info, 4 warning)."""
        self._message(b"L", bytes([ord(str(level))]) + struct.pack("<Q", boot_us) + message.encode())

    def sample(self, s: Sample, arming_state: int) -> None:
        t = int(s.boot_s * 1e6)
        x, y, z = s.position
        vx, vy, vz = s.velocity
        self.data("vehicle_local_position", t, x, y, z, vx, vy, vz, s.heading, True, True)
        sx, sy, sz = s.setpoint if s.setpoint is not None else (math.nan,) * 3
        self.data("vehicle_local_position_setpoint", t, sx, sy, sz, math.nan, math.nan, math.nan, math.nan)
        lat, lon, alt = s.geodetic
        self.data("vehicle_global_position", t, lat, lon, alt)
        self.data("vehicle_gps_position", t, int(s.utc_s * 1e6), lat, lon, alt, 3)
        self.data("battery_status", t, s.battery_voltage, s.battery_remaining)
        self.data("vehicle_status", t, arming_state, PX4_NAV_STATES.get(s.mode, 0))


class DataFlashWriter:
    """An ArduPilot DataFlash binary log: each record type described by a FMT record before its first use."""

    HEAD = b"\xa3\x95"
    #: name: (format characters, columns), as AP_Logger's LogStructure.h names them (a subset of the columns).
    RECORDS = {
        "MSG": ("QZ", "TimeUS,Message"),
        "MODE": ("QMBB", "TimeUS,Mode,ModeNum,Rsn"),
        "EV": ("QB", "TimeUS,Id"),
        "XKF1": ("QBfffffffff", "TimeUS,C,Roll,Pitch,Yaw,VN,VE,VD,PN,PE,PD"),
        "PSCN": ("Qffff", "TimeUS,TPN,PN,TVN,VN"),
        "PSCE": ("Qffff", "TimeUS,TPE,PE,TVE,VE"),
        "PSCD": ("Qffff", "TimeUS,TPD,PD,TVD,VD"),
        "POS": ("QLLff", "TimeUS,Lat,Lng,Alt,RelHomeAlt"),
        "GPS": ("QBIHLLf", "TimeUS,Status,GMS,GWk,Lat,Lng,Alt"),
        "BAT": ("QBffB", "TimeUS,Inst,Volt,Curr,RemPct"),
    }
    _CHARS = {"Q": "Q", "Z": "64s", "M": "B", "B": "B", "f": "f", "L": "i", "I": "I", "H": "H", "N": "16s",
              "n": "4s"}

    def __init__(self, file: BinaryIO) -> None:
        self._file = file
        self._structs: dict[str, tuple[int, struct.Struct]] = {}
        fmt = struct.Struct("<BB4s16s64s")
        self._file.write(self.HEAD + bytes([128]) + fmt.pack(128, 3 + fmt.size, b"FMT", b"BBnNZ",
                                                              b"Type,Length,Name,Format,Columns"))
        for type_id, (name, (chars, columns)) in enumerate(self.RECORDS.items(), start=129):
            packer = struct.Struct("<" + "".join(self._CHARS[c] for c in chars))
            self._structs[name] = (type_id, packer)
            self._file.write(self.HEAD + bytes([128]) + fmt.pack(type_id, 3 + packer.size, name.encode(),
                                                                  chars.encode(), columns.encode()))

    def record(self, name: str, *values: float | int | bytes) -> None:
        type_id, packer = self._structs[name]
        self._file.write(self.HEAD + bytes([type_id]) + packer.pack(*values))

    def message(self, boot_us: int, text: str) -> None:
        self.record("MSG", boot_us, text.encode()[:64])

    def sample(self, s: Sample, mode_number: int) -> None:
        t = int(s.boot_s * 1e6)
        pn, pe, pd = s.position
        vn, ve, vd = s.velocity
        self.record("XKF1", t, 0, 0.0, 0.0, math.degrees(s.heading) % 360.0, vn, ve, vd, pn, pe, pd)
        target = s.setpoint if s.setpoint is not None else (math.nan,) * 3
        self.record("PSCN", t, target[0], pn, math.nan, vn)
        self.record("PSCE", t, target[1], pe, math.nan, ve)
        self.record("PSCD", t, target[2], pd, math.nan, vd)
        lat, lon, alt = s.geodetic
        self.record("POS", t, round(lat * 1e7), round(lon * 1e7), alt, -pd)
        week, week_ms = gps_week_time(s.utc_s)
        self.record("GPS", t, 3, week_ms, week, round(lat * 1e7), round(lon * 1e7), alt)
        self.record("BAT", t, 0, s.battery_voltage, 0.0, round(max(0.0, min(1.0, s.battery_remaining)) * 100))


def gps_week_time(utc_s: float) -> tuple[int, int]:
    """The GPS week and milliseconds into it of a UTC time (seconds since 1970)."""
    gps = utc_s + GPS_LEAP_S - _GPS_EPOCH.timestamp()
    week = int(gps // (7 * 86400))
    return week, int(round((gps - week * 7 * 86400) * 1000))


class OnboardLog:
    """The autopilot's logger: a new file at each arming, closed at disarming, in ``folder``.

    PX4 names it ``log/YYYY-MM-DD/HH_MM_SS.ulg`` (UTC); ArduPilot numbers it ``logs/00000001.BIN`` and writes the
    last number to ``logs/LASTLOG.TXT``. ``record`` is called by the vehicle's loop; it writes a sample every
    :data:`SAMPLE_S` of simulated time while armed.
    """

    def __init__(self, folder: Path, autopilot: str, system_name: str, version: str) -> None:
        self.folder = Path(folder)
        self.autopilot = autopilot
        self._system_name = system_name
        self._version = version
        self._file: BinaryIO | None = None
        self._writer: ULogWriter | DataFlashWriter | None = None
        self._next = 0.0
        self._mode: str | None = None
        self.paths: list[Path] = []

    @property
    def recording(self) -> bool:
        """A file is open (between an arming and its disarming)."""
        return self._writer is not None

    def record(self, sample: Sample, armed: bool, mode_number: int = 0) -> None:
        """Log the vehicle's state now; opens a file when it arms, closes it when it disarms."""
        if armed and self._writer is None:
            self._open(sample)
        if self._writer is None:
            return
        boot_us = int(sample.boot_s * 1e6)
        if sample.mode != self._mode:
            self._mode = sample.mode
            if isinstance(self._writer, DataFlashWriter):
                self._writer.record("MODE", boot_us, mode_number, mode_number, 1)
            else:
                self._writer.text(boot_us, 6, f"[commander] mode {sample.mode}")
        if not armed:
            self._sample(sample, armed)
            self.close(sample.boot_s)
            return
        if sample.boot_s >= self._next:
            self._next = sample.boot_s + SAMPLE_S
            self._sample(sample, armed)

    def _sample(self, sample: Sample, armed: bool) -> None:
        if isinstance(self._writer, ULogWriter):
            self._writer.sample(sample, PX4_ARMED if armed else PX4_DISARMED)
        elif self._writer is not None:
            self._writer.sample(sample, 0)

    def _open(self, sample: Sample) -> None:
        boot_us = int(sample.boot_s * 1e6)
        try:
            path = self._new_path(sample.utc_s)
            path.parent.mkdir(parents=True, exist_ok=True)
            self._file = path.open("wb")
        except OSError as error:
            logger.warning("the vehicle cannot write its flight log in %s: %s", self.folder, error)
            self._next = math.inf
            return
        self.paths.append(path)
        if self.autopilot == "px4":
            self._writer = ULogWriter(self._file, boot_us, {"sys_name": self._system_name,
                                                            "ver_sw": self._version})
            self._writer.text(boot_us, 6, "[commander] Armed by external command")
        else:
            self._writer = DataFlashWriter(self._file)
            self._writer.message(boot_us, f"{self._system_name} {self._version}")
            self._writer.record("EV", boot_us, AP_EVENT_ARMED)
        self._mode = None
        self._next = 0.0
        logger.info("flight log %s", path)

    def close(self, boot_s: float | None = None) -> None:
        """Close the file (at disarming, or when the vehicle stops)."""
        if self._writer is None or self._file is None:
            return
        boot_us = int((boot_s or 0.0) * 1e6)
        if boot_s is not None:
            if isinstance(self._writer, ULogWriter):
                self._writer.text(boot_us, 6, "[commander] Disarmed")
            else:
                self._writer.record("EV", boot_us, AP_EVENT_DISARMED)
        try:
            self._file.close()
        except OSError as error:
            logger.warning("the vehicle's flight log %s was not written whole: %s", self.paths[-1], error)
        self._file = self._writer = None

    def _new_path(self, utc_s: float) -> Path:
        if self.autopilot == "px4":
            when = datetime.datetime.fromtimestamp(utc_s, datetime.UTC)
            return self.folder / "log" / when.strftime("%Y-%m-%d") / when.strftime("%H_%M_%S.ulg")
        logs = self.folder / "logs"
        numbers = [int(p.stem) for p in logs.glob("*.BIN") if p.stem.isdigit()] if logs.is_dir() else []
        number = max(numbers, default=0) + 1
        logs.mkdir(parents=True, exist_ok=True)
        (logs / "LASTLOG.TXT").write_text(f"{number}\r\n")
        return logs / f"{number:08d}.BIN"


def ned(enu: Sequence[float]) -> tuple[float, float, float]:
    """North, east, down from east, north, up."""
    return (float(enu[1]), float(enu[0]), -float(enu[2]))
