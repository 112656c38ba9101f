"""Fleet scale on one machine: simulated drones flying a patrol in one process, paced at real time.

Run ``python bench/fleet.py`` (``--sizes 1 50 100``, ``--seconds 10``, ``--speed 1``). Every drone of a size runs in
this one process, one engine each, on one Zenoh session (router mode on a free loopback port), exactly as
``aeroexec fleet`` flies them. Printed per size: the achieved real-time factor (simulated seconds per wall
second; 1.00 = kept up with real time), CPU use (process CPU time over wall time, in cores), drones at real time
per core (drones x real-time factor / cores: how many drones one core keeps at real time at that size), and the
fleet link's latency, put -> arrival, median and p99, as another process hears it (an observer process connected
to the fleet's endpoint, as ``aeroexec ctl`` or a process of its own would be). The load average is printed
before and after: the figures are this machine's under that load.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

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
    """Drones on a grid 4 m apart around the middle of the field."""
    side = math.ceil(math.sqrt(n))
    corner = -2.0 * (side - 1)
    return [(corner + 4 * (i % side), corner + 4 * (i // side)) for i in range(n)]


def field(n: int):
    """The default field, cleared of obstacles and grown to hold the grid of ``n`` drones."""
    from aeroexec.drones.sim import default_world
    from aeroexec.drones.sim.world import Bounds

    world = default_world()
    half = max(world.bounds.upper[0], 2.0 * math.ceil(math.sqrt(n)) + 4.0)
    bounds = Bounds((-half, -half, world.bounds.lower[2]), (half, half, world.bounds.upper[2]))
    return dataclasses.replace(world, obstacles=(), bounds=bounds)


def percentile(samples: list[float], q: float) -> float:
    ordered = sorted(samples)
    return ordered[min(len(ordered) - 1, int(q * len(ordered)))] if ordered else float("nan")


def observe(endpoint: str, out: str) -> int:
    """The observer process: every tick's put -> arrival (s), written to ``out`` when stdin closes."""
    import threading

    from aeroexec.fleet.transport import open_session

    session = open_session("client", connect=[endpoint])
    samples: list[float] = []
    lock = threading.Lock()

    def heard(sample) -> None:
        received = time.time()
        try:
            sent = json.loads(bytes(sample.payload)).get("sent")
        except ValueError:
            return
        if isinstance(sent, float):
            with lock:
                samples.append(received - sent)

    sub = session.declare_subscriber("aeroexec/bench/*/tick", heard)
    print("ready", flush=True)
    sys.stdin.read()
    sub.undeclare()
    session.close()
    with lock:
        Path(out).write_text(json.dumps(samples))
    return 0


def run_size(n: int, seconds: float, speed: float) -> dict[str, float]:
    from aeroexec.fleet.fleet_file import DroneSpec
    from aeroexec.fleet.node import FleetNode
    from aeroexec.fleet.transport import free_endpoint, open_session
    from aeroexec.flight.fleet import FleetFlight
    from aeroexec.flight.spec import FlightSpec

    endpoint = free_endpoint()
    session = open_session("router", listen=[endpoint])
    folder = Path(tempfile.mkdtemp(prefix="aeroexec-bench-fleet-"))
    latencies = folder / "latencies.json"
    observer = subprocess.Popen([sys.executable, __file__, "--observe", endpoint, str(latencies)],
                                stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    observer.stdout.readline()  # "ready": it hears the fleet from its first period
    node = FleetNode(session, "bench", "bench-token")
    mission = folder / "patrol.py"
    mission.write_text(PATROL)
    drones = [DroneSpec(f"d{i + 1}", mission, home, seed=i) for i, home in enumerate(homes(n))]
    world = field(n)
    fleet = FleetFlight(node, drones, FlightSpec(mission=mission, max_time=seconds), output=folder / "out",
                        speed=speed, world=world).open()
    cpu0, wall0 = time.process_time(), time.monotonic()
    try:
        fleet.fly()
    finally:
        wall = time.monotonic() - wall0
        cpu = time.process_time() - cpu0
        node.close()
        observer.communicate("", timeout=60)
        session.close()
    remote = json.loads(latencies.read_text()) if latencies.exists() else []
    flying = sum(1 for m in fleet.members if m.engine.log.events(kind="GOAL_ACHIEVED")[2:])
    rtf = fleet.clock.now() / wall  # simulated time includes the landings after the limit
    return {"drones": n, "flying": flying, "rtf": rtf, "cores": cpu / wall,
            "per_core": n * min(rtf, 1.0) / (cpu / wall),
            "median": statistics.median(remote) * 1e3 if remote else float("nan"),
            "p99": percentile(remote, 0.99) * 1e3, "samples": len(remote)}


def main() -> int:
    if sys.argv[1:2] == ["--observe"]:
        return observe(sys.argv[2], sys.argv[3])
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[1, 50, 100, 200, 500])
    parser.add_argument("--seconds", type=float, default=10.0, help="simulated seconds per size")
    parser.add_argument("--speed", type=float, default=1.0, help="pace: times real time")
    args = parser.parse_args()
    print(f"fleet patrol, {args.seconds:g} s simulated per size, paced at {args.speed:g}x real time, "
          f"{os.cpu_count()} cores, 1 worker (one process); load average {os.getloadavg()[0]:.2f}")
    print(f"{'drones':>6} {'patrolling':>10} {'real-time factor':>17} {'CPU cores':>10} {'drones/core at RT':>18} "
          f"{'link median':>12} {'link p99':>9} {'samples':>8}")
    for n in args.sizes:
        r = run_size(n, args.seconds, args.speed)
        print(f"{n:>6} {r['flying']:>10} {r['rtf']:>16.2f}x {r['cores']:>10.2f} {r['per_core']:>18.0f} "
              f"{r['median']:>9.2f} ms {r['p99']:>6.2f} ms {r['samples']:>8}", flush=True)
    print(f"load average after: {os.getloadavg()[0]:.2f}; target: 500 drones at real time (factor >= 0.95) over "
          f"the machine's cores, link median <= 2 ms and p99 <= 50 ms ({sys.platform})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
