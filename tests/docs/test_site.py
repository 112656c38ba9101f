"""The documentation site (issue 41): ``mkdocs build --strict`` passes, and a broken link, anchor or nav entry
fails it while a page not yet in the nav does not; README.md's first missions verify and fly as written; every
``aeroexec ...`` line the guides show parses with the command's own parser, and every Python block compiles; the
reference pages say what the code says."""

from __future__ import annotations

import ast
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from aeroexec.cli.main import COMMANDS, build_parser, main

ROOT = Path(__file__).parents[2]
DOCS = ROOT / "docs"
README = ROOT / "README.md"
PAGES = sorted(DOCS.rglob("*.md"))
#: A fence and its language; the block's text.
FENCE = re.compile(r"^ *```(\w*)\n(.*?)^ *```", re.S | re.M)
#: Blocks in these languages are data (missions, catalogs, rules), not commands.
DATA = {"python", "xml", "yaml", "json", "toml", "prolog"}


def build(folder: Path, site: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(site)], cwd=folder,
                          capture_output=True, text=True, env={"NO_MKDOCS_2_WARNING": "1", "PATH": "/usr/bin:/bin"})


def test_the_site_builds_strictly(tmp_path):
    result = build(ROOT, tmp_path / "site")
    assert result.returncode == 0, result.stderr
    assert (tmp_path / "site" / "index.html").is_file()
    assert (tmp_path / "site" / "reference" / "cli" / "index.html").is_file()


def test_a_broken_link_fails_the_build_and_a_page_outside_the_nav_does_not(tmp_path):
    shutil.copytree(DOCS, tmp_path / "docs")
    shutil.copy(ROOT / "mkdocs.yml", tmp_path)
    (tmp_path / "docs" / "not-in-nav-yet.md").write_text("# A page another engineer just wrote\n")
    result = build(tmp_path, tmp_path / "site")
    assert result.returncode == 0, result.stderr
    assert "not included in the \"nav\" configuration" in result.stderr and "not-in-nav-yet.md" in result.stderr
    fleets = tmp_path / "docs" / "fleets.md"
    fleets.write_text(fleets.read_text() + "\nSee [how a run ends](running.md#how-a-run-finishes).\n")
    result = build(tmp_path, tmp_path / "site")
    assert result.returncode == 1
    assert "does not contain an anchor '#how-a-run-finishes'" in result.stderr
    fleets.write_text(fleets.read_text() + "\nSee [the journal](journal.md).\n")
    result = build(tmp_path, tmp_path / "site")
    assert result.returncode == 1 and "'journal.md', but the target is not found" in result.stderr


def readme_missions() -> dict[str, str]:
    """``{file name: text}`` of README.md's first missions: a block right after a line ending `` `NAME`: ``."""
    return dict(re.findall(r"`([\w.]+)`:\n\n```\w*\n(.*?)```", README.read_text(), re.S))


def test_the_readme_shows_a_first_mission_of_each_kind():
    assert sorted(readme_missions()) == sorted(["hello.xml", "hello.yaml", "hello.py", "hello.waypoints",
                                                "hello.tml.xml", "hello_aerostack.py", "hello_as2.json"])
    assert len(README.read_text().splitlines()) <= 250


@pytest.mark.parametrize("name", sorted(readme_missions()))
def test_a_readme_mission_verifies_and_flies_as_written(name, tmp_path, capsys):
    mission = tmp_path / name
    mission.write_text(readme_missions()[name])
    assert main(["verify", str(mission)]) == 0
    assert "0 errors, 0 warnings; ready to fly" in capsys.readouterr().out
    assert main(["run", str(mission), "--plain", "--output", str(tmp_path / "out")]) == 0
    out = capsys.readouterr().out
    assert "run_ended: completed" in out and "3 goals achieved" in out


def test_the_readme_test_command_is_what_ci_runs():
    ci = (ROOT / ".ci" / "run").read_text()
    readme = README.read_text()
    for line in ('install --quiet -e ".[test]"', "install --quiet -e examples/rover", "\npython -m pytest\n"):
        assert line in ci
    for line in ('pip install -e ".[test]"', "pip install -e examples/rover", "\npython -m pytest "):
        assert line in readme


def blocks(path: Path) -> list[tuple[str, str, int]]:
    """``(language, text, line)`` of each fenced block of a page."""
    text = path.read_text()
    return [(m.group(1), m.group(2), text.count("\n", 0, m.start(2)) + 1) for m in FENCE.finditer(text)]


def command_lines() -> list[tuple[str, str]]:
    """``(page:line, command line)`` of every ``aeroexec`` command the pages' shell blocks show, continuation
    lines joined, from ``aeroexec`` on (after a prompt, an environment assignment or a label)."""
    found = []
    for path in [README, *PAGES]:
        for language, text, first in blocks(path):
            if language in DATA:
                continue
            joined = re.sub(r"\\\n\s*", " ", text)
            for offset, line in enumerate(joined.splitlines()):
                match = re.search(r"(?:^|[\s:$])(aeroexec (?:[a-z-]+|--[a-z-]+).*)", line)
                if match and not line.lstrip().startswith("#"):
                    found.append((f"{path.relative_to(ROOT)}:{first + offset}", match.group(1)))
    return found


def options_of(parser) -> set[str]:
    return {option for action in parser._actions for option in action.option_strings}


def words_of(line: str) -> list[str]:
    """The words the shell hands ``aeroexec``: up to a pipe, a list, a redirection or a comment."""
    lexer = shlex.shlex(line, posix=True, punctuation_chars=";&|>")
    lexer.whitespace_split = True
    words = []
    for word in lexer:
        if word and set(word) <= set(";&|>"):
            break
        words.append(word)
    return words


#: A placeholder the reader replaces (``FILE``, ``DIR``, ``N``, ``P``): a line holding one is a synopsis.
PLACEHOLDER = re.compile(r"(?<![\w/.-])[A-Z][A-Z_]*(?![\w.(])")


@pytest.mark.parametrize(("where", "line"), command_lines(), ids=[w for w, _ in command_lines()])
def test_every_command_line_shown_parses(where, line):
    """A line is parsed as the shell would hand it to ``aeroexec``; a synopsis (``[--speed N]``, ``a | b``, a
    placeholder ``--port P``) that does not parse names only options its command has."""
    argv = words_of(line)[1:]
    parser = build_parser(argv)
    command = next((w for w in argv if not w.startswith("-")), None)
    try:
        parser.parse_args(argv)
        return
    except SystemExit as exit:
        if exit.code == 0:
            return
        synopsis = "[" in line or " | " in line or "..." in line or PLACEHOLDER.search(line.split("#")[0])
        assert synopsis, f"{where}: {line}"
    assert command in COMMANDS, f"{where}: {line}"
    known = options_of(parser) | options_of(parser.commands[command])
    named = set(re.findall(r"(?<![\w-])(--?[a-zA-Z][\w-]*)", line.split("#")[0]))
    assert named <= known, f"{where}: {line}: no such option {sorted(named - known)}"


def test_the_guides_show_commands_of_every_kind():
    shown = {next((w for w in line.split()[1:] if not w.startswith("-")), "") for _, line in command_lines()}
    assert set(COMMANDS) <= shown


@pytest.mark.parametrize("page", [README, *PAGES], ids=lambda p: str(p.relative_to(ROOT)))
def test_every_python_block_compiles(page):
    for language, text, line in blocks(page):
        if language == "python":
            compile(text, f"{page.relative_to(ROOT)}:{line}", "exec")


def test_the_command_line_reference_lists_every_command():
    page = (DOCS / "reference" / "cli.md").read_text()
    for name in COMMANDS:
        assert f"| `aeroexec {name}` |" in page, name
    listed = re.findall(r"^\| `aeroexec ([\w-]+)` \|", page, re.M)
    assert listed == list(COMMANDS)


def test_the_messages_page_has_the_sentences_the_engine_writes():
    from aeroexec.beliefs.errors import BeliefSyntaxError, UnknownPredicateError
    from aeroexec.engine import events
    from aeroexec.engine.errors import unsupported_message

    page = (DOCS / "reference" / "messages.md").read_text().replace("&lt;", "<").replace("&gt;", ">")
    for sentence in (events.failed_preconditions_message("<x>"), events.wrong_progress_message("<x>"),
                     events.achieved_goal_message("<x>"), unsupported_message("<x>"),
                     str(BeliefSyntaxError("<x>")), str(UnknownPredicateError("<x>", "<y>")),
                     events.time_out_message("<x>", 1.0).replace("(1 seconds)", "(<y> seconds)")):
        assert f"| {sentence} |" in page, sentence


def python_block(page: str, starts: str) -> str:
    return next(text for language, text, _line in blocks(DOCS / page) if language == "python" and starts in text)


def test_the_belief_memory_example_answers_what_its_comments_say():
    """docs/beliefs.md's example, line by line: an expression followed by ``# LITERAL`` gives that value."""
    namespace: dict = {}
    checked = 0
    for line in python_block("beliefs.md", "BeliefMemory(").splitlines():
        code, _, comment = line.partition(" # ")
        try:
            expected = ast.literal_eval(comment.strip())
        except (ValueError, SyntaxError):
            exec(code, namespace)
            continue
        assert eval(code, namespace) == expected, line
        checked += 1
    assert checked == 4


def test_the_specialist_example_raises_and_returns_what_its_comments_say():
    from aeroexec.engine.errors import SpecificationError

    text = python_block("behaviors.md", "BehaviorSpecialist()")
    shown = re.search(r"# SpecificationError WRONG_VALUE: (.*?)\n(?!#)", text, re.S).group(1)
    namespace: dict = {}
    exec(text.split("specialist.check_request")[0], namespace)
    specialist = namespace["specialist"]
    with pytest.raises(SpecificationError) as caught:
        specialist.check_request("GO_TO_POINT", {"COORDINATES": (1, 2)})
    assert caught.value.kind == "WRONG_VALUE"
    assert caught.value.message == " ".join(part.strip("# ") for part in shown.splitlines())
    kind, message = re.search(r"# \[(\w+): (.*?) \(\.\.\.\)\]", text).groups()
    errors = specialist.check_sequence(["TAKE_OFF", "LAND", "LAND"])
    assert [e.kind for e in errors] == [kind] and errors[0].message.startswith(message + " (")
