"""Fleet scale on this machine: simulated drones flying a patrol with ``aeroexec fleet``, paced at real time, in one
process and spread over worker processes.

Run ``python bench/fleet.py`` (``--sizes 100 500``, ``--workers 1 2``, ``--seconds 10``, ``--speed 1``; ``--docs``
rewrites the fleet table of ``docs/performance/run.md``; ``--hover``: the drones take off and hold still instead, a
period in which nothing changes, counted in "patrolling" once they took off). Each size is flown by ``aeroexec fleet
FLEET.yaml --workers W`` as an operator would fly it (its own router, credentials and access rules), for each number of
workers. Printed per run: the achieved real-time factor (simulated seconds per wall second of the flight; 1.00 =
kept up with real time), CPU use (the workers' and the router's CPU time over wall time, in cores), the CPU of one
drone per simulated second (the flight's CPU, accounted per process: each worker's own CPU time over its flight,
every thread of it, plus the coordinator's, over drones x simulated seconds; the goal is 2 ms, 500 drones per core),
the same from the whole processes' CPU as the kernel counts it for the ``aeroexec fleet`` process and the workers it
reaped (set-up and landing included), drones at real time per core (drones x real-time factor / cores: how many
drones one core keeps at real time at that size), and the fleet link's latency, put -> arrival, median and p99, as
another process hears it (an observer with the fleet's operator credentials, as ``aeroexec ctl`` would be,
listening to every tenth drone). The load average is printed before and after: the figures are this machine's under
that load.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from provenance import measured_at, write_section

PAGE = Path(__file__).resolve().parents[1] / "docs" / "performance" / "run.md"
BEGIN, END = "<!-- fleet-table: begin (python bench/fleet.py --docs) -->", "<!-- fleet-table: end -->"

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


HOVER = """import aeroexec.engine.api as api


def mission():  # take off and hold still until the engine stops: a period in which nothing changes
    api.execute_behavior("TAKE_OFF", altitude=3)
    while True:
        api.wait(1000)
"""


def homes(n: int) -> list[tuple[float, float]]:
    """Drones on a grid 4 m apart around the middle of the field."""
    side = math.ceil(math.sqrt(n))
    corner = -2.0 * (side - 1)
    return [(corner + 4 * (i % side), corner + 4 * (i // side)) for i in range(n)]


def fleet_file(folder: Path, n: int, seconds: float) -> Path:
    """A fleet of ``n`` drones on a grid, in a field without obstacles grown to hold them."""
    (folder / "patrol.py").write_text(PATROL)
    half = 2.0 * math.ceil(math.sqrt(n)) + 8.0
    (folder / "field.yaml").write_text(f"home: {{lat: 40.4168, lon: -3.7038, alt: 650}}\n"
                                       f"bounds: {{min: [{-half}, {-half}, 0], max: [{half}, {half}, 25]}}\n")
    lines = ["fleet: bench", "world: field.yaml", "drones:"]
    lines += [f"  - {{name: d{i + 1}, mission: patrol.py, home: [{x:g}, {y:g}], seed: {i}}}"
              for i, (x, y) in enumerate(homes(n))]
    path = folder / "fleet.yaml"
    path.write_text("\n".join(lines) + "\n")
    return path


def build() -> str:
    """Which simulated vehicle the runs fly: the compiled build's (``tools/build-compiled``) or the Python code."""
    import aeroexec.drones.sim.vehicle.multicopter as vehicle

    compiled = not str(vehicle.__file__).endswith(".py")
    return "the vehicle compiled (tools/build-compiled)" if compiled else "the vehicle in Python"


def percentile(samples: list[float], q: float) -> float:
    ordered = sorted(samples)
    return ordered[min(len(ordered) - 1, int(q * len(ordered)))] if ordered else float("nan")


def observe(folder: str, out: str, drones: int) -> int:
    """The observer process: the put -> arrival (s) of every tick of every tenth drone, written to ``out`` when stdin
    closes. It waits for the fleet's ``fleet.json`` in ``folder`` and connects with the operator's credentials."""
    import threading

    from aeroexec.fleet.members import operator_identity
    from aeroexec.fleet.transport import open_session

    info = Path(folder) / "fleet.json"
    while not info.exists() or not info.read_text().strip():
        time.sleep(0.05)
    fleet = json.loads(info.read_text())
    material = operator_identity(fleet["credentials"]).read(fleet["fleet"])
    session = open_session("client", connect=fleet["endpoints"][:1], identity=material)
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

    # every tenth drone's ticks: enough samples, and the observer's own CPU stays off the fleet's cores
    subs = [session.declare_subscriber(f"aeroexec/bench/d{i}/tick", heard) for i in range(1, drones + 1, 10)]
    print("ready", flush=True)
    sys.stdin.read()
    for sub in subs:
        sub.undeclare()
    session.close()
    with lock:
        Path(out).write_text(json.dumps(samples))
    return 0


def run(n: int, workers: int, seconds: float, speed: float, hover: bool = False) -> dict[str, float]:
    folder = Path(tempfile.mkdtemp(prefix="aeroexec-bench-fleet-"))
    fleet = fleet_file(folder, n, seconds)
    if hover:
        (folder / "patrol.py").write_text(HOVER)
    out, latencies = folder / "out", folder / "latencies.json"
    out.mkdir()
    observer = subprocess.Popen([sys.executable, __file__, "--observe", str(out), str(latencies), str(n)],
                                stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    with (folder / "stderr.txt").open("w+") as errors:
        flown = subprocess.Popen([sys.executable, "-m", "aeroexec", "fleet", str(fleet), "--workers", str(workers),
                                  "--speed", str(speed), "--max-time", str(seconds), "--quiet", "--output", str(out)],
                                 stdout=subprocess.DEVNULL, stderr=errors)
        _, exit_status, usage = os.wait4(flown.pid, 0)  # the process and the workers it reaped: every thread
        errors.seek(0)
        stderr = errors.read()
    observer.communicate("", timeout=120)
    if not (out / "fleet_status.json").exists():  # exit 1 is expected: the time limit ends every patrol
        raise SystemExit(f"aeroexec fleet ended with exit status {os.waitstatus_to_exitcode(exit_status)}:\n"
                         f"{stderr[-3000:]}")
    status = json.loads((out / "fleet_status.json").read_text())
    took = status["time"]
    remote = json.loads(latencies.read_text()) if latencies.exists() else []
    flying = 0
    for drone in status["drones"]:
        goals = sum('"GOAL_ACHIEVED"' in line for line in (out / drone / "events.jsonl").open())
        flying += goals >= (1 if hover else 3)  # took off (and reached two corners)
    rtf, cores = took["simulated"] / took["wall"], took["cpu"] / took["wall"]
    whole = usage.ru_utime + usage.ru_stime
    return {"drones": n, "workers": took["workers"], "flying": flying, "rtf": rtf, "cores": cores,
            "per_drone": took["cpu"] / (n * took["simulated"]) * 1e3,
            "whole_per_drone": whole / (n * took["simulated"]) * 1e3,
            "per_core": n * min(rtf, 1.0) / cores,
            "median": statistics.median(remote) * 1e3 if remote else float("nan"),
            "p99": percentile(remote, 0.99) * 1e3, "samples": len(remote)}


def main() -> int:
    if sys.argv[1:2] == ["--observe"]:
        return observe(sys.argv[2], sys.argv[3], int(sys.argv[4]))
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[100, 500])
    parser.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--seconds", type=float, default=10.0, help="simulated seconds per run")
    parser.add_argument("--speed", type=float, default=1.0, help="pace: times real time")
    parser.add_argument("--docs", action="store_true", help="rewrite the fleet table of docs/performance/run.md")
    parser.add_argument("--hover", action="store_true", help="the drones take off and hold still instead (a period "
                        "in which nothing changes; not for --docs: the table is the patrol's)")
    args = parser.parse_args()
    if args.hover and args.docs:
        parser.error("--docs writes the patrol's table: measure --hover without it")
    began = os.getloadavg()[0]
    flown = "holding still" if args.hover else "patrol"
    print(f"fleet {flown}, {args.seconds:g} s simulated per run, paced at {args.speed:g}x real time, "
          f"{os.cpu_count()} cores, {build()}; load average {began:.2f}")
    print(f"{'drones':>6} {'workers':>7} {'patrolling':>10} {'real-time factor':>17} {'CPU cores':>10} "
          f"{'ms CPU/drone/s':>15} {'(whole)':>8} {'drones/core at RT':>18} {'link median':>12} {'link p99':>9} "
          f"{'samples':>8}")
    rows = ["| drones | workers | patrolling | real-time factor | CPU (cores) | CPU per drone per simulated second "
            "(the flight, per process) | the same, whole processes (set-up and landing included) | drones per core "
            "at real time | link median / p99 |", "|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for n in args.sizes:
        for workers in args.workers:
            r = run(n, workers, args.seconds, args.speed, args.hover)
            print(f"{n:>6} {r['workers']:>7} {r['flying']:>10} {r['rtf']:>16.2f}x {r['cores']:>10.2f} "
                  f"{r['per_drone']:>12.2f} ms {r['whole_per_drone']:>5.2f} ms {r['per_core']:>18.0f} "
                  f"{r['median']:>9.2f} ms {r['p99']:>6.2f} ms {r['samples']:>8}", flush=True)
            verdict = "met" if r["per_drone"] <= 2.0 else "MISSED"
            rows.append(f"| {n} | {r['workers']} | {r['flying']} | {r['rtf']:.2f}× | {r['cores']:.2f} | "
                        f"{r['per_drone']:.2f} ms (≤ 2 ms: {verdict}) | {r['whole_per_drone']:.2f} ms | "
                        f"{r['per_core']:.0f} | {r['median']:.1f} / {r['p99']:.1f} ms |")
    print(f"load average after: {os.getloadavg()[0]:.2f}; target: 500 drones at real time (factor >= 0.95) over "
          f"the machine's cores, <= 2 ms CPU per drone per simulated second, link median <= 2 ms and p99 <= 50 ms "
          f"({sys.platform})")
    said = (f"Measured by `python bench/fleet.py --sizes {' '.join(map(str, args.sizes))} --workers "
            f"{' '.join(map(str, args.workers))} --seconds {args.seconds:g} --speed {args.speed:g} --docs` (a patrol "
            f"paced at {args.speed:g}× real time, {build()}; the baseline is the goal, 2 ms of CPU per drone per "
            f"simulated second, 500 drones per core) at {measured_at(began)}.")
    print(said)
    if args.docs:
        write_section(PAGE, BEGIN, END, "\n".join([*rows, "", said]))
        print(f"{PAGE}: fleet table rewritten")
    return 0


if __name__ == "__main__":
    sys.exit(main())
