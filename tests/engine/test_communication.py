"""Communication behaviors: the operator is notified, asked (scripted, logged, at a console) and shown images;
the robot speaks (with or without a text-to-speech engine); drones of one run exchange broadcasts."""

import logging
import os
import shutil
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest
from aeroexec.drones.sim import SimulatedDrone, default_world
from aeroexec.engine.behaviors.communication import describe_tasks
from aeroexec.engine.engine import Engine
from aeroexec.engine.events import Outcome
from aeroexec.engine.supervision.operator import (
    ConsoleOperator,
    LoggingOperator,
    OperatorError,
    ScriptedOperator,
    make_operator,
)
from message_bus import MessageBus
from patience import hang_guard

ROOT = Path(__file__).parents[2]
PNG = b"\x89PNG\r\n\x1a\nfake camera frame"


def make_engine(operator=None, **options):
    world = default_world()
    return Engine(SimulatedDrone(world), obstacles=world, operator=operator, **options)


@pytest.fixture
def engines():
    made = []

    def build(operator=None, **options):
        engine = make_engine(operator, **options)
        made.append(engine)
        return engine

    yield build
    for engine in made:
        engine.stop()


def run(engine, name, arguments=None, within=10.0, **options):
    """Activate ``name`` and tick until it ends (at most ``within`` s); returns (outcome, result)."""
    ended = []
    result = engine.coordinator.activate(name, arguments or {}, on_end=lambda o, m, r: ended.append((o, r)),
                                         **options)
    assert result.accepted, result.message
    engine.run_until(lambda: bool(ended), within)
    assert ended, f"{name} did not end in {within} s"
    return ended[0]


def operator_events(engine, action=None):
    return [e for e in engine.log.events("operator") if action is None or e.data.get("action") == action]


def hover(engine, point=(0.0, 0.0, 2.0), yaw=0.0):
    engine.drone.takeoff(2.0)
    engine.run_until(lambda: engine.memory.holds("flight_state(self, hovering)"), 30)
    engine.drone.goto(point, yaw=yaw)
    engine.run_until(lambda: engine.drone.telemetry().speed < 0.05
                     and abs(engine.drone.telemetry().yaw - yaw) < 1.0, 30)


# -- the operator ------------------------------------------------------------------------------------------
def test_notify_operator_delivers_the_message_and_records_it(engines):
    operator = LoggingOperator()
    engine = engines(operator)
    assert run(engine, "NOTIFY_OPERATOR", {"MESSAGE": "marker 3 found"})[0] is Outcome.GOAL_ACHIEVED
    assert operator.notifications == ["marker 3 found"]
    event = operator_events(engine, "notify")[0]
    assert event.behavior == "NOTIFY_OPERATOR" and event.detail == "marker 3 found"


def test_without_an_operator_channel_messages_are_only_logged(engines):
    engine = engines(None)
    assert run(engine, "NOTIFY_OPERATOR", {"MESSAGE": "hello"})[0] is Outcome.GOAL_ACHIEVED
    outcome, answer = run(engine, "ASK_OPERATOR", {"QUESTION": "Go on?", "POSSIBLE_ANSWERS": ("yes", "no")})
    assert (outcome, answer) == (Outcome.GOAL_ACHIEVED, "yes")


def test_ask_operator_from_a_scripted_answers_file(engines, tmp_path):
    answers = tmp_path / "answers.yaml"
    answers.write_text("Which side first?: Left\nLand now?: no\n")
    engine = engines(ScriptedOperator.from_file(answers))
    outcome, answer = run(engine, "ASK_OPERATOR", {"QUESTION": "Which side first?",
                                                   "POSSIBLE_ANSWERS": ("left", "right")})
    assert (outcome, answer) == (Outcome.GOAL_ACHIEVED, "left")  # as the possible answers spell it
    assert engine.memory.query('answer("Which side first?", ?A)') == {"?A": "left"}
    assert run(engine, "ASK_OPERATOR", {"QUESTION": "Land now?", "POSSIBLE_ANSWERS": ("yes", "no")})[1] == "no"
    assert engine.memory.holds('answer("Land now?", no)')  # YAML's boolean no is the answer no
    asked = operator_events(engine, "ask")
    assert [e.detail for e in asked] == ["Which side first?", "Land now?"] and asked[0].data["answers"] == \
        ["left", "right"]


def test_an_unknown_question_gets_the_first_possible_answer_and_a_warning(engines, caplog):
    engine = engines(ScriptedOperator({"Something else?": "no"}))
    with caplog.at_level(logging.WARNING, logger="aeroexec.engine.supervision.operator"):
        outcome, answer = run(engine, "ASK_OPERATOR", {"QUESTION": "Continue?", "POSSIBLE_ANSWERS": ("yes", "no")})
    assert (outcome, answer) == (Outcome.GOAL_ACHIEVED, "yes")
    assert "does not answer 'Continue?'" in caplog.text
    assert "not in the answers file" in operator_events(engine, "answer")[0].data["note"]


def test_a_wrong_answer_is_refused_and_the_question_asked_again(engines):
    operator = ScriptedOperator(["maybe", " No "])  # answers in order
    engine = engines(operator)
    outcome, answer = run(engine, "ASK_OPERATOR", {"QUESTION": "Land?", "POSSIBLE_ANSWERS": ("yes", "no")})
    assert (outcome, answer) == (Outcome.GOAL_ACHIEVED, "no")
    assert [e.data["attempt"] for e in operator_events(engine, "ask")] == [1, 2]
    assert operator_events(engine, "wrong_answer")[0].data["answer"] == "maybe"


def test_wrong_answers_every_time_fail_the_behavior(engines):
    engine = engines(ScriptedOperator({"Land?": "perhaps"}))
    assert run(engine, "ASK_OPERATOR", {"QUESTION": "Land?", "POSSIBLE_ANSWERS": ("yes", "no")})[0] is \
        Outcome.WRONG_PROGRESS
    assert len(operator_events(engine, "ask")) == 3
    assert "outside the possible answers" in engine.log.events("WRONG_PROGRESS")[0].detail
    assert not engine.memory.holds("answer(?Q, ?A)")


def test_any_answer_goes_without_possible_answers(engines):
    engine = engines(LoggingOperator(default="north tower"))
    assert run(engine, "ASK_OPERATOR", {"QUESTION": "Where?"})[1] == "north tower"


def test_answers_files_and_their_errors(tmp_path):
    wrapped = tmp_path / "wrapped.yaml"
    wrapped.write_text("answers: [yes, left]\nvoice_command: land now\n")
    operator = ScriptedOperator.from_file(wrapped)
    assert operator.voice_command == operator.last_voice_command == "land now"
    assert [operator.ask("a?").value, operator.ask("b?").value, operator.ask("c?", ["x", "y"]).value] == \
        ["yes", "left", "x"]
    for text, message in (("just text", "a mapping question -> answer or a list"),
                          ("a: [b", "not valid YAML")):
        bad = tmp_path / "bad.yaml"
        bad.write_text(text)
        with pytest.raises(OperatorError, match=message):
            make_operator(bad)
    with pytest.raises(OperatorError, match="cannot read"):
        make_operator(tmp_path / "missing.yaml")
    assert isinstance(make_operator(None, interactive=False), LoggingOperator)
    terminal = make_operator(None, interactive=True)
    assert isinstance(terminal, ConsoleOperator)
    terminal.close()


# -- the console operator --------------------------------------------------------------------------------------
@pytest.fixture
def console():
    read, write = os.pipe()
    stdin, typing = os.fdopen(read, "r"), os.fdopen(write, "w")
    output = open(os.devnull, "w")  # noqa: SIM115 - closed below
    operator = ConsoleOperator(stdin, output)
    yield operator, typing
    operator.close()
    typing.close()  # the reader thread sees the end of its input and finishes
    operator._reader.join(timeout=2.0)
    assert not operator._reader.is_alive()
    stdin.close()
    output.close()


def tick_until(engine, condition, wall=3.0):
    """Tick while a thread of this process works: bounded in wall time."""
    deadline = time.monotonic() + hang_guard(wall)
    while not condition() and time.monotonic() < deadline:
        engine.step(0.05)
        time.sleep(0.005)
    return condition()


def test_the_console_operator_never_blocks_the_tick(engines, console):
    operator, typing = console
    engine = engines(operator)
    ended = []
    engine.coordinator.activate("ASK_OPERATOR", {"QUESTION": "Land?", "POSSIBLE_ANSWERS": ("yes", "no")},
                                on_end=lambda o, m, r: ended.append((o, r)))
    started = time.monotonic()
    engine.step(2.0)  # 40 ticks with nobody typing
    assert time.monotonic() - started < 2.0 and not ended
    typing.write("2\n")  # the second possible answer, by its number
    typing.flush()
    assert tick_until(engine, lambda: bool(ended))
    assert ended == [(Outcome.GOAL_ACHIEVED, "no")] and engine.memory.holds("answer(\"Land?\", no)")
    assert operator_events(engine, "answer")[0].data["note"] == "typed by the operator"


def test_the_console_hears_voice_commands_and_wrong_answers(engines, console):
    operator, typing = console
    engine = engines(operator)
    typing.write("take off\n")  # nothing asked: a voice command
    typing.flush()
    assert tick_until(engine, lambda: operator.voice_command == "take off")
    ended = []
    engine.coordinator.activate("ASK_OPERATOR", {"QUESTION": "Land?", "POSSIBLE_ANSWERS": ("yes", "no")},
                                on_end=lambda o, m, r: ended.append((o, r)))
    typing.write("later\n")
    typing.flush()
    assert tick_until(engine, lambda: bool(operator_events(engine, "wrong_answer")))
    typing.write("1\n")  # asked again: now the first possible answer
    typing.flush()
    assert tick_until(engine, lambda: bool(ended))
    assert ended == [(Outcome.GOAL_ACHIEVED, "yes")]
    assert [e.data["attempt"] for e in operator_events(engine, "ask")] == [1, 2]
    assert operator.voice_command == "take off"  # answers are not voice commands


def test_a_question_nobody_answers_times_out_and_is_withdrawn(engines, console):
    operator, _ = console
    engine = engines(operator)
    outcome, _ = run(engine, "ASK_OPERATOR", {"QUESTION": "Hello?"}, within=10, timeout=3.0)
    assert outcome is Outcome.TIME_OUT
    assert len(operator._waiting) == 1 and operator._waiting[0].cancelled  # a later line answers nothing


def test_when_the_console_input_ends_questions_get_the_first_answer(engines, console):
    operator, typing = console
    typing.close()
    operator._reader.join(timeout=2.0)
    engine = engines(operator)
    assert run(engine, "ASK_OPERATOR", {"QUESTION": "Land?", "POSSIBLE_ANSWERS": ("yes", "no")})[1] == "yes"


# -- images ------------------------------------------------------------------------------------------------------
def test_ask_for_object_image_selects_the_nearest_object_in_view(engines, tmp_path):
    operator = LoggingOperator()
    engine = engines(operator, output_dir=tmp_path / "run")
    hover(engine)  # facing east: the red box at (4, 2) on the ground
    engine.drone.capture_image = lambda: PNG
    nearest = min(engine.drone.observations(), key=lambda o: o.distance).name
    outcome, selected = run(engine, "ASK_FOR_OBJECT_IMAGE")
    assert (outcome, selected) == (Outcome.GOAL_ACHIEVED, nearest)
    reference = engine.memory.query(f"image({nearest}, ?R)")["?R"]
    assert Path(reference).read_bytes() == PNG and Path(reference).parent == tmp_path / "run"
    assert operator.last_image == PNG  # the operator was shown the image to select in
    assert operator_events(engine, "image_selected")[0].data["object"] == nearest


def test_ask_for_object_image_without_images_or_objects(engines):
    engine = engines(LoggingOperator())
    engine.drone.capture_image = lambda: None  # a drone that gives no images
    hover(engine, yaw=90)  # facing north: nothing in view
    outcome, _ = run(engine, "ASK_FOR_OBJECT_IMAGE", within=10, timeout=2.0)
    assert outcome is Outcome.TIME_OUT
    assert operator_events(engine, "request_image")[0].detail.startswith("nothing in view")
    engine.drone.goto((0.0, 0.0, 2.0), yaw=0.0)  # turn to the red box; the drone gives no images
    engine.run_until(lambda: abs(engine.drone.telemetry().yaw) < 1.0, 30)
    outcome, selected = run(engine, "ASK_FOR_OBJECT_IMAGE")
    assert outcome is Outcome.GOAL_ACHIEVED
    assert engine.memory.query(f"image({selected}, ?R)")["?R"].startswith("camera:")


def test_display_camera_image_at_a_modest_rate_and_without_images(engines):
    operator = LoggingOperator()
    engine = engines(operator)
    engine.drone.capture_image = lambda: None  # a drone that gives no images
    assert engine.coordinator.activate("DISPLAY_CAMERA_IMAGE").accepted
    engine.step(2.0)
    assert engine.coordinator.is_active("DISPLAY_CAMERA_IMAGE") and operator.images_shown == 0
    assert [e.data["available"] for e in operator_events(engine, "display")] == [False]  # said once
    engine.drone.capture_image = lambda: PNG
    engine.step(2.0)
    assert 3 <= operator.images_shown <= 5 and operator.last_image == PNG  # every 0.5 s
    assert [e.data["available"] for e in operator_events(engine, "display")] == [False, True]
    engine.coordinator.inhibit("DISPLAY_CAMERA_IMAGE")
    assert operator_events(engine, "display_stopped")[0].data["images"] == operator.images_shown


# -- speech ------------------------------------------------------------------------------------------------------
def test_say_without_a_text_to_speech_engine_is_logged(engines, monkeypatch):
    monkeypatch.setattr(shutil, "which", lambda name, *a, **k: None)
    operator = LoggingOperator()
    engine = engines(operator)
    assert run(engine, "SAY", {"SENTENCE": "Hello operator"})[0] is Outcome.GOAL_ACHIEVED
    said = operator_events(engine, "say")[0]
    assert said.detail == "Hello operator" and said.data["spoken"] is False
    assert operator.spoken == ["Hello operator"]
    assert "no text-to-speech engine" in engine.log.events("speech_synthesizer")[0].detail


@pytest.fixture
def fake_tts(tmp_path, monkeypatch):
    """An ``espeak-ng`` that writes what it is told to say to a file (and a slow one, to be killed)."""
    heard = tmp_path / "heard.txt"
    program = tmp_path / "espeak-ng"
    program.write_text(textwrap.dedent(f"""\
        #!{sys.executable}
        import sys, time
        text = sys.argv[-1]
        open({str(heard)!r}, "a").write(text + "\\n")
        if text.startswith("slow"):
            time.sleep(30)
        """))
    program.chmod(0o755)
    monkeypatch.setattr(shutil, "which", lambda name, *a, **k: str(program) if name == "espeak-ng" else None)
    return heard


def wait_for_file(path, lines, wall=5.0):
    deadline = time.monotonic() + hang_guard(wall)
    while time.monotonic() < deadline:
        if path.exists() and len(path.read_text().splitlines()) >= lines:
            return path.read_text().splitlines()
        time.sleep(0.02)
    return path.read_text().splitlines() if path.exists() else []


def test_say_speaks_with_the_local_text_to_speech_engine(engines, fake_tts):
    engine = engines(LoggingOperator())
    started = time.monotonic()
    assert run(engine, "SAY", {"SENTENCE": "-v is not an option"})[0] is Outcome.GOAL_ACHIEVED
    assert time.monotonic() - started < 1.0  # never waited on
    assert operator_events(engine, "say")[0].data["spoken"] is True
    assert wait_for_file(fake_tts, 1) == ["-v is not an option"]


def test_speech_is_killed_when_the_synthesizer_stops(engines, fake_tts):
    engine = engines(LoggingOperator())
    run(engine, "SAY", {"SENTENCE": "slow sentence"})
    synthesizer = engine.resources.processes("SPEECH_GENERATION")[0]
    assert wait_for_file(fake_tts, 1) == ["slow sentence"] and synthesizer.speaking
    process = synthesizer._current
    engine.step(3.0)  # past the capability's grace period
    assert "SPEECH_GENERATION" not in engine.resources.running()
    assert process.wait(timeout=5) != 0  # killed


def test_speak_up_says_the_active_behaviors_when_they_change(engines, monkeypatch):
    monkeypatch.setattr(shutil, "which", lambda name, *a, **k: None)
    operator = LoggingOperator()
    engine = engines(operator)
    engine.step(0.2)
    assert engine.coordinator.activate("SPEAK_UP").accepted
    engine.step(0.5)
    assert len(operator.spoken) == 1 and "wait" not in operator.spoken[0]  # what runs now, said once
    assert engine.coordinator.activate("WAIT", {"DURATION": 1.0}).accepted
    engine.step(2.0)
    spoken = operator.spoken
    assert len(spoken) == 3 and "wait" in spoken[1] and spoken[2] == spoken[0]  # WAIT started, then ended
    assert all(e.data["spoken"] is False for e in operator_events(engine, "say"))
    assert describe_tasks(["TAKE_OFF", "PAY_ATTENTION_TO_COLORS", "WAIT"]) == \
        "Now: take off, pay attention to colors and wait."
    assert describe_tasks([]) == "Nothing to do now."


# -- other drones ------------------------------------------------------------------------------------------------
def test_two_drones_on_one_bus_exchange_a_broadcast(engines):
    bus = MessageBus()
    first, second = engines(bus=bus), engines(bus=bus)
    bus.join("alpha", first.memory, first.log)
    bus.join("bravo", second.memory, second.log)
    assert run(first, "BROADCAST_MESSAGE", {"MESSAGE": "marker 3 at the tower"})[0] is Outcome.GOAL_ACHIEVED
    second.step(0.1)
    assert second.memory.holds('message(alpha, "marker 3 at the tower")')
    assert not first.memory.holds("message(?F, ?T)")  # not to itself
    received = second.log.events("message_received")[0]
    assert received.data["sender"] == "alpha" and first.log.events("message_sent")[0].data["receivers"] == ["bravo"]
    run(second, "BROADCAST_MESSAGE", {"MESSAGE": "going there"})
    run(second, "BROADCAST_MESSAGE", {"MESSAGE": "arrived"})
    assert len(first.memory.query_all("message(bravo, ?T)")) == 2  # multi-valued: both are kept


def test_engines_in_their_own_threads_get_messages_on_their_own_tick(engines):
    bus = MessageBus()
    first, second = engines(), engines()
    bus.join_engine("alpha", first)
    bus.join_engine("bravo", second)
    assert first.context.bus is bus
    run(first, "BROADCAST_MESSAGE", {"MESSAGE": "hello"})
    assert not second.memory.holds("message(alpha, hello)")  # waits in bravo's mailbox
    second.step(0.1)
    assert second.memory.holds("message(alpha, hello)")


def test_a_drone_alone_broadcasts_to_nobody(engines):
    engine = engines()
    assert run(engine, "BROADCAST_MESSAGE", {"MESSAGE": "anyone?"})[0] is Outcome.GOAL_ACHIEVED
    assert engine.log.events("message_sent")[0].data["receivers"] == []


# -- aeroexec run --answers ------------------------------------------------------------------------------------
def test_aeroexec_run_with_an_answers_file(tmp_path):
    mission = tmp_path / "ask.py"
    mission.write_text(textwrap.dedent("""\
        import aeroexec.engine.api as api

        def mission():
            side = api.ask_behavior("ASK_OPERATOR", question="Which side first?", possible_answers=["left", "right"])
            api.execute_behavior("NOTIFY_OPERATOR", message=f"starting on the {side}")
        """))
    answers = tmp_path / "answers.yaml"
    answers.write_text("Which side first?: right\n")
    result = subprocess.run([sys.executable, "-m", "aeroexec.cli.main", "run", str(mission), "--answers",
                             str(answers)], capture_output=True, text=True, timeout=60, cwd=tmp_path,
                            stdin=subprocess.DEVNULL)
    assert result.returncode == 0, result.stderr + result.stdout
    assert "operator ASK_OPERATOR: Which side first? right" in result.stdout
    assert "operator NOTIFY_OPERATOR: starting on the right" in result.stdout
    bad = subprocess.run([sys.executable, "-m", "aeroexec.cli.main", "run", str(mission), "--answers",
                          str(tmp_path / "none.yaml")], capture_output=True, text=True, timeout=60, cwd=tmp_path,
                         stdin=subprocess.DEVNULL)
    assert bad.returncode == 1 and "--answers" in bad.stderr and "cannot read" in bad.stderr


def test_nobody_there_says_no_to_a_yes_no_question_asked_again_and_nothing_else_changes():
    """A replay loop (``while confirm("Replay")``) with nobody there ends after one replay; a question without a
    "no", or a channel given a default answer, answers as before every time."""
    absent = LoggingOperator()
    replay = [absent.ask("Replay? (y/n):", ["y", "n"]) for _ in range(3)]
    assert [p.value for p in replay] == ["y", "n", "n"]
    assert replay[1].note == "no operator: asked again, 'n'"
    assert [absent.ask("Which way?", ["east", "south"]).value for _ in range(2)] == ["east", "east"]
    told = LoggingOperator(default="y")
    assert [told.ask("Replay? (y/n):", ["y", "n"]).value for _ in range(2)] == ["y", "y"]
