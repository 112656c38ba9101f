"""Cases flown and judged: one (:func:`run_case`), many on every core or a Dask cluster (:func:`run_campaign`, the
workers and cluster of ``aeroexec rehearse``), a failing one shrunk (:func:`shrink`: its actions, faults and rules
dropped one at a time while the same invariant still fails), and the one command that replays a seed."""

from __future__ import annotations

import contextlib
import gc
import logging
import os
import re
import shutil
import tempfile
import time
from collections.abc import Callable, Iterable
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field, replace
from pathlib import Path

from aeroexec.rehearsal.simulation.cases import Case, draw
from aeroexec.rehearsal.simulation.flights import Part, fly_case
from aeroexec.rehearsal.simulation.invariants import Violation, check

logger = logging.getLogger(__name__)


def replay_command(seed: int, extra: Iterable[str] = ()) -> str:
    """The command that flies the case of ``seed`` again, its files kept."""
    flags = "".join(f" --with {name}" for name in sorted(extra))
    return f"aeroexec campaign --seed {seed}{flags}"


@dataclass
class CaseResult:
    """How one case went: its violations, how the run ended (word, or refused), and its cost."""

    seed: int
    violations: list[Violation] = field(default_factory=list)
    ended: str = ""
    why: str = ""  # the run's reasons (the refusal, the failure), or the set-up's refusal
    steps: int = 0  # engine steps flown, over every part
    parts: int = 0
    wall: float = 0.0
    cpu: float = 0.0
    longest_step: float = 0.0
    peak_memory: float = 0.0
    description: str = ""
    extra: tuple[str, ...] = ()

    @property
    def failed(self) -> bool:
        return bool(self.violations)

    def outcome_line(self) -> str:
        """The case's outcome as one JSON line: its seed, how it ended, its parts and the invariants it violated
        (no costs: two runs of the same seeds give the same lines)."""
        import json

        return json.dumps({"seed": self.seed, "ended": self.ended, "why": self.why, "steps": self.steps,
                           "parts": self.parts, "violated": sorted({v.invariant for v in self.violations})})

    def report(self) -> str:
        """Each violation with its invariant's name, the case, and the command that replays it."""
        lines = [f"seed {self.seed}: {v}" for v in self.violations]
        lines.append(f"  replay: {replay_command(self.seed, self.extra)}")
        lines += ["  " + line for line in self.description.splitlines()]
        return "\n".join(lines)


def judge(case: Case, keep: Path | None = None, extra: Iterable[str] = ()) -> CaseResult:
    """Fly ``case`` (its files in ``keep``, else thrown away) and check every invariant (``extra``: the gated kinds
    asked for)."""
    extra = frozenset(extra)
    warm_up()
    with tempfile.TemporaryDirectory(prefix="aeroexec-campaign-", dir=_scratch_root()) as scratch:
        where = Path(keep) if keep is not None else Path(scratch)
        if keep is not None and where.exists():  # a replay starts from nothing, as the campaign's case did
            shutil.rmtree(where)
        where.mkdir(parents=True, exist_ok=True)
        if case.fleet:
            from aeroexec.rehearsal.simulation.fleets import fly_fleet

            flown, violations = fly_fleet(case, where)
        elif case.subprocess:
            from aeroexec.rehearsal.simulation.processes import fly_process

            flown = fly_process(case, where)
            violations = check(flown)
        else:
            flown = fly_case(case, where, extra)
            violations = check(flown)
    if any(v.invariant == "step_bound" for v in violations) and keep is None:
        violations = _again(case, violations, extra)
    last = flown.parts[-1] if flown.parts else None
    ended = ("refused" if last is None or last.refused is not None else "killed" if last.crashed
             else "error" if last.error or last.outcome is None else last.outcome.status.word)
    return CaseResult(case.seed, violations, ended, _why(last, where), sum(p.steps for p in flown.parts),
                      len(flown.parts), round(flown.wall, 3), round(flown.cpu, 3),
                      max((p.longest_step for p in flown.parts), default=0.0), flown.peak_memory, case.describe())


def _why(last: Part | None, where: Path) -> str:
    """Why the case's last part ended as it did, without what differs run to run by design: its scratch folder's
    name and the runs' identities (``run-`` and a random UUID)."""
    if last is None:
        return ""
    if last.refused is not None or last.error or last.outcome is None:
        text = last.refused or last.error or ""
    else:
        text = "; ".join(last.outcome.status.reasons)
    return re.sub(r"run-[0-9a-f]{32}", "run-ID", text.replace(str(where), "CASE"))


def _again(case: Case, violations: list[Violation], extra: frozenset[str]) -> list[Violation]:
    """A long step is flown again: a shared machine (another process, a virtual machine's stolen time) may charge
    one step of a run with CPU it did not use, but a step that does too much is long every time it is flown."""
    with tempfile.TemporaryDirectory(prefix="aeroexec-campaign-", dir=_scratch_root()) as scratch:
        again = [v for v in check(fly_case(case, Path(scratch), extra)) if v.invariant == "step_bound"]
    kept = [v for v in violations if v.invariant != "step_bound"]
    if again:
        kept += [Violation("step_bound", f"{v.detail}; flown again: {a.detail}")
                 for v, a in zip([v for v in violations if v.invariant == "step_bound"], again, strict=False)]
    return kept


def _scratch_root() -> str | None:
    """Scratch on memory when the machine has it (no disk syncs in the way of hundreds of short flights)."""
    return "/dev/shm" if os.path.isdir("/dev/shm") and os.access("/dev/shm", os.W_OK) else None


def run_case(seed: int, extra: tuple[str, ...] = (), keep: str | None = None) -> CaseResult:
    """The case of ``seed`` drawn, flown and judged."""
    result = judge(draw(seed, frozenset(extra)), Path(keep) if keep else None, extra)
    result.extra = tuple(sorted(extra))
    return result


def shrink(case: Case, invariant: str, budget: int = 12, extra: Iterable[str] = ()) -> Case:
    """``case`` with as few actions, faults and rules as still fail ``invariant`` (one dropped at a time, at most
    ``budget`` flights)."""
    flights = 0
    progress = True
    while progress and flights < budget:
        progress = False
        for part in case.parts():
            if flights >= budget:
                break
            smaller = case.without(part)
            flights += 1
            if any(v.invariant == invariant for v in judge(smaller, extra=extra).violations):
                case, progress = smaller, True
                break
    return case


WARM_UP = (1, 3, 6, 15)  # seeds of a tree, a Python mission, a plan and a link drop: the modules they load, loaded
_warm: list[bool] = []


def warm_up() -> None:
    """Fly a few cases once per process, unjudged, then freeze what they left (``gc.freeze``, as ``aeroexec run``
    does after its imports): an engine step is timed for what it does, not for a module imported the first time
    a process meets a behavior, nor a collection walking what the imports made."""
    if _warm:
        return
    _warm.append(True)
    for seed in WARM_UP:
        with contextlib.suppress(Exception), tempfile.TemporaryDirectory(dir=_scratch_root()) as scratch:
            fly_case(replace(draw(seed), subprocess=False, fleet=()), Path(scratch))
    gc.collect()
    gc.freeze()


def _worker(arguments: tuple) -> CaseResult:
    """One case in a worker, or in this process (one worker): what a run logs below an error stays in the run, and
    the engine's loggers are left at the level they had (a program that runs a campaign keeps its warnings)."""
    engine = logging.getLogger("aeroexec")
    level = engine.level
    engine.setLevel(logging.ERROR)
    try:
        warm_up()
        seed, extra = arguments
        try:
            return run_case(seed, extra)
        except Exception as error:  # noqa: BLE001 - the campaign's own failure, said for its seed
            return CaseResult(seed, [Violation("no_internal_error", f"the case could not be flown: "
                                                                    f"{type(error).__name__}: {error}")],
                              "error", extra=tuple(sorted(extra)))
    finally:
        engine.setLevel(level)


def run_campaign(seeds: Iterable[int], extra: tuple[str, ...] = (), workers: int | None = None,
                 scheduler: str | None = None, dask: bool = False,
                 progress: Callable[[CaseResult], None] = lambda result: None) -> list[CaseResult]:
    """Every case of ``seeds`` in worker processes (one per core, as ``aeroexec rehearse`` runs them), or on a
    Dask cluster (``dask``: a local one; ``scheduler``: the one at that address); in the order of the seeds."""
    from aeroexec.rehearsal.campaign import _clean_start

    jobs = [(seed, tuple(extra)) for seed in seeds]
    workers = workers or os.cpu_count() or 1
    results: list[CaseResult] = []
    if dask or scheduler:
        from aeroexec.extras import require

        with require("rehearse"):
            from distributed import Client, LocalCluster
        cluster = None if scheduler else LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                                      host="127.0.0.1", dashboard_address=None)
        try:
            with Client(scheduler or cluster) as client:
                for result in client.gather(client.map(_worker, jobs, pure=False)):
                    progress(result)
                    results.append(result)
        finally:
            if cluster is not None:
                cluster.close()
        return results
    if workers == 1:
        for job in jobs:
            results.append(_worker(job))
            progress(results[-1])
        return results
    pool = ProcessPoolExecutor(max_workers=min(workers, max(len(jobs), 1)), mp_context=_clean_start())
    try:
        for result in pool.map(_worker, jobs, chunksize=4):
            progress(result)
            results.append(result)
    except KeyboardInterrupt:  # Ctrl-C: what was flown is kept, the rest dropped; the workers end their cases
        pool.shutdown(wait=False, cancel_futures=True)
        raise Interrupted(results) from None
    pool.shutdown()
    return results


class Interrupted(KeyboardInterrupt):
    """A campaign interrupted (Ctrl-C): ``results`` holds the cases flown before."""

    def __init__(self, results: list[CaseResult]) -> None:
        super().__init__("interrupted")
        self.results = results


@dataclass
class Figures:
    """A campaign's figures: flights, violations by invariant, flights per minute."""

    flights: int
    failed: int
    by_invariant: dict[str, int]
    wall: float
    per_minute: float
    ended: dict[str, int]


def figures(results: list[CaseResult], wall: float) -> Figures:
    by: dict[str, int] = {}
    ended: dict[str, int] = {}
    for result in results:
        ended[result.ended] = ended.get(result.ended, 0) + 1
        for name in {v.invariant for v in result.violations}:
            by[name] = by.get(name, 0) + 1
    return Figures(len(results), sum(r.failed for r in results), by, wall,
                   len(results) / wall * 60.0 if wall > 0 else 0.0, ended)


def timed_campaign(seeds: Iterable[int], **options) -> tuple[list[CaseResult], Figures]:  # noqa: ANN003
    began = time.perf_counter()
    results = run_campaign(seeds, **options)
    return results, figures(results, time.perf_counter() - began)


__all__ = ["CaseResult", "Figures", "Interrupted", "figures", "judge", "replay_command", "run_campaign", "run_case",
           "shrink", "timed_campaign"]
