"""The flight report's one-page HTML summary: outcome, duration, distance, battery, each behavior's outcomes, the
failures with their reasons, every activation, and the report's images embedded (so the page stands alone)."""

from __future__ import annotations

import base64
from html import escape
from pathlib import Path

from aeroexec.cli.reporting.render import OUTCOME_COLORS
from aeroexec.flight.summary import FlightSummary

STYLE = """
body { font-family: sans-serif; margin: 2em; color: #222; }
table { border-collapse: collapse; margin: 0.5em 0 1.5em; font-size: 0.9em; }
th, td { border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: left; vertical-align: top; }
th { background: #f0f0f0; }
.outcome { font-weight: bold; }
img { max-width: 100%; border: 1px solid #ddd; margin: 0.5em 0; }
"""


def write_html(summary: FlightSummary, images: dict[str, Path], path: Path) -> Path:
    """Write the summary page to ``path``; ``images`` are title -> PNG file, embedded as data URIs."""
    mission = escape(str(summary.meta.get("mission", "mission")))
    battery = summary.battery_used
    facts = [
        ("outcome", summary.outcome),
        ("started", str(summary.meta.get("wall_time", "on the simulated clock" if summary.meta.get("clock") ==
                                          "simulated" else "?"))),
        ("duration", f"{summary.duration:.1f} s (engine time)"),
        ("distance flown", f"{summary.distance:.1f} m"),
        ("battery used", f"{battery:.1f} %" if battery is not None else "no drone state samples"),
        ("behavior activations", str(len(summary.behaviors))),
        ("beliefs held at the end", str(sum(not b.removed for b in summary.beliefs))),
        ("drone", str(summary.meta.get("drone", "?"))),
        ("world", str(summary.meta.get("world") or "default")),
    ]
    parts = [f"<!DOCTYPE html>\n<html><head><meta charset='utf-8'><title>aeroexec report: {mission}</title>"
             f"<style>{STYLE}</style></head><body>", f"<h1>Flight report: {mission}</h1>",
             _table(["", ""], [[escape(k), escape(v)] for k, v in facts], header=False)]
    parts.append("<h2>Outcomes by behavior</h2>")
    outcomes = sorted({o for per in summary.outcome_counts().values() for o in per})
    parts.append(_table(["behavior", *outcomes],
                        [[escape(name), *(str(per.get(o, "")) for o in outcomes)]
                         for name, per in summary.outcome_counts().items()]))
    parts.append("<h2>Failures</h2>")
    if summary.failures:
        parts.append(_table(["time (s)", "event", "behavior", "reason"],
                            [[f"{f.time:.2f}", escape(f.kind), escape(f.behavior), escape(f.reason)]
                             for f in summary.failures]))
    else:
        parts.append("<p>None.</p>")
    for title, image in images.items():
        data = base64.b64encode(Path(image).read_bytes()).decode("ascii")
        parts.append(f"<h2>{escape(title)}</h2><img alt='{escape(title)}' src='data:image/png;base64,{data}'>"
                     f"<p><a href='{escape(Path(image).name)}'>{escape(Path(image).name)}</a></p>")
    parts.append("<h2>Activations</h2>")
    parts.append(_table(["behavior", "arguments", "source", "start (s)", "end (s)", "outcome", "reason"],
                        [[escape(s.behavior), escape(", ".join(f"{k}={v}" for k, v in s.arguments.items())),
                          escape(s.source), f"{s.start:.2f}", f"{s.end:.2f}",
                          f"<span class='outcome' style='color:{OUTCOME_COLORS.get(s.outcome, '#e377c2')}'>"
                          f"{escape(s.outcome)}</span>", escape(s.reason)] for s in summary.behaviors]))
    parts.append("</body></html>\n")
    path.write_text("\n".join(parts), encoding="utf-8")
    return path


def _table(headers: list[str], rows: list[list[str]], header: bool = True) -> str:
    """An HTML table of already escaped cells."""
    head = "<tr>" + "".join(f"<th>{h}</th>" for h in headers) + "</tr>" if header else ""
    body = "".join("<tr>" + "".join(f"<td>{c}</td>" for c in row) + "</tr>" for row in rows)
    return f"<table>{head}{body}</table>"
