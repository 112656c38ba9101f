"""Telemetry streams of the simulated MAVLink vehicle: which message is due when, on wall time, at rates a client
sets with SET_MESSAGE_INTERVAL (or, as ArduPilot, REQUEST_DATA_STREAM)."""

from __future__ import annotations

_MAX_RATE_HZ = 100.0


class StreamScheduler:
    """When each streamed message is next due, on wall time; rates follow SET_MESSAGE_INTERVAL."""

    def __init__(self, defaults: dict[int, float]) -> None:
        self._defaults = dict(defaults)
        self._hz = dict(defaults)
        self._next = {msg_id: 0.0 for msg_id in defaults}

    def set_interval(self, msg_id: int, interval_us: float) -> bool:
        """Apply a SET_MESSAGE_INTERVAL (-1 stops, 0 restores the default); False for unknown messages."""
        if msg_id not in self._defaults:
            return False
        if interval_us < 0:
            self._hz[msg_id] = 0.0
        elif interval_us == 0:
            self._hz[msg_id] = self._defaults[msg_id]
        else:
            self._hz[msg_id] = min(1e6 / interval_us, _MAX_RATE_HZ)
        self._next[msg_id] = 0.0
        return True

    def interval_us(self, msg_id: int) -> int | None:
        if msg_id not in self._hz:
            return None
        hz = self._hz[msg_id]
        return int(1e6 / hz) if hz > 0 else -1

    def due(self, wall_now: float) -> list[int]:
        ready = []
        for msg_id, hz in self._hz.items():
            if hz > 0 and wall_now >= self._next[msg_id]:
                self._next[msg_id] = max(self._next[msg_id] + 1.0 / hz, wall_now)
                ready.append(msg_id)
        return ready
