"""Engine speed: engine step CPU, the longest engine step of every mission, planning off the loop, and tree ticks,
each as a ratio to a baseline measured in the same run, with min/median over repeats (the command's start-up:
``bench/startup.py``).

Run ``python bench/engine.py`` (``--repeat N``, ``--quick`` for fewer and shorter runs). Baselines: a bare simulated
drone's integration for the engine step, a blocking plan for the longest step of
a GO_TO_POINT to an enclosed goal, and for trees a bare py_trees tree of the same shape and plain recursion over the
same nodes making the same belief queries. Targets (issue 19) are printed next to the figures, with ``met`` or
``MISSED``; the targets are absolute times on the reference machine (2 cores), so a loaded machine misses them
where the ratios would not.
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import io
import statistics
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "performance" / "run.md"
STEP_BEGIN = "<!-- engine-step: begin (python bench/engine.py --only step --docs) -->"
STEP_END = "<!-- engine-step: end -->"
MISSIONS = sorted(p for p in (ROOT / "missions").iterdir()
                  if p.suffix in (".py", ".xml", ".yaml") and p.name != "__init__.py")


def spread(values: list[float]) -> tuple[float, float]:
    return min(values), statistics.median(values)


def line(name: str, value: str, ratio: str = "", target: str = "") -> None:
    print(f"  {name:50s} {value:>22s}  {ratio:>16s}  {target}")


def verdict(value: float, target: float) -> str:
    return f"target <= {target:g}: " + ("met" if value <= target else f"MISSED by {value / target:.1f}x")


# -- engine step ---------------------------------------------------------------------------------------------
def cpu_per_call(function: Callable[[], int], repeat: int) -> list[float]:
    out = []
    for _ in range(repeat):
        began = time.process_time()
        calls = function()
        out.append((time.process_time() - began) / calls)
    return out


def engine_step(repeat: int, seconds: float, docs: bool = False) -> None:
    from aeroexec.drones.sim import SimulatedDrone, default_world
    from aeroexec.engine.engine import Engine
    from provenance import load, measured_at, write_section

    print("Engine step of a flying drone on the simulator (CPU per step; ratio to the bare drone's integration)")
    began = load()
    world = default_world()
    corners = [(-10.0, -10.0, 3.0), (10.0, -10.0, 3.0), (10.0, -15.0, 3.0), (-10.0, -15.0, 3.0)]

    drone = SimulatedDrone(world)
    drone.arm()
    drone.takeoff(3.0)
    clock = [0.0]
    for _ in range(100):
        clock[0] += 0.05
        drone.update(clock[0])

    def bare(steps: int = int(seconds * 20)) -> int:
        for n in range(steps):
            if n % 100 == 0:
                drone.goto(corners[(n // 100) % 4])
            clock[0] += 0.05
            drone.update(clock[0])
            drone.telemetry()
        return steps

    def flying(engine: Engine) -> None:
        engine.coordinator.activate("TAKE_OFF", {"ALTITUDE": 3.0})
        engine.run_until(lambda: not engine.coordinator.is_active("TAKE_OFF"), 30.0)

    engine, idle_engine = Engine(SimulatedDrone(world), obstacles=world), Engine(SimulatedDrone(world), obstacles=world)
    flying(engine)
    flying(idle_engine)  # then it hovers: nothing active, nothing changes
    state = {"leg": 0}

    def patrol() -> int:
        steps, end = 0, engine.now() + seconds
        while engine.now() < end:
            if not engine.coordinator.is_active("GO_TO_POINT"):
                engine.coordinator.activate("GO_TO_POINT", {"COORDINATES": list(corners[state["leg"] % 4])})
                state["leg"] += 1
            engine.step(engine.period)
            steps += 1
        return steps

    def idle() -> int:
        steps, end = 0, idle_engine.now() + seconds
        while idle_engine.now() < end:
            idle_engine.step(idle_engine.period)
            steps += 1
        return steps

    patrol()
    idle()
    times: list[list[float]] = [[], [], []]
    for _ in range(repeat):  # interleaved: a load that comes and goes weighs on the three alike
        for measured, function in zip(times, (bare, patrol, idle), strict=True):
            measured += cpu_per_call(function, 1)
    base, step, hover = (spread(t) for t in times)
    line("simulated drone alone: integrate + telemetry (baseline)", f"{base[0] * 1e6:.0f} / {base[1] * 1e6:.0f} us")
    line("engine step, GO_TO_POINT patrol", f"{step[0] * 1e6:.0f} / {step[1] * 1e6:.0f} us",
         f"{step[0] / base[0]:.1f}x / {step[1] / base[1]:.1f}x", verdict(step[1] * 1e6, 50))
    line("engine step, hovering with nothing active", f"{hover[0] * 1e6:.0f} / {hover[1] * 1e6:.0f} us",
         f"{hover[0] / base[0]:.1f}x / {hover[1] / base[1]:.1f}x")
    engine.stop()
    idle_engine.stop()
    said = (f"Measured by `python bench/engine.py --only step --repeat {repeat} --docs` ({seconds:g} simulated s "
            f"of each per repeat, CPU time of this process, the three interleaved in every repeat) at "
            f"{measured_at(began)}.")
    print(said)
    if docs:
        rows = ["| engine period (20 Hz) | CPU per step (min / median) | ratio to the bare simulated drone (median) |",
                "|---|---:|---:|",
                f"| the bare simulated drone: integration + telemetry (the baseline) | {base[0] * 1e6:.0f} / "
                f"{base[1] * 1e6:.0f} µs | 1× |",
                f"| an engine flying a GO_TO_POINT patrol (monitors, telemetry beliefs, localization) | "
                f"{step[0] * 1e6:.0f} / {step[1] * 1e6:.0f} µs | {step[1] / base[1]:.2f}× |",
                f"| an engine hovering with nothing active | {hover[0] * 1e6:.0f} / {hover[1] * 1e6:.0f} µs | "
                f"{hover[1] / base[1]:.2f}× |"]
        write_section(PAGE, STEP_BEGIN, STEP_END, "\n".join([*rows, "", said]))
        print(f"{PAGE}: engine step table rewritten")


# -- longest engine steps -------------------------------------------------------------------------------------
class TickTimer:
    """Wraps ``Engine.tick`` to time every tick, for the longest one: wall time in ``ticks``, the loop thread's CPU
    time in ``cpu`` (what the step itself computed, without the time other threads and processes took the core)."""

    def __init__(self) -> None:
        from aeroexec.engine.engine import Engine

        self.engine_class, self.original = Engine, Engine.tick
        self.ticks: list[float] = []
        self.cpu: list[float] = []
        timer = self

        def tick(engine: object) -> None:
            began, cpu = time.perf_counter(), time.thread_time()
            timer.original(engine)
            timer.ticks.append(time.perf_counter() - began)
            timer.cpu.append(time.thread_time() - cpu)

        Engine.tick = tick  # type: ignore[method-assign]

    def close(self) -> None:
        self.engine_class.tick = self.original  # type: ignore[method-assign]


def longest_steps(quick: bool) -> None:
    from aeroexec.cli.main import main

    print("Longest engine step of every mission in missions/ (`aeroexec run --plain`: CPU of the loop thread, then "
          "wall; ratio to the median step of that run)")
    timer = TickTimer()
    try:
        for mission in MISSIONS[:3] if quick else MISSIONS:
            timer.ticks.clear()
            timer.cpu.clear()
            with tempfile.TemporaryDirectory() as out, contextlib.redirect_stdout(io.StringIO()), \
                    contextlib.redirect_stderr(io.StringIO()):
                main(["run", str(mission), "--plain", "--output", out])
            if not timer.ticks:  # a fleet file (`aeroexec fleet` flies it): `run` refuses it
                line(mission.name, "no step: not a one-drone mission")
                continue
            cpu, ticks = max(timer.cpu), max(timer.ticks)
            line(f"{mission.name} ({len(timer.ticks)} steps)", f"CPU {cpu * 1000:.1f} ms, wall {ticks * 1000:.1f} ms",
                 f"{cpu / statistics.median(timer.cpu):.0f}x median", verdict(cpu * 1000, 50))
    finally:
        timer.close()


def enclosed_goal() -> None:
    from aeroexec.drones.sim import SimulatedDrone, default_world
    from aeroexec.drones.sim.shapes import Box
    from aeroexec.engine.behaviors.planning import planner_settings
    from aeroexec.engine.clock import WallClock
    from aeroexec.engine.engine import Engine
    from aeroexec.engine.execution.process import EngineSettings
    from aeroexec.engine.planning import grid as grids
    from aeroexec.engine.planning.path_planner import PathPlanner

    print("GO_TO_POINT to an enclosed goal (cold grids; wall; ratio to planning it inside the tick)")
    walls = [Box(f"shell{n}", c, size) for n, (c, size) in enumerate([  # a closed box 10 m wide, 8 m high
        ((0.0, -15.0, 0.25), (10.0, 10.0, 0.5)), ((0.0, -15.0, 7.75), (10.0, 10.0, 0.5)),
        ((-4.75, -15.0, 4.0), (0.5, 10.0, 8.0)), ((4.75, -15.0, 4.0), (0.5, 10.0, 8.0)),
        ((0.0, -19.75, 4.0), (10.0, 0.5, 8.0)), ((0.0, -10.25, 4.0), (10.0, 0.5, 8.0))])]
    world = dataclasses.replace(default_world(), obstacles=default_world().obstacles + tuple(walls))
    goal = [0.0, -15.0, 4.0]  # 3.5 m or more from every wall: GO_TO_POINT's precondition asks 3 m

    grids._GRIDS.clear()
    began = time.perf_counter()
    PathPlanner(world, planner_settings(EngineSettings())).plan((0.0, 0.0, 2.0), goal)
    blocking = time.perf_counter() - began
    grids._GRIDS.clear()

    # on the wall clock, as a real drone (or a run paced by --speed) flies: the loop keeps its 20 Hz
    engine = Engine(SimulatedDrone(world), obstacles=world, clock=WallClock())
    timer = TickTimer()
    try:
        engine.start()
        with engine._lock:
            engine.coordinator.activate("TAKE_OFF", {"ALTITUDE": 2.0})
        wait_until(lambda: not engine.coordinator.is_active("TAKE_OFF"), 30.0)
        timer.ticks.clear()
        began = time.perf_counter()
        with engine._lock:
            engine.coordinator.activate("GO_TO_POINT", {"COORDINATES": goal})
        wait_until(lambda: not engine.coordinator.is_active("GO_TO_POINT"), 120.0)
        took = time.perf_counter() - began
        engine.stop()
        ticks = list(timer.ticks)
    finally:
        timer.close()
    ending = [e for e in engine.log.events() if e.behavior == "GO_TO_POINT"][-1]
    line("the plan, computed inside a tick (baseline)", f"{blocking * 1000:.0f} ms")
    line(f"longest step while it plans (it ends {ending.kind})", f"{max(ticks) * 1000:.1f} ms",
         f"{max(ticks) / blocking:.3f}x", verdict(max(ticks) * 1000, 50))
    line("steps meanwhile / request to answer", f"{len(ticks)} in {took * 1000:.0f} ms",
         f"{len(ticks) / took:.0f} Hz", "(20 Hz asked)")
    print("  (on the simulated clock the answer is used planning_time = 0.5 s of simulated time after the request;\n"
          "   a slower worker is waited for there, with simulated time standing still, so nothing is missed)")


def wait_until(condition: Callable[[], bool], seconds: float) -> None:
    end = time.monotonic() + seconds
    while not condition() and time.monotonic() < end:
        time.sleep(0.01)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--quick", action="store_true", help="fewer missions and shorter runs")
    parser.add_argument("--only", choices=["step", "missions", "planning", "trees"])
    parser.add_argument("--docs", action="store_true",
                        help="rewrite the tables of docs/performance/run.md (the engine step's and the tree ticks')")
    options = parser.parse_args()
    logging_quiet()
    parts = {"step": lambda: engine_step(options.repeat, 5.0 if options.quick else 20.0, options.docs),
             "missions": lambda: longest_steps(options.quick),
             "planning": enclosed_goal,
             "trees": lambda: tree_ticks().trees(options.repeat, options.quick, options.docs)}
    print(f"{'':52s}{'min / median':>22s}  {'ratio':>16s}")
    for name, part in parts.items():
        if options.only in (None, name):
            part()


def tree_ticks() -> Any:
    import tree_ticks  # bench/tree_ticks.py, beside this script

    return tree_ticks


def logging_quiet() -> None:
    import logging

    logging.basicConfig(level=logging.ERROR)


if __name__ == "__main__":
    main()
