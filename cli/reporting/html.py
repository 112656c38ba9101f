"""The flight report's page: a header a pilot reads first (outcome, date, aeroexec version, mission, drone, seed,
world and home, duration, distance, battery, highest altitude and speed), the images inline as SVG (their labels
stay text; each links its PNG), the outcomes by behavior, the failures with their reasons, the safety rules held or
violated, the changes of the mission in flight, and every activation. The page stands alone: no script, no file it
needs besides itself."""

from __future__ import annotations

from dataclasses import dataclass
from html import escape
from pathlib import Path

from aeroexec.cli.reporting.style import OUTCOME_COLORS
from aeroexec.flight.summary import FlightSummary

WORD_COLORS = {"completed": "#2e7d32", "completed with refused requests": "#b26a00", "failed": "#c62828",
               "aborted": "#c62828", "suspended": "#b26a00", "incomplete": "#546e7a"}

STYLE = """
body { margin: 0; font: 14px/1.45 system-ui, "DejaVu Sans", sans-serif; color: #1d2330; background: #f4f5f7; }
header { background: #1d2330; color: #fff; padding: 14px 24px 16px; }
header h1 { font-size: 20px; margin: 0 0 10px; font-weight: 600; }
.outcome { display: inline-block; padding: 2px 10px; border-radius: 4px; color: #fff; font-weight: 700;
           margin-left: 10px; font-size: 16px; }
dl.facts { display: grid; grid-template-columns: repeat(auto-fill, minmax(180px, 1fr)); gap: 8px 24px; margin: 0; }
dl.facts div { min-width: 0; }
dt { font-size: 11px; text-transform: uppercase; letter-spacing: 0.04em; color: #aab4c3; }
dd { margin: 0; font-weight: 600; overflow-wrap: anywhere; }
main { padding: 8px 24px 32px; }
h2 { font-size: 15px; margin: 22px 0 8px; text-transform: uppercase; letter-spacing: 0.04em; color: #556; }
section.image { background: #fff; border: 1px solid #d5d9e0; padding: 8px; max-width: 1400px; }
section.image svg { width: 100%; height: auto; display: block; }
section.image svg text { white-space: pre; }  /* matplotlib's spaces are kept, as in the PNG */
section.image p { margin: 4px 0 0; font-size: 12px; }
table { border-collapse: collapse; background: #fff; font-size: 13px; }
th, td { border: 1px solid #d5d9e0; padding: 3px 8px; text-align: left; vertical-align: top; }
th { background: #eef0f4; }
td.outcome-word { font-weight: 700; }
details summary { cursor: pointer; margin: 6px 0; }
"""


@dataclass
class Image:
    """One image of the report: its PNG file and its SVG text."""

    title: str
    png: Path
    svg: str


def header_facts(summary: FlightSummary, version: str, flown: str, log: Path) -> list[tuple[str, str]]:
    """The facts of the header, in reading order."""
    meta = summary.meta
    series = summary.series()
    battery = summary.battery_used
    drone = str(meta.get("drone", "?"))
    robot = meta.get("robot")
    home = meta.get("home")
    facts = [
        ("flown", flown),
        ("mission", str(meta.get("mission", "?"))),
        ("drone", drone + (f" ({robot})" if robot and robot != "drone" else "")),
        ("seed", str(meta.get("seed", "?"))),
        ("world", str(meta.get("world") or "built-in default")),
        ("duration", f"{summary.duration:.1f} s ({'simulated' if meta.get('clock') == 'simulated' else 'wall'} "
                     f"clock)"),
        ("distance flown", f"{summary.distance:.1f} m"),
        ("battery used", f"{battery:.1f} %" if battery is not None else "no drone state samples"),
        ("highest altitude", f"{max(series['altitude']):.1f} m" if series["altitude"] else "-"),
        ("top speed", f"{max(series['speed']):.1f} m/s" if series["speed"] else "-"),
        ("aeroexec", f"{meta['aeroexec']} (flown), {version} (report)" if meta.get("aeroexec") else version),
        ("event log", str(log)),
    ]
    if isinstance(home, list | tuple) and len(home) >= 2:
        facts.insert(5, ("home", f"{float(home[0]):.6f}, {float(home[1]):.6f}"
                                 + (f", {float(home[2]):.1f} m" if len(home) > 2 else "")))
    return facts


def write_html(summary: FlightSummary, images: list[Image], path: Path, version: str, flown: str, log: Path
               ) -> Path:
    """Write the report page to ``path``."""
    mission = escape(str(summary.meta.get("mission", "mission")))
    word = summary.outcome
    facts = "".join(f"<div><dt>{escape(k)}</dt><dd>{escape(v)}</dd></div>"
                    for k, v in header_facts(summary, version, flown, log))
    parts = [f"<!DOCTYPE html>\n<html lang='en'><head><meta charset='utf-8'>"
             f"<meta name='viewport' content='width=device-width, initial-scale=1'>"
             f"<title>aeroexec report: {mission}</title><style>{STYLE}</style></head><body>",
             f"<header><h1>Flight report: {mission}<span class='outcome' id='outcome' "
             f"style='background:{WORD_COLORS.get(word, '#546e7a')}'>{escape(word)}</span></h1>"
             f"<dl class='facts'>{facts}</dl></header><main>"]
    for image in images[:2]:
        parts.append(_image(image))
    parts.append("<h2>Outcomes by behavior</h2>")
    counts = summary.outcome_counts()
    outcomes = sorted({o for per in counts.values() for o in per})
    parts.append(_table(["behavior", *outcomes],
                        [[escape(name), *(str(per.get(o, "")) for o in outcomes)] for name, per in counts.items()]))
    parts.append("<h2>Failures</h2>")
    if summary.failures:
        parts.append(_table(["time (s)", "event", "behavior", "reason"],
                            [[f"{f.time:.2f}", escape(f.kind), escape(f.behavior), escape(f.reason)]
                             for f in summary.failures]))
    else:
        parts.append("<p>None.</p>")
    if summary.safety:  # compliance: each safety rule, held or violated, when, and the contingency taken
        parts.append("<h2>Safety rules</h2>")
        parts.append(_table(["rule", "held", "when", "contingency", "rule text"],
                            [[escape(c.rule), "held" if c.held else "<b>violated</b>",
                              escape("; ".join(f"{t:.1f} s {k[7:]}: {d}" for t, k, d in c.events) or "-"),
                              escape(c.contingency), escape(f"{c.text} ({c.where})")] for c in summary.safety]))
    if summary.changes:
        parts.append("<h2>Mission changes</h2>")
        parts.append(_table(["time (s)", "from", "change", "taken", "what it did, or why it was refused"],
                            [[f"{c.time:.2f}", escape(c.origin), escape(f"{c.command} {c.argument}".strip()),
                              "yes" if c.taken else "<b>refused</b>",
                              escape(c.said) + "".join(f"<br>{escape(p)}" for p in c.problems[1:])]
                             for c in summary.changes]))
    for image in images[2:]:
        parts.append(_image(image))
    parts.append(f"<h2>Activations</h2><details><summary>{len(summary.behaviors)} activations: behavior, arguments, "
                 f"source, start, end, outcome, reason</summary>")
    parts.append(_table(["behavior", "arguments", "source", "start (s)", "end (s)", "outcome", "reason"],
                        [[escape(s.behavior), escape(", ".join(f"{k}={v}" for k, v in s.arguments.items())),
                          escape(s.source), f"{s.start:.2f}", f"{s.end:.2f}",
                          f"<span style='color:{OUTCOME_COLORS.get(s.outcome, '#e377c2')}'>{escape(s.outcome)}</span>",
                          escape(s.reason)] for s in summary.behaviors]))
    parts.append("</details></main></body></html>\n")
    path.write_text("\n".join(parts), encoding="utf-8")
    return path


def _image(image: Image) -> str:
    name = escape(image.png.name)
    return (f"<h2>{escape(image.title)}</h2><section class='image' id='{escape(image.png.stem)}'>{image.svg}"
            f"<p><a href='{name}'>{name}</a></p></section>")


def _table(headers: list[str], rows: list[list[str]]) -> str:
    """An HTML table of already escaped cells."""
    head = "<tr>" + "".join(f"<th>{h}</th>" for h in headers) + "</tr>"
    body = "".join("<tr>" + "".join(f"<td>{c}</td>" for c in row) + "</tr>" for row in rows)
    return f"<table>{head}{body}</table>"
