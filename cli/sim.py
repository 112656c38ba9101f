"""``aeroexec sim``: the simulated drone exposed over MAVLink as a PX4 multicopter (or, with ``--autopilot
ardupilot``, as an ArduCopter), until Ctrl-C or SIGTERM.

MAVSDK scripts (``python -m aeroexec.drones.mavsdk.demo``), ``aeroexec run --drone udpin://...`` or
QGroundControl can then fly it. ``--home LAT,LON[,ALT]`` puts it where a plan was made for: a mission uploaded
through MAVSDK or QGroundControl then flies its own latitudes and longitudes.
"""

from __future__ import annotations

import argparse
import dataclasses
import logging
import math
import signal
import sys
import threading
from pathlib import Path

from aeroexec.drones.geodesy import parse_home
from aeroexec.drones.sim import SimulatedDrone, World, WorldError, default_world, load_world
from aeroexec.drones.sim.mavlink.vehicle import AUTOPILOTS, MavlinkVehicle, MavlinkVehicleError, normalize_url
from aeroexec.drones.sim.open_field import field_at
from aeroexec.flight.errors import FlightError

logger = logging.getLogger("aeroexec.sim")

DEFAULT_URL = "udpout://127.0.0.1:14540"
SIM_REACH, SIM_CEILING = 5000.0, 500.0  # m: the open field of --home (the aerial catalog's vehicle limits)


def _speed(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"must be a positive number, not {text}")
    return value


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The options of ``aeroexec sim``."""
    parser.add_argument("--world", type=Path, help="world file (YAML); the packaged default world if omitted (with "
                                                   "--home: an open field of 5 km around it, 500 m high)")
    parser.add_argument("--home", type=_home, metavar="LAT,LON[,ALT]",
                        help="where the vehicle stands: latitude, longitude and altitude AMSL (default 0); a mission "
                             "uploaded to it flies to its own latitudes and longitudes from there")
    parser.add_argument(
        "--connect",
        default=DEFAULT_URL,
        metavar="URL",
        help=f"where the vehicle talks MAVLink (default {DEFAULT_URL}, where MAVSDK and PX4 SITL clients listen; "
        "also udpin://HOST:PORT, tcpin://HOST:PORT, tcpout://HOST:PORT)",
    )
    parser.add_argument(
        "--speed", type=_speed, default=1.0, metavar="N", help="simulated seconds per wall second (default 1)"
    )
    parser.add_argument("--seed", type=int, default=0, help="seed of the simulation's sensor noise (default 0)")
    parser.add_argument("--system-id", type=int, default=1, help="MAVLink system id of the vehicle (default 1)")
    parser.add_argument("--logs", type=Path, metavar="DIR",
                        help="write the vehicle's own flight log in DIR from each arming to disarming, as the "
                             "autopilot does: a PX4 ULog (DIR/log/DATE/TIME.ulg) or an ArduPilot DataFlash log "
                             "(DIR/logs/NNNNNNNN.BIN); `aeroexec report RUN_DIR --autopilot-log FILE` lays it beside "
                             "the mission")
    parser.add_argument(
        "--autopilot",
        choices=AUTOPILOTS,
        default="px4",
        help="which autopilot the vehicle behaves like (default px4): px4 streams telemetry at once; ardupilot "
        "(ArduCopter) streams nothing until asked (SET_MESSAGE_INTERVAL, REQUEST_DATA_STREAM), uses Copter mode "
        "numbers and brings its EKF up in steps (armable first, then GPS origin and home)",
    )
    parser.add_argument("--vehicle", type=Path, metavar="FILE",
                        help="the vehicle's profile (YAML, as run and verify take it: endurance in minutes of hover, "
                             "speeds, rates...; docs/vehicles.md): the simulated vehicle flies with its figures "
                             "(default: the simulated multicopter's, 20 min of hover)")
    parser.add_argument("--camera", nargs="?", const="", default=None, metavar="DIR",
                        help="give the vehicle a camera component (MAVLink component 100: IMAGE_START_CAPTURE, "
                             "CAMERA_IMAGE_CAPTURED), its photos the simulator's camera images, saved in DIR when "
                             "given; without it the vehicle has no camera, as a SITL has none")


def run(args: argparse.Namespace) -> int:
    """Run the vehicle until interrupted; 0 on a clean stop, 2 on a bad URL, world file or port."""
    if not logging.getLogger().handlers:
        logging.basicConfig(level=logging.INFO, stream=sys.stderr, format="%(asctime)s %(levelname)s %(message)s")
    try:
        normalize_url(args.connect)
        world = sim_world(args.world, args.home)
        config = None
        if args.vehicle is not None:  # the profile as run and verify read it (its errors: file and line)
            from aeroexec.flight.robot import vehicle_config

            config = vehicle_config(str(args.vehicle))
    except (MavlinkVehicleError, WorldError, FlightError) as exc:
        print(f"aeroexec sim: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:
        print(f"aeroexec sim: cannot read the world file {args.world}: {exc.strerror or exc}", file=sys.stderr)
        return 2
    drone = SimulatedDrone(world, config=config, seed=args.seed)
    try:
        vehicle = MavlinkVehicle(drone, connect=args.connect, speed=args.speed, system_id=args.system_id,
                                 autopilot=args.autopilot, log_folder=args.logs, camera=args.camera is not None,
                                 camera_folder=Path(args.camera) if args.camera else None)
        vehicle.start()
    except (MavlinkVehicleError, ValueError) as exc:
        print(f"aeroexec sim: {exc}", file=sys.stderr)
        return 2
    stop = threading.Event()
    previous = _on_signals(stop)
    logger.info("simulated drone (%s) ready on %s (Ctrl-C to stop)", args.autopilot, args.connect)
    try:
        while not stop.wait(0.5):
            if not vehicle.running:
                print("aeroexec sim: the vehicle stopped unexpectedly", file=sys.stderr)
                return 1
    except KeyboardInterrupt:
        pass
    finally:
        _restore_signals(previous)
        vehicle.stop()
    logger.info("simulated drone stopped")
    return 0


def _home(text: str) -> tuple:
    try:
        return parse_home(text)
    except ValueError as error:
        raise argparse.ArgumentTypeError(str(error)) from None


def sim_world(world: Path | None, home: tuple | None) -> World:
    """The vehicle's world: the world file (moved to ``home`` when given), else an open field at ``home``, else the
    packaged default world."""
    if world is not None:
        loaded = load_world(world)
        if home is None:
            return loaded
        return dataclasses.replace(loaded, home=(home[0], home[1], loaded.home[2] if home[2] is None else home[2]))
    if home is None:
        return default_world()
    return field_at((home[0], home[1], 0.0 if home[2] is None else home[2]), SIM_REACH, SIM_CEILING)


def _on_signals(stop: threading.Event) -> dict:
    """SIGINT and SIGTERM set ``stop`` (only the main thread may install handlers)."""
    if threading.current_thread() is not threading.main_thread():
        return {}
    previous = {}
    for sig in (signal.SIGINT, signal.SIGTERM):
        previous[sig] = signal.signal(sig, lambda signum, frame: stop.set())
    return previous


def _restore_signals(previous: dict) -> None:
    for sig, handler in previous.items():
        signal.signal(sig, handler)
