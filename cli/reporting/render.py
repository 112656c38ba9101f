"""The flight report's images, drawn with matplotlib (Agg): the path flown over the world, seen from above (the
outbound and the return legs in their own colors), with where each behavior started and ended; altitude, speed
and battery over time with the behaviors shaded and the flight state changes marked (what PX4 Flight Review
users look at first); and a timeline of behaviors (colored by outcome) and beliefs. Labels are never clipped:
images are saved with a bounding box around everything drawn."""

from __future__ import annotations

import logging
from pathlib import Path
from typing import Any

from aeroexec.flight.summary import BeliefSpan, FlightSummary
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.patches import Circle, Patch, Rectangle

logger = logging.getLogger(__name__)

PATH_COLOR = "#0a64e6"  # the outbound leg; used by nothing else, so the path can be found in the image
RETURN_COLOR = "#e6550d"  # the return leg, from the point farthest from home
SHADES = ("#c6dbef", "#fdd0a2", "#c7e9c0", "#dadaeb", "#fcbba1", "#d9d9d9")  # behaviors over time
OUTCOME_COLORS = {
    "GOAL_ACHIEVED": "#2ca02c",
    "INTERRUPTED": "#9e9e9e",
    "TIME_OUT": "#ff7f0e",
    "WRONG_PROGRESS": "#d62728",
    "FAILED_PRECONDITIONS": "#8c564b",
    "RUNNING": "#bcbd22",
}
MAX_BELIEF_ROWS = 30
MANY_VALUES = 6  # a predicate with more spans than this gets one row with a tick per change


def draw_path(summary: FlightSummary, world: Any, path: Path, dpi: int = 100) -> Path:
    """The path flown over ``world`` (obstacles, markers, objects, home) with behavior starts (o) and ends (s)."""
    fig = path_figure(summary, world, dpi)
    fig.savefig(path, bbox_inches="tight", pad_inches=0.2)  # anything beyond the axes is kept, not clipped
    return path


def path_figure(summary: FlightSummary, world: Any, dpi: int = 100) -> Figure:
    """The figure of :func:`draw_path`, not yet saved."""
    fig = Figure(figsize=(9, 8), dpi=dpi)
    FigureCanvasAgg(fig)  # the Agg backend, whatever pyplot's default is
    ax = fig.subplots()
    if world is not None:
        _draw_world(ax, world)
    points = summary.path
    if points:
        turn = summary.farthest_sample()
        out, back = points[:turn + 1], points[turn:]
        ax.plot([p[0] for p in out], [p[1] for p in out], color=PATH_COLOR, linewidth=2.0,
                label="outbound", zorder=4.5, solid_capstyle="round")
        if len(back) > 1:  # wider and under the outbound leg, so a way back along it shows as a border
            ax.plot([p[0] for p in back], [p[1] for p in back], color=RETURN_COLOR, linewidth=5.0,
                    label="return", zorder=4, solid_capstyle="round")
    ax.plot([0], [0], marker="*", markersize=16, color="black", linestyle="none", label="home", zorder=6)
    _draw_behavior_places(ax, summary)
    ax.set_aspect("equal")
    ax.set_xlabel("x east (m)")
    ax.set_ylabel("y north (m)")
    ax.set_title(f"{summary.meta.get('mission', 'mission')}: path flown ({summary.distance:.1f} m, "
                 f"{summary.duration:.1f} s)")
    ax.grid(True, linewidth=0.3, color="#dddddd")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, borderaxespad=0)
    fig.tight_layout()
    return fig


def draw_flight(summary: FlightSummary, path: Path, dpi: int = 100) -> Path:
    """Altitude, speed and battery over time; the mission's behaviors shaded and named; flight state changes
    as dashed lines."""
    series = summary.series()
    fig = Figure(figsize=(11, 7), dpi=dpi)
    FigureCanvasAgg(fig)
    axes = fig.subplots(3, 1, sharex=True)
    for ax, key, label, color in zip(axes, ("altitude", "speed", "battery"),
                                     ("altitude (m)", "speed (m/s)", "battery (%)"),
                                     ("#1f77b4", "#2ca02c", "#d62728"), strict=True):
        ax.plot(series["time"], series[key], color=color, linewidth=1.5)
        ax.set_ylabel(label, fontsize=8)
        ax.grid(True, linewidth=0.3, color="#dddddd")
    duration = max(summary.end - summary.start, 1.0)
    segments = _mode_segments(summary)
    names = list(dict.fromkeys(name for name, _, _ in segments))
    for name, start, end in segments:
        for ax in axes:
            ax.axvspan(start, end, color=SHADES[names.index(name) % len(SHADES)], alpha=0.7, zorder=0, lw=0)
        if end - start >= 0.04 * duration:  # named where it is wide enough to read
            axes[0].annotate(name, ((start + end) / 2, 1.0), xycoords=("data", "axes fraction"), xytext=(0, 3),
                             textcoords="offset points", fontsize=6.5, ha="center", va="bottom",
                             annotation_clip=False)
    for when, state in _merged(summary.flight_states, 0.04 * duration):
        for ax in axes:
            ax.axvline(when, color="#555555", linestyle="--", linewidth=0.7)
        axes[2].annotate(state, (when, 0.0), xycoords=("data", "axes fraction"), xytext=(2, -22),
                         textcoords="offset points", fontsize=6.5, rotation=30, annotation_clip=False)
    axes[0].set_title(f"{summary.meta.get('mission', 'mission')}: altitude, speed and battery (shaded: the "
                      f"mission's behaviors; dashed: flight state changes)", fontsize=9, pad=14)
    axes[2].set_xlabel("engine time (s)", labelpad=24)
    axes[2].set_xlim(summary.start, max(summary.end, summary.start + 1.0))
    fig.tight_layout()
    fig.savefig(path, bbox_inches="tight", pad_inches=0.2)
    return path


def _mode_segments(summary: FlightSummary) -> list[tuple[str, float, float]]:
    """The mission's behaviors as a sequence of (name, start, end), as a flight mode timeline: each one from its
    start until it ends or the next one starts (reactive behaviors are left out)."""
    spans = sorted((s for s in summary.behaviors if s.source != "reactive"), key=lambda s: s.start)
    segments = []
    for i, span in enumerate(spans):
        end = min([span.end, *(later.start for later in spans[i + 1:] if later.start > span.start)])
        if end > span.start:
            segments.append((span.behavior, span.start, end))
    return segments


def _merged(changes: list[tuple[float, str]], gap: float) -> list[tuple[float, str]]:
    """Changes closer than ``gap`` seconds to the previous one shown as one, named by the latest state."""
    merged: list[tuple[float, str]] = []
    for when, state in changes:
        if merged and when - merged[-1][0] < gap:
            merged[-1] = (merged[-1][0], state)
        else:
            merged.append((when, state))
    return merged


def _draw_behavior_places(ax: Any, summary: FlightSummary) -> None:
    """A circle where each behavior started and a square where it ended, colored by outcome; the labels of one
    place (to half a meter) are joined into one."""
    labels: dict[tuple[float, float], list[str]] = {}
    for span in summary.behaviors:
        if span.source == "reactive" and span.outcome in ("GOAL_ACHIEVED", "INTERRUPTED", "RUNNING"):
            continue  # reactive behaviors come and go all the time: only their failures are marked
        color = OUTCOME_COLORS.get(span.outcome, "#e377c2")
        places = [("o", span.start_position, f"{span.start:.1f}s {span.behavior} starts")]
        if span.outcome != "RUNNING":
            places.append(("s", span.end_position, f"{span.end:.1f}s {span.behavior} {span.outcome}"))
        for marker, position, label in places:
            if position is None:
                continue
            x, y = position[0], position[1]
            ax.plot([x], [y], marker=marker, markersize=7 if marker == "o" else 6, color=color,
                    markeredgecolor="black", linestyle="none", zorder=5)
            labels.setdefault((round(x * 2) / 2, round(y * 2) / 2), []).append(label)
    middle_x, middle_y = sum(ax.get_xlim()) / 2, sum(ax.get_ylim()) / 2
    for (x, y), texts in labels.items():
        texts.sort(key=lambda text: float(text.split("s", 1)[0]))  # in time order
        shown = texts if len(texts) <= 8 else [*texts[:7], f"... {len(texts) - 7} more"]
        right, down = x <= middle_x, y >= middle_y  # labels grow towards the middle, never off the map's edge
        ax.annotate("\n".join(shown), (x, y), textcoords="offset points",
                    xytext=(8 if right else -8, -4 if down else 4), fontsize=6.5, va="top" if down else "bottom",
                    ha="left" if right else "right", zorder=7, annotation_clip=False,
                    bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": "#cccccc", "alpha": 0.6})


def _draw_world(ax: Any, world: Any) -> None:
    (x0, y0, _), (x1, y1, _) = world.bounds.lower, world.bounds.upper
    ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, fill=False, edgecolor="#777777", linestyle="--",
                           linewidth=1, label="bounds"))
    ax.set_xlim(x0 - 1, x1 + 1)
    ax.set_ylim(y0 - 1, y1 + 1)
    for i, obstacle in enumerate(world.obstacles):
        label = "obstacles" if i == 0 else None
        if hasattr(obstacle, "size"):
            (cx, cy, _), (sx, sy, _) = obstacle.center, obstacle.size
            patch = Rectangle((cx - sx / 2, cy - sy / 2), sx, sy, color="#8d8d8d", alpha=0.8, label=label)
            center = (cx, cy)
        else:
            patch = Circle(tuple(obstacle.center), obstacle.radius, color="#8d8d8d", alpha=0.8, label=label)
            center = tuple(obstacle.center)
        ax.add_patch(patch)
        ax.annotate(obstacle.name, center, fontsize=7, ha="center", va="center", color="white", zorder=3)
    for i, marker in enumerate(world.markers):
        x, y = marker.position[0], marker.position[1]
        ax.plot([x], [y], marker="D", markersize=6, color="#9467bd", linestyle="none",
                label="markers" if i == 0 else None, zorder=3)
        ax.annotate(f"m{marker.id}", (x, y), textcoords="offset points", xytext=(4, -9), fontsize=7,
                    color="#9467bd")
    for i, thing in enumerate(getattr(world, "objects", ())):
        x, y = thing.position[0], thing.position[1]
        ax.plot([x], [y], marker="^", markersize=6, color="#e6a800", linestyle="none",
                label="objects" if i == 0 else None, zorder=3)
        ax.annotate(thing.name, (x, y), textcoords="offset points", xytext=(4, 4), fontsize=6, color="#8a6500")
    platform = getattr(world, "platform", None)
    if platform is not None and platform.path:
        xs = [p[0] for p in platform.path] + ([platform.path[0][0]] if platform.loop else [])
        ys = [p[1] for p in platform.path] + ([platform.path[0][1]] if platform.loop else [])
        ax.plot(xs, ys, color="#17becf", linewidth=1, linestyle=":", label=f"{platform.name} route")


def draw_timeline(summary: FlightSummary, path: Path, dpi: int = 100) -> Path:
    """Behaviors as bars from activation to end (colored by outcome), and beliefs as bars while held."""
    behaviors = list(dict.fromkeys(span.behavior for span in summary.behaviors))
    rows = _belief_rows(summary.beliefs)
    height = 2.0 + 0.28 * (len(behaviors) + len(rows))
    fig = Figure(figsize=(11, max(height, 4.0)), dpi=dpi)
    FigureCanvasAgg(fig)
    top, bottom = fig.subplots(2, 1, sharex=True,
                               gridspec_kw={"height_ratios": [max(len(behaviors), 1), max(len(rows), 1)]})
    for row, name in enumerate(behaviors):
        for span in (s for s in summary.behaviors if s.behavior == name):
            top.barh(row, max(span.end - span.start, 0.05), left=span.start, height=0.7,
                     color=OUTCOME_COLORS.get(span.outcome, "#e377c2"), edgecolor="black", linewidth=0.3)
    top.set_yticks(range(len(behaviors)), behaviors, fontsize=7)
    top.set_ylim(max(len(behaviors), 1) - 0.5, -0.5)  # the first behavior on top
    top.set_title("behaviors (bar: activation to end, colored by outcome)", fontsize=9)
    top.legend(handles=[Patch(color=color, label=outcome) for outcome, color in OUTCOME_COLORS.items()],
               fontsize=6, loc="upper center", bbox_to_anchor=(0.5, -0.02), ncol=6, frameon=False)
    for row, (_, spans, ticks) in enumerate(rows):
        for span in spans:
            bottom.barh(row, max(span.end - span.start, 0.05), left=span.start, height=0.6, color="#4c72b0")
        if ticks:
            bottom.plot(ticks, [row] * len(ticks), marker="|", color="#4c72b0", linestyle="none")
    bottom.set_yticks(range(len(rows)), [label for label, _, _ in rows], fontsize=6)
    bottom.set_ylim(max(len(rows), 1) - 0.5, -0.5)
    bottom.set_title("beliefs (bar: held; ticks: changes of a predicate with many values)", fontsize=9)
    bottom.set_xlabel("engine time (s)")
    bottom.set_xlim(summary.start, max(summary.end, summary.start + 1.0))
    fig.tight_layout()
    fig.savefig(path, bbox_inches="tight", pad_inches=0.2)
    return path


def _belief_rows(spans: list[BeliefSpan]) -> list[tuple[str, list[BeliefSpan], list[float]]]:
    """(label, spans to draw as bars, change times to draw as ticks) per row, at most MAX_BELIEF_ROWS rows."""
    by_predicate: dict[str, list[BeliefSpan]] = {}
    for span in spans:
        by_predicate.setdefault(span.predicate, []).append(span)
    rows: list[tuple[str, list[BeliefSpan], list[float]]] = []
    for predicate, group in by_predicate.items():
        by_belief: dict[str, list[BeliefSpan]] = {}
        for span in group:
            by_belief.setdefault(span.belief, []).append(span)
        if len(by_belief) > MANY_VALUES:
            ticks = sorted({s.start for s in group})
            rows.append((f"{predicate}(...) x{len(group)}", [], ticks))
        else:
            rows.extend((belief if len(belief) <= 48 else belief[:45] + "...", held, [])
                        for belief, held in by_belief.items())
    if len(rows) > MAX_BELIEF_ROWS:
        logger.info("%d belief rows; the timeline shows the first %d", len(rows), MAX_BELIEF_ROWS)
    return rows[:MAX_BELIEF_ROWS]
