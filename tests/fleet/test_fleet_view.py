"""The fleet's live view: one line per drone and the events of all, prefixed by drone."""

import io

from aeroexec.cli.views.fleet_view import FleetView
from aeroexec.drones.sim import SimConfig, SimulatedDrone
from aeroexec.engine.engine import Engine
from rich.console import Console


class Link:
    mission = "patrol.py"
    silent = {"d9"}


def test_the_view_shows_each_drone_on_its_line_and_every_drones_events():
    engines = {"d1": Engine(SimulatedDrone()), "d2": Engine(SimulatedDrone(config=SimConfig(start=(3.0, -2.0))))}
    view = FleetView("survey", engines, {"d1": Link()})
    try:
        for engine in engines.values():
            engine.step(0.5)
        engines["d2"].log.record("message_sent", detail="hello")
        console = Console(file=io.StringIO(), width=140)
        console.print(view.render())
        text = console.file.getvalue()
    finally:
        for engine in engines.values():
            engine.stop()
    d1 = next(line for line in text.splitlines() if " d1 " in line and "running" in line)
    d2 = next(line for line in text.splitlines() if " d2 " in line and "running" in line)
    assert "patrol.py" in d1 and "(0.0, 0.0, 0.0)" in d1 and "100 %" in d1 and "d9" in d1
    assert "(3.0, -2.0, 0.0)" in d2 and "SELF_LOCALIZE_BY_ODOMETRY" in d2
    assert "  d2 | [    0.50] message_sent: hello" in text
