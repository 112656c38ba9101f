"""The live view fits an 80 x 24 terminal (issue 18, point 7): panels shrink, the key line stays, failure
explanations wrap whole, the header shows how the run ended, the drone line the flight mode and the behavior
commanding it."""

from __future__ import annotations

import io
import re
import textwrap

from aeroexec.cli.views.live import KEYS_HELP, LiveView
from aeroexec.drones.sim import SimulatedDrone, default_world
from aeroexec.engine import api
from aeroexec.engine.engine import Engine
from aeroexec.flight.run_status import record_run_status, run_status
from rich.console import Console

NOTE = "(5, 5, 3) is 2.1 m from tower; GO_TO_POINT needs 3 m"


def screen(view: LiveView, width: int = 80, height: int = 24) -> list[str]:
    console = Console(width=width, height=height, force_terminal=True, record=True, file=io.StringIO())
    view.console = console
    view.refresh()
    console.print(view.render())
    return console.export_text().rstrip("\n").split("\n")


def panel_text(lines: list[str]) -> str:
    """The screen's words without the panels' borders, wrapped lines joined."""
    return " ".join(re.sub(r"[│╭╮╰╯─]", " ", line).strip() for line in lines)


def test_the_view_fits_80_by_24_with_wrapped_explanations_and_the_final_status():
    world = default_world()
    engine = Engine(SimulatedDrone(world), obstacles=world)
    view = LiveView(engine, "busy_mission.py")

    def mission() -> None:
        api.execute_behavior("TAKE_OFF", altitude=3)
        x = 5
        api.execute_behavior("GO_TO_POINT", coordinates=(x, x, 3))  # refused, with a long explanation
        for i in range(30):
            api.add_belief(f"visited(self, ({i}, 0, 3))")
        api.execute_behavior("LAND")

    try:
        engine.memory.declare("visited", 2)
        engine.start_mission(mission, "busy_mission")
        assert engine.run_until(lambda: engine.coordinator.is_active("TAKE_OFF"), 10)
        engine.step(1.0)
        during = screen(view)
        assert len(during) <= 24 and during[-1].strip() == KEYS_HELP
        assert "(commanded by TAKE_OFF)" in panel_text(during) and "flight mode TAKEOFF" in panel_text(during)
        engine.run_until(lambda: engine.bridge.state == "done", 60)
        record_run_status(engine.log, run_status(engine.log.events()))
        after = screen(view)
        assert len(after) <= 24, "\n".join(after)
        assert after[-1].strip() == KEYS_HELP
        assert "COMPLETED WITH REFUSED REQUESTS" in after[0]
        text = panel_text(after)
        assert "run_ended" in text  # the newest events stay
        big = screen(view, 140, 60)  # a larger terminal shows more, the explanation whole
        assert NOTE in " ".join(panel_text(big).split()) and len(big) <= 60
        assert len(big) > len(after) and all(len(line) <= 80 for line in after)
    finally:
        view.stop()
        engine.stop()


def test_a_long_explanation_wraps_whole_in_a_narrow_view():
    world = default_world()
    engine = Engine(SimulatedDrone(world), obstacles=world)
    view = LiveView(engine, "m.py")
    try:
        reason = "Behavior GO_TO_POINT cannot be executed because its preconditions are not satisfied. " + \
            "minimum_distance_to_obstacle(?DESTINATION, ?d), ?d > 3: ?d > 3 does not hold with ?d = 2.12 " + \
            f"({NOTE})"
        engine.log.record("failed_preconditions", "GO_TO_POINT", reason, source="mission")
        lines = screen(view)
        assert len(lines) <= 24 and lines[-1].strip() == KEYS_HELP
        words = " ".join(panel_text(lines).split())
        assert " ".join(textwrap.wrap(reason, 10_000)) in words  # every word of it, in order
    finally:
        view.stop()
        engine.stop()


def test_safety_rules_have_a_line_of_their_own_held_then_violated_with_the_contingency_in_effect():
    from aeroexec.engine.catalog import default_catalog
    from aeroexec.engine.catalog.safety_rules import read_safety_rules_text
    from aeroexec.engine.safety.declared import vocabulary

    catalog = default_catalog()
    text = ("- {rule: fence, always: 'position(self, (?x, ?y, ?z)), ?x < 6', contingency: hold}\n"
            "- {rule: max_time, never: 'mission_time(?t), ?t > 900', contingency: land}\n")
    rules = read_safety_rules_text(text, "rules.yaml", vocabulary(catalog)).rules
    world = default_world()
    engine = Engine(SimulatedDrone(world), obstacles=world, catalog=catalog.with_safety_rules(rules))
    view = LiveView(engine, "fenced.py")

    def mission() -> None:
        api.execute_behavior("TAKE_OFF", altitude=3)
        api.execute_behavior("GO_TO_POINT", coordinates=(10, 0, 3))

    try:
        engine.start_mission(mission, "fenced")
        assert engine.run_until(lambda: engine.coordinator.is_active("GO_TO_POINT"), 20)
        held = screen(view)
        assert held[1].strip() == "safety: 2 rules held", held[:3]
        engine.run_until(lambda: engine.log.events("safety_violated"), 30)
        engine.step(0.5)
        violated = screen(view)
        line = " ".join(row.strip() for row in violated[1:3])
        assert line.startswith("safety: violated fence (t=") and "in effect: fence hold, holding at (" in line
        assert len(violated) <= 24 and violated[-1].strip() == KEYS_HELP
    finally:
        view.stop()
        engine.stop()
