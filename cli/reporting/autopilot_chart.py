"""The autopilot's estimate and setpoints on the mission's clock: the mission's behaviors and the autopilot's flight
modes ("modes") as strips, then altitude, north and east, each with the autopilot's estimate (line), its position
setpoint (dashed) and the positions the engine recorded (dots) — where they part, the link or the engine lagged."""

from __future__ import annotations

import math

from aeroexec.cli.reporting.autopilot_log import Alignment, AutopilotLog, mission_path
from aeroexec.cli.reporting.flight_chart import FONT, behavior_segments, strip
from aeroexec.cli.reporting.labels import LabelPlacer
from aeroexec.cli.reporting.style import SHADES, figure, span_limits
from aeroexec.flight.summary import FlightSummary

from aeroexec.extras import require

with require("report"):
    import numpy as np
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D

ESTIMATE, SETPOINT, ENGINE = "#1f77b4", "#ff7f0e", "#222222"
#: row label, the NED column and its sign (altitude is up)
ROWS = (("altitude (m)", 2, -1.0), ("north (m)", 0, 1.0), ("east (m)", 1, 1.0))


def autopilot_figure(summary: FlightSummary, log: AutopilotLog, alignment: Alignment, dpi: int = 100) -> Figure:
    """The chart of :mod:`this module <aeroexec.cli.reporting.autopilot_chart>`."""
    fig = figure((12.5, 7.6), dpi)
    grid = fig.add_gridspec(5, 1, height_ratios=[0.5, 0.5, 2, 2, 2], left=0.07, right=0.77, top=0.93, bottom=0.08,
                            hspace=0.12)
    behaviors_ax = fig.add_subplot(grid[0])
    modes_ax = fig.add_subplot(grid[1], sharex=behaviors_ax)
    plots = [fig.add_subplot(grid[i], sharex=behaviors_ax) for i in (2, 3, 4)]
    shift = alignment.offset
    log_time = log.time - shift
    start = min(summary.start, float(log_time[0]))
    end = max(summary.end, float(log_time[-1]), start + 1.0)
    behaviors_ax.set_xlim(start, end)
    times, path = mission_path(summary)
    for ax, (label, axis, sign) in zip(plots, ROWS, strict=True):
        estimate = sign * log.estimate[:, axis]
        ax.plot(log_time, estimate, color=ESTIMATE, linewidth=1.5)
        shown = [*estimate]
        if len(log.setpoint):
            target = sign * log.setpoint[:, axis]
            ax.plot(log.setpoint_time - shift, target, color=SETPOINT, linewidth=1.2, linestyle="--")
            shown += [v for v in target if math.isfinite(v)]
        engine = sign * path[:, axis]
        ax.plot(times, engine, linestyle="none", marker="o", markersize=2.5, color=ENGINE)
        shown += list(engine)
        ax.set_ylim(*span_limits(float(np.nanmin(shown)), float(np.nanmax(shown)), 2.0))
        ax.set_ylabel(label, fontsize=FONT + 1)
        ax.grid(True, linewidth=0.4, color="#dddddd")
        ax.tick_params(labelsize=FONT)
    for ax in (behaviors_ax, modes_ax, *plots[:-1]):
        ax.tick_params(labelbottom=False)
    plots[-1].set_xlabel("engine time (s)", fontsize=FONT + 1)
    fig.canvas.draw()
    placer = LabelPlacer(fig)
    segments = behavior_segments(summary)
    names = list(dict.fromkeys(name for name, _, _ in segments))
    colors = {name: SHADES[i % len(SHADES)] for i, name in enumerate(names)}
    strip(behaviors_ax, "behaviors", [(n, a, b, colors[n]) for n, a, b in segments], placer)
    modes = [(name, when - shift) for when, name in log.modes]
    mode_names = list(dict.fromkeys(name for name, _ in modes))
    mode_colors = {name: SHADES[(i + 5) % len(SHADES)] for i, name in enumerate(mode_names)}
    mode_spans = [(name, when, modes[i + 1][1] if i + 1 < len(modes) else float(log_time[-1]), mode_colors[name])
                  for i, (name, when) in enumerate(modes)]
    strip(modes_ax, "modes", [span for span in mode_spans if span[2] > span[1]], placer)
    handles = [Line2D([], [], color=ESTIMATE, linewidth=1.5, label="autopilot's estimate"),
               Line2D([], [], color=SETPOINT, linewidth=1.2, linestyle="--", label="autopilot's setpoint"),
               Line2D([], [], color=ENGINE, linestyle="none", marker="o", markersize=3, label="engine's record")]
    fig.legend(handles=handles, loc="upper left", bbox_to_anchor=(0.785, 0.93), fontsize=FONT, frameon=False)
    fig.text(0.785, 0.78, f"{log.kind}\n{log.system}\n{log.path.name}\n\nboot time = engine time + "
             f"{alignment.offset:.3f} s\n{alignment.rms:.2f} m RMS over {alignment.samples} positions",
             fontsize=FONT, va="top")
    mission = summary.meta.get("mission", "mission")
    fig.suptitle(f"{mission}: the autopilot's estimate and setpoints on the engine's clock", fontsize=FONT + 2,
                 x=0.42, y=0.985)
    return fig
