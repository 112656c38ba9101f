"""The monitors' schedule never changes what they see: checking a rule only when it may have flipped (odometers of
the believed positions, the charge's and the clock's rates, the beliefs it reads) finds every violation at the same
tick, with the same beliefs and the same contingency, as checking every rule at every tick."""

from __future__ import annotations

import math
import textwrap

import aeroexec.engine.api as api
import pytest
from aeroexec.beliefs import FunctionUpdater, Struct
from aeroexec.drones.sim import SimulatedDrone
from aeroexec.drones.sim.config import SimConfig
from aeroexec.engine.catalog import default_catalog
from aeroexec.engine.catalog.safety_rules import read_safety_rules_text
from aeroexec.engine.engine import Engine
from aeroexec.engine.safety.declared import vocabulary

RULES = {  # each broken at some point of the patrol below
    "pad": "never: 'position(self, ?p), distance(?p, (11, 9, 6), ?d), ?d < 2.5', contingency: hold",
    "fence_x": "always: 'position(self, (?x, ?y, ?z)), ?x > -13, ?x < 13.5', contingency: hold",
    "ground": "never: 'position(self, (?x, ?y, ?z)), distance((?x, ?y, 0), (11, 9, 0), ?d), ?d < 2', "
              "contingency: hold",  # a point built of its variables: the memory's solver fills it in
    "ceiling": "always: 'position(self, (?x, ?y, ?z)), ?z < 7.5', contingency: hold",
    "braking": "never: 'stopping_point(self, ?p), distance(?p, (-12, 4, 6), ?d), ?d < 3', contingency: hold",
    "mate": "never: 'position(?o, ?q), ?o != self, position(self, ?p), distance(?p, ?q, ?d), ?d < 4', "
            "contingency: hold",
    "margin": "always: 'return_margin(self, ?m), ?m >= 30', contingency: return",
    "home_far": "never: 'battery_to_home(self, ?b), ?b > 9.7', contingency: land",
    "rally": "never: 'rally_distance(self, ?r), ?r > 16.5', contingency: hold",
    "clock": "never: 'mission_time(?t), ?t > 61.3', contingency: land",
}


def patrol() -> None:
    api.execute_behavior("TAKE_OFF", ALTITUDE=6)
    for point in [(12, 0, 6), (12, 12, 8), (-12, 12, 6), (-12, -12, 6), (14, -12, 6), (0, 0, 6)] * 2:
        api.execute_behavior("GO_TO_POINT", COORDINATES=list(point))


def mate(memory, now: float) -> None:
    """A fleet mate flying a circle across the patrol (its position as the fleet link writes it)."""
    angle = now / 9.0
    memory.add(Struct("position", ("d2", (round(9 * math.cos(angle), 2), round(9 * math.sin(angle), 2), 6.0))))


def safety_events(rules: str, every_tick: bool, config: SimConfig) -> tuple[list[tuple], dict[str, int]]:
    catalog = default_catalog()
    found = read_safety_rules_text(textwrap.dedent(rules), "rules.yaml", vocabulary(catalog))
    assert not found.problems, found.problems
    engine = Engine(SimulatedDrone(config=config), catalog=catalog.with_safety_rules(found.rules),
                    updaters=[FunctionUpdater("mate", mate, 0.1)])
    engine.safety.every_tick = every_tick
    engine.run(patrol, max_time=90)
    engine.stop()
    return [(round(e.time, 2), e.kind, e.data.get("rule"), e.detail) for e in engine.log.events()
            if e.kind.startswith("safety_") and e.kind != "safety_watch"], engine.safety.checks


@pytest.mark.parametrize("rule", sorted(RULES))
def test_each_rule_breaks_at_the_same_tick_as_when_checked_every_tick(rule):
    """One rule at a time (another rule's contingency would end the comparison), with position noise, wind and
    gusts, a battery that drains fast and a fleet mate crossing: the same events, and fewer checks."""
    text = f"- {{rule: {rule}, {RULES[rule]}}}\n"
    config = SimConfig(position_noise_std=0.2, wind=(3.0, -2.0), wind_gust=1.5, initial_battery_percent=48,
                       battery_hover_minutes=4)
    scheduled, checks = safety_events(text, False, config)
    reference, every = safety_events(text, True, config)
    assert any(kind == "safety_violated" for _, kind, _, _ in reference), f"{rule} is never broken: no test"
    assert scheduled == reference
    assert checks[rule] < every[rule], (checks, every)
