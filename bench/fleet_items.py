"""Where a fleet drone's engine period goes: the patrol of ``bench/fleet.py`` flown by ``aeroexec fleet`` in this
process (one worker, not paced), each item of every drone's period timed on its own.

Run ``python bench/fleet_items.py`` (``--drones 50``, ``--seconds 20``; ``--hover``: the drones take off and hold
still, a period in which nothing changes). Each item's CPU time (this thread's, as ``time.thread_time_ns`` counts
it, the timer's own cost taken off) is printed per drone and engine period (20 Hz), with its share of the period:
the simulated vehicle's integration, each belief updater (the telemetry beliefs, the fleet link's), the
capabilities' processes (the odometry estimate), the monitors and reactive rules, each tick callback (the journal,
the event log), and, per drone, the fleet's exchange at the end of the period and serving the missions. The
baseline is the whole period, measured in the same run: the items are shares of it; what is left over is the engine
tick's own work and the timers' error. A profile, not a figure to compare across machines: the CPU goal is
``bench/fleet.py``'s.
"""

from __future__ import annotations

import argparse
import collections
import contextlib
import io
import math
import os
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))

from fleet import fleet_file  # noqa: E402  (the same fleet bench/fleet.py flies)

spent: collections.Counter[str] = collections.Counter()
calls: collections.Counter[str] = collections.Counter()
clock = time.thread_time_ns
NESTED = "timed calls within the engine periods"

HOVER = """import aeroexec.engine.api as api


def mission():  # take off and hold still until the engine stops
    api.execute_behavior("TAKE_OFF", altitude=3)
    while True:
        api.wait(1000)
"""


def timed(name: str, function: Callable[..., Any]) -> Callable[..., Any]:
    """``function`` with its CPU time and calls counted under ``name``."""

    def counted(*args: Any, **kwargs: Any) -> Any:
        began = clock()
        try:
            return function(*args, **kwargs)
        finally:
            spent[name] += clock() - began
            calls[name] += 1

    return counted


def instrument() -> None:
    """Time each item of every engine's period, the fleet's exchange and the missions' serving."""
    from aeroexec.engine.engine import Engine
    from aeroexec.fleet.node import FleetNode
    from aeroexec.flight.fleet.fleet_flight import FleetFlight

    tick = Engine.tick

    def period(engine: Engine) -> None:
        if not getattr(engine, "_bench_timed", False):  # the items are known once the engine has them all
            engine._bench_timed = True  # type: ignore[attr-defined]
            engine.drone.update = timed("the vehicle's integration (drone.update)", engine.drone.update)
            for updater in engine.updaters:
                updater.tick = timed(f"belief updater: {type(updater).__name__}", updater.tick)
            engine.resources.update = timed("capabilities' processes (odometry)", engine.resources.update)
            engine.coordinator.tick = timed("monitors and reactive rules (coordinator.tick)", engine.coordinator.tick)
            engine.tick_callbacks[:] = [timed(f"tick callback: {getattr(c, '__qualname__', c)}", c)
                                        for c in engine.tick_callbacks]
        inside = calls.total()
        began = clock()
        tick(engine)
        spent["the engine period (Engine.tick)"] += clock() - began
        calls["the engine period (Engine.tick)"] += 1
        calls[NESTED] += calls.total() - inside - 1  # the timed calls within it: their cost is taken off it

    Engine.tick = period  # type: ignore[method-assign]
    FleetNode.exchange = timed("the fleet's exchange (per drone)", FleetNode.exchange)  # type: ignore[method-assign]
    FleetFlight._serve = timed("serving the missions (per drone)", FleetFlight._serve)  # type: ignore[method-assign]


def timer_cost() -> float:
    """Nanoseconds a timed call adds to what encloses it (its two clock reads, its wrapper's call), measured here;
    its counts taken back."""
    rounds = 50_000

    def nothing() -> None:
        return None

    counted = timed("calibration", nothing)
    began = clock()
    for _ in range(rounds):
        nothing()
    bare = clock() - began
    began = clock()
    for _ in range(rounds):
        counted()
    cost = (clock() - began - bare) / rounds
    del spent["calibration"], calls["calibration"]
    return cost


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--drones", type=int, default=50)
    parser.add_argument("--seconds", type=float, default=20.0, help="simulated seconds of patrol")
    parser.add_argument("--hover", action="store_true", help="the drones take off and hold still: a period in "
                        "which nothing changes")
    args = parser.parse_args()
    began = os.getloadavg()[0]
    folder = Path(tempfile.mkdtemp(prefix="aeroexec-bench-items-"))
    fleet = fleet_file(folder, args.drones, args.seconds)
    if args.hover:
        (folder / "patrol.py").write_text(HOVER)
    instrument()
    cost = timer_cost()
    from aeroexec.cli.main import main as aeroexec

    said = io.StringIO()
    with contextlib.suppress(SystemExit), contextlib.redirect_stdout(said), contextlib.redirect_stderr(said):
        aeroexec(["fleet", str(fleet), "--workers", "1", "--quiet", "--max-time", f"{args.seconds:g}",
                  "--output", str(folder / "out")])  # exit status 1: the time limit ends every patrol
    if not (folder / "out" / "fleet_status.json").exists():
        raise SystemExit(f"aeroexec fleet did not fly:\n{said.getvalue()[-3000:]}")
    periods = calls["the engine period (Engine.tick)"]
    whole = (spent["the engine period (Engine.tick)"] - (periods + calls.pop(NESTED)) * cost) / periods
    flown = "holding still" if args.hover else "of patrol"
    print(f"a fleet drone's engine period, {args.drones} drones in one process, {args.seconds:g} s {flown}, not "
          f"paced; CPU per drone and period (20 Hz), timer cost {cost:.0f} ns taken off; load average {began:.2f}")
    within = 0.0
    for name, total in sorted(spent.items(), key=lambda item: -item[1]):
        own = whole if "Engine.tick" in name else (total - calls[name] * cost) / periods
        share = f"{own / whole:6.1%}" if whole > 0 and not math.isclose(own, whole) else "  100%"
        print(f"  {name:<60} {own / 1e3:7.2f} µs  {share}")
        if "per drone" not in name and "Engine.tick" not in name:
            within += own
    left = whole - within
    print(f"  {'left over: the tick itself, and the timers error':<60} {left / 1e3:7.2f} µs  {left / whole:6.1%}")
    print(f"load average after: {os.getloadavg()[0]:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
