"""Fleet scale on one machine: 1, 10, 25 and 50 simulated drones flying a patrol, paced at real time.

Run ``python bench/fleet.py`` (``--sizes 1 10``, ``--seconds 20``, ``--speed 1``). Every drone of a size runs in
this one process, one engine each, on one Zenoh session (router mode on a free loopback port), exactly as
``aeroexec fleet`` flies them. Printed per size: the achieved real-time factor (simulated seconds per wall
second; 1.00 = kept up with real time), CPU use (process CPU time over wall time, in cores, and per drone as a
ratio to the 1-drone run of the same invocation), and the fleet-link latency of telemetry, publish -> receive,
median and p99: in-process (the fleet's own subscriber) and over TCP (a second session in this process,
connected to the fleet's endpoint as ``aeroexec ctl`` or another process would be).
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import os
import statistics
import sys
import tempfile
import threading
import time
from pathlib import Path

from aeroexec.drones.sim import default_world
from aeroexec.fleet.fleet_file import DroneSpec
from aeroexec.fleet.node import FleetNode
from aeroexec.fleet.transport import free_endpoint, open_session
from aeroexec.flight.fleet import FleetFlight
from aeroexec.flight.spec import FlightSpec

PATROL = """import aeroexec.engine.api as api


def mission():  # take off and fly a 3 m square around home until the engine stops
    ok, found = api.consult_belief("position(self, ?P)")
    x, y = found["?P"][0], found["?P"][1]
    api.execute_behavior("TAKE_OFF", altitude=3)
    while True:
        for dx, dy in ((1.5, 1.5), (-1.5, 1.5), (-1.5, -1.5), (1.5, -1.5)):
            if api.execute_behavior("GO_TO_POINT", coordinates=[x + dx, y + dy, 3]) != api.GOAL_ACHIEVED:
                api.wait(1)  # refused (too near an obstacle): simulated time must pass before trying again
"""


def homes(n: int) -> list[tuple[float, float]]:
    """Drones on a grid 4 m apart from the south-west corner of the field."""
    side = math.ceil(math.sqrt(n))
    return [(-16 + 4 * (i % side), -16 + 4 * (i // side)) for i in range(n)]


def percentile(samples: list[float], q: float) -> float:
    ordered = sorted(samples)
    return ordered[min(len(ordered) - 1, int(q * len(ordered)))] if ordered else float("nan")


def run_size(n: int, seconds: float, speed: float) -> dict[str, float]:
    endpoint = free_endpoint()
    session = open_session("router", listen=[endpoint])
    observer = open_session("client", connect=[endpoint])
    tcp: list[float] = []
    lock = threading.Lock()

    def heard(sample) -> None:
        received = time.time()
        try:
            import json

            sent = json.loads(bytes(sample.payload)).get("sent")
        except ValueError:
            return
        if isinstance(sent, float):
            with lock:
                tcp.append(received - sent)

    sub = observer.declare_subscriber("aeroexec/bench/*/telemetry", heard)
    node = FleetNode(session, "bench", "bench-token")
    folder = Path(tempfile.mkdtemp(prefix="aeroexec-bench-fleet-"))
    mission = folder / "patrol.py"
    mission.write_text(PATROL)
    drones = [DroneSpec(f"d{i + 1}", mission, home, seed=i) for i, home in enumerate(homes(n))]
    world = dataclasses.replace(default_world(), obstacles=())  # the default field, cleared for the grid of drones
    fleet = FleetFlight(node, drones, FlightSpec(mission=mission, max_time=seconds), output=folder / "out",
                        speed=speed, world=world).open()
    cpu0, wall0 = time.process_time(), time.monotonic()
    try:
        fleet.fly()
    finally:
        wall = time.monotonic() - wall0
        cpu = time.process_time() - cpu0
        sub.undeclare()
        node.close()
        observer.close()
        session.close()
    local = list(node.latencies)
    flying = sum(1 for m in fleet.members if m.engine.log.events(kind="GOAL_ACHIEVED")[2:])
    # simulated time includes the landings after the limit
    return {"drones": n, "flying": flying, "rtf": fleet.clock.now() / wall, "cores": cpu / wall,
            "local_median": statistics.median(local) * 1e3 if local else float("nan"),
            "local_p99": percentile(local, 0.99) * 1e3, "tcp_median": statistics.median(tcp) * 1e3 if tcp else
            float("nan"), "tcp_p99": percentile(tcp, 0.99) * 1e3, "samples": len(tcp)}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[1, 10, 25, 50])
    parser.add_argument("--seconds", type=float, default=20.0, help="simulated seconds per size")
    parser.add_argument("--speed", type=float, default=1.0, help="pace: times real time")
    args = parser.parse_args()
    print(f"fleet patrol, {args.seconds:g} s simulated per size, paced at {args.speed:g}x real time, "
          f"{os.cpu_count()} cores")
    print(f"{'drones':>6} {'patrolling':>10} {'real-time factor':>17} {'CPU cores':>10} {'CPU/drone vs 1':>15} "
          f"{'link median':>12} {'link p99':>9} {'TCP median':>11} {'TCP p99':>8}")
    base = None
    for n in args.sizes:
        r = run_size(n, args.seconds, args.speed)
        per_drone = r["cores"] / n
        base = base if base is not None else per_drone
        print(f"{n:>6} {r['flying']:>10} {r['rtf']:>16.2f}x {r['cores']:>10.2f} {per_drone / base:>14.2f}x "
              f"{r['local_median']:>9.2f} ms {r['local_p99']:>6.2f} ms {r['tcp_median']:>8.2f} ms "
              f"{r['tcp_p99']:>5.2f} ms", flush=True)
    print(f"target: 50 drones at real time (factor >= 0.95) with p99 under 50 ms ({sys.platform})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
