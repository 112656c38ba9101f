"""Safety monitors' cost: the engine step (CPU per simulated period) of a drone flying a GO_TO_POINT patrol, with
no safety rules (the baseline, same run) and with 20 rules (keep-out volumes, a fence, the return margin, wind,
link, mission time...), as a ratio. Target (issue 31): 20 rules add at most 5 %.

Run ``python bench/safety.py`` (``--repeat N``)."""

from __future__ import annotations

import argparse
import statistics
import time

import aeroexec.engine.api as api
from aeroexec.drones.sim import SimulatedDrone
from aeroexec.engine.catalog import default_catalog
from aeroexec.engine.catalog.safety_rules import read_safety_rules_text
from aeroexec.engine.engine import Engine
from aeroexec.engine.safety.declared import vocabulary

RULES = "\n".join([
    *(f"- {{rule: keep_out_{i}, never: 'position(self, ?p), distance(?p, ({-18 + 4 * i}, 19, 3), ?d), ?d < 1', "
      f"contingency: hold}}" for i in range(10)),
    "- {rule: fence_x, always: 'position(self, (?x, ?y, ?z)), ?x > -19, ?x < 19', contingency: hold}",
    "- {rule: fence_y, always: 'position(self, (?x, ?y, ?z)), ?y > -19, ?y < 19', contingency: hold}",
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


def patrol() -> None:
    api.execute_behavior("TAKE_OFF", ALTITUDE=6)
    for _ in range(3):
        for point in [(12, 0, 6), (12, 12, 6), (-12, 12, 6), (-12, -12, 6)]:
            api.execute_behavior("GO_TO_POINT", COORDINATES=list(point))


def step_cpu(rules: str) -> tuple[float, int]:
    catalog = default_catalog()
    found = read_safety_rules_text(rules, "bench.yaml", vocabulary(catalog)) if rules else None
    engine = Engine(SimulatedDrone(), catalog=catalog.with_safety_rules(found.rules) if found else catalog)
    began = time.thread_time()
    engine.run(patrol, max_time=600)
    cpu = time.thread_time() - began
    periods = round(engine.now() / engine.period)
    checks = sum(engine.safety.checks.values()) if engine.safety else 0
    engine.stop()
    return cpu / periods * 1e6, checks


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    base, ruled, checks = [], [], 0
    for _ in range(args.repeat):  # interleaved: the load hits both alike
        base.append(step_cpu("")[0])
        cost, checks = step_cpu(RULES)
        ruled.append(cost)
    b, r = statistics.median(base), statistics.median(ruled)
    print(f"engine step, no rules (baseline)   {min(base):6.1f} / {b:6.1f} us (min / median)")
    print(f"engine step, 20 safety rules       {min(ruled):6.1f} / {r:6.1f} us; {checks} rule checks in the run")
    print(f"ratio (median)                     {r / b:6.3f}  target <= 1.05: {'met' if r / b <= 1.05 else 'MISSED'}")


if __name__ == "__main__":
    main()
