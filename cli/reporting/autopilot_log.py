"""The autopilot's own flight log beside the mission: a PX4 ULog (read with ``pyulog``) or an ArduPilot DataFlash
log (pymavlink's ``DFReader``), laid on the mission's clock.

The two clocks are unrelated (the autopilot counts from its boot, the engine from the run's start), so the log is
aligned by the motion both saw: the shift of the autopilot's clock that lays its position estimate over the
positions the engine recorded, with any constant offset between the two frames taken out. The search is coarse
to fine (0.25 s, then 0.01 s, then 1 ms).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from aeroexec.flight.summary import FlightSummary

from aeroexec.extras import require

with require("report"):
    import numpy as np

#: PX4's vehicle_status.nav_state names (PX4-Autopilot msg/VehicleStatus.msg), for the mode strip.
PX4_NAV_STATES = {0: "MANUAL", 1: "ALTCTL", 2: "POSCTL", 3: "MISSION", 4: "HOLD", 5: "RETURN", 10: "ACRO",
                  12: "DESCEND", 13: "TERMINATION", 14: "OFFBOARD", 15: "STAB", 17: "TAKEOFF", 18: "LAND",
                  19: "FOLLOW", 20: "PRECLAND", 21: "ORBIT", 22: "VTOL_TAKEOFF"}
MISMATCH_M = 3.0  # RMS metres beyond which the log is not this run's flight


class AutopilotLogError(ValueError):
    """The file is not an autopilot log this report reads, or it does not match the run."""


@dataclass
class AutopilotLog:
    """What the report draws of an autopilot's log: series on its boot clock (s), positions NED (m)."""

    path: Path
    kind: str  # "PX4 ULog" or "ArduPilot DataFlash"
    system: str  # what wrote it (sys_name, the first MSG)
    time: Any  # numpy array of the estimate's times
    estimate: Any  # N x 3: north, east, down
    setpoint_time: Any
    setpoint: Any  # M x 3, NaN where the controller had no position target
    modes: list[tuple[float, str]] = field(default_factory=list)  # (time, mode) at each change
    armed: list[tuple[float, bool]] = field(default_factory=list)  # (time, armed) at each change


@dataclass(frozen=True)
class Alignment:
    """engine time = autopilot boot time - ``offset``; ``rms`` metres between the two paths once aligned."""

    offset: float
    rms: float
    samples: int


def read_autopilot_log(path: Path) -> AutopilotLog:
    """The log at ``path``, by its content (a ULog starts with ``ULog``, a DataFlash log with 0xA3 0x95)."""
    try:
        with path.open("rb") as file:
            head = file.read(7)
    except OSError as error:
        raise AutopilotLogError(f"{path}: cannot read the autopilot log: {error.strerror or error}") from None
    if head.startswith(b"ULog\x01\x12\x35"):
        return _read_ulog(path)
    if head[:2] == b"\xa3\x95":
        return _read_dataflash(path)
    raise AutopilotLogError(f"{path}: not an autopilot log this report reads (expected a PX4 ULog .ulg or an "
                            "ArduPilot DataFlash .bin)")


def _read_ulog(path: Path) -> AutopilotLog:
    with require("report"):
        from pyulog import ULog
    try:
        ulog = ULog(str(path), ["vehicle_local_position", "vehicle_local_position_setpoint", "vehicle_status"])
    except Exception as error:  # pyulog raises what its parser meets (struct.error, IndexError...)
        raise AutopilotLogError(f"{path}: a damaged ULog: {error}") from None
    topics = {data.name: data.data for data in ulog.data_list if data.multi_id == 0}
    position = topics.get("vehicle_local_position")
    if position is None or not len(position["timestamp"]):
        raise AutopilotLogError(f"{path}: the ULog has no vehicle_local_position (the autopilot's position "
                                "estimate)")
    time = position["timestamp"] / 1e6
    setpoint = topics.get("vehicle_local_position_setpoint")
    status = topics.get("vehicle_status")
    modes: list[tuple[float, str]] = []
    armed: list[tuple[float, bool]] = []
    if status is not None:
        for t, nav, arming in zip(status["timestamp"] / 1e6, status["nav_state"], status["arming_state"],
                                  strict=True):
            name = PX4_NAV_STATES.get(int(nav), f"nav state {int(nav)}")
            if not modes or modes[-1][1] != name:
                modes.append((float(t), name))
            if not armed or armed[-1][1] != (int(arming) == 2):
                armed.append((float(t), int(arming) == 2))
    return AutopilotLog(
        path, "PX4 ULog", str(ulog.msg_info_dict.get("sys_name", "PX4")), time,
        np.column_stack([position["x"], position["y"], position["z"]]),
        setpoint["timestamp"] / 1e6 if setpoint is not None else np.empty(0),
        np.column_stack([setpoint["x"], setpoint["y"], setpoint["z"]]) if setpoint is not None else np.empty((0, 3)),
        modes, armed)


def _read_dataflash(path: Path) -> AutopilotLog:
    from pymavlink import DFReader, mavutil

    try:
        reader = DFReader.DFReader_binary(str(path))
    except Exception as error:  # DFReader raises what it meets in a damaged file
        raise AutopilotLogError(f"{path}: a damaged DataFlash log: {error}") from None
    system = ""
    estimate: list[tuple[float, float, float, float]] = []
    targets: dict[float, list[float]] = {}
    modes: list[tuple[float, str]] = []
    armed: list[tuple[float, bool]] = []
    axes = {"PSCN": 0, "PSCE": 1, "PSCD": 2}
    while True:
        try:
            msg = reader.recv_msg()
        except Exception as error:  # a record cut short at the end of a log written during a crash
            raise AutopilotLogError(f"{path}: a damaged DataFlash log: {error}") from None
        if msg is None:
            break
        kind = msg.get_type()
        if kind in ("XKF1", "NKF1"):
            if getattr(msg, "C", 0) == 0:  # the primary EKF core
                estimate.append((msg.TimeUS / 1e6, msg.PN, msg.PE, msg.PD))
        elif kind in axes:
            targets.setdefault(msg.TimeUS / 1e6, [math.nan] * 3)[axes[kind]] = getattr(msg, "TP" + kind[3], math.nan)
        elif kind == "MODE":
            names = mavutil.mode_mapping_bynumber(reader.mav_type) or {}
            modes.append((msg.TimeUS / 1e6, names.get(int(msg.ModeNum), f"mode {int(msg.ModeNum)}")))
        elif kind == "EV" and msg.Id in (10, 11):
            armed.append((msg.TimeUS / 1e6, msg.Id == 10))
        elif kind == "MSG" and not system:
            system = str(msg.Message)
    if not estimate:
        raise AutopilotLogError(f"{path}: the DataFlash log has no XKF1 or NKF1 records (the EKF's position "
                                "estimate)")
    rows = np.array(estimate)
    target_times = sorted(targets)
    return AutopilotLog(path, "ArduPilot DataFlash", system or "ArduPilot", rows[:, 0], rows[:, 1:4],
                        np.array(target_times), np.array([targets[t] for t in target_times]).reshape(-1, 3),
                        modes, armed)


def mission_path(summary: FlightSummary) -> tuple[Any, Any]:
    """The engine's samples as (times, N x 3 north-east-down), the autopilot's frame; a sample's time is when its
    position came from the vehicle when the log says (``measured``), else when the engine recorded it."""
    times = np.array([_measured(s) for s in summary.samples])
    ned = np.array([(p[1], p[0], -p[2]) for p in summary.path]).reshape(-1, 3)
    order = np.argsort(times, kind="stable")
    return times[order], ned[order]


def _measured(sample: dict[str, Any]) -> float:
    """When a sample's position was measured: its ``measured`` time when that is at most 2 s before the record (a
    stale position, or one stamped on another clock, counts at the record's time)."""
    recorded = float(sample["time"])
    measured = sample.get("measured")
    if isinstance(measured, int | float) and recorded - 2.0 <= measured <= recorded:
        return float(measured)
    return recorded


def align(log: AutopilotLog, summary: FlightSummary) -> Alignment:
    """The shift of the autopilot's clock that lays its estimate over the engine's path (see the module)."""
    times, path = mission_path(summary)
    if len(times) < 3:
        raise AutopilotLogError(f"{log.path}: the run recorded {len(times)} positions: too few to lay the "
                                "autopilot's log beside it")
    start, end = float(log.time[0]), float(log.time[-1])
    low, high = start - float(times[-1]), end - float(times[0])

    def cost(offset: float) -> tuple[float, int]:
        shifted = times + offset
        inside = (shifted >= start) & (shifted <= end)
        used = int(inside.sum())
        if used < max(3, len(times) // 2):
            return math.inf, used
        estimate = np.column_stack([np.interp(shifted[inside], log.time, log.estimate[:, axis]) for axis in range(3)])
        difference = estimate - path[inside]
        difference -= difference.mean(axis=0)  # a constant offset between the frames is not a misalignment
        return float(np.sqrt((difference ** 2).sum(axis=1).mean())), used

    candidates = np.arange(low, high + 0.25, 0.25)
    if not len(candidates):
        raise AutopilotLogError(f"{log.path}: the autopilot's log does not match this run's flight: no shift of its "
                                "clock lays its positions over the run's (too little overlap)")
    best = min(candidates, key=lambda o: cost(float(o))[0])
    for step, reach in ((0.01, 0.5), (0.001, 0.02)):
        best = min(np.arange(best - reach, best + reach + step, step), key=lambda o: cost(float(o))[0])
    rms, used = cost(float(best))
    if not math.isfinite(rms) or rms > MISMATCH_M:
        raise AutopilotLogError(
            f"{log.path}: the autopilot's log does not match this run's flight: no shift of its clock lays its "
            f"positions over the run's ({'too little overlap' if not math.isfinite(rms) else f'{rms:.1f} m apart'})")
    return Alignment(float(best), rms, used)
