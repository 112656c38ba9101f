"""Altitude, speed and battery over time, under two strips a pilot reads first (as in PX4 Flight Review's flight
mode bar): the mission's behaviors and the flight states, each a row of colored spans named inside when the name
fits, and listed with their colors in the legend beside the chart. Axes fit the data with sensible minimum spans:
a 1 % battery drop does not fill the battery plot."""

from __future__ import annotations

from typing import Any

from aeroexec.cli.reporting.labels import LabelPlacer
from aeroexec.cli.reporting.style import SHADES, figure, span_limits
from aeroexec.flight.summary import FlightSummary

from aeroexec.extras import require

with require("report"):
    from matplotlib.figure import Figure
    from matplotlib.patches import Patch

STATE_COLORS = {"landed": "#bdbdbd", "taking_off": "#9ecae1", "hovering": "#a1d99b", "moving": "#3182bd",
                "landing": "#fdae6b", "flying": "#74c476"}
#: key, label, color, the narrowest span shown, a value always in view (the ground, standing still), floor, ceiling
SERIES = (("altitude", "altitude (m)", "#1f77b4", 2.0, 0.0, None, None),
          ("speed", "speed (m/s)", "#2ca02c", 1.0, 0.0, 0.0, None),
          ("battery", "battery (%)", "#d62728", 10.0, None, 0.0, 100.0))
FONT = 8


def flight_figure(summary: FlightSummary, dpi: int = 100) -> Figure:
    """The chart of :mod:`this module <aeroexec.cli.reporting.flight_chart>`."""
    fig = figure((12.5, 7.6), dpi)
    grid = fig.add_gridspec(5, 1, height_ratios=[0.5, 0.5, 2, 2, 2], left=0.07, right=0.77, top=0.93, bottom=0.08,
                            hspace=0.12)
    behaviors_ax = fig.add_subplot(grid[0])
    states_ax = fig.add_subplot(grid[1], sharex=behaviors_ax)
    plots = [fig.add_subplot(grid[i], sharex=behaviors_ax) for i in (2, 3, 4)]
    start, end = summary.start, max(summary.end, summary.start + 1.0)
    behaviors_ax.set_xlim(start, end)
    series = summary.series()
    segments = behavior_segments(summary)
    names = list(dict.fromkeys(name for name, _, _ in segments))
    colors = {name: SHADES[i % len(SHADES)] for i, name in enumerate(names)}
    for ax, (key, label, color, min_span, always, floor, ceiling) in zip(plots, SERIES, strict=True):
        for name, left, right in segments:
            ax.axvspan(left, right, color=colors[name], alpha=0.45, zorder=0, lw=0)
        values = series[key]
        ax.plot(series["time"], values, color=color, linewidth=1.5)
        shown = [*values, *([always] if always is not None else [])] or [0.0]
        ax.set_ylim(*span_limits(min(shown), max(shown), min_span, floor, ceiling))
        ax.set_ylabel(label, fontsize=FONT + 1)
        ax.grid(True, linewidth=0.4, color="#dddddd")
        ax.tick_params(labelsize=FONT)
    for ax in (behaviors_ax, states_ax, *plots[:-1]):
        ax.tick_params(labelbottom=False)
    plots[-1].set_xlabel("engine time (s)", fontsize=FONT + 1)
    fig.canvas.draw()
    placer = LabelPlacer(fig)
    strip(behaviors_ax, "behaviors", [(n, a, b, colors[n]) for n, a, b in segments], placer)
    states = _state_segments(summary, end)
    strip(states_ax, "flight state", [(s, a, b, STATE_COLORS.get(s, "#dddddd")) for s, a, b in states], placer)
    handles = [Patch(color="none", label="behaviors"), *(Patch(color=colors[n], label=n) for n in names),
               Patch(color="none", label=""), Patch(color="none", label="flight states"),
               *(Patch(color=STATE_COLORS.get(s, "#dddddd"), label=s) for s in dict.fromkeys(s for s, _, _ in states))]
    legend = fig.legend(handles=handles, loc="upper left", bbox_to_anchor=(0.785, 0.93), fontsize=FONT,
                        frameon=False, handlelength=1.2)
    for text in legend.get_texts():
        if text.get_text() in ("behaviors", "flight states"):
            text.set_fontweight("bold")
    fig.canvas.draw()  # the legend laid out: where its names end
    renderer = fig.canvas.get_renderer()
    for text in legend.get_texts():
        while text.get_window_extent(renderer).x1 > fig.bbox.x1 - 4 and len(text.get_text()) > 8:
            text.set_text(text.get_text().removesuffix("...")[:-2] + "...")  # cut to fit beside the chart
    mission = summary.meta.get("mission", "mission")
    fig.suptitle(f"{mission}: altitude, speed and battery (shaded: the mission's behaviors)", fontsize=FONT + 2,
                 x=0.42, y=0.985)
    return fig


def strip(ax: Any, title: str, spans: list[tuple[str, float, float, str]], placer: LabelPlacer) -> None:
    """A row of colored spans, each named inside when the name fits."""
    ax.set_ylim(0, 1)
    ax.set_yticks([])
    ax.set_ylabel(title, fontsize=FONT, rotation=0, ha="right", va="center")
    for _, left, right, color in spans:
        ax.axvspan(left, right, color=color, lw=0.5, ec="white")
    for name, left, right, _ in spans:
        placer.place_inside(ax, name, (left, 0, right, 1), fontsize=FONT - 0.5, color="#222222")


def behavior_segments(summary: FlightSummary) -> list[tuple[str, float, float]]:
    """The mission's behaviors as a sequence of (name, start, end), as a flight mode timeline: each one from its
    start until it ends or the next one starts (reactive behaviors are left out)."""
    spans = sorted((s for s in summary.behaviors if s.source != "reactive"), key=lambda s: s.start)
    segments = []
    for i, span in enumerate(spans):
        end = min([span.end, *(later.start for later in spans[i + 1:] if later.start > span.start)])
        if end > span.start:
            segments.append((span.behavior, span.start, end))
    return segments


def _state_segments(summary: FlightSummary, end: float) -> list[tuple[str, float, float]]:
    """The flight state from each change to the next."""
    changes = summary.flight_states
    return [(state, when, changes[i + 1][0] if i + 1 < len(changes) else end)
            for i, (when, state) in enumerate(changes) if (changes[i + 1][0] if i + 1 < len(changes) else end) > when]
