"""The rehearsal report: success rate, the distributions of duration, battery at the end and clearance, which
rules fired and where, and the worst runs with the command that flies each again (an HTML page with plots)."""

from __future__ import annotations

import base64
import html
import io
import math
from collections import Counter
from collections.abc import Sequence
from pathlib import Path

from aeroexec.rehearsal.campaign import STRONG_WIND, RunResult


def summary(results: Sequence[RunResult], worst: int = 5) -> dict:
    """The campaign's figures: runs, successes, rate, the windy runs' rate, rules fired, the worst runs."""
    done = [r for r in results if r.success]
    windy = [r for r in results if r.variation.wind_speed > STRONG_WIND]
    fired = Counter(event["rule"] for r in results for event in r.rules)
    ranked = sorted(results, key=lambda r: (r.success, r.battery if r.success else -len(r.rules), r.variation.seed))
    return {"runs": len(results), "successes": len(done), "rate": len(done) / len(results) if results else 0.0,
            "windy": len(windy), "windy_successes": sum(r.success for r in windy), "fired": dict(fired),
            "worst": ranked[:worst]}


def _plot(values: Sequence[float], title: str, unit: str) -> str:
    from aeroexec.extras import require

    with require("report"):
        import matplotlib

    matplotlib.use("Agg")
    from matplotlib import pyplot

    figure, axes = pyplot.subplots(figsize=(4.2, 2.8), dpi=90)
    finite = [v for v in values if v is not None and math.isfinite(v)]
    axes.hist(finite or [0.0], bins=min(20, max(5, len(finite) // 3)), color="#3b7dd8")
    axes.set_title(title)
    axes.set_xlabel(unit)
    axes.set_ylabel("runs")
    figure.tight_layout()
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png")
    pyplot.close(figure)
    data = base64.b64encode(buffer.getvalue()).decode()
    return f'<img alt="{html.escape(title)}" src="data:image/png;base64,{data}">'


def _beliefs(beliefs: dict) -> str:
    return ", ".join(f"{k} = {v}" for k, v in beliefs.items())


def write_report(results: Sequence[RunResult], mission: str, path: Path, engine: str) -> Path:
    """Write the campaign's HTML page to ``path``."""
    figures = summary(results)
    e = html.escape
    rows = "".join(
        f"<tr><td>{r.variation.seed}</td><td>{e(r.status)}</td><td>{r.duration:.1f}</td><td>{r.battery:.1f}</td>"
        f"<td>{r.variation.wind_speed:.1f}</td><td>{e(', '.join(sorted({x['rule'] for x in r.rules})) or '-')}</td>"
        f"<td><code>aeroexec rehearse {e(mission)} --replay {r.variation.seed}</code></td></tr>"
        for r in figures["worst"])
    where = "".join(f"<tr><td>{e(str(event['rule']))}</td><td>{r.variation.seed}</td>"
                    f"<td>{event['time']:.1f}</td><td>{e(_beliefs(event['beliefs']))}</td></tr>"
                    for r in results for event in r.rules)
    plots = "".join([
        _plot([r.duration for r in results], "duration", "simulated s"),
        _plot([r.battery for r in results], "battery at the end", "%"),
        _plot([r.clearance for r in results], "least clearance to obstacles", "m"),
        _plot([r.variation.wind_speed for r in results if not r.success], "wind of the failed runs", "m/s")])
    page = f"""<!doctype html><html><head><meta charset="utf-8"><title>Rehearsal of {e(mission)}</title>
<style>body{{font-family:sans-serif;margin:2em}}table{{border-collapse:collapse}}td,th{{border:1px solid #ccc;
padding:2px 6px}}img{{margin:4px}}</style></head><body>
<h1>Rehearsal of {e(mission)}</h1>
<p><b>{figures['successes']} of {figures['runs']} runs completed ({100 * figures['rate']:.0f} %)</b>;
in wind above {STRONG_WIND:g} m/s: {figures['windy_successes']} of {figures['windy']}. Flown on {e(engine)}.</p>
<div>{plots}</div>
<h2>Safety rules that fired</h2><table><tr><th>rule</th><th>run</th><th>t (s)</th><th>beliefs</th></tr>{where}</table>
<h2>Worst runs</h2><table><tr><th>seed</th><th>status</th><th>duration (s)</th><th>battery (%)</th><th>wind (m/s)</th>
<th>rules</th><th>fly it again</th></tr>{rows}</table></body></html>"""
    path.write_text(page)
    return path


__all__ = ["summary", "write_report"]
