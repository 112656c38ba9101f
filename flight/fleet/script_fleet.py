"""A fleet made for a script that drives several drones (an Aerostack2 swarm: ``DroneInterface`` objects of
several namespaces), so that ``aeroexec run script.py`` flies it as ``python3 script.py`` would: every drone it
names, in this process, one flight session each, on the fleet's one clock (:class:`~.fleet_flight.FleetFlight`),
each drone's files in ``<output>/<drone>/``.

The drones are named as the script names them (the dialects say which: ``StandIns.drones``) and start where the
world spawns them (a simulator's world config the script's project keeps), else :data:`SPACING` meters apart on an
east-west line through the world's home, as a simulator's swarm launch places them. :func:`open_script_fleet` sets
the fleet up with its Zenoh router on the loopback and credentials made in the output folder (the ``fleet``
extra); the caller flies it and closes it.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Callable
from contextlib import ExitStack
from dataclasses import dataclass, field
from pathlib import Path

from aeroexec.flight.spec import FlightSpec

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:  # imported by open_script_fleet: a run asks whether its mission is such a script before flying it
    from typing import Any

    from aeroexec.flight.fleet.fleet_flight import FleetFlight

logger = logging.getLogger(__name__)

#: Meters between two drones' starts.
SPACING = 2.0


def homes(count: int) -> list[tuple[float, float]]:
    """Where ``count`` drones start (east, north meters from the world's home): :data:`SPACING` apart on a line
    centred on the home."""
    return [(round(SPACING * (i - (count - 1) / 2), 3), 0.0) for i in range(count)]


def spawned(drones: tuple[str, ...], world: Any) -> bool:
    """Whether ``world`` says where each of ``drones`` starts (``World.starts``: a simulator's world config)."""
    spawns = dict(getattr(world, "starts", ()) or ())
    return bool(drones) and all(d in spawns for d in drones)


def starts(drones: tuple[str, ...], world: Any) -> list[tuple[float, float]]:
    """Where ``drones`` start: where ``world`` spawns each when it names them all (:func:`spawned`); else
    :func:`homes`."""
    if spawned(drones, world):
        spawns = dict(world.starts)
        return [tuple(spawns[d]) for d in drones]  # type: ignore[misc]
    return homes(len(drones))


@dataclass
class ScriptFleet:
    """The fleet made for a script: its name, its drones, and what flies them (closed by :meth:`close`)."""

    name: str
    drones: tuple[str, ...]
    flight: FleetFlight
    endpoints: list[str]
    _stack: ExitStack = field(default_factory=ExitStack)

    def close(self) -> None:
        self._stack.close()


def open_script_fleet(spec: FlightSpec, drones: tuple[str, ...], folder: Path, world: Any, *,
                      notify: Callable[[str], None] = logger.info, report: Callable[[Any], None] = logger.warning,
                      remote_questions: bool = False) -> ScriptFleet:
    """The fleet flying ``spec``'s script with one drone per name of ``drones``, set up (every session open) in
    ``world``, its files in ``folder``; raises FlightError, MissingExtra (no ``fleet`` extra) or the fleet's
    transport and credential errors."""
    from aeroexec.extras import require

    require("fleet")
    from aeroexec.fleet import members
    from aeroexec.fleet.fleet_file import DroneSpec, FleetSpec
    from aeroexec.fleet.fleet_json import FLEET_FILE, write_fleet_file
    from aeroexec.fleet.transport import free_endpoint
    from aeroexec.flight.fleet.fleet_flight import FleetFlight

    name = Path(spec.mission).stem.replace(".", "_") or "script"
    fleet_spec = FleetSpec(name=name, drones=tuple(DroneSpec(d, Path(spec.mission), home, seed=spec.seed + i)
                                                   for i, (d, home) in enumerate(zip(drones, starts(drones, world),
                                                                                    strict=True))),
                           file=str(spec.mission))
    stack = ExitStack()
    try:
        membership = members.listen(fleet_spec, [free_endpoint("tls")], folder)
        stack.callback(membership.close)
        token = os.urandom(16).hex()  # secrets.token_hex(16), without importing secrets (~3 ms of a start)
        node = membership.node(token)
        stack.callback(node.close)
        stack.callback(lambda: (folder / FLEET_FILE).unlink(missing_ok=True))
        write_fleet_file(folder, name, membership.endpoints, token, membership.operator, drones)
        flight = FleetFlight(node, list(fleet_spec.flown), spec, output=folder, speed=spec.speed, world=world,
                             remote_questions=remote_questions, notify=notify, report=report)
        stack.callback(flight.close)
        flight.open()
    except BaseException:
        stack.close()
        raise
    return ScriptFleet(name, drones, flight, list(membership.endpoints), stack)


__all__ = ["SPACING", "ScriptFleet", "homes", "open_script_fleet", "spawned", "starts"]
