"""The web console in a real browser (headless Chromium through Selenium) against ``aeroexec run --web``: the page
loads with its token, the map shows the drone moving, tree nodes turn RUNNING then SUCCESS, pausing from the page
holds the mission, answering ASK_OPERATOR from the page lets it go on, and a wrong token gets 403."""

import json
import os
import subprocess
import sys
import threading
import time
import urllib.error
import urllib.request
from pathlib import Path

import pytest
from patience import hang_guard
from selenium.common.exceptions import TimeoutException
from selenium.webdriver.common.by import By
from selenium.webdriver.support.select import Select
from selenium.webdriver.support.ui import WebDriverWait
from websockets.exceptions import InvalidStatus
from websockets.sync.client import connect

ROOT = Path(__file__).parents[2]
DATA = Path(__file__).with_name("data")

pytestmark = pytest.mark.browser


class Run:
    """``aeroexec run MISSION --web 0`` in a subprocess; ``url`` is the console's address with its token."""

    def __init__(self, mission, output, *options, held=False):
        self.output = output
        self.process = subprocess.Popen(
            [sys.executable, "-m", "aeroexec.cli.main", "run", str(mission), "--plain", "--web", "--output",
             str(output), *options], cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
            env={**os.environ, "PYTHONUNBUFFERED": "1"})
        self.url = None
        deadline = time.monotonic() + hang_guard(60)
        while self.url is None and time.monotonic() < deadline:
            line = self.process.stderr.readline()
            if not line:
                break
            if line.startswith("web console: "):
                self.url = line.split(": ", 1)[1].strip()
        assert self.url, "aeroexec run printed no web console URL"
        # the rest of stderr read as it comes: a run whose pipe filled would block in its next write
        self._stderr: list[str] = []
        self._reader = threading.Thread(target=lambda: self._stderr.extend(self.process.stderr), daemon=True)
        self._reader.start()
        if held:
            self.hold()

    def hold(self):
        """Pause the mission over the console's socket at once: the page, slow to load on a loaded machine, then
        sees the mission where it was held rather than after the node the test looks at ended."""
        base, token = self.url.split("?")
        with connect(base.replace("http", "ws") + "ws?" + token, open_timeout=hang_guard(10)) as ws:
            ws.send(json.dumps({"id": 1, "drone": "drone", "command": "pause", "argument": ""}))
            while (reply := json.loads(ws.recv(timeout=hang_guard(10))))["type"] != "result":
                pass
        assert reply["ok"], reply

    def wait(self, timeout=120):
        code = self.process.wait(timeout=hang_guard(timeout))
        self._reader.join(timeout=hang_guard(10))
        return code, "".join(self._stderr)

    def events(self):
        """The run's records so far (a last line still being written is left for the next look)."""
        path = self.output / "events.jsonl"
        text = path.read_text() if path.exists() else ""
        return [json.loads(line) for line in text[:text.rfind("\n") + 1].splitlines() if line.strip()]

    def tail(self, count=12):
        """What the run did last, for a failure's message: its last records and what it wrote on stderr."""
        records = [f"{e.get('time')} {e.get('kind')} {e.get('data') or e.get('behavior') or ''}"
                   for e in self.events()[-count:]]
        return "last records:\n  " + "\n  ".join(records) + "\nstderr:\n" + "".join(self._stderr)[-2000:]

    def stop(self):
        if self.process.poll() is None:
            self.process.terminate()
            self.process.wait(timeout=30)


def wait_for(driver, condition, timeout=30, what="the page"):
    return WebDriverWait(driver, hang_guard(timeout), poll_frequency=0.1).until(lambda d: condition(d),
                                                                    message=f"waiting for {what}")


# The page redraws its panels on every update: read what it shows in one script call, never through elements
# that a redraw may replace between two calls.
def drone_position(driver):
    return driver.execute_script("""const m = document.getElementById("drone-drone");
        return m ? [parseFloat(m.getAttribute("data-x")), parseFloat(m.getAttribute("data-y"))] : null;""")


def node_status(driver, name):
    return driver.execute_script("""const r = document.querySelector(`#mission .node[data-name="${arguments[0]}"]`);
        return r ? r.dataset.status : null;""", name)


def shown(driver, element_id):
    return driver.execute_script("return document.getElementById(arguments[0]).textContent;", element_id)


def test_a_tree_mission_seen_live_nodes_turn_running_then_success_and_the_drone_moves(browser, tmp_path):
    run = Run("missions/figure10.xml", tmp_path / "out", "--speed", "1", held=True)
    try:
        browser.get(run.url)
        wait_for(browser, lambda d: shown(d, "link") == "online", what="the socket")
        wait_for(browser, lambda d: shown(d, "state") == "paused", what="the held mission")
        # the behavior the pause held RUNNING: TAKE_OFF (or, on a slow start, the one flying then)
        held = browser.execute_script("""const r = [...document.querySelectorAll('#mission .node')].find(n =>
            n.dataset.status === "RUNNING" && ["TAKE_OFF", "GO_TO_POINT", "LAND"].includes(n.dataset.name));
            return r ? r.dataset.name : null;""")
        browser.find_element(By.ID, "resume").click()
        if held is None:  # held before the first tick: TAKE_OFF runs once resumed
            held = "TAKE_OFF"
            wait_for(browser, lambda d: node_status(d, held) == "RUNNING", what=f"{held} RUNNING")
        wait_for(browser, lambda d: node_status(d, held) == "SUCCESS", what=f"{held} SUCCESS")
        first = wait_for(browser, drone_position, what="the drone on the map")
        wait_for(browser, lambda d: (p := drone_position(d)) and abs(p[0] - first[0]) + abs(p[1] - first[1]) > 1.0,
                 what="the drone to move on the map")
        assert browser.find_elements(By.CSS_SELECTOR, "#map .obstacle"), "the world's obstacles are drawn"
        browser.save_screenshot(str(tmp_path / "console.png"))
        code, err = run.wait()
        assert code == 0, err
    finally:
        run.stop()


def test_pausing_from_the_page_holds_the_mission_and_resuming_finishes_it(browser, tmp_path):
    run = Run("missions/figure10.py", tmp_path / "out", "--speed", "1")
    try:
        browser.get(run.url)
        wait_for(browser, lambda d: "GO_TO_POINT" in shown(d, "active"), what="GO_TO_POINT active")
        wait_for(browser, lambda d: d.execute_script("return document.querySelectorAll('#map .planned').length"),
                 what="GO_TO_POINT's planned path on the map")
        browser.find_element(By.ID, "pause").click()
        wait_for(browser, lambda d: shown(d, "state") == "paused", what="PAUSED")
        time.sleep(2.0)  # it brakes from cruise speed
        held = drone_position(browser)
        time.sleep(2.0)
        moved = drone_position(browser)
        assert abs(moved[0] - held[0]) + abs(moved[1] - held[1]) < 0.3, "the drone holds while paused"
        assert "GO_TO_POINT" not in shown(browser, "active")
        browser.find_element(By.ID, "resume").click()
        wait_for(browser, lambda d: shown(d, "state") == "running", what="RUNNING again")
        code, err = run.wait()
        assert code == 0, err
        commands = [e for e in run.events() if e["kind"] == "operator_command"]
        assert [(c["data"]["command"], c["data"]["origin"]) for c in commands] == [("pause", "web console"),
                                                                                 ("resume", "web console")]
    finally:
        run.stop()


def test_answering_the_drones_question_from_the_page_lets_the_mission_go_on(browser, tmp_path):
    run = Run(DATA / "ask_the_way.py", tmp_path / "out", "--speed", "2")
    try:
        browser.get(run.url)
        wait_for(browser, lambda d: d.find_element(By.ID, "question-dialog").get_attribute("open") is not None,
                 timeout=60, what="the question dialog")
        assert "Which way?" in shown(browser, "question-text")
        buttons = {b.text: b for b in browser.find_elements(By.CSS_SELECTOR, "#question-answers .answer")}
        assert set(buttons) == {"east", "south"}
        buttons["south"].click()
        code, err = run.wait()
        assert code == 0, err
        arrived = [e for e in run.events() if e["kind"] == "GOAL_ACHIEVED" and e["behavior"] == "GO_TO_POINT"]
        assert arrived
        states = [e for e in run.events() if e["kind"] == "state" and e["time"] <= arrived[-1]["time"]]
        x, y, _ = states[-1]["position"]
        assert y < -3 and abs(x) < 1, "the drone flew south, as answered"
    finally:
        run.stop()


def test_a_wrong_token_gets_403_on_the_page_and_the_socket(tmp_path):
    run = Run("missions/figure10.xml", tmp_path / "out", "--speed", "0.5")
    try:
        base = run.url.split("?")[0]
        with pytest.raises(urllib.error.HTTPError) as page:
            urllib.request.urlopen(base + "?token=wrong", timeout=10)
        assert page.value.code == 403
        with pytest.raises(urllib.error.HTTPError):
            urllib.request.urlopen(base, timeout=10)
        with pytest.raises(InvalidStatus) as socket:
            connect(base.replace("http", "ws") + "ws?token=wrong", open_timeout=10)
        assert socket.value.response.status_code == 403
        with connect(base.replace("http", "ws") + "ws?" + run.url.split("?")[1], open_timeout=10) as ws:
            hello = json.loads(ws.recv(timeout=10))
            assert hello["type"] == "hello" and hello["drones"] == ["drone"]
            ws.send(json.dumps({"id": 1, "drone": "drone", "command": "query", "argument": "flight_state(self, ?S)"}))
            while (reply := json.loads(ws.recv(timeout=10)))["type"] != "result":
                pass
            assert reply["ok"] and reply["data"]["answers"][0]["?S"]
    finally:
        run.stop()


def test_a_finished_run_replays_read_only_with_a_time_slider(browser, tmp_path):
    flown = subprocess.run([sys.executable, "-m", "aeroexec.cli.main", "run", "missions/figure10.xml", "--plain",
                            "--output", str(tmp_path / "flown")], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert flown.returncode == 0, flown.stderr
    replay = subprocess.Popen([sys.executable, "-m", "aeroexec.cli.main", "console", str(tmp_path / "flown")],
                              cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                              env={**os.environ, "PYTHONUNBUFFERED": "1"})
    try:
        url = replay.stdout.readline().split(": ", 1)[1].strip()
        browser.get(url)
        wait_for(browser, lambda d: node_status(d, "TAKE_OFF") == "SUCCESS", what="the end of the run")
        assert browser.execute_script("return document.getElementById('controls-panel').hidden")
        end = drone_position(browser)
        browser.execute_script("""const s = document.getElementById('slider'); s.value = 1.0;
                                  s.dispatchEvent(new Event('input'));""")
        assert node_status(browser, "TAKE_OFF") == "RUNNING"
        early = drone_position(browser)
        assert early != end
        assert shown(browser, "replay-time") == "1.0 s"
    finally:
        replay.terminate()
        replay.wait(timeout=30)


def test_a_fleet_shows_every_drone_on_one_map_with_a_drone_selector(browser, tmp_path):
    fleet = subprocess.Popen([sys.executable, "-m", "aeroexec.cli.main", "fleet", "missions/relay.yaml", "--plain",
                              "--web", "--speed", "3", "--output", str(tmp_path / "out")], cwd=ROOT,
                             stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                             env={**os.environ, "PYTHONUNBUFFERED": "1"})
    try:
        url = next((line.split(": ", 1)[1].strip() for line in fleet.stderr if line.startswith("web console: ")), None)
        assert url, "aeroexec fleet printed no web console URL"
        browser.get(url)
        wait_for(browser, lambda d: d.execute_script(
            "return document.querySelectorAll('#map .drone-marker').length") == 2, what="both drones on the map")
        options = browser.execute_script("return [...document.getElementById('drone').options].map(o => o.value)")
        assert sorted(options) == ["carrier", "scout"]
        browser.execute_script("""const s = document.getElementById('drone'); s.value = 'carrier';
                                  s.dispatchEvent(new Event('change'));""")
        wait_for(browser, lambda d: "carrier" in shown(d, "mission") or "relay_carrier" in shown(d, "mission")
                 or shown(d, "state") in ("running", "paused"), what="the carrier's panels")
        assert fleet.wait(timeout=120) == 0
    finally:
        if fleet.poll() is None:
            fleet.terminate()
            fleet.wait(timeout=30)


def test_the_mission_is_changed_from_the_page_and_a_refused_change_says_why(browser, tmp_path):
    # held at the start until the page is there; at half speed corner A flies for 5 s, time to pause it from the
    # page even on a loaded machine (at 2x its 1.3 s were over before a slow page showed it)
    # (at 0.25x corner A flies 10 s; it is seen running in the run's own log, not in a page a starved browser may not
    # have redrawn while it ran)
    run = Run(ROOT / "tests" / "changes" / "data" / "patrol.xml", tmp_path / "out", "--speed", "0.25", held=True)
    try:
        browser.get(run.url)
        wait_for(browser, lambda d: shown(d, "link") == "online", what="the socket")  # else the click goes nowhere
        wait_for(browser, lambda d: shown(d, "state") == "paused", what="the held mission")
        browser.find_element(By.ID, "resume").click()
        try:
            wait_for(browser, lambda d: any(e.get("kind") == "node_status" and e["data"].get("node") == "corner A"
                                            and e["data"].get("new") == "RUNNING" for e in run.events()),
                     timeout=60, what="corner A RUNNING in the run's log")
        except TimeoutException:  # seen once on a loaded machine, cause unknown: what the run did, for the next look
            pytest.fail(f"corner A was not seen RUNNING; the page says {shown(browser, 'message')!r}; {run.tail()}")
        browser.find_element(By.ID, "pause").click()
        wait_for(browser, lambda d: shown(d, "state") == "paused", what="PAUSED")
        browser.find_element(By.ID, "skip").click()
        wait_for(browser, lambda d: node_status(d, "corner A") == "SKIPPED", what="corner A SKIPPED")
        Select(browser.find_element(By.ID, "change-command")).select_by_visible_text("insert")
        for argument in ("after 3 TAKE_OFF", "after 3 'GO_TO_POINT COORDINATES=\"9, -3, 4\" name=detour'"):
            field = browser.find_element(By.ID, "change-argument")
            field.clear()
            field.send_keys(argument)
            browser.find_element(By.ID, "change").click()
            if "TAKE_OFF" in argument:
                wait_for(browser, lambda d: "TAKE_OFF needs landed" in shown(d, "message"),
                         what="the refusal's reason")
        wait_for(browser, lambda d: node_status(d, "detour") == "IDLE", what="the inserted item in the tree")
        browser.find_element(By.ID, "abort").click()  # what the changes did is in the log: no need to fly on
        browser.switch_to.alert.accept()
        code, err = run.wait()
        assert code == 4, err
        changes = [(e["data"]["command"], e["data"]["ok"], e["data"]["origin"]) for e in run.events()
                   if e["kind"] == "mission_change"]
        assert changes == [("skip", True, "web console"), ("insert", False, "web console"),
                           ("insert", True, "web console")]
    finally:
        run.stop()
