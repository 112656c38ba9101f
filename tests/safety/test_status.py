"""What the live view and the console show of the safety rules: held, then the rule violated since when and the
contingency in effect, and a ``within`` rule's obligation due by its deadline (SafetyMonitor.status)."""

from __future__ import annotations

import aeroexec.engine.api as api
from aeroexec.console.feed import ConsoleFeed
from aeroexec.drones.sim import SimulatedDrone
from aeroexec.drones.sim.config import SimConfig
from aeroexec.engine.catalog import default_catalog
from aeroexec.engine.catalog.safety_rules import read_safety_rules_text
from aeroexec.engine.engine import Engine
from aeroexec.engine.safety.declared import vocabulary

RULES = """\
- {rule: fence, always: 'position(self, (?x, ?y, ?z)), ?x < 8', contingency: hold}
- {rule: link_loss, within: 60, after: 'communication(wireless, lost)', ensure: 'flight_state(self, landed)',
   contingency: land}
"""


def test_the_console_shows_the_rules_held_then_an_obligation_due_then_a_violation_and_its_contingency():
    catalog = default_catalog()
    rules = read_safety_rules_text(RULES, "rules.yaml", vocabulary(catalog)).rules
    engine = Engine(SimulatedDrone(config=SimConfig(link_loss=(20.0, 100.0))), catalog=catalog.with_safety_rules(rules))
    feed = ConsoleFeed(engine, "d1")

    def mission() -> None:
        api.execute_behavior("TAKE_OFF", ALTITUDE=3)
        api.execute_behavior("GO_TO_POINT", COORDINATES=[12, 0, 3])

    try:
        engine.start_mission(mission, "fenced")
        engine.step(1.0)
        assert feed.snapshot()["safety"] == {"rules": 2, "level": "held", "summary": "safety: 2 rules held",
                                             "violated": [], "due": [], "in_effect": None}
        engine.run_until(lambda: engine.log.events("safety_violated"), 20)
        violated = feed.snapshot()["safety"]
        (when,) = [round(e.time, 2) for e in engine.log.events("safety_violated")]
        assert violated["level"] == "violated" and violated["violated"] == [["fence", when]]
        assert violated["in_effect"][:2] == ["fence", "hold"] and violated["in_effect"][2].startswith("holding at (")
        assert violated["summary"].startswith(f"safety: violated fence (t={when:.1f} s); in effect: fence hold, "
                                              "holding at (")
        engine.run_until(lambda: engine.log.events("safety_triggered"), 30)  # the link drops at 20 s
        (triggered,) = engine.log.events("safety_triggered")
        both = feed.snapshot()["safety"]
        assert both["in_effect"] == ["link_loss", "land", "landing where it is"]  # it outranks the hold
        assert both["due"] == [["link_loss", round(triggered.time + 60, 2)]]
        assert both["summary"] == (f"safety: violated fence (t={when:.1f} s); in effect: link_loss land, landing "
                                   f"where it is; due: link_loss by t={triggered.time + 60:.1f} s")
    finally:
        engine.stop()
