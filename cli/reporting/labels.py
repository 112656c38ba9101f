"""Text labels that never overlap: each label tries places around its anchor and takes the first one free of the
labels and marks already there; a label with no free place is left off the drawing (the caller lists it in a
legend instead). :func:`overlaps` finds overlapping texts in a drawn figure (the tests hold every report image
to it)."""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import Any

from matplotlib.figure import Figure
from matplotlib.text import Text
from matplotlib.transforms import Bbox

#: Offsets (points) tried in turn around an anchor: right, left, above, below, then the diagonals.
AROUND = ((7, 0), (-7, 0), (0, 7), (0, -7), (6, 6), (-6, 6), (6, -6), (-6, -6), (12, 0), (-12, 0))
PAD = 2.0  # pixels kept free around every label


class LabelPlacer:
    """Places labels on the axes of one figure, each where it overlaps nothing placed or reserved before it: first
    where it crosses no line either, else over a line on a white ground."""

    def __init__(self, figure: Figure) -> None:
        self.figure = figure
        self.renderer = figure.canvas.get_renderer()
        self.taken: list[Bbox] = []
        self.segments: list[tuple[float, float, float, float]] = []  # lines to keep clear, in pixels

    def reserve(self, box: Bbox) -> None:
        """Keep ``box`` (display pixels) free of labels: a marker, a legend."""
        self.taken.append(box)

    def reserve_point(self, ax: Any, xy: Sequence[float], radius: float = 5.0) -> None:
        """Keep a marker at data point ``xy`` free, ``radius`` pixels around it."""
        x, y = ax.transData.transform(xy)
        self.reserve(Bbox.from_extents(x - radius, y - radius, x + radius, y + radius))

    def reserve_line(self, ax: Any, xs: Sequence[float], ys: Sequence[float]) -> None:
        """Keep labels off the polyline through the data points (xs, ys) where they can be."""
        points = ax.transData.transform(list(zip(xs, ys, strict=True))) if len(xs) else []
        kept: list[Any] = []
        for point in points:  # a vertex every 3 pixels or more is enough to tell where the line runs
            if not kept or abs(point[0] - kept[-1][0]) + abs(point[1] - kept[-1][1]) >= 3:
                kept.append(point)
        self.segments += [(a[0], a[1], b[0], b[1]) for a, b in zip(kept, kept[1:], strict=False)]

    def place(self, ax: Any, text: str, xy: Sequence[float], offsets: Iterable[tuple[float, float]] = AROUND,
              inside: bool = True, **style: Any) -> Text | None:
        """The label ``text`` next to data point ``xy`` at the first free offset; None (nothing drawn) when every
        offset overlaps something or, with ``inside``, falls outside the axes."""
        frame = ax.get_window_extent(self.renderer)
        offsets = list(offsets)
        for clear_of_lines in (True, False):
            for dx, dy in offsets:
                ha = "left" if dx > 0 else "right" if dx < 0 else "center"
                va = "bottom" if dy > 0 else "top" if dy < 0 else "center"
                ground = {} if clear_of_lines else {"bbox": {"boxstyle": "square,pad=0.1", "fc": "white",
                                                             "ec": "none", "alpha": 0.85}}
                label = ax.annotate(text, xy, xytext=(dx, dy), textcoords="offset points", ha=ha, va=va,
                                    annotation_clip=False, **ground, **{"zorder": 9, **style})
                box = label.get_window_extent(self.renderer)
                if (not inside or _within(box, frame)) and self.free(box) and \
                        (not clear_of_lines or not self.crosses(box)):
                    self.taken.append(box)
                    return label
                label.remove()
        return None

    def place_inside(self, ax: Any, text: str, box_data: tuple[float, float, float, float], **style: Any
                     ) -> Text | None:
        """``text`` centred in the data rectangle (x0, y0, x1, y1) if it fits there and overlaps nothing."""
        x0, y0, x1, y1 = box_data
        label = ax.text((x0 + x1) / 2, (y0 + y1) / 2, text, ha="center", va="center", clip_on=False, **style)
        box = label.get_window_extent(self.renderer)
        space = Bbox(ax.transData.transform([(x0, y0), (x1, y1)]))
        if box.width + 2 * PAD <= abs(space.width) and box.height <= abs(space.height) + 1 and self.free(box) \
                and not self.crosses(box):
            self.taken.append(box)
            return label
        label.remove()
        return None

    def free(self, box: Bbox) -> bool:
        grown = box.expanded(1.0, 1.0).padded(PAD)
        return not any(grown.overlaps(other) for other in self.taken)

    def crosses(self, box: Bbox) -> bool:
        """Whether a reserved line runs through ``box``."""
        grown = box.padded(PAD)
        return any(segment_meets(segment, grown) for segment in self.segments)


def segment_meets(segment: tuple[float, float, float, float], box: Bbox) -> bool:
    """Whether the segment (x0, y0, x1, y1) enters ``box`` (Liang-Barsky clipping)."""
    x0, y0, x1, y1 = segment
    if max(x0, x1) < box.x0 or min(x0, x1) > box.x1 or max(y0, y1) < box.y0 or min(y0, y1) > box.y1:
        return False
    dx, dy = x1 - x0, y1 - y0
    low, high = 0.0, 1.0
    for p, q in ((-dx, x0 - box.x0), (dx, box.x1 - x0), (-dy, y0 - box.y0), (dy, box.y1 - y0)):
        if p == 0:
            if q < 0:
                return False
            continue
        t = q / p
        if p < 0:
            low = max(low, t)
        else:
            high = min(high, t)
        if low > high:
            return False
    return True


def _within(box: Bbox, frame: Bbox) -> bool:
    return box.x0 >= frame.x0 and box.x1 <= frame.x1 and box.y0 >= frame.y0 and box.y1 <= frame.y1


def overlaps(figure: Figure, tolerance: float = 0.5) -> list[tuple[str, str]]:
    """Pairs of the texts :func:`drawn_texts` finds whose boxes overlap by more than ``tolerance`` pixels both
    ways."""
    renderer = figure.canvas.get_renderer()
    boxes = [(t.get_text(), t.get_window_extent(renderer)) for t in drawn_texts(figure)]
    found = []
    for i, (a, box_a) in enumerate(boxes):
        for b, box_b in boxes[i + 1:]:
            width = min(box_a.x1, box_b.x1) - max(box_a.x0, box_b.x0)
            height = min(box_a.y1, box_b.y1) - max(box_a.y0, box_b.y0)
            if width > tolerance and height > tolerance:
                found.append((a, b))
    return found


def drawn_texts(figure: Figure) -> list[Text]:
    """Every text a drawn ``figure`` shows: titles, axis and tick labels (of ticks in view), legends,
    annotations and the figure's own texts."""
    figure.draw_without_rendering()
    texts: list[Text] = list(figure.texts)
    legends = list(figure.legends)
    for ax in figure.axes:
        if not ax.get_visible():
            continue
        texts += [ax.title, ax.xaxis.label, ax.yaxis.label, *ax.texts]
        for axis, limits in ((ax.xaxis, ax.get_xlim()), (ax.yaxis, ax.get_ylim())):
            low, high = sorted(limits)
            slack = (high - low) * 1e-9
            for tick in (*axis.get_major_ticks(), *axis.get_minor_ticks()):
                if low - slack <= tick.get_loc() <= high + slack and tick.get_visible():
                    texts += [tick.label1, tick.label2]
            texts.append(axis.get_offset_text())
        if ax.get_legend() is not None:
            legends.append(ax.get_legend())
    for legend in legends:
        texts += [*legend.get_texts(), legend.get_title()]
    return [t for t in texts if t.get_visible() and t.get_text().strip()]
