"""The path flown, seen from above, as a map a pilot reads at a glance: the world around it (bounds, obstacles,
markers, objects), the outbound and return legs in their own colors, the places where behaviors started and ended
numbered on the map and listed beside it, a grid, a scale bar, a north arrow, and the home's latitude/longitude.

The view fits the flight (the world's bounds too when they are not much larger), so a 10 m hop and a flight of
several kilometres both fill the map; distances switch to kilometres past 2 km. Labels go where they overlap
nothing (:mod:`~.labels`); a label with no free place is listed beside the map instead."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from aeroexec.cli.reporting.labels import LabelPlacer
from aeroexec.cli.reporting.labels import segment_meets as _meets
from aeroexec.cli.reporting.style import OUTCOME_COLORS, PATH_COLOR, RETURN_COLOR, figure, nice_step
from aeroexec.flight.summary import FlightSummary

from aeroexec.extras import require

with require("report"):
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D
    from matplotlib.patches import Circle, Rectangle
    from matplotlib.ticker import FuncFormatter, MultipleLocator

MIN_SPAN = 10.0  # m: the narrowest view, for a flight that hardly moved
MAX_LISTED = 40  # lines of the places list beside the map
WORLD_FACTOR = 4.0  # the world's bounds are shown whole when no more than this many times the flight's extent
FONT = 8


@dataclass
class Place:
    """A spot where behaviors started or ended, numbered on the map."""

    number: int
    x: float
    y: float
    events: list[tuple[float, str, str]] = field(default_factory=list)  # (time, behavior, what: starts / outcome)


def path_figure(summary: FlightSummary, world: Any, dpi: int = 100) -> Figure:
    """The map of the flight in ``summary`` over ``world`` (None: no world)."""
    fig = figure((12.5, 8.2), dpi)
    ax = fig.add_axes((0.07, 0.07, 0.58, 0.86))
    side = fig.add_axes((0.67, 0.03, 0.32, 0.94))
    side.set_axis_off()
    (x0, x1), (y0, y1) = _view(summary, world, ax.get_window_extent())
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_aspect("equal", adjustable="box")  # the limits already have the axes' proportions
    placer = LabelPlacer(fig)
    kilometres = max(x1 - x0, y1 - y0) > 2000
    _grid(ax, kilometres)
    handles: list[Any] = []
    names: list[WorldLabel] = []
    if world is not None:
        world_handles, names = _world(ax, world, placer)
        handles += world_handles
    handles += _path(ax, summary)
    placer.reserve_line(ax, [p[0] for p in summary.path], [p[1] for p in summary.path])
    places = _places(summary, ax)
    for place in places:
        placer.reserve_point(ax, (place.x, place.y), 6)
    placer.reserve_point(ax, (0, 0), 9)
    used = _in_a_free_corner(ax, placer, lambda corner: _scale_bar(ax, kilometres, placer, corner), set())
    _in_a_free_corner(ax, placer, lambda corner: _north_arrow(ax, placer, corner), {used})
    unlabelled: list[str] = []
    for place in places:  # the places first: what the pilot looks for
        if placer.place(ax, str(place.number), (place.x, place.y), fontsize=FONT + 0.5, fontweight="bold",
                        color="#111111") is None:
            unlabelled.append(f"place {place.number} at ({place.x:.1f}, {place.y:.1f})")
    for name in names:
        inside = name.box is not None and placer.place_inside(ax, name.text, name.box, fontsize=FONT - 1,
                                                               color="white", zorder=3)
        if not inside and placer.place(ax, name.text, name.at, fontsize=FONT - 1, color=name.color) is None:
            unlabelled.append(f"{name.kind} {name.text} at ({name.at[0]:.1f}, {name.at[1]:.1f})")
    ax.set_xlabel("east (km)" if kilometres else "east (m)", fontsize=FONT + 1)
    ax.set_ylabel("north (km)" if kilometres else "north (m)", fontsize=FONT + 1)
    ax.tick_params(labelsize=FONT)
    home = _home(summary, world)
    ax.set_title(f"path flown: {_distance(summary.distance)} in {summary.duration:.1f} s"
                 + (f"; home {home}" if home else ""), fontsize=FONT + 2)
    _side(side, handles, places, unlabelled)
    return fig


def _view(summary: FlightSummary, world: Any, frame: Any) -> tuple[tuple[float, float], tuple[float, float]]:
    """(x limits, y limits): the flight and home, padded, the world's bounds too when they are not much larger;
    widened to the proportions of ``frame`` (the axes, in pixels) so that a metre is as long both ways."""
    xs = [0.0, *(p[0] for p in summary.path)]
    ys = [0.0, *(p[1] for p in summary.path)]
    x0, x1, y0, y1 = min(xs), max(xs), min(ys), max(ys)
    extent = max(x1 - x0, y1 - y0, MIN_SPAN)
    if world is not None:
        (bx0, by0, _), (bx1, by1, _) = world.bounds.lower, world.bounds.upper
        if max(bx1 - bx0, by1 - by0) <= WORLD_FACTOR * extent:
            x0, x1, y0, y1 = min(x0, bx0), max(x1, bx1), min(y0, by0), max(y1, by1)
    span = max(x1 - x0, y1 - y0, MIN_SPAN)
    pad = 0.13 * span  # room in the corners for the scale bar and the north arrow
    cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
    half_x, half_y = max(x1 - x0, MIN_SPAN) / 2 + pad, max(y1 - y0, MIN_SPAN) / 2 + pad
    ratio = frame.width / frame.height  # metres across per metre up
    half_x, half_y = max(half_x, half_y * ratio), max(half_y, half_x / ratio)
    return (cx - half_x, cx + half_x), (cy - half_y, cy + half_y)


def _grid(ax: Any, kilometres: bool) -> None:
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    step = nice_step(max(x1 - x0, y1 - y0) / 8)
    for axis in (ax.xaxis, ax.yaxis):
        axis.set_major_locator(MultipleLocator(step))
        axis.set_major_formatter(FuncFormatter(lambda v, _: _coordinate(v, step, kilometres)))
    ax.grid(True, linewidth=0.4, color="#d5d9de", zorder=0)


def _coordinate(value: float, step: float, kilometres: bool) -> str:
    if kilometres:
        value, step = value / 1000, step / 1000
    decimals = max(0, -math.floor(math.log10(step))) if step < 1 else 0
    text = f"{value:.{decimals}f}"
    return "0" if text.strip("-0.") == "" else text


@dataclass
class WorldLabel:
    """The name of a thing of the world, to place once the flight is drawn."""

    kind: str
    text: str
    at: tuple[float, float]
    color: str
    box: tuple[float, float, float, float] | None = None  # the shape it may be written inside


def _world(ax: Any, world: Any, placer: LabelPlacer) -> tuple[list[Any], list[WorldLabel]]:
    """Draw the world's bounds, obstacles, markers, objects and platform route; their legend entries and the
    names to place."""
    (x0, y0, _), (x1, y1, _) = world.bounds.lower, world.bounds.upper
    handles: list[Any] = [Rectangle((0, 0), 1, 1, fill=False, edgecolor="#777777", linestyle="--", label="bounds")]
    ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, fill=False, edgecolor="#777777", linestyle="--",
                           linewidth=1, zorder=1))
    placer.reserve_line(ax, [x0, x1, x1, x0, x0], [y0, y0, y1, y1, y0])
    names: list[WorldLabel] = []
    if world.obstacles:
        handles.append(Rectangle((0, 0), 1, 1, color="#8d8d8d", alpha=0.8, label="obstacles"))
    for obstacle in world.obstacles:
        if hasattr(obstacle, "size"):
            (cx, cy, _), (sx, sy, _) = obstacle.center, obstacle.size
            ax.add_patch(Rectangle((cx - sx / 2, cy - sy / 2), sx, sy, color="#8d8d8d", alpha=0.8, zorder=2))
            box = (cx - sx / 2, cy - sy / 2, cx + sx / 2, cy + sy / 2)
        else:
            (cx, cy, *_), r = obstacle.center, obstacle.radius  # a cylinder's center is (x, y)
            ax.add_patch(Circle((cx, cy), r, color="#8d8d8d", alpha=0.8, zorder=2))
            box = (cx - r * 0.7, cy - r * 0.7, cx + r * 0.7, cy + r * 0.7)
        names.append(WorldLabel("obstacle", obstacle.name, (cx, cy), "#555555", box))
    kinds = [("marker", "markers", "D", "#9467bd", [(f"m{m.id}", m.position) for m in world.markers]),
             ("object", "objects", "^", "#b8860b", [(o.name, o.position) for o in getattr(world, "objects", ())])]
    for kind, label, marker, color, things in kinds:
        if not things:
            continue
        handles.append(Line2D([], [], marker=marker, color=color, linestyle="none", label=label))
        ax.plot([p[0] for _, p in things], [p[1] for _, p in things], marker=marker, markersize=6, color=color,
                linestyle="none", zorder=3)
        for name, position in things:
            placer.reserve_point(ax, position[:2], 4)
            names.append(WorldLabel(kind, name, (position[0], position[1]), color))
    platform = getattr(world, "platform", None)
    if platform is not None and platform.path:
        points = [*platform.path, *([platform.path[0]] if platform.loop else [])]
        ax.plot([p[0] for p in points], [p[1] for p in points], color="#17becf", linewidth=1, linestyle=":")
        placer.reserve_line(ax, [p[0] for p in points], [p[1] for p in points])
        handles.append(Line2D([], [], color="#17becf", linestyle=":", label=f"{platform.name} route"))
    return handles, names


def _path(ax: Any, summary: FlightSummary) -> list[Any]:
    points = summary.path
    handles: list[Any] = []
    if points:
        turn = summary.homeward_sample()
        out, back = points[:turn + 1], points[turn:]
        ax.plot([p[0] for p in out], [p[1] for p in out], color=PATH_COLOR, linewidth=2.0, zorder=4.5,
                solid_capstyle="round")
        handles.append(Line2D([], [], color=PATH_COLOR, linewidth=2.0, label="outbound"))
        if len(back) > 1:  # wider and under the outbound leg, so a way back along it shows as a border
            ax.plot([p[0] for p in back], [p[1] for p in back], color=RETURN_COLOR, linewidth=5.0, zorder=4,
                    solid_capstyle="round")
            handles.append(Line2D([], [], color=RETURN_COLOR, linewidth=5.0, label="return"))
    ax.plot([0], [0], marker="*", markersize=15, color="black", linestyle="none", zorder=6)
    handles.append(Line2D([], [], marker="*", markersize=11, color="black", linestyle="none", label="home"))
    handles.append(Line2D([], [], marker="o", color="#dddddd", markeredgecolor="black", linestyle="none",
                          label="a behavior starts"))
    handles.append(Line2D([], [], marker="s", color="#dddddd", markeredgecolor="black", linestyle="none",
                          label="ends (color: outcome)"))
    return handles


def _places(summary: FlightSummary, ax: Any) -> list[Place]:
    """Where behaviors started and ended (reactive ones only when they failed), joined into one place when closer
    than 1.5 % of the view; circles and squares colored by outcome, numbered in time order."""
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    near = 0.015 * max(x1 - x0, y1 - y0)
    places: list[Place] = []
    events = []
    for span in summary.behaviors:
        if span.source == "reactive" and span.outcome in ("GOAL_ACHIEVED", "INTERRUPTED", "RUNNING"):
            continue  # reactive behaviors come and go all the time: only their failures are marked
        events.append((span.start, span.behavior, "starts", span.start_position, "o", "#dddddd"))
        if span.outcome != "RUNNING":
            events.append((span.end, span.behavior, span.outcome, span.end_position, "s",
                           OUTCOME_COLORS.get(span.outcome, "#e377c2")))
    for when, behavior, what, position, marker, color in sorted(events, key=lambda e: e[0]):
        if position is None:
            continue
        x, y = position[0], position[1]
        ax.plot([x], [y], marker=marker, markersize=7 if marker == "o" else 6, color=color, markeredgecolor="black",
                linestyle="none", zorder=5)
        place = next((p for p in places if math.hypot(p.x - x, p.y - y) <= near), None)
        if place is None:
            place = Place(len(places) + 1, x, y)
            places.append(place)
        place.events.append((when, behavior, what))
    return places


CORNERS = ("lower left", "lower right", "upper left", "upper right")


def _scale_bar(ax: Any, kilometres: bool, placer: LabelPlacer, corner: str) -> list[Any]:
    """A bar of a round length, about a fifth of the map's width, in ``corner``; its artists."""
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    w, h = x1 - x0, y1 - y0
    length = nice_step(w / 5)
    left = x0 + 0.04 * w if "left" in corner else x1 - 0.04 * w - length
    base = y0 + 0.04 * h if "lower" in corner else y1 - 0.09 * h
    frame = ax.add_patch(Rectangle((left - 0.015 * w, base - 0.02 * h), length + 0.03 * w, 0.085 * h,
                                   facecolor="white", edgecolor="#bbbbbb", alpha=0.85, zorder=7))
    bar = ax.plot([left, left + length], [base, base], color="black", linewidth=3, solid_capstyle="butt", zorder=8)
    label = ax.text(left + length / 2, base + 0.012 * h, _length(length, kilometres), ha="center", va="bottom",
                    fontsize=FONT, zorder=8)
    return [frame, *bar, label]


def _north_arrow(ax: Any, placer: LabelPlacer, corner: str) -> list[Any]:
    """An arrow pointing north (up: the map is east-north) with an N, in ``corner``; its artists."""
    x = 0.05 if "left" in corner else 0.95
    top = 0.97 if "upper" in corner else 0.16
    label = ax.annotate("N", xy=(x, top), xytext=(x, top - 0.11), xycoords="axes fraction",
                        textcoords="axes fraction", ha="center", va="center", fontsize=FONT + 2, fontweight="bold",
                        arrowprops={"arrowstyle": "-|>", "color": "black", "linewidth": 1.5}, zorder=8,
                        bbox={"boxstyle": "circle,pad=0.2", "fc": "white", "ec": "#bbbbbb", "alpha": 0.85})
    return [label]


def _in_a_free_corner(ax: Any, placer: LabelPlacer, draw: Any, taken: set[str]) -> str:
    """Draw with ``draw(corner)`` in the first corner where it covers no line, marker or label (else where it
    covers fewest lines); reserve its box; the corner used."""
    best: tuple[int, str] | None = None
    for corner in (c for c in CORNERS if c not in taken):
        artists = draw(corner)
        box = _box_of(artists, placer)
        crossed = sum(1 for segment in placer.segments if _meets(segment, box))
        for artist in artists:
            artist.remove()
        if crossed == 0 and placer.free(box):
            best = (0, corner)
            break
        if best is None or crossed < best[0]:
            best = (crossed, corner)
    corner = best[1] if best else CORNERS[0]
    placer.reserve(_box_of(draw(corner), placer))
    return corner


def _box_of(artists: list[Any], placer: LabelPlacer) -> Any:
    from matplotlib.transforms import Bbox

    boxes = [a.get_window_extent(placer.renderer) for a in artists]
    for artist in artists:  # an annotation's arrow reaches beyond its text
        patch = getattr(artist, "arrow_patch", None)
        if patch is not None:
            boxes.append(patch.get_window_extent(placer.renderer))
    return Bbox.union(boxes)


def _side(side: Any, handles: list[Any], places: list[Place], unlabelled: list[str]) -> None:
    """The legend, then one line per numbered place (when, and which behaviors started or ended there; an
    outcome other than GOAL_ACHIEVED is named), then what could not be labelled on the map."""
    side.legend(handles=handles, loc="upper left", fontsize=FONT, frameon=False, ncols=2, bbox_to_anchor=(0, 1),
                borderaxespad=0)
    rows = 1 + (len(handles) + 1) // 2
    lines: list[str] = []
    for place in places:
        first, last = place.events[0][0], place.events[-1][0]
        when = f"{first:.1f} s" if last - first < 0.05 else f"{first:.1f}-{last:.1f} s"
        names = list(dict.fromkeys(behavior + ("" if what in ("starts", "GOAL_ACHIEVED") else f" {what}")
                                   for _, behavior, what in place.events))
        lines += _wrapped(f"{place.number:>3}  {when:<13} ", ", ".join(names))
    hidden = [f"   {u}" for u in unlabelled[:6]] + ([f"   ... {len(unlabelled) - 6} more"] if len(unlabelled) > 6
                                                   else [])
    room = MAX_LISTED - (len(hidden) + 2 if hidden else 0)
    if len(lines) > room:
        lines = [*lines[:room - 1], "     ... the rest in report.html (activations)"]
    if hidden:
        lines += ["", "not labelled on the map:", *hidden]
    top = 1.0 - rows * 0.032
    side.text(0, top, "places: number, time, behaviors that started or ended there", fontsize=FONT,
              fontweight="bold", va="top", transform=side.transAxes)
    side.text(0, top - 0.03, "\n".join(lines), fontsize=FONT - 0.5, va="top", family="monospace",
              transform=side.transAxes, linespacing=1.25)


def _wrapped(head: str, text: str, width: int = 68) -> list[str]:
    """``head`` then ``text``, wrapped at commas to ``width`` characters, later lines indented under the text."""
    lines, line = [], head
    for word in text.split(", "):
        piece = word if line in (head, " " * len(head)) else ", " + word
        if len(line) + len(piece) > width and line not in (head, " " * len(head)):
            lines.append(line + ",")
            line, piece = " " * len(head), word
        line += piece
    return [*lines, line]


def _home(summary: FlightSummary, world: Any) -> str:
    """The home's latitude and longitude: the log's (``home: [lat, lon, alt]``), else the world's."""
    home = summary.meta.get("home")
    if not (isinstance(home, list | tuple) and len(home) >= 2) and world is not None:
        home = getattr(world, "home", None)
    try:
        lat, lon = float(home[0]), float(home[1])  # type: ignore[index]
    except (TypeError, ValueError, IndexError):
        return ""
    return f"{abs(lat):.6f}° {'N' if lat >= 0 else 'S'}, {abs(lon):.6f}° {'E' if lon >= 0 else 'W'}"


def _distance(meters: float) -> str:
    """A distance flown: metres, kilometres past 2 km."""
    return f"{meters / 1000:.2f} km" if meters >= 2000 else f"{meters:.1f} m"


def _length(meters: float, kilometres: bool) -> str:
    """A scale bar's round length."""
    return f"{meters / 1000:g} km" if kilometres else f"{meters:g} m"
