"""A case flown by a fleet of 2 to 5 drones: a real ``aeroexec fleet FILE`` process (one session per drone in
lockstep on one clock, linked over Zenoh on loopback); each drone's files judged by the invariants of one run, and
the fleet's exit status against its drones' (0 only when every drone's flight completed)."""

from __future__ import annotations

import contextlib
import json
import subprocess
import sys
import time
from pathlib import Path

from aeroexec.rehearsal.simulation.cases import Case
from aeroexec.rehearsal.simulation.flights import Flown, Part
from aeroexec.rehearsal.simulation.invariants import Violation, check
from aeroexec.rehearsal.simulation.processes import LIMIT, _records, last_state

#: Where each drone of a fleet takes off (x, y in the built-in field, metres from its home): 6 m apart along the
#: south of the field, clear of its trees and walls.
HOMES = ((-12.0, -13.0), (-6.0, -13.0), (0.0, -13.0), (6.0, -13.0), (12.0, -13.0))
SCALE = 0.4  # a drone's points, drawn within 6 m of home, brought within 2.4 m of its own


def shifted(text: str, points: tuple[tuple[float, float, float], ...], home: tuple[float, float]) -> str:
    """A tree mission's points brought around ``home`` (each drone flies around its own take-off point)."""
    for x, y, z in points:
        text = text.replace(f'"{x}, {y}, {z}"',
                            f'"{round(home[0] + SCALE * x, 1)}, {round(home[1] + SCALE * y, 1)}, {z}"')
    return text


def _member(folder: Path, name: str, case: Case) -> Flown:
    """One drone's part, read from its files (its last state sample, its run_ended)."""
    from aeroexec.flight.run_status import FlightOutcome, RunStatus, last_part

    flown = Flown(case, folder)
    part = Part()
    records = last_part(_records(folder))
    ended = [r for r in records if r.get("kind") == "run_ended"]
    states = [r for r in records if r.get("kind") == "state"]
    last_state(part, states)
    part.state_known = bool(states)
    if ended:
        status = RunStatus(ended[-1]["detail"], list((ended[-1].get("data") or {}).get("reasons", [])))
        part.outcome = FlightOutcome(status, [], None, folder)
    else:
        part.refused = f"{name}: no run_ended"
    flown.parts.append(part)
    return flown


def fly_fleet(case: Case, scratch: Path) -> tuple[Flown, list[Violation]]:
    """Fly ``case``'s fleet; the first drone's files as the case's, and every violation of every drone (named)."""
    began = time.perf_counter()
    names = [f"d{i + 1}" for i in range(len(case.fleet))]
    lines = ["fleet: campaign", "world: default", "drones:"]
    for name, mission, home in zip(names, case.fleet, HOMES, strict=False):
        path = scratch / f"{name}{mission.suffix}"
        path.write_text(shifted(mission.text, mission.points, home))
        lines.append(f"  - {{name: {name}, mission: {path.name}, home: [{home[0]}, {home[1]}]}}")
    fleet_file = scratch / "fleet.yaml"
    fleet_file.write_text("\n".join(lines) + "\n")
    output = scratch / "run"
    try:
        process = subprocess.run([sys.executable, "-m", "aeroexec.cli.main", "fleet", str(fleet_file), "--quiet",
                                  "--workers", "1", "--output", str(output), "--max-time", "300"],
                                 capture_output=True, text=True, cwd=scratch, timeout=LIMIT)
        status, said = process.returncode, [line for line in process.stderr.splitlines() if line.strip()]
    except subprocess.TimeoutExpired:
        status, said = None, [f"the fleet did not end within {LIMIT:g} s"]
    violations: list[Violation] = []
    flowns = []
    for name in names:
        if not (output / name / "events.jsonl").is_file():
            continue
        flown = _member(output / name, name, case)
        flowns.append((name, flown))
        violations += [Violation(v.invariant, f"drone {name}: {v.detail}") for v in check(flown)
                       if v.invariant not in ("goals_at_most_once", "flies_the_journaled_mission")]
    first = flowns[0][1] if flowns else Flown(case, output, [Part(refused=said[-1] if said else "refused")])
    if status in (70, None) or any("please report it" in line for line in said):
        violations.append(Violation("no_internal_error", f"the fleet exited {status}: {said[-1] if said else ''}"))
    words = {}
    with contextlib.suppress(OSError, ValueError):
        words = json.loads((output / "fleet_status.json").read_text()).get("drones", {})
    if words:
        expected = 0 if all(d.get("exit_status") == 0 for d in words.values()) else 1
        if status != expected:
            violations.append(Violation("exit_status_agrees", f"the fleet exited {status}; its drones ended "
                                        f"{sorted({d.get('status') for d in words.values()})}"))
        for name, flown in flowns:
            part = flown.parts[-1]
            if part.outcome is not None and name in words and words[name].get("status") != part.outcome.status.word:
                violations.append(Violation("exit_status_agrees", f"drone {name}: fleet_status.json says "
                                            f"{words[name].get('status')!r}, its run_ended "
                                            f"{part.outcome.status.word!r}"))
    first.wall = time.perf_counter() - began
    first.exit_status = None
    return first, violations


__all__ = ["HOMES", "fly_fleet", "shifted"]
