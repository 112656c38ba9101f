"""The error of a flight that cannot be set up (:class:`FlightError`), apart from the records a flight is made of
(:mod:`aeroexec.flight.spec`, which names it too): ``aeroexec verify`` says why a mission or a world cannot be read
without making those records (a dataclass of 32 fields is ~2 ms of a start, ``bench/startup.py``)."""

from __future__ import annotations


class FlightError(Exception):
    """A flight that cannot be set up, phrased for the operator (a file or option named). ``usage`` marks an
    option that cannot be used (exit status 2), otherwise the mission is refused (exit status 1)."""

    def __init__(self, message: str, usage: bool = False) -> None:
        super().__init__(message)
        self.usage = usage


__all__ = ["FlightError"]
