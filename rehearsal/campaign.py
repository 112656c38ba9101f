"""A rehearsal: the mission flown in the simulator many times, each run with its own variations (wind, battery
capacity and drain, sensor noise, marker detection, a link drop), drawn from the run's seed alone so that any run
is flown again, the same, from its seed.

Runs go to worker processes on every core (:func:`fly_local`), or to a Dask cluster (:func:`fly_dask`: a
``LocalCluster`` when no scheduler address is given); the same seeds give the same results either way.
"""

from __future__ import annotations

import math
import multiprocessing
import os
import random
import tempfile
from collections.abc import Callable, Iterable
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict, dataclass, field
from pathlib import Path

STRONG_WIND = 8.0  # m/s: the windy part of the campaign's draws is above it


@dataclass(frozen=True)
class Variation:
    """What one run varies, drawn from its ``seed``."""

    seed: int
    wind: tuple[float, float] = (0.0, 0.0)  # m/s east, north
    wind_gust: float = 0.0
    battery_minutes: float = 20.0  # of hover
    drain: float = 0.5  # extra drain at full speed, as a fraction of hover drain
    position_noise: float = 0.0  # m
    detection_probability: float = 1.0
    link_loss: tuple[float, float] | None = None

    @classmethod
    def draw(cls, seed: int) -> Variation:
        rng = random.Random(seed)
        speed, heading = rng.uniform(0.0, 12.0), rng.uniform(0.0, 2.0 * math.pi)
        drop = (round(rng.uniform(10.0, 60.0), 1), round(rng.uniform(2.0, 20.0), 1)) if rng.random() < 0.1 else None
        return cls(seed, (round(speed * math.cos(heading), 2), round(speed * math.sin(heading), 2)),
                   round(rng.uniform(0.0, 1.5), 2), round(rng.uniform(12.0, 22.0), 1), round(rng.uniform(0.3, 0.9), 2),
                   round(rng.uniform(0.0, 0.15), 3), round(rng.uniform(0.6, 1.0), 2), drop)

    @property
    def wind_speed(self) -> float:
        return math.hypot(*self.wind)

    def config(self):  # noqa: ANN201 - a SimConfig
        from aeroexec.drones.sim.config import SimConfig

        return SimConfig(wind=self.wind, wind_gust=self.wind_gust, battery_hover_minutes=self.battery_minutes,
                         battery_speed_drain=self.drain, position_noise_std=self.position_noise,
                         detection_probability=self.detection_probability, link_loss=self.link_loss)


@dataclass
class RunResult:
    """How one run went."""

    variation: Variation
    status: str = ""
    reasons: list[str] = field(default_factory=list)
    duration: float = 0.0  # simulated seconds
    battery: float = 0.0  # percent at the end
    clearance: float = math.inf  # m: the least distance to an obstacle
    rules: list[dict] = field(default_factory=list)  # the safety events: rule, time, where
    wall: float = 0.0  # CPU seconds of the worker's process
    worker: int = 0  # the process that flew it (its id)

    @property
    def success(self) -> bool:
        return self.status == "completed"

    def as_dict(self) -> dict:
        found = asdict(self)
        found["clearance"] = None if math.isinf(self.clearance) else self.clearance
        return found


def seeds(runs: int, first: int = 0) -> list[int]:
    """The seeds of a campaign of ``runs`` runs."""
    return [first + i for i in range(runs)]


def fly(mission: str, seed: int, rules: tuple[str, ...] = (), max_time: float = 900.0,
        output: str | None = None) -> RunResult:
    """Fly ``mission`` once with the variation of ``seed`` (its files in ``output``, else thrown away)."""
    import time

    from aeroexec.drones.sim import SimulatedDrone
    from aeroexec.flight.robot import load_world
    from aeroexec.flight.session import FlightSession
    from aeroexec.flight.spec import FlightError, FlightSpec

    variation = Variation.draw(seed)
    result = RunResult(variation, worker=os.getpid())
    began = time.process_time()
    with tempfile.TemporaryDirectory(prefix="aeroexec-rehearse-") as scratch:
        folder = Path(output) if output else Path(scratch) / "run"
        world = load_world(None, default=True)
        drone = SimulatedDrone(world, config=variation.config(), seed=seed)
        spec = FlightSpec(mission=Path(mission), seed=seed, max_time=max_time, output=str(folder), register=False,
                          safety_rules=tuple(rules))
        session = FlightSession(spec, notify=lambda message: None, robot=drone, world=world)
        try:
            session.open()
        except FlightError as error:
            session.close()
            result.status, result.reasons = "refused", [str(error)]
            return result
        engine = session.engine
        clearance = [math.inf]

        def sample() -> None:
            if int(engine.now() * 20) % 10 == 0 and drone.telemetry().position[2] > 0.2:
                clearance[0] = min(clearance[0], world.distance_to_obstacle(drone.telemetry().position))

        engine.tick_callbacks.append(sample)
        outcome = session.fly()
        result.status, result.reasons = outcome.status.word, list(outcome.status.reasons)
        result.duration = round(engine.now(), 2)
        result.battery = round(drone.telemetry().battery_percent, 2)
        result.clearance = round(clearance[0], 2) if clearance[0] < math.inf else math.inf
        result.rules = [{"rule": e.data.get("rule"), "kind": e.kind, "time": round(e.time, 2),
                         "beliefs": e.data.get("beliefs", {})}
                        for e in engine.log.events() if e.kind in ("safety_violated", "safety_triggered")]
    result.wall = round(time.process_time() - began, 3)
    return result


def _fly(arguments: tuple) -> RunResult:
    """A worker's run: what the engine logs below an error stays in the run, not on the campaign's terminal."""
    import logging

    logging.getLogger("aeroexec").setLevel(logging.ERROR)
    return fly(*arguments)


def _clean_start() -> multiprocessing.context.BaseContext:
    """Workers started from a clean process (a fork server, else spawned): a fork of a process whose other threads
    hold locks (a console, a logging handler, a test runner's I/O) can leave the child waiting on them forever."""
    try:
        return multiprocessing.get_context("forkserver")
    except ValueError:  # no fork server on this platform
        return multiprocessing.get_context("spawn")


def fly_local(mission: str, run_seeds: Iterable[int], rules: tuple[str, ...] = (), workers: int | None = None,
              max_time: float = 900.0, progress: Callable[[RunResult], None] = lambda result: None
              ) -> list[RunResult]:
    """Every run in worker processes, one per core (``workers``), in the order of the seeds."""
    jobs = [(str(mission), seed, tuple(rules), max_time) for seed in run_seeds]
    workers = workers or os.cpu_count() or 1
    results = []
    with ProcessPoolExecutor(max_workers=min(workers, max(len(jobs), 1)), mp_context=_clean_start()) as pool:
        for result in pool.map(_fly, jobs):
            progress(result)
            results.append(result)
    return results


def fly_dask(mission: str, run_seeds: Iterable[int], rules: tuple[str, ...] = (), scheduler: str | None = None,
             workers: int | None = None, max_time: float = 900.0,
             progress: Callable[[RunResult], None] = lambda result: None) -> list[RunResult]:
    """Every run on a Dask cluster: the scheduler at ``scheduler``, else a ``LocalCluster`` of ``workers``
    processes on this machine (loopback only)."""
    from aeroexec.extras import require

    with require("rehearse"):
        from distributed import Client, LocalCluster

    jobs = [(str(mission), seed, tuple(rules), max_time) for seed in run_seeds]
    cluster = None
    if scheduler is None:
        cluster = LocalCluster(n_workers=workers or os.cpu_count() or 1, threads_per_worker=1, processes=True,
                               host="127.0.0.1", dashboard_address=None)
    try:
        with Client(scheduler or cluster) as client:
            futures = client.map(_fly, jobs, pure=False)
            results = client.gather(futures)
            for result in results:
                progress(result)
            return list(results)
    finally:
        if cluster is not None:
            cluster.close()


__all__ = ["STRONG_WIND", "RunResult", "Variation", "fly", "fly_dask", "fly_local", "seeds"]
