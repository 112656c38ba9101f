"""The timeline of a run: each behavior's activations as bars colored by outcome, and the beliefs as bars while
held (a predicate with many values as one row of ticks, one per change)."""

from __future__ import annotations

import logging

from aeroexec.cli.reporting.style import OUTCOME_COLORS, figure
from aeroexec.flight.summary import BeliefSpan, FlightSummary

from aeroexec.extras import require

with require("report"):
    from matplotlib.figure import Figure
    from matplotlib.patches import Patch

logger = logging.getLogger(__name__)

MAX_BELIEF_ROWS = 30
MANY_VALUES = 6  # a predicate with more spans than this gets one row with a tick per change
ROW = 0.3  # inches a row takes
FONT = 8


def timeline_figure(summary: FlightSummary, dpi: int = 100) -> Figure:
    behaviors = list(dict.fromkeys(span.behavior for span in summary.behaviors))
    rows = _belief_rows(summary.beliefs)
    fig = figure((12.5, max(2.2 + ROW * (len(behaviors) + len(rows)), 4.0)), dpi)
    fig.set_layout_engine("constrained")
    top, bottom = fig.subplots(2, 1, sharex=True,
                               gridspec_kw={"height_ratios": [max(len(behaviors), 1), max(len(rows), 1)]})
    for row, name in enumerate(behaviors):
        for span in (s for s in summary.behaviors if s.behavior == name):
            top.barh(row, max(span.end - span.start, 0.05), left=span.start, height=0.7,
                     color=OUTCOME_COLORS.get(span.outcome, "#e377c2"), edgecolor="black", linewidth=0.3)
    top.set_yticks(range(len(behaviors)), behaviors, fontsize=FONT)
    top.set_ylim(max(len(behaviors), 1) - 0.5, -0.5)  # the first behavior on top
    top.set_title("behaviors (bar: activation to end, colored by outcome)", fontsize=FONT + 1)
    top.legend(handles=[Patch(color=color, label=outcome) for outcome, color in OUTCOME_COLORS.items()],
               fontsize=FONT, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False, title="outcome",
               title_fontsize=FONT)
    for row, (_, spans, ticks) in enumerate(rows):
        for span in spans:
            bottom.barh(row, max(span.end - span.start, 0.05), left=span.start, height=0.6, color="#4c72b0")
        if ticks:
            bottom.plot(ticks, [row] * len(ticks), marker="|", color="#4c72b0", linestyle="none")
    bottom.set_yticks(range(len(rows)), [label for label, _, _ in rows], fontsize=FONT - 0.5)
    bottom.set_ylim(max(len(rows), 1) - 0.5, -0.5)
    bottom.set_title("beliefs (bar: held; ticks: changes of a predicate with many values)", fontsize=FONT + 1)
    bottom.set_xlabel("engine time (s)", fontsize=FONT + 1)
    bottom.set_xlim(summary.start, max(summary.end, summary.start + 1.0))
    for ax in (top, bottom):
        ax.tick_params(axis="x", labelsize=FONT)
        ax.grid(True, axis="x", linewidth=0.4, color="#dddddd")
    return fig


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
