"""The flight report's images read at a glance (issue 35, point 8): no two texts overlap, axes fit the data with
sensible minimum spans, the map has a grid, a scale bar, a north arrow and the home's latitude/longitude, and stays
readable from a 10 m hop to a flight of kilometres."""

from __future__ import annotations

import math

import pytest
from aeroexec.cli.reporting.flight_chart import flight_figure
from aeroexec.cli.reporting.labels import drawn_texts, overlaps
from aeroexec.cli.reporting.path_map import path_figure
from aeroexec.cli.reporting.timeline import timeline_figure
from aeroexec.drones.sim import default_world
from aeroexec.flight.summary import summarize


def flight(points, home=None, behaviors=("GO_TO_POINT",), speed=5.0, battery_drop=1.0):
    """The records of a synthetic flight through ``points`` (x, y, z) at ``speed``, one activation of each of
    ``behaviors`` per leg, the battery falling by ``battery_drop`` % over the flight."""
    meta = {"kind": "log_started", "time": 0.0, "mission": "synthetic.py", "clock": "simulated", "drone": "sim",
            "seed": 3, **({"home": list(home)} if home else {})}
    records, t = [meta], 0.0
    legs = list(zip(points, points[1:], strict=False))
    total = sum(math.dist(a, b) for a, b in legs) / speed
    for a, b in legs:
        for behavior in behaviors:
            records.append({"kind": "activated", "time": t, "behavior": behavior, "data": {"source": "mission"}})
        steps = max(int(math.dist(a, b) / speed / 0.5), 1)
        for k in range(steps):
            p = [a[i] + (b[i] - a[i]) * k / steps for i in range(3)]
            records.append({"kind": "state", "time": round(t, 2), "position": p, "velocity": [speed, 0, 0],
                            "battery": 100 - battery_drop * t / total, "armed": True, "landed_state": "in_air"})
            t += 0.5
        for behavior in behaviors:
            records.append({"kind": "GOAL_ACHIEVED", "time": t, "behavior": behavior})
        state = "moving" if b[2] else "landed"
        records.append({"kind": "belief_added", "time": t, "belief": f"flight_state(self, {state})"})
    records.append({"kind": "log_closed", "time": t})
    return summarize(records)


FLIGHTS = {
    "a 10 m hop": flight([(0, 0, 0), (0, 0, 3), (6, 4, 3), (6, 4, 0)]),
    "a survey of the field": flight([(0, 0, 0), *((x, y, 3) for y in range(-15, 16, 5) for x in (-15, 15)),
                                     (0, 0, 0)], behaviors=("GO_TO_POINT", "TAKE_PHOTO")),
    "edges of the field": flight([(19.5, 19.5, 3), (19.5, -19.5, 3), (-19.5, -19.5, 3), (-19.5, 19.5, 3)],
                                 behaviors=("A_VERY_LONG_BEHAVIOR_NAME_FOR_A_LABEL",)),
    "3 km out and back": flight([(0, 0, 0), (0, 0, 60), (0, 1500, 60), (2500, 1500, 60), (2500, -800, 60),
                                 (0, 0, 60), (0, 0, 0)], home=(47.3977419, 8.5455938, 488.0), speed=12.0),
}


@pytest.mark.parametrize("name", list(FLIGHTS))
def test_no_two_texts_overlap_in_any_image(name):
    summary = FLIGHTS[name]
    for figure in (path_figure(summary, default_world()), flight_figure(summary), timeline_figure(summary)):
        assert len(drawn_texts(figure)) > 10
        assert overlaps(figure) == []
        box = figure.bbox  # and nothing is drawn off the image
        renderer = figure.canvas.get_renderer()
        for text in drawn_texts(figure):
            extent = text.get_window_extent(renderer)
            assert box.x0 - 1 <= extent.x0 and extent.x1 <= box.x1 + 1, text.get_text()
            assert box.y0 - 1 <= extent.y0 and extent.y1 <= box.y1 + 1, text.get_text()


def test_places_near_the_edges_are_numbered_on_the_map_and_listed_beside_it():
    figure = path_figure(FLIGHTS["edges of the field"], default_world())
    ax = figure.axes[0]
    numbers = sorted(t.get_text() for t in ax.texts if t.get_text().isdigit())
    assert numbers == ["1", "2", "3", "4"]
    frame = ax.get_window_extent(figure.canvas.get_renderer())
    for text in (t for t in ax.texts if t.get_text().isdigit()):
        extent = text.get_window_extent(figure.canvas.get_renderer())
        assert frame.x0 <= extent.x0 and extent.x1 <= frame.x1 and frame.y0 <= extent.y0 and extent.y1 <= frame.y1
    listed = "\n".join(t.get_text() for t in figure.axes[1].texts)
    assert "A_VERY_LONG_BEHAVIOR_NAME_FOR_A_LABEL" in listed


def test_the_map_has_a_grid_a_scale_bar_a_north_arrow_and_the_home():
    figure = path_figure(FLIGHTS["a 10 m hop"], default_world())
    texts = [t.get_text() for t in drawn_texts(figure)]
    assert "N" in texts and "10 m" in texts  # the north arrow; the scale bar (the world's field, 40 m wide)
    assert any("home 47.397742° N, 8.545594° E" in t for t in texts)  # the built-in world's home
    ax = figure.axes[0]
    assert ax.xaxis.get_gridlines()[0].get_visible() and ax.get_xlabel() == "east (m)"


def test_a_flight_of_kilometres_fills_the_map_in_kilometres():
    summary = FLIGHTS["3 km out and back"]
    figure = path_figure(summary, default_world())
    ax = figure.axes[0]
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    assert x0 < 0 and x1 > 2500 and y0 < -800 and y1 > 1500 and x1 - x0 < 4000  # the flight, not a dot
    assert ax.get_xlabel() == "east (km)" and ax.get_ylabel() == "north (km)"
    texts = [t.get_text() for t in drawn_texts(figure)]
    assert any(t.endswith(" km") and t[0].isdigit() for t in texts), texts  # the scale bar
    assert any("home 47.397742° N, 8.545594° E" in t for t in texts)  # the log's home
    assert any(t.startswith("path flown: ") and " km in " in t for t in texts)


def test_axes_fit_the_data_with_minimum_spans():
    figure = flight_figure(FLIGHTS["a 10 m hop"])
    altitude, speed, battery = figure.axes[2:5]
    low, high = battery.get_ylim()
    assert high - low >= 10 and high <= 100.0 + 1e-9  # a 1 % drop does not fill the plot
    assert speed.get_ylim()[0] == 0 and speed.get_ylim()[1] >= 5
    assert altitude.get_ylim()[1] >= 3 and altitude.get_ylim()[1] - altitude.get_ylim()[0] >= 2
    strips = [t.get_text() for t in figure.axes[0].texts]
    assert "GO_TO_POINT" in strips  # named inside its span where it fits


def test_the_world_drawn_is_the_one_the_run_flew_in():
    from aeroexec.cli.report import world_of_run

    built_in = default_world()
    home, bounds = list(built_in.home), [list(built_in.bounds.lower), list(built_in.bounds.upper)]
    assert world_of_run({"drone": "sim", "home": home, "bounds": bounds}).obstacles == built_in.obstacles
    generated = world_of_run({"drone": "sim", "world": None, "home": [48.1351, 11.582, 120.0],
                              "bounds": [[-333.6, -333.6, 0.0], [2565.3, 3669.9, 165.0]]})
    assert generated.home == (48.1351, 11.582, 120.0) and generated.bounds.upper[1] == 3669.9
    assert not generated.obstacles  # an open field generated around a mission planned on a map
    assert world_of_run({"drone": "mavsdk:udpin://0.0.0.0:14540"}) is None  # a vehicle flown without a world
    assert world_of_run({"drone": "sim"}).name == built_in.name  # an older log of a simulated run
    assert world_of_run({}, "/nonexistent/world.yaml").startswith("--world /nonexistent/world.yaml: ")


def test_the_way_home_is_drawn_from_the_last_transect_not_from_the_farthest_corner():
    survey = flight([(0, 0, 0), (0, 0, 30), (1000, 250, 30), (0, 250, 30), (0, 125, 30), (1000, 125, 30),
                     (1000, -125, 30), (0, -125, 30), (0, 0, 30), (0, 0, 0)], speed=12.0)
    turn = survey.homeward_sample()
    assert math.dist(survey.path[turn][:2], (1000, -125)) < 1  # the last transect: home is straight ahead from there
    out_and_back = FLIGHTS["3 km out and back"]
    assert math.dist(out_and_back.path[out_and_back.homeward_sample()][:2], (2500, -800)) < 10
