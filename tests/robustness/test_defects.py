"""The defects of issue 23, one regression file each in ``data/``: every one ends as one clear message naming the
file and line, exit status 1, never a traceback or a hang; an internal error exits 70 asking to report it."""

from __future__ import annotations

import io
import json
import logging
import os
import re
import shutil
import socket
import subprocess
import sys
import threading
from pathlib import Path

import pytest
from aeroexec.beliefs import BeliefMemory, BeliefSyntaxError, parse_expression
from aeroexec.cli import main as cli_main
from aeroexec.cli.main import INTERNAL_ERROR, main
from aeroexec.drones.sim import SimulatedDrone, default_world
from aeroexec.engine.engine import Engine
from aeroexec.flight.control import CONTROL_FILE, MAX_LINE, ControlServer

from aeroexec.limits import MAX_NESTING, MAX_TERM_DEPTH

DATA = Path(__file__).with_name("data")
ROOT = Path(__file__).parents[2]
MISSION = str(ROOT / "missions" / "inspection.py")


def aeroexec(capsys, *argv: str) -> tuple[int, str]:
    """Run the command in this process; its status and everything it printed."""
    status = main(list(argv))
    out = capsys.readouterr()
    return status, out.out + out.err


# (file in data/, command before the file, command after it, the line named, words of the message)
CASES = [
    ("d1_control_char_tree.yaml", ["verify"], [], 1, "control character #x0007"),
    ("d1_control_char_aerostack.yaml", ["verify"], [], 5, "control character #x000b"),
    ("d1_control_char_world.yaml", ["run", "--plain", "--world"], [MISSION], 4, "control character #x0000"),
    ("d1_control_char_catalog.yaml", ["catalog", "--check"], [], 4, "control character #x001b"),
    ("d2_deep_tree.yaml", ["verify"], [], 1, f"nested more than {MAX_NESTING} levels deep"),
    ("d2_deep_world.yaml", ["run", "--plain", "--world"], [MISSION], 1, f"nested more than {MAX_NESTING} levels"),
    ("d2_deep_catalog.yaml", ["catalog", "--check"], [], 1, f"nested more than {MAX_NESTING} levels deep"),
    ("d3_deep_inverters.xml", ["verify"], [], 3, f"<Inverter> is nested more than {MAX_NESTING} elements deep"),
    ("d3_deep_tasks.tml.xml", ["verify"], [], 3, f"<task> is nested more than {MAX_NESTING} elements deep"),
    ("d4_long_expression.py", ["verify"], [], 5, "nested too deeply to read"),
    ("d4_unary_minus.py", ["verify"], [], 5, "nested too deeply to read"),
    ("d5_huge_port.xml", ["verify"], [], 4, "WRONG_VALUE: The value 9999"),
    ("d5_huge_port.yaml", ["verify"], [], 4, "a number of 309 characters is longer than the limit"),
    ("d5_huge_port.tml.xml", ["verify"], [], 5, "WRONG_VALUE: The value 9999"),
    ("d6_huge_altitude.py", ["verify"], [], 5, "WRONG_VALUE: The value 9999"),
    ("d7_deep_negation.xml", ["verify"], [], 5, f"nested more than {MAX_TERM_DEPTH} levels deep at column"),
    ("d8_null_children.yaml", ["verify"], [], 2, "The node Sequence must have at least 1 child, not 0"),
    ("d9_huge_number.yaml", ["run", "--plain", "--world"], [MISSION], 2, "a number of 400 characters"),
    ("d10_huge_timeout.yaml", ["catalog", "--check"], [], 4, "a number of 400 characters"),
    ("d10_huge_timeout.yaml", ["catalog", "--catalog"], [], 4, "a number of 400 characters"),
    ("d10_infinite_range.yaml", ["catalog", "--check"], [], 7, "must be a finite number, not '-.inf'"),
    ("d10_infinite_range.yaml", ["verify", MISSION, "--catalog"], [], 7, "must be a finite number, not '-.inf'"),
    ("not_utf8.xml", ["verify"], [], 3, "not well-formed"),
    ("not_utf8.tml.xml", ["verify"], [], 3, "not well-formed"),
    ("not_utf8.yaml", ["verify"], [], 4, "not UTF-8 text: byte 0xff at column 23"),
    ("not_utf8.py", ["verify"], [], 5, "not UTF-8 text: byte 0xff"),
    ("not_utf8_world.yaml", ["run", "--plain", "--world"], [MISSION], 4, "not UTF-8 text: byte 0xff at column 3"),
    ("not_utf8_catalog.yaml", ["catalog", "--check"], [], 4, "not UTF-8 text: byte 0xff"),
]


@pytest.mark.parametrize(("name", "before", "after", "line", "words"), CASES,
                         ids=[f"{c[0]}-{c[1][0]}" for c in CASES])
def test_each_defect_is_one_clear_error_with_its_line(capsys, tmp_path, monkeypatch, name, before, after, line, words):
    monkeypatch.chdir(tmp_path)  # a run that got as far as flying would write its output here
    status, printed = aeroexec(capsys, *before, str(DATA / name), *after)
    assert status == 1, printed
    assert "Traceback" not in printed and "Error:" not in printed.split(words)[0][-40:]
    assert re.search(rf"{re.escape(name)}:{line}(:\d+)?: .*{re.escape(words)}", printed), printed


def test_an_include_of_a_fifo_is_refused_without_reading_it(capsys, tmp_path):
    mission = tmp_path / "d11_include_fifo.xml"
    shutil.copy(DATA / mission.name, mission)
    os.mkfifo(tmp_path / "pipe.xml")  # opening it for reading would block until a writer came: it must not be opened
    status, printed = aeroexec(capsys, "verify", str(mission))
    assert status == 1
    assert f"{mission}:2: error: cannot read the included file {tmp_path / 'pipe.xml'}: not a regular file: it is " \
           "a FIFO (named pipe), refused before reading" in printed


def test_a_fifo_or_a_directory_given_as_the_mission_is_refused(capsys, tmp_path):
    os.mkfifo(tmp_path / "pipe.yaml")
    status, printed = aeroexec(capsys, "verify", str(tmp_path / "pipe.yaml"))
    assert status == 1 and "it is a FIFO (named pipe), refused before reading" in printed
    (tmp_path / "folder.py").mkdir()
    status, printed = aeroexec(capsys, "verify", str(tmp_path / "folder.py"))
    assert status == 1 and "it is a directory" in printed


def test_deep_belief_terms_are_refused_by_the_parser_before_the_memory_sees_them():
    memory = BeliefMemory()
    deep = "p(" + "f(" * 400 + "x" + ")" * 400 + ")"
    with pytest.raises(BeliefSyntaxError, match=f"nested more than {MAX_TERM_DEPTH} levels deep at column"):
        memory.add(deep)
    with pytest.raises(BeliefSyntaxError, match="nested more than"):
        memory.query_all("p(" + "[" * 400 + "?X" + "]" * 400 + ")")
    at_limit = "p(" + "f(" * (MAX_TERM_DEPTH - 2) + "x" + ")" * (MAX_TERM_DEPTH - 2) + ")"
    memory.add(at_limit)
    assert memory.query_all("p(?X)") and parse_expression(at_limit)


def test_a_deep_json_line_on_the_control_socket_is_refused_with_a_reason(tmp_path, capfd):
    world = default_world()
    engine = Engine(SimulatedDrone(world), obstacles=world)
    with ControlServer(engine, tmp_path) as server, socket.create_connection(("127.0.0.1", server.port), 10) as conn:
        conn.sendall(b"[" * min(60_000, MAX_LINE - 10) + b"\n")
        answer = json.loads(conn.makefile("rb").readline())
    engine.stop()
    assert not answer["ok"] and f"nested more than {MAX_NESTING} levels deep" in answer["error"]
    assert "Traceback" not in capfd.readouterr().err


def test_a_stale_control_file_names_its_port_and_the_run_that_is_gone(tmp_path, capsys):
    finished = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    with socket.socket() as probe:  # a port nothing listens on any more
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    (tmp_path / CONTROL_FILE).write_text(json.dumps({"host": "127.0.0.1", "port": port, "token": "t",
                                                     "pid": int(finished.stdout)}))
    status, printed = aeroexec(capsys, "ctl", "--run", str(tmp_path), "status")
    assert status == 1
    assert f"cannot reach the run on port {port}" in printed
    assert f"process {int(finished.stdout)}, is no longer running" in printed
    assert str(tmp_path / CONTROL_FILE) in printed


def test_an_internal_error_exits_70_with_one_line_asking_to_report_it(capsys, monkeypatch):
    def broken(args):
        raise KeyError("a bug")

    monkeypatch.setattr("aeroexec.cli.verify.run", broken)
    status, printed = aeroexec(capsys, "verify", MISSION)
    assert status == INTERNAL_ERROR == 70
    assert printed.count("\n") == 1 and "internal error (KeyError: 'a bug')" in printed and "please report" in printed
    assert "Traceback" not in printed


def test_a_refused_mission_exits_1_and_a_usage_error_2(capsys):
    assert aeroexec(capsys, "verify", str(DATA / "d8_null_children.yaml"))[0] == 1
    with pytest.raises(SystemExit) as usage:
        main(["verify", "--no-such-option"])
    assert usage.value.code == 2
    assert cli_main.REFUSED == 1 and cli_main.USAGE == 2


def test_a_failure_in_a_background_task_is_one_log_line_without_a_traceback():
    stream = io.StringIO()
    handler = logging.StreamHandler(stream)
    handler.setFormatter(cli_main.OneLineFormatter("%(levelname)s %(name)s: %(message)s"))
    log = logging.getLogger("aeroexec.test.background")
    log.addHandler(handler)
    try:
        try:
            raise ZeroDivisionError("division by zero")
        except ZeroDivisionError:
            log.exception("a tick callback failed")
    finally:
        log.removeHandler(handler)
    assert stream.getvalue() == ("ERROR aeroexec.test.background: a tick callback failed (ZeroDivisionError: "
                                 "division by zero; -v shows the traceback)\n")


def test_a_thread_that_dies_logs_one_line_asking_to_report_it(capsys, caplog, monkeypatch):
    monkeypatch.setattr(threading, "excepthook", threading.excepthook)  # main() installs its own: undone after
    aeroexec(capsys, "verify", str(DATA / "d8_null_children.yaml"))

    def task():
        raise RuntimeError("the camera is gone")

    thread = threading.Thread(target=task, name="aeroexec-background")
    thread.start()
    thread.join()
    assert "Traceback" not in capsys.readouterr().err
    assert [r.getMessage() for r in caplog.records if r.levelno == logging.ERROR] == [
        "aeroexec: internal error in the thread aeroexec-background (RuntimeError: the camera is gone); this is a "
        "bug in aeroexec, not in your input: please report it with the command you ran (-v shows the traceback)"]
