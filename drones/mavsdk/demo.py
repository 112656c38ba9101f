"""A plain MAVSDK script (mavsdk 4.1 asyncio API only, not aeroexec's adapter): arm, take off, fly a square, land.

It proves ``aeroexec sim`` talks to MAVSDK like any PX4 or ArduCopter does. Run the simulator, then::

    aeroexec sim --connect udpout://127.0.0.1:14540        # or with --autopilot ardupilot
    python -m aeroexec.drones.mavsdk.demo --url udpin://0.0.0.0:14540
"""

from __future__ import annotations

import argparse
import asyncio
import math
import sys

from mavsdk import LogLevel, log_subscribe
from mavsdk.asyncio import ComponentType, Configuration, Mavsdk, MavsdkError
from mavsdk.asyncio.plugins.action import ActionAsync
from mavsdk.asyncio.plugins.telemetry import TelemetryAsync

EARTH_RADIUS = 6378137.0


def offset(lat: float, lon: float, east: float, north: float) -> tuple[float, float]:
    """The latitude and longitude ``east``/``north`` meters away (small distances)."""
    return (
        lat + math.degrees(north / EARTH_RADIUS),
        lon + math.degrees(east / (EARTH_RADIUS * math.cos(math.radians(lat)))),
    )


async def first(stream, predicate, timeout: float, what: str):
    """The first item of a telemetry stream that satisfies ``predicate``, or TimeoutError naming ``what``."""

    async def scan():
        async for item in stream:
            if predicate(item):
                return item

    try:
        return await asyncio.wait_for(scan(), timeout)
    except TimeoutError:
        raise TimeoutError(f"timed out after {timeout:g} s waiting for {what}") from None
    finally:
        await stream.aclose()  # unsubscribes now rather than when garbage collected


def plain_native_log(verbose: bool = False) -> None:
    """MAVSDK's own log as plain lines on stderr (it colours them, even into a file or a pipe), its debug lines
    (every MAVLink status text) only with ``--verbose``."""

    def show(level: LogLevel, message: str, file: str, line: int) -> bool:
        if verbose or level != LogLevel.DEBUG:
            print(f"mavsdk {level.name.lower()}: {message}", file=sys.stderr, flush=True)
        return True  # handled: MAVSDK prints nothing itself

    log_subscribe(show)


async def fly(url: str, altitude: float, side: float, timeout: float) -> None:
    async with Mavsdk(Configuration.create_with_component_type(ComponentType.GROUND_STATION)) as mavsdk:
        await mavsdk.add_any_connection(url)
        print(f"waiting for a vehicle on {url} ...")
        system = await mavsdk.first_autopilot(timeout_s=timeout)
        if system is None:
            raise TimeoutError(f"no autopilot heard on {url} within {timeout:g} s")
        action, telemetry = ActionAsync(system), TelemetryAsync(system)
        # ArduPilot streams nothing until asked (PX4 streams all of it anyway): health is SYS_STATUS.
        for set_rate, hz in ((telemetry.set_rate_health, 1.0), (telemetry.set_rate_position, 10.0),
                             (telemetry.set_rate_landed_state, 4.0), (telemetry.set_rate_home, 0.5)):
            await set_rate(hz)

        await first(
            telemetry.subscribe_health(),
            lambda h: h.is_armable and h.is_global_position_ok and h.is_home_position_ok,
            timeout,
            "a global position, a home position and pre-arm checks",
        )
        home = await first(telemetry.subscribe_home(), lambda h: True, timeout, "the home position")
        print(f"home at {home.latitude_deg:.7f}, {home.longitude_deg:.7f}, {home.absolute_altitude_m:.1f} m AMSL")

        await action.set_takeoff_altitude(altitude)
        print("arming")
        await action.arm()
        print(f"taking off to {altitude:g} m")
        await action.takeoff()
        await first(
            telemetry.subscribe_position(),
            lambda p: p.relative_altitude_m > altitude - 0.3,
            timeout,
            "the take-off altitude",
        )

        corners = [(side, 0.0), (side, side), (0.0, side), (0.0, 0.0)]
        for east, north in corners:
            lat, lon = offset(home.latitude_deg, home.longitude_deg, east, north)
            print(f"flying to {east:g} m east, {north:g} m north")
            await action.goto_location(lat, lon, home.absolute_altitude_m + altitude, math.nan)

            def arrived(p, lat=lat, lon=lon):
                north_err = math.radians(p.latitude_deg - lat) * EARTH_RADIUS
                east_err = math.radians(p.longitude_deg - lon) * EARTH_RADIUS * math.cos(math.radians(lat))
                return math.hypot(north_err, east_err) < 0.5

            await first(telemetry.subscribe_position(), arrived, timeout, f"the corner {east:g} E {north:g} N")

        print("landing")
        await action.land()
        await first(telemetry.subscribe_in_air(), lambda in_air: not in_air, timeout, "touchdown")
        armed = await first(telemetry.subscribe_armed(), lambda a: True, timeout, "the armed state")
        if armed:
            await action.disarm()
        print("landed and disarmed")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--url", default="udpin://0.0.0.0:14540", help="MAVSDK connection URL")
    parser.add_argument("--altitude", type=float, default=5.0, help="flight altitude above home (m)")
    parser.add_argument("--side", type=float, default=10.0, help="side of the square (m)")
    parser.add_argument("--timeout", type=float, default=60.0, help="longest wait for any step (s)")
    parser.add_argument("--verbose", "-v", action="store_true", help="also MAVSDK's debug lines")
    args = parser.parse_args(argv)
    plain_native_log(args.verbose)
    try:
        asyncio.run(fly(args.url, args.altitude, args.side, args.timeout))
    except (MavsdkError, TimeoutError) as exc:
        print(f"demo failed: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return 130
    return 0


if __name__ == "__main__":
    sys.exit(main())
