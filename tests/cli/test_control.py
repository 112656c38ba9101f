"""The control socket (engine/control.py, ``aeroexec ctl``) on a simulated mission paced at 20x real time, and
the live view (cli/views/live.py) rendered once to text."""

from __future__ import annotations

import importlib.util
import io
import json
import math
import os
import socket
import stat
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import pytest
from aeroexec.cli.views.live import KeyReader, LiveView
from aeroexec.drones import LandedState
from aeroexec.drones.sim import SimulatedDrone, default_world
from aeroexec.engine.clock import SimulatedClock
from aeroexec.engine.engine import Engine
from aeroexec.engine.events import Outcome
from aeroexec.engine.supervision.operator import RemoteOperator
from aeroexec.flight.control import CONTROL_FILE, ControlServer, read_control_file, send_command
from aeroexec.trees.model import TreeDocument, TreeNode
from aeroexec.trees.runtime.runner import TreeMission
from patience import hang_guard
from rich.console import Console

ROOT = Path(__file__).parents[2]
WAIT = 60.0  # wall seconds any condition may take on a loaded machine


def until(condition: Callable[[], object], timeout: float = WAIT) -> object:
    end = time.monotonic() + hang_guard(timeout)
    while time.monotonic() < end:
        value = condition()
        if value:
            return value
        time.sleep(0.02)
    raise AssertionError("the condition did not hold in time")


MISSION = '''
from aeroexec.engine import api

steps = []


def mission():
    api.execute_behavior("TAKE_OFF", altitude=3)
    steps.append("took off")
    steps.append(api.ask_behavior("ASK_OPERATOR", question="Fly east?", possible_answers=["yes", "no"]))
    api.execute_behavior("GO_TO_POINT", coordinates=(10, 0, 3), speed=0.5)  # 20 s: long enough to pause
    steps.append("arrived")
    api.ask_behavior("ASK_OPERATOR", question="Go north?")
    api.execute_behavior("GO_TO_POINT", coordinates=(10, 8, 3))
    steps.append("second point")
'''


def load_mission(tmp_path: Path):
    path = tmp_path / "ctl_mission.py"
    path.write_text(MISSION)
    spec = importlib.util.spec_from_file_location("ctl_mission", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture
def run(tmp_path):
    world = default_world()
    engine = Engine(SimulatedDrone(world), obstacles=world, clock=SimulatedClock(speed=20),
                    operator=RemoteOperator())
    server = ControlServer(engine, tmp_path / "out").start()
    yield engine, server, tmp_path / "out"
    server.close()
    engine.stop()


def test_pause_resume_answer_and_abort_through_the_socket(run, tmp_path):
    engine, server, folder = run
    module = load_mission(tmp_path)
    port, token = read_control_file(folder)
    assert port == server.port and stat.S_IMODE(os.stat(folder / CONTROL_FILE).st_mode) == 0o600

    def ctl(command: str, argument: str = "") -> dict:
        return send_command(port, token, command, argument)

    engine.start_mission(module.mission, "ctl_mission")
    engine.start()
    until(lambda: engine.context.operator.pending_questions())
    assert ctl("status")["status"]["questions"] == ["Fly east?"]
    answer = ctl("answer", "yes")
    assert answer["ok"], answer
    until(lambda: engine.coordinator.is_active("GO_TO_POINT"))
    assert module.steps == ["took off", "yes"] and engine.memory.holds("answer('Fly east?', yes)")

    assert ctl("pause")["ok"]
    status = ctl("status")["status"]
    assert status["state"] == "paused" and "GO_TO_POINT" not in [a["name"] for a in status["active"]]
    until(lambda: engine.drone.telemetry().speed < 0.1 and engine.now() > 0)
    time.sleep(0.1)
    held, start = engine.drone.telemetry().position, engine.now()
    until(lambda: engine.now() > start + 4)  # 4 s of paused flight
    assert math.dist(held, engine.drone.telemetry().position) < 0.3 and module.steps == ["took off", "yes"]

    assert ctl("resume")["ok"]
    until(lambda: "arrived" in module.steps)  # the mission went on from where it was
    assert engine.drone.telemetry().position[0] == pytest.approx(10, abs=0.5)
    until(lambda: engine.context.operator.pending_questions())  # the mission waits for its second answer
    abort = ctl("abort")
    assert abort["ok"] and "landing" in abort["message"]
    until(lambda: engine.drone.telemetry().landed_state is LandedState.ON_GROUND)
    assert "second point" not in module.steps and engine.bridge.state == "done"
    kinds = [(e.data["command"], e.data["origin"]) for e in engine.log.events(kind="operator_command")]
    assert kinds == [("answer", "ctl"), ("pause", "ctl"), ("resume", "ctl"), ("abort", "ctl")]


def test_a_wrong_token_is_refused_and_the_server_stops_with_the_engine(run):
    engine, server, folder = run
    port, token = read_control_file(folder)
    engine.start()
    refused = send_command(port, "0" * len(token), "abort")
    assert not refused["ok"] and "wrong token" in refused["error"]
    assert not engine.log.events(kind="operator_command")
    with socket.create_connection(("127.0.0.1", port), timeout=5) as connection:  # not JSON
        connection.sendall(b"pause\n")
        assert b"bad request" in connection.makefile("rb").readline()
    assert send_command(port, token, "status")["ok"]
    began = time.monotonic()
    engine.stop()
    until(lambda: server.closed, 5)
    assert time.monotonic() - began < 5 and not (folder / CONTROL_FILE).exists()
    with pytest.raises(OSError):
        send_command(port, token, "status", timeout=2)


def test_a_wrong_or_missing_token_learns_nothing_of_the_run(tmp_path, capsys):
    from aeroexec.cli.main import main

    folder = tmp_path / "secret-survey-run"
    with ControlServer(None, folder, name="secret_survey.plan", register=False) as server:
        requests = [b'{"token": "0123", "command": "status"}\n', b'{"command": "status"}\n',
                    b'{"token": null, "command": "abort"}\n']
        for request in requests:
            with socket.create_connection(("127.0.0.1", server.port), timeout=WAIT) as connection:
                connection.sendall(request)
                said = connection.makefile("rb").readline()
            assert said == b'{"ok": false, "error": "wrong token"}\n'
        for secret in (b"secret", str(os.getpid()).encode(), str(tmp_path).encode()):  # a bad request neither
            with socket.create_connection(("127.0.0.1", server.port), timeout=WAIT) as connection:
                connection.sendall(b"status\n")
                assert secret not in connection.makefile("rb").readline()
        assert main(["ctl", "--port", str(server.port), "--token", "nope", "status"]) == 1
        assert capsys.readouterr().err == "refused: wrong token\n"
        answer = send_command(server.port, server.token, "status")  # the token's holder is told which run it is
        assert answer["run"] == {"mission": "secret_survey.plan", "pid": os.getpid(), "folder": str(folder.resolve())}


def test_bad_updates_are_answered_and_the_connection_stays_usable(run):
    engine, server, folder = run
    port, token = read_control_file(folder)
    engine.start()
    updates = ["INSERT \u00b2 LAND", "INSERT " + "9" * 5000 + " LAND", "INSERT", "JUMP_TO \u0661"]
    with socket.create_connection(("127.0.0.1", port), timeout=WAIT) as connection:
        reader = connection.makefile("rb")
        answers = []
        for update in [*updates, None]:
            request = {"token": token, "command": "update", "argument": update} if update else \
                {"token": token, "command": "status"}
            connection.sendall((json.dumps(request) + "\n").encode())
            answers.append(json.loads(reader.readline()))
    assert [a["ok"] for a in answers] == [False, False, False, False, True], answers
    assert answers[0]["error"].startswith("update INSERT: '\u00b2' is not an item id")
    assert answers[1]["error"].startswith("update INSERT: '999999999999999999999999'... (5000 characters) is not an "
                                          "item id")
    assert answers[2]["error"].startswith("update INSERT: the fragment to insert is missing")
    assert answers[3]["error"].startswith("update JUMP_TO: '\u0661' is not an item id")
    assert answers[4]["status"]["state"] == "running"


def test_a_command_the_engine_cannot_run_says_so(tmp_path, monkeypatch):
    monkeypatch.setattr("aeroexec.flight.control.COMMAND_TIMEOUT", 0.3)
    world = default_world()
    engine = Engine(SimulatedDrone(world), obstacles=world)  # never ticked
    with ControlServer(engine, tmp_path) as server:
        answer = send_command(server.port, server.token, "pause")
        assert not answer["ok"] and "not ticking" in answer["error"]
    engine.stop()


def test_aeroexec_ctl_commands_a_run(tmp_path):
    out = tmp_path / "out"
    command = [sys.executable, "-m", "aeroexec.cli.main"]
    flying = subprocess.Popen([*command, "run", str(ROOT / "missions" / "square_patrol.py"), "--speed", "2",
                               "--output", str(out), "--plain"], cwd=ROOT, stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True)
    try:
        until(lambda: (out / CONTROL_FILE).exists())

        def ctl(*args: str) -> subprocess.CompletedProcess:
            return subprocess.run([*command, "ctl", *args], cwd=ROOT, capture_output=True, text=True, timeout=60)

        until(lambda: "running at t=" in ctl("--run", str(out), "status").stdout)  # listed while it starts
        status = ctl("--run", str(out), "status")
        assert status.returncode == 0 and "running at t=" in status.stdout, status.stderr
        wrong = ctl("--port", str(read_control_file(out)[0]), "--token", "nope", "pause")
        assert wrong.returncode == 1 and wrong.stderr == "refused: wrong token\n"  # nothing of the run
        until(lambda: "GO_TO_POINT" in (out / "events.jsonl").read_text())  # flying
        aborted = ctl("--run", str(out), "abort")
        assert aborted.returncode == 0 and "mission aborted" in aborted.stdout
        stdout, stderr = flying.communicate(timeout=120)
    finally:
        if flying.poll() is None:
            flying.kill()
            flying.communicate()
    assert flying.returncode == 4 and "square_patrol.py: aborted at" in stderr
    assert "operator_command: abort" in stdout and "GOAL_ACHIEVED LAND" in stdout
    assert not (out / CONTROL_FILE).exists()


# -- the live view -----------------------------------------------------------------------------------------
def rendered(view: LiveView) -> str:
    console = Console(record=True, width=140, file=io.StringIO())
    view.refresh()
    console.print(view.render())
    return console.export_text()


def test_the_live_view_shows_the_mission_line_behaviors_beliefs_events_and_drone(tmp_path):
    module = load_mission(tmp_path)
    world = default_world()
    engine = Engine(SimulatedDrone(world), obstacles=world, operator=RemoteOperator())
    try:
        view = LiveView(engine, "ctl_mission.py", mission_file=tmp_path / "ctl_mission.py")
        engine.start_mission(module.mission, "ctl_mission")
        assert engine.run_until(lambda: engine.coordinator.is_active("TAKE_OFF"), 10)
        engine.step(1.0)
        engine.memory.add("visible(marker_7)")
        text = rendered(view)
        for section in ("mission", "active behaviors", "beliefs", "events", "drone", "battery", "RUNNING"):
            assert section in text
        assert "ctl_mission.py:8" in text and 'api.execute_behavior("TAKE_OFF"' in text  # the current line
        assert "TAKE_OFF" in text and "deliberative" in text and "visible(marker_7)" in text
        assert "activated TAKE_OFF" in text
        assert engine.run_until(lambda: engine.context.operator.pending_questions(), 30)
        assert "the drone asks: Fly east?" in rendered(view)
        engine.supervisor.execute("pause")
        assert "PAUSED" in rendered(view)
        view.stop()
    finally:
        engine.stop()


def test_the_live_view_shows_a_tree_with_node_statuses():
    world = default_world()
    engine = Engine(SimulatedDrone(world), obstacles=world)
    try:
        root = TreeNode("Sequence", "", {}, [TreeNode("TAKE_OFF", "", {}, [], "m.xml", 2),
                                             TreeNode("LAND", "", {}, [], "m.xml", 3)], "m.xml", 1)
        tree = TreeMission(TreeDocument({"Main": root}, "Main", "m.xml"), engine)
        view = LiveView(engine, "m.xml")
        tree.start()
        engine.step(1.0)
        text = rendered(view)
        assert "[RUNNING] Sequence" in text and "[RUNNING] TAKE_OFF" in text and "[IDLE] LAND" in text
    finally:
        engine.stop()


def test_keys_become_commands():
    submitted = []

    class Supervisor:
        def submit(self, command: str, argument: str, origin: str):
            submitted.append((command, argument, origin))

            class Ticket:
                def wait(self, timeout: float):
                    return None

            return Ticket()

    keys = KeyReader(Supervisor(), stream=io.StringIO())
    assert keys.start() is keys  # not a terminal: no reader thread
    for key in "pri" + "keep_hoverx\x7fing\r" + "t" + "yes\x1b" + "t2\n" + "q":
        keys.press(key)
    keys.stop()
    assert submitted == [("pause", "", "keyboard"), ("resume", "", "keyboard"),
                         ("inhibit", "keep_hovering", "keyboard"), ("answer", "2", "keyboard"),
                         ("abort", "", "keyboard")]



TAKE_OFF_MISSION = '''
from aeroexec.engine import api

steps = []


def mission():
    steps.append(api.execute_behavior("TAKE_OFF", altitude=12))
    steps.append(api.execute_behavior("GO_TO_POINT", coordinates=(2, 0, 12)))
'''


def test_pause_during_take_off_then_resume_climbs_on_and_the_mission_goes_on(tmp_path):
    """Issue 18, point 1: as PX4's Hold then Resume, a take-off paused half-way continues to its altitude."""

    world = default_world()  # paced at 4x: the pause lands mid-climb even on a loaded machine
    engine = Engine(SimulatedDrone(world), obstacles=world, clock=SimulatedClock(speed=4))
    folder = tmp_path / "out"
    server = ControlServer(engine, folder).start()
    try:
        climb_pause_resume(engine, folder, tmp_path)
    finally:
        server.close()
        engine.stop()


def climb_pause_resume(engine, folder, tmp_path):
    from aeroexec.flight.run_status import COMPLETED, run_status

    path = tmp_path / "take_off_mission.py"
    path.write_text(TAKE_OFF_MISSION)
    spec = importlib.util.spec_from_file_location("take_off_mission", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    port, token = read_control_file(folder)
    engine.start_mission(module.mission, "take_off_mission")
    engine.start()
    until(lambda: engine.drone.telemetry().altitude > 2.0)
    assert send_command(port, token, "pause")["ok"]
    until(lambda: engine.drone.telemetry().speed < 0.1)
    held, start = engine.drone.telemetry().altitude, engine.now()
    until(lambda: engine.now() > start + 3)  # 3 s of paused flight: the climb has stopped
    assert held < 10 and abs(engine.drone.telemetry().altitude - held) < 0.3 and module.steps == []

    resumed = send_command(port, token, "resume")
    assert resumed["ok"] and "requested again: TAKE_OFF" in resumed["message"], resumed
    until(lambda: engine.bridge.state == "done")
    assert module.steps == [Outcome.GOAL_ACHIEVED] * 2
    assert engine.drone.telemetry().altitude == pytest.approx(12, abs=0.4)
    take_off_end = engine.log.events(kind="GOAL_ACHIEVED", behavior="TAKE_OFF")[0].time
    assert take_off_end > start + 3 and engine.log.events(kind="GOAL_ACHIEVED", behavior="GO_TO_POINT")
    assert not engine.log.events(kind="failed_preconditions", behavior="TAKE_OFF")
    assert run_status(engine.log.events()).word == COMPLETED
    activations = engine.log.events(kind="activated", behavior="TAKE_OFF")
    assert len(activations) == 2  # the paused request and the resumed one, not a second take-off



def test_ctl_from_another_directory_finds_the_live_run(tmp_path, private_runtime_dir):
    """Issue 18, point 6: runs list themselves in the per-user runtime directory, so ``aeroexec ctl`` needs no
    --run wherever it is started; the entry goes away with the run."""
    here, elsewhere = tmp_path / "here", tmp_path / "elsewhere"
    here.mkdir()
    elsewhere.mkdir()
    command = [sys.executable, "-m", "aeroexec"]
    flying = subprocess.Popen([*command, "run", str(ROOT / "missions" / "square_patrol.py"), "--speed", "1",
                               "--plain"], cwd=here, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        until(lambda: list(private_runtime_dir.glob("aeroexec/run-*.json")))

        def ctl(*args: str) -> subprocess.CompletedProcess:
            return subprocess.run([*command, "ctl", *args], cwd=elsewhere, capture_output=True, text=True,
                                  timeout=60)

        listed = ctl("list")
        assert listed.returncode == 0 and "square_patrol.py" in listed.stdout
        assert str(here / "aeroexec_output") in listed.stdout and f"pid {flying.pid}" in listed.stdout
        def running() -> subprocess.CompletedProcess | None:  # a run lists itself while it is still starting
            status = ctl("status")
            assert status.returncode == 0, status.stderr
            assert "running at t=" in status.stdout or "the run is " in status.stdout, status.stdout  # its stage
            return status if "running at t=" in status.stdout else None

        until(running, timeout=60)
        by_pid = ctl("--run", str(flying.pid), "status")
        assert by_pid.returncode == 0 and "at t=" in by_pid.stdout
        assert ctl("abort").returncode == 0
        flying.communicate(timeout=120)
    finally:
        if flying.poll() is None:
            flying.kill()
            flying.communicate()
    assert flying.returncode == 4
    assert not list(private_runtime_dir.glob("aeroexec/run-*.json"))
    gone = subprocess.run([*command, "ctl", "status"], cwd=elsewhere, capture_output=True, text=True, timeout=60)
    assert gone.returncode == 1 and "no live run" in gone.stderr


@pytest.mark.parametrize("tmpdir", ["writable", "missing", "read-only", ""])
def test_without_a_runtime_directory_runs_are_listed_where_tempfile_puts_temporary_files(tmp_path, tmpdir):
    """Without ``$XDG_RUNTIME_DIR`` the live runs are listed in ``<tmp>/aeroexec-<uid>``: the folder
    :func:`tempfile.gettempdir` answers (``$TMPDIR`` when a file can be written there, else /tmp...), found without
    importing :mod:`tempfile` (a run's start does not need it)."""
    folder = tmp_path / "tmp"
    if tmpdir != "missing":
        folder.mkdir()
    if tmpdir == "read-only":
        folder.chmod(0o500)
    env = {k: v for k, v in os.environ.items() if k not in ("XDG_RUNTIME_DIR", "TMPDIR", "TEMP", "TMP")}
    if tmpdir:
        env["TMPDIR"] = str(folder)
    code = ("import sys\nfrom aeroexec.flight.control import runtime_dir\nfound = runtime_dir()\n"
            "imported = 'tempfile' in sys.modules\nimport os, tempfile\n"
            "print(found == __import__('pathlib').Path(tempfile.gettempdir()) / f'aeroexec-{os.getuid()}', imported)")
    shown = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True).stdout
    assert shown.split() == ["True", "False"]
