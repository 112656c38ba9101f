"""Safety monitors' cost: the engine step (CPU per simulated period) of a drone flying a GO_TO_POINT patrol, with
no safety rules (the baseline, same run) and with 20 rules (keep-out volumes, a fence, the return margin, wind,
link, mission time...), as a ratio. Target (issue 31): 20 rules add at most 5 %. None of them breaks: the believed
position drifts (dead reckoning) by up to 8 m over the four laps, the fence is wide of it.

The step is measured as ``bench/engine.py`` measures it, after the start: the CPU of a patrol of four laps less
that of one lap, over the periods between (take-off, the first lap, and the rules' first check, when their
queries are compiled, are left out: that start-up is printed apart). ``--callgrind`` counts instructions instead
of CPU time (valgrind's callgrind: the same on a loaded machine), running each variant in its own process.

Run ``python bench/safety.py`` (``--repeat N``, ``--callgrind``)."""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import aeroexec.engine.api as api
from aeroexec.drones.sim import SimulatedDrone
from aeroexec.engine.catalog import default_catalog
from aeroexec.engine.catalog.safety_rules import read_safety_rules_text
from aeroexec.engine.engine import Engine
from aeroexec.engine.safety.declared import vocabulary

RULES = "\n".join([
    *(f"- {{rule: keep_out_{i}, never: 'position(self, ?p), distance(?p, ({-18 + 4 * i}, 19, 3), ?d), ?d < 1', "
      f"contingency: hold}}" for i in range(10)),
    "- {rule: fence_x, always: 'position(self, (?x, ?y, ?z)), ?x > -30, ?x < 30', contingency: hold}",
    "- {rule: fence_y, always: 'position(self, (?x, ?y, ?z)), ?y > -30, ?y < 30', contingency: hold}",
    "- {rule: ceiling, always: 'position(self, (?x, ?y, ?z)), ?z < 18', contingency: hold}",
    "- {rule: margin, always: 'return_margin(self, ?m), ?m >= 10', contingency: return}",
    "- {rule: low, never: 'charge(battery, ?c), ?c < 8', contingency: land}",
    "- {rule: wind, never: 'wind(self, ?w), ?w > 12', contingency: land}",
    "- {rule: clock, never: 'mission_time(?t), ?t > 3000', contingency: return}",
    "- {rule: link, within: 30, after: 'communication(wireless, lost)', ensure: 'flight_state(self, landed)', "
    "contingency: land}",
    "- {rule: armed, never: 'armed(self, no), flight_state(self, moving)', contingency: land}",
    "- {rule: stop, never: 'stopping_point(self, ?p), distance(?p, (0, 0, 30), ?d), ?d < 2', contingency: hold}",
])


def patrol(laps: int) -> Any:
    def fly() -> None:
        api.execute_behavior("TAKE_OFF", ALTITUDE=6)
        for _ in range(laps):
            for point in [(12, 0, 6), (12, 12, 6), (-12, 12, 6), (-12, -12, 6)]:
                api.execute_behavior("GO_TO_POINT", COORDINATES=list(point))
    return fly


def flight(rules: str, laps: int) -> tuple[float, int, int]:
    """CPU seconds of the engine's thread flying ``laps`` laps, the periods it took, and the rule checks."""
    catalog = default_catalog()
    found = read_safety_rules_text(rules, "bench.yaml", vocabulary(catalog)) if rules else None
    engine = Engine(SimulatedDrone(), catalog=catalog.with_safety_rules(found.rules) if found else catalog)
    began = time.thread_time()
    engine.run(patrol(laps), max_time=900)
    cpu = time.thread_time() - began
    periods = round(engine.now() / engine.period)
    checks = sum(engine.safety.checks.values()) if engine.safety else 0
    fired = [e.detail for e in engine.log.events() if e.kind == "safety_violated"]
    engine.stop()
    if fired:  # its contingency changes the flight: it would not be the baseline's any more
        sys.exit(f"a rule broke in the measured flight: {fired[0]}")
    return cpu, periods, checks


def step(rules: str) -> tuple[float, float, int]:
    """The steady step (us per period: four laps less one), the start-up (ms), and the checks in the laps between."""
    short, long = flight(rules, 1), flight(rules, 4)
    return (long[0] - short[0]) / (long[1] - short[1]) * 1e6, short[0] * 1e3, long[2] - short[2]


def callgrind(rules: bool, laps: int) -> int:
    """Instructions of a process that builds the engine and flies ``laps`` laps (0: builds it only)."""
    with tempfile.TemporaryDirectory() as folder:
        out = Path(folder) / "callgrind.out"
        subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", sys.executable, __file__,
                        "--fly", str(laps)] + (["--rules"] if rules else []), check=True, capture_output=True,
                       env={**os.environ, "PYTHONHASHSEED": "0"})
        return next(int(line.split()[1]) for line in out.read_text().splitlines() if line.startswith("summary:"))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--callgrind", action="store_true", help="count instructions (valgrind) instead of CPU time")
    parser.add_argument("--fly", type=int, help=argparse.SUPPRESS)  # one flight, counted by callgrind
    parser.add_argument("--rules", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.fly is not None:
        flight(RULES if args.rules else "", args.fly)
        return
    if args.callgrind:
        steps = flight("", 4)[1] - flight("", 1)[1]
        base = (callgrind(False, 4) - callgrind(False, 1)) / steps
        ruled = (callgrind(True, 4) - callgrind(True, 1)) / steps
        print(f"engine step, no rules (baseline)   {base / 1000:7.1f} k instructions")
        print(f"engine step, 20 safety rules       {ruled / 1000:7.1f} k instructions")
        print(f"ratio                              {ruled / base:7.3f}  target <= 1.05: "
              f"{'met' if ruled / base <= 1.05 else 'MISSED'}")
        return
    base, ruled, starts, checks = [], [], [], 0
    for _ in range(args.repeat):  # interleaved: the load hits both alike
        base.append(step("")[0])
        cost, start, checks = step(RULES)
        ruled.append(cost)
        starts.append(start - flight("", 1)[0] * 1e3)
    b, r = statistics.median(base), statistics.median(ruled)
    print(f"engine step, no rules (baseline)   {min(base):6.1f} / {b:6.1f} us (min / median)")
    print(f"engine step, 20 safety rules       {min(ruled):6.1f} / {r:6.1f} us; {checks} rule checks in three laps")
    print(f"ratio (median)                     {r / b:6.3f}  target <= 1.05: {'met' if r / b <= 1.05 else 'MISSED'}")
    print(f"start-up: take-off and a first lap {statistics.median(starts):+6.1f} ms CPU with the rules (their "
          f"queries compiled, each checked once)")


if __name__ == "__main__":
    main()
