"""What the report's images share: colors, a figure on matplotlib's Agg canvas, round steps for grids and scale
bars, and saving an image twice: as a PNG file, and as SVG whose texts stay texts (for the HTML page, where a
browser can read every label's place)."""

from __future__ import annotations

import io
import math
from pathlib import Path

from aeroexec.extras import require

with require("report"):
    import matplotlib
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

PATH_COLOR = "#0a64e6"  # the outbound leg; used by nothing else, so the path can be found in the image
RETURN_COLOR = "#e6550d"  # the way home: from where the drone only came nearer home
OUTCOME_COLORS = {
    "GOAL_ACHIEVED": "#2ca02c",
    "INTERRUPTED": "#9e9e9e",
    "TIME_OUT": "#ff7f0e",
    "WRONG_PROGRESS": "#d62728",
    "FAILED_PRECONDITIONS": "#8c564b",
    "RUNNING": "#bcbd22",
}
SHADES = ("#c6dbef", "#fdd0a2", "#c7e9c0", "#dadaeb", "#fcbba1", "#d9d9d9", "#fde0ef", "#e5f5e0", "#fff7bc",
          "#d0d1e6")


def figure(size: tuple[float, float], dpi: int = 100) -> Figure:
    """A figure of ``size`` inches drawn by Agg, whatever pyplot's backend is."""
    fig = Figure(figsize=size, dpi=dpi)
    FigureCanvasAgg(fig)
    return fig


def nice_step(rough: float) -> float:
    """The round value (1, 2 or 5 times a power of ten) nearest below ``rough`` (> 0)."""
    if not rough > 0 or not math.isfinite(rough):
        return 1.0
    power = 10 ** math.floor(math.log10(rough))
    return max((m * power for m in (1, 2, 5) if m * power <= rough), default=power)


def save(fig: Figure, png: Path) -> str:
    """Write ``fig`` to ``png``; its SVG (texts as ``<text>``, no XML prologue), ready to put inside a page."""
    fig.savefig(png, pad_inches=0.1)
    out = io.StringIO()
    with matplotlib.rc_context({"svg.fonttype": "none", "svg.hashsalt": png.stem}):
        fig.savefig(out, format="svg", pad_inches=0.1)
    text = out.getvalue()
    return text[text.index("<svg"):]


def span_limits(low: float, high: float, min_span: float, floor: float | None = None,
                ceiling: float | None = None) -> tuple[float, float]:
    """Axis limits around [low, high] with a margin, at least ``min_span`` wide (a 1 % battery drop must not fill
    the plot), kept within [floor, ceiling] when given."""
    span = max(high - low, 0.0)
    margin = 0.08 * span
    low, high = low - margin, high + margin
    if high - low < min_span:
        middle = (low + high) / 2
        low, high = middle - min_span / 2, middle + min_span / 2
    if ceiling is not None and high > ceiling:
        low, high = low - (high - ceiling), ceiling
    if floor is not None and low < floor:
        low, high = floor, high + (floor - low) if ceiling is None else min(ceiling, high + (floor - low))
    return low, high


