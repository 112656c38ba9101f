"""Rules at the `aeroexec beliefs` prompt: added, listed, asked, explained; a rules file with --rules."""

from __future__ import annotations

import io
from pathlib import Path

import pytest
from aeroexec.cli.main import main

MISSIONS = Path(__file__).resolve().parents[2] / "missions"


@pytest.fixture(scope="module")
def flight(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("flight")
    assert main(["run", str(MISSIONS / "figure10.py"), "--quiet", "--output", str(folder)]) == 0
    return folder / "events.jsonl"


def test_rules_are_added_asked_and_explained_at_the_prompt(flight, monkeypatch, capsys):
    lines = ["seen(?M) :- object(?M, marker), code(?M, ?C).",
             "low(?M) :- seen(?M), code(?M, ?C), ?C < 3.",
             "rules",
             "low(?M)",
             "why low(marker_1)",
             "why not low(marker_5)",
             "bad(?X) :- seen(?Y).",
             "quit"]
    monkeypatch.setattr("sys.stdin", io.StringIO("\n".join(lines) + "\n"))
    assert main(["beliefs", str(flight)]) == 0
    out, err = capsys.readouterr()
    assert out.count("added 1 clause") == 2
    assert "seen(?M) :- object(?M, marker), code(?M, ?C).    % <prompt>:1" in out
    assert "marker_2" in out and "low(?M): 2 answers" in out
    assert "low(marker_1)  <- the rule at <prompt>:1: low(?M) :- seen(?M), code(?M, ?C), ?C < 3." in out
    assert "  seen(marker_1)  <- the rule at <prompt>:1" in out and "    code(marker_1, 1)  <- a belief" in out
    assert "5 < 3 does not hold" in out
    assert "<prompt>:1: The rule bad(?X) :- seen(?Y). is not safe: ?X appears only in the head" in err
    assert "Traceback" not in err


def test_a_rules_file_is_read_with_its_errors_lines(flight, tmp_path, capsys):
    rules = tmp_path / "markers.rules"
    rules.write_text("% markers by code\nlow(?M) :- object(?M, marker), code(?M, ?C), ?C < 3.\n")
    assert main(["beliefs", str(flight), "--rules", str(rules), "--query", "low(?M)"]) == 0
    assert "marker_1" in capsys.readouterr().out
    rules.write_text("% markers by code\nlow(?M) :- object(?M, marker), not(code(?M, ?C)).\n")
    assert main(["beliefs", str(flight), "--rules", str(rules), "--query", "low(?M)"]) == 1
    err = capsys.readouterr().err
    assert f"{rules}:2: The rule low(?M) :- object(?M, marker), not(code(?M, ?C)). is not safe: ?C appears only " \
           "in a negation" in err
