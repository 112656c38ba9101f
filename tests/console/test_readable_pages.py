"""A console and a report a pilot reads at a glance (issue 35, points 8 and 9), judged in headless Chromium at
1400 x 900 and 1920 x 1080 from the pages' own geometry: no two pieces of text overlap (HTML and SVG alike, clipped
as the reader sees them), the console's events panel is in view without scrolling, its header shows altitude and
speed, and a replay says it is one. The console's screenshot is docs/console.png (``--refresh-docs`` writes it)."""

import os
import shutil
import subprocess
import sys
import time

import pytest
from console_helpers import geometry, viewport
from test_console_browser import ROOT, Run, shown, wait_for

pytestmark = pytest.mark.browser

SIZES = ((1400, 900), (1920, 1080))


def readable(driver, what, panel=None):
    """Assert, at each size, that no texts overlap (and ``panel`` is in view); the geometry at each size."""
    seen = {}
    for width, height in SIZES:
        viewport(driver, width, height)
        time.sleep(0.5)  # a redraw at the new size (the map draws in screen pixels)
        page = geometry(driver, panel)
        assert page["texts"] > 20, f"{what} at {width}x{height}: the page shows almost no text"
        assert page["overlaps"] == [], f"{what} at {width}x{height}: texts overlap: {page['overlaps']}"
        if panel:
            box = page["panel"]
            assert box["top"] >= 0 and box["bottom"] <= height and box["bottom"] - box["top"] >= 150, \
                f"{what} at {width}x{height}: #{panel} is not in view without scrolling: {box}"
            assert not page["scrollable"], f"{what} at {width}x{height}: the page scrolls"
        seen[(width, height)] = page
    return seen


@pytest.fixture(scope="module")
def flown(tmp_path_factory):
    return tmp_path_factory.mktemp("flown") / "out"


def test_the_live_console_reads_at_a_glance_at_both_sizes(browser, flown, request):
    rules = flown.parent / "rules.yaml"  # rules that hold all along: the header says so
    rules.write_text("- {rule: ceiling, always: 'position(self, (?x, ?y, ?z)), ?z < 60', contingency: land}\n"
                     "- {rule: max_time, never: 'mission_time(?t), ?t > 900', contingency: return}\n")
    run = Run("missions/iarc7.xml", flown, "--speed", "2", "--safety-rules", str(rules))
    try:
        viewport(browser, *SIZES[0])
        browser.get(run.url)
        wait_for(browser, lambda d: shown(d, "link") == "online", what="the socket")
        wait_for(browser, lambda d: d.execute_script("return document.querySelectorAll('#map .planned').length"),
                 timeout=60, what="GO_TO_POINT's planned path")
        readable(browser, "the live console", "events-panel")
        altitude, speed = shown(browser, "altitude"), shown(browser, "speed")
        assert altitude.endswith(" m") and float(altitude.split()[0]) > 1.0, altitude
        assert speed.endswith(" m/s"), speed
        assert shown(browser, "safety") == "safety: 2 rules held"
        assert browser.execute_script("return !!document.querySelector('#map .scale-bar')")
        assert browser.execute_script("return document.querySelector('#map .north-label').textContent") == "N"
        assert browser.execute_script("return document.querySelectorAll('#map .grid').length") >= 8
        assert "home 47.39" in browser.execute_script("return document.querySelector('#map .home-label').textContent")
        viewport(browser, *SIZES[0])
        time.sleep(0.5)
        picture = flown.parent / "console.png"
        browser.save_screenshot(str(picture))
        if request.config.getoption("--refresh-docs"):
            shutil.copy(picture, ROOT / "docs" / "console.png")
        code, err = run.wait()
        assert code == 0, err
    finally:
        run.stop()


def test_a_replay_says_replay_and_reads_at_a_glance(browser, flown):
    if not (flown / "events.jsonl").exists():
        pytest.fail("the live console's test flies the run this test replays")
    replay = subprocess.Popen([sys.executable, "-m", "aeroexec.cli.main", "console", str(flown)], cwd=ROOT,
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                              env={**os.environ, "PYTHONUNBUFFERED": "1"})
    try:
        url = replay.stdout.readline().split(": ", 1)[1].strip()
        viewport(browser, *SIZES[0])
        browser.get(url)
        wait_for(browser, lambda d: shown(d, "state") == "replay", what="the replay's header")
        assert "online" not in shown(browser, "link") and "read-only" in shown(browser, "link")
        assert shown(browser, "replay-mission") == "iarc7.xml"
        readable(browser, "the replay", "events-panel")
        assert shown(browser, "altitude") == "0.0 m"  # at the end of the run: landed
        assert shown(browser, "safety") == "safety: 2 rules held"  # from the run's safety events
    finally:
        replay.terminate()
        replay.wait(timeout=30)


def test_the_report_reads_at_a_glance_at_both_sizes(browser, flown, tmp_path):
    if not (flown / "events.jsonl").exists():
        pytest.fail("the live console's test flies the run this test reports")
    made = subprocess.run([sys.executable, "-m", "aeroexec.cli.main", "report", str(flown), "--output",
                           str(tmp_path)], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert made.returncode == 0, made.stderr
    viewport(browser, *SIZES[0])
    browser.get((tmp_path / "report.html").as_uri())
    facts = browser.execute_script(
        "return Object.fromEntries([...document.querySelectorAll('dl.facts div')].map("
        "d => [d.querySelector('dt').textContent, d.querySelector('dd').textContent]))")
    assert facts["mission"] == "iarc7.xml" and facts["drone"] == "sim" and facts["seed"] == "0"
    assert facts["aeroexec"] and facts["flown"][:2] == "20"
    assert shown(browser, "outcome") == "completed"
    svg_texts = browser.execute_script("return document.querySelectorAll('section.image svg text').length")
    assert svg_texts > 100, "the images' labels are text the page can measure"
    pages = readable(browser, "the report")
    assert pages[SIZES[1]]["texts"] >= pages[SIZES[0]]["texts"] - 5
