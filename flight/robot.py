"""The robot of a flight and the world it moves in: the robot kind (``drone`` by default, or one an installed
plugin adds: its catalog, behaviors, processes, own-state beliefs, simulated robot, default world and engine
settings), the adapter that drives it (the built-in simulator, MAVSDK, or an ``aeroexec.drones`` adapter), the
world file, and the engine built for the robot (:func:`make_engine`) with the operator its questions go to."""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from aeroexec.engine.catalog import BehaviorCatalog, default_catalog, load_catalog
from aeroexec.engine.library import (
    LibraryError,
    behavior_names,
    default_library,
    default_processes,
    default_updaters,
)
from aeroexec.engine.library import make_drone as make_adapter_drone
from aeroexec.engine.robots import DRONE, RobotKind, RobotKindError, robot_kind
from aeroexec.flight.errors import FlightError

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

    from aeroexec.engine.engine import Engine
    from aeroexec.flight.spec import FlightSpec

logger = logging.getLogger(__name__)

RATE = 20.0  # Hz: the engine's period


def chosen_catalog(path: str | None) -> BehaviorCatalog:
    """The catalog of a ``--catalog`` option (the aerial one without it) as the behavior library serves it
    (see :meth:`BehaviorCatalog.served_by`); raises CatalogError."""
    catalog = load_catalog(path) if path else default_catalog()
    return catalog.served_by(behavior_names(), default_catalog())


@dataclass
class RobotChoice:
    """The chosen kind (None: the built-in drone) and what the engine is built with for it."""

    kind: RobotKind | None

    def catalog(self, path: str | None) -> BehaviorCatalog:
        """The ``--catalog`` given, else the kind's, as the kind's behaviors serve it; raises CatalogError."""
        if self.kind is None:
            return chosen_catalog(path)
        catalog = load_catalog(path or self.kind.catalog)
        return catalog.served_by(self.library().names())

    def library(self) -> Any:
        return self.kind.behaviors() if self.kind is not None and self.kind.behaviors else None

    def world_file(self, given: str | None) -> str | None:
        """The world file a flight uses: the one given, else the kind's (None: the built-in field)."""
        return given or (str(self.kind.world) if self.kind is not None and self.kind.world else None)

    def engine_options(self, robot: Any, library: tuple[str, ...] = (), processes: tuple[str, ...] = ()
                       ) -> dict[str, Any]:
        """The Engine keyword arguments of this kind for ``robot`` (the drone: the aerial library with the
        ``library`` and ``processes`` plugins); raises LibraryError."""
        if self.kind is None:
            return {"library": default_library(library), "processes": default_processes(processes)}
        options: dict[str, Any] = {"library": self.library(), "settings": self.kind.settings()}
        if self.kind.catalog is not None:
            options["described_in"] = load_catalog(self.kind.catalog)
        if self.kind.processes is not None:
            options["processes"] = self.kind.processes()
        if self.kind.telemetry is not None:
            options["telemetry"] = self.kind.telemetry(robot)
        return options


def with_rule_files(catalog: BehaviorCatalog, paths: tuple[str, ...] | list[str]) -> BehaviorCatalog:
    """``catalog`` with the rules of the files ``paths`` (``--rules FILE``) added; raises FlightError naming each
    problem with its file and line."""
    from aeroexec.beliefs import RuleError, read_rules

    try:
        rules = [rule for path in paths for rule in read_rules(path)]
        return catalog.with_rules(rules) if rules else catalog
    except RuleError as error:
        raise FlightError(str(error)) from None


def robot_choice(name: str = DRONE) -> RobotChoice:
    """The robot kind named ``name``; raises :class:`FlightError` (a usage error) with a sentence."""
    try:
        return RobotChoice(robot_kind(name))
    except RobotKindError as error:
        raise FlightError(str(error), usage=True) from None


def vehicle_config(path: str | None) -> Any:
    """The :class:`~aeroexec.drones.sim.SimConfig` of the vehicle profile ``path`` (``--vehicle FILE``), None without
    one; raises FlightError naming the file and line."""
    if path is None:
        return None
    from aeroexec.drones.profile import VehicleProfileError, load_vehicle_profile

    try:
        return load_vehicle_profile(path).config()
    except VehicleProfileError as error:
        raise FlightError(f"--vehicle {error}") from None


def load_world(path: str | None, default: bool = True, mission: Path | None = None,
               home: tuple | None = None) -> Any:
    """The world ``mission`` flies in (``trees.mission_world``): the world of ``path`` (at ``home`` when given);
    without one, an open field around a mission planned on a map, else the built-in field when ``default`` (else
    None)."""
    from aeroexec.drones.sim import WorldError
    from aeroexec.trees.mission_world import mission_world

    try:
        return mission_world(mission, path, home, default)
    except WorldError as error:
        raise FlightError(str(error)) from None


def make_robot(spec: FlightSpec, choice: RobotChoice, world: Any, notify: Callable[[str], None] = logger.info,
               cancelled: Callable[[], bool] = lambda: False, start_time: float = 0.0,
               vehicle: Any = None) -> tuple[Any, bool]:
    """The robot a flight drives, and whether it runs on simulated time (from ``start_time``: a resumed run's);
    the simulator flies with the figures of ``vehicle`` (a profile's SimConfig) when given.
    A MAVSDK vehicle is waited for until it is ready to fly (at most ``spec.ready_timeout`` s, or until
    ``cancelled()``), saying so to ``notify``; raises FlightError."""
    kind = choice.kind
    if kind is not None:
        if spec.drone != "sim" or kind.simulator is None:
            raise FlightError(f"--robot {kind.name}: only its simulated robot can be flown from here")
        return kind.simulator(world, spec.seed), True
    if spec.drone == "sim":
        from aeroexec.drones.sim import SimulatedDrone

        return SimulatedDrone(world, seed=spec.seed, start_time=start_time, config=vehicle), True
    if spec.drone.startswith("mavsdk:"):
        return _mavsdk_vehicle(spec, notify, cancelled), False
    scheme, _, address = spec.drone.partition(":")
    try:  # an installed adapter (an aeroexec.drones entry point)
        return make_adapter_drone(scheme, address), False
    except LibraryError as error:
        raise FlightError(f"--drone {spec.drone}: expected sim or mavsdk:URL (e.g. mavsdk:udpin://0.0.0.0:14540), "
                          f"or NAME:ADDRESS of an installed adapter; {error}") from None


def make_engine(spec: FlightSpec, choice: RobotChoice, robot: Any, *, catalog: BehaviorCatalog, clock: Any,
                world: Any, operator: Any, folder: Path | None, vehicle: Any = None) -> Engine:
    """The engine that flies ``robot``: its kind's behaviors, processes and settings (the drone's: the aerial library
    with the flight's plugins) and own-state updaters, at :data:`RATE`; its safety rules estimate with ``vehicle``
    (a profile's SimConfig) when given, else the robot's figures; raises FlightError."""
    from aeroexec.drones.vehicle import VehicleModel
    from aeroexec.engine.engine import Engine

    try:
        updaters = default_updaters(robot, spec.updaters)
        options = choice.engine_options(robot, spec.library, spec.processes)
    except LibraryError as error:
        raise FlightError(str(error)) from None
    model = None
    if vehicle is not None:  # a profile: its figures (a real vehicle's home at 0, as without one)
        model = VehicleModel.of(robot)
        model = model if model.config is vehicle else VehicleModel(vehicle, model.home)
    return Engine(robot, catalog=catalog, clock=clock, rate=RATE, obstacles=world, operator=operator,
                  output_dir=folder, updaters=updaters, vehicle=model, **options)


def flight_operator(spec: FlightSpec) -> Any:
    """Where the mission's questions go: the ``--answers`` file, the console or ``ctl answer`` (remote questions),
    this terminal, or the default answers; raises FlightError."""
    from aeroexec.engine.supervision.operator import OperatorError, RemoteOperator, make_operator

    if spec.remote_questions and spec.answers is None:
        return RemoteOperator()
    try:
        return make_operator(spec.answers, interactive=spec.interactive)
    except OperatorError as error:
        raise FlightError(f"--answers {error}") from None


def _mavsdk_vehicle(spec: FlightSpec, notify: Callable[[str], None], cancelled: Callable[[], bool]) -> Any:
    from aeroexec.drones.mavsdk import MavsdkDrone

    url = spec.drone[len("mavsdk:"):]
    try:
        drone = MavsdkDrone(url, ready_timeout=spec.ready_timeout)
    except ValueError as error:
        raise FlightError(f"--drone {spec.drone}: {error}") from None
    notify(f"connecting to {url} (waiting up to {spec.ready_timeout:g} s for the vehicle to be ready) ...")
    waited = 0.0
    try:
        while not drone.wait_ready(min(0.5, spec.ready_timeout - waited)):
            waited += 0.5
            if cancelled():
                raise FlightError(f"--drone {spec.drone}: the start was aborted while waiting for the vehicle")
            if waited >= spec.ready_timeout:
                why = "; ".join(drone.not_ready_because()) or "no answer"
                raise FlightError(f"--drone {spec.drone}: the vehicle is not ready to fly after "
                                  f"{spec.ready_timeout:g} s: {why} (--ready-timeout gives it longer)")
    except BaseException:
        drone.close()
        raise
    notify(f"{drone.autopilot} vehicle ready on {url}")
    return drone


__all__ = ["DRONE", "RATE", "FlightError", "RobotChoice", "chosen_catalog", "flight_operator", "load_world",
           "make_engine", "make_robot", "robot_choice", "vehicle_config"]
