"""What a command imports before it does anything (issue 45): each module a start-up does not need is CPU every
``aeroexec`` command pays, measured by ``bench/startup.py`` against the interpreter's own start."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

MISSIONS = Path(__file__).resolve().parents[2] / "missions"


def imported_after(code: str, cache: Path | None = None, **environment: str) -> set[str]:
    """The modules a fresh interpreter holds after running ``code`` (written to standard error at its end), with
    ``cache`` as its user's cache folder (``XDG_CACHE_HOME``) when given, and ``environment`` added to its own."""
    script = textwrap.dedent(code) + "\nimport sys\nprint('\\n'.join(sorted(sys.modules)), file=sys.stderr)\n"
    env = {**os.environ, **({"XDG_CACHE_HOME": str(cache)} if cache is not None else {}), **environment}
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True, cwd="/",
                          env=env)
    return set(done.stderr.split())


def verify(mission: Path) -> str:
    """The code of a ``aeroexec verify MISSION`` whose mission has no errors."""
    return f"""
        import contextlib, io, sys
        sys.argv = ["aeroexec", "verify", {str(mission)!r}]
        from aeroexec.cli.main import main
        shown = io.StringIO()
        with contextlib.redirect_stdout(shown), contextlib.suppress(SystemExit):
            main()
        assert "0 errors" in shown.getvalue(), shown.getvalue()
    """


def test_the_top_level_help_imports_nothing_it_does_not_print_with():
    """``aeroexec --help`` lists the sub-commands and the mission formats (built-in and plugins'): it needs neither
    logging, typing, dataclasses, pathlib, shutil nor importlib.metadata (~20 ms of its CPU together)."""
    bare = imported_after("")
    helped = imported_after("""
        import contextlib, io, sys
        sys.argv = ["aeroexec", "--help"]
        from aeroexec.cli.main import main
        shown = io.StringIO()
        with contextlib.redirect_stdout(shown), contextlib.suppress(SystemExit):
            main()
        assert "usage: aeroexec" in shown.getvalue() and "BehaviorTree.CPP XML (.xml)" in shown.getvalue()
    """)
    needless = {"logging", "typing", "dataclasses", "pathlib", "shutil", "importlib.metadata"}
    assert sorted((helped - bare) & needless) == []


def test_a_plugin_group_no_package_names_is_answered_without_reading_every_package():
    modules = imported_after("""
        from aeroexec.plugins import installed_plugins
        assert installed_plugins("aeroexec.no-such-group") == []
    """)
    assert "importlib.metadata" not in modules


def test_a_plugin_group_a_package_names_is_still_read(tmp_path):
    site = tmp_path / "site"
    (site / "toy_group-0.1.dist-info").mkdir(parents=True)
    (site / "toy_group-0.1.dist-info" / "METADATA").write_text("Metadata-Version: 2.1\nName: toy-group\n"
                                                                 "Version: 0.1\n")
    (site / "toy_group-0.1.dist-info" / "entry_points.txt").write_text("[aeroexec.toy_group]\nanswer = json:dumps\n")
    modules = imported_after(f"""
        import sys
        sys.path.insert(0, {str(site)!r})
        import json
        from aeroexec.plugins import installed_plugins
        assert installed_plugins("aeroexec.toy_group", named=True) == [("answer", json.dumps)]
    """)
    assert "importlib.metadata" not in modules  # read from its entry_points.txt as importlib.metadata reads it


def test_a_run_reads_its_declared_rules_and_robot_kind_without_the_web_or_package_metadata():
    """The safety rules a mission declares are unescaped without ``xml.sax.saxutils`` (it imports urllib.request,
    http.client and ssl), and the built-in drone is chosen without reading every installed package."""
    modules = imported_after("""
        from aeroexec.engine.robots import robot_kind
        from aeroexec.engine.safety.declared import _unescape
        assert robot_kind("drone") is None
        assert _unescape("a &lt; b &amp;&amp; c &gt; &quot;d&apos; &amp;lt;") == "a < b && c > \\"d' &lt;"
    """)
    assert sorted(modules & {"xml.sax.saxutils", "urllib.request", "ssl", "importlib.metadata"}) == []


def test_verifying_an_xml_mission_imports_neither_the_web_nor_ssl():
    """``aeroexec verify missions/figure10.xml`` reads the XML with expat and refuses what ``defusedxml`` refuses,
    without SAX: ``xml.sax.saxutils`` imports urllib.request, http.client and ssl (~10 ms of every verify)."""
    modules = imported_after(f"""
        import contextlib, io, sys
        sys.argv = ["aeroexec", "verify", {str(MISSIONS / "figure10.xml")!r}]
        from aeroexec.cli.main import main
        shown = io.StringIO()
        with contextlib.redirect_stdout(shown), contextlib.suppress(SystemExit):
            main()
        assert "0 errors" in shown.getvalue(), shown.getvalue()
    """)
    assert sorted(modules & {"xml.sax", "xml.sax.saxutils", "urllib.request", "http.client", "ssl"}) == []


def test_a_mission_whose_beliefs_are_flat_and_has_no_script_is_verified_without_lark():
    """figure10.xml's one belief (``position(self, ?here)``) is read by hand and it has no script: Lark (~50 ms of
    every start) is not imported; a belief of another shape, or a script, still is read with the grammar."""
    modules = imported_after(f"""
        import contextlib, io, sys
        sys.argv = ["aeroexec", "verify", {str(MISSIONS / "figure10.xml")!r}]
        from aeroexec.cli.main import main
        shown = io.StringIO()
        with contextlib.redirect_stdout(shown), contextlib.suppress(SystemExit):
            main()
        assert "0 errors" in shown.getvalue(), shown.getvalue()
    """)
    assert "lark" not in modules
    read = imported_after("""
        from aeroexec.beliefs import parse_expression
        from aeroexec.trees.script import compile_script
        assert len(parse_expression("charge(battery, ?X), ?X > 20").literals) == 2
        assert compile_script("x := 1").writes == ["x"]
    """)
    assert "lark" in read


def test_verifying_a_mission_without_aerostack2_nodes_does_not_import_their_mapping():
    """Every XML mission is asked whether it uses Aerostack2's nodes (its tree mapping, the ground it was written
    for): a mission that does not never imports the mapping (``tree_nodes``, with Aerostack2's behavior tables and
    the ROS checks behind it); one that does is still mapped (tests/aerostack/test_aerostack2_trees.py)."""
    modules = imported_after(verify(MISSIONS / "figure10.xml"))
    assert "aeroexec.dialects.aerostack2.node_ports" in modules  # asked
    assert sorted(modules & {"aeroexec.dialects.aerostack2.tree_nodes", "aeroexec.dialects.aerostack2.behaviors",
                             "aeroexec.dialects.ros"}) == []


def test_verify_names_the_behaviors_without_implementation_without_importing_the_behaviors(tmp_path):
    """The behaviors the aerial library serves are read once and kept in the user's cache folder: the next verify
    says which behaviors have no implementation without importing the behaviors or the engine's processes."""
    first = imported_after(verify(MISSIONS / "figure10.xml"), cache=tmp_path)
    assert "aeroexec.engine.behaviors.aerial" in first  # nothing kept yet: the library itself is read
    assert [p.name.split(".")[0] for p in (tmp_path / "aeroexec").glob("behaviors.*")] == ["behaviors"]
    again = imported_after(verify(MISSIONS / "figure10.xml"), cache=tmp_path)
    assert sorted(again & {"aeroexec.engine.behaviors.aerial", "aeroexec.engine.execution.process"}) == []


def test_verify_checks_expressions_and_a_catalog_without_safety_rules_without_the_belief_memory(tmp_path):
    """The belief memory and its rules engine (~10 ms) are built for what needs one: a mission's expressions are
    checked against the catalog's vocabulary without it, and a catalog with no safety rules decides none at the
    mission's destinations (a rule that is decided there still builds one: tests/safety)."""
    imported_after(verify(MISSIONS / "figure10.xml"), cache=tmp_path)  # the catalog and world kept parsed
    modules = imported_after(verify(MISSIONS / "figure10.xml"), cache=tmp_path)
    assert "aeroexec.beliefs.expression" in modules  # the expressions are read
    assert sorted(modules & {"aeroexec.beliefs.memory", "aeroexec.beliefs.query", "sortedcontainers"}) == []


def test_verify_reads_no_yaml_once_its_catalog_and_world_are_kept_parsed(tmp_path):
    """The catalog and the default world are YAML files: once kept parsed in the user's cache folder, a verify of an
    XML mission imports no PyYAML (~15 ms) to load them, nor tempfile (only writing a kept file needs it), nor hashlib
    (its OpenSSL, ~3 ms, for the keys of the kept files: CPython's own SHA-256 gives the same digests)."""
    first = imported_after(verify(MISSIONS / "figure10.xml"), cache=tmp_path)
    assert "yaml" in first  # nothing kept yet: the files are read
    again = imported_after(verify(MISSIONS / "figure10.xml"), cache=tmp_path)
    assert sorted(m for m in again if m.split(".")[0] in ("yaml", "tempfile", "hashlib", "_hashlib")) == []


def test_verifying_a_behavior_tree_does_not_import_the_tml_dialect_or_elementtree():
    """Every XML mission is handed to TML's reader and checks, and asked for the ground Aerostack2's missions fly
    in: a behavior tree that is neither imports none of TML's reader, compiler and checks, nor ElementTree (the
    ground's reader) when the file names none of Aerostack2's nodes; a TML mission is still read as TML
    (tests/trees/test_tml.py)."""
    modules = imported_after(verify(MISSIONS / "figure10.xml"))
    assert sorted(modules & {"aeroexec.dialects.tml.compiler", "aeroexec.dialects.tml.reader",
                             "aeroexec.dialects.tml.verify", "xml.etree.ElementTree"}) == []


def empty_run_modules(tmp_path) -> set[str]:
    """The modules imported by an empty run of missions/figure10.py (``aeroexec run ... --max-time 0``)."""
    runtime = tmp_path / "runtime"
    runtime.mkdir(mode=0o700)
    return imported_after(f"""
        import contextlib, io, sys
        from aeroexec.cli.main import main
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            main(["run", {str(MISSIONS / "figure10.py")!r}, "--plain", "--max-time", "0",
                  "--output", {str(tmp_path / "out")!r}])
    """, XDG_RUNTIME_DIR=str(runtime))


def test_an_empty_run_starts_without_the_modules_only_some_runs_need(tmp_path):
    """A run's start (``aeroexec run MISSION --max-time 0``) makes its control token and run id from os.urandom, keys
    its files with CPython's own SHA-256, probes its output folder, and finds a script's sibling modules and ROS
    stand-ins, without secrets, hmac, hashlib's OpenSSL, uuid and platform, tempfile and importlib.abc (which imports
    importlib.resources), nor what only a resumed run reads (its resume point, the journal's reader), nor Aerostack2's
    drone interfaces for a program that never names its API: together ~25 ms of every run. (hmac is imported when a
    client asks the control socket; tempfile when there is no runtime directory.)"""
    modules = empty_run_modules(tmp_path)
    assert "aeroexec.engine.engine" in modules  # it ran
    assert sorted(modules & {"secrets", "hmac", "hashlib", "_hashlib", "uuid", "platform", "tempfile",
                             "importlib.abc", "importlib.resources", "subprocess", "aeroexec.flight.journal.resumption",
                             "aeroexec.flight.journal.resume_point", "aeroexec.flight.journal.reader",
                             "aeroexec.dialects.aerostack2.drone_objects",
                             "aeroexec.dialects.aerostack2.behaviors"}) == []



def test_an_empty_run_of_a_python_mission_imports_no_tree_model_change_script_fleet_or_runs_of_looks(tmp_path):
    """A Python mission's run needs no tree model (a tree mission's: ``trees.model``, ``trees.mission_file``), no
    mission change until the operator asks one (``engine.supervision.changes``), no script fleet unless its script
    flies several drones (``flight.fleet.script_fleet``) and no runs of looks until the mission first looks
    (``flight.journal.looks``, with zlib): ~6M instructions of every such start (bench/startup.py)."""
    modules = empty_run_modules(tmp_path)
    assert "aeroexec.engine.engine" in modules and "aeroexec.flight.mission_changes" in modules  # it ran
    assert sorted(modules & {"aeroexec.trees.model", "aeroexec.trees.mission_file",
                             "aeroexec.engine.supervision.changes", "aeroexec.flight.fleet.script_fleet",
                             "aeroexec.flight.journal.looks", "zlib"}) == []


def test_an_empty_run_with_its_catalog_and_world_kept_needs_neither_pickle_py_shlex_nor_ros_messages(tmp_path):
    """The second empty run of a mission reads its kept catalog and world with the C unpickler alone (pickle.py is for
    writing them), reads no mission change (shlex: when one comes) and, its program naming no ROS module, builds no
    ROS message type (dialects/ros_messages.py: on the first ROS name): ~2 ms of every run's start."""
    runtime, cache = tmp_path / "runtime", tmp_path / "cache"
    runtime.mkdir(mode=0o700)
    code = f"""
        import contextlib, io, sys
        from aeroexec.cli.main import main
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            main(["run", {str(MISSIONS / "figure10.py")!r}, "--plain", "--max-time", "0",
                  "--output", {str(tmp_path / "out")!r}])
    """
    imported_after(code, cache, XDG_RUNTIME_DIR=str(runtime))  # the first run parses the catalog and world, keeps them
    assert any(cache.rglob("catalog.*.pickle")) and any(cache.rglob("world.*.pickle"))
    modules = imported_after(code, cache, XDG_RUNTIME_DIR=str(runtime))
    assert "aeroexec.engine.engine" in modules and "_pickle" in modules  # it ran, and read what was kept
    assert sorted(modules & {"pickle", "shlex", "aeroexec.dialects.ros_messages"}) == []

def test_a_named_sub_command_is_parsed_alone_and_the_help_before_it_still_lists_every_one(capsys):
    """``aeroexec verify ...`` builds the verify parser alone (the others' cost every start); ``aeroexec -h verify``
    is the top-level help, listing every sub-command, and a misspelt sub-command is told the ones there are."""
    from aeroexec.cli.main import COMMANDS, build_parser, main

    assert sorted(build_parser(["verify", "m.xml"]).commands) == ["verify"]
    with pytest.raises(SystemExit):
        main(["-h", "verify"])
    shown = capsys.readouterr().out
    assert all(name in shown for name in COMMANDS), shown
    with pytest.raises(SystemExit):
        main(["verif", "m.xml"])
    assert "invalid choice: 'verif' (choose from 'run', 'verify'" in capsys.readouterr().err


def test_a_command_that_needs_no_extra_does_not_read_the_extras_table():
    """Which extras a command line needs is known from its sub-command and options: verify needs none, and the
    extras' table (and what it imports) is read only for one that does (tests/cli/test_extras.py)."""
    assert "aeroexec.extras" not in imported_after(verify(MISSIONS / "figure10.xml"))


def test_an_empty_run_imports_the_behaviors_it_activates_and_no_other(tmp_path):
    """The aerial behaviors and capability processes are known by their modules (kept in the user's cache folder),
    each module imported when one of its behaviors is first activated or one of its processes started: the catalog
    starts the localization processes; figure10.py's TAKE_OFF is imported when the engine activates it (checking
    the mission's request asks only whether the library implements it), which an empty run does only when its one
    period came to serve the request; recording, targets, speech... and the path planner's grid (imported when a
    route is first planned) are not imported."""
    run = f"""
        import contextlib, io
        from aeroexec.cli.main import main
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            main(["run", {str(MISSIONS / "figure10.py")!r}, "--plain", "--max-time", "0",
                  "--output", {str(tmp_path / "out")!r}])
    """
    imported_after(run, cache=tmp_path / "cache")  # the library's index read and kept
    modules = imported_after(run, cache=tmp_path / "cache")
    assert "aeroexec.engine.behaviors.localization" in modules
    events = [json.loads(line) for line in (tmp_path / "out" / "events.jsonl").read_text().splitlines()]
    took_off = any(e["kind"] == "activated" and e.get("behavior") == "TAKE_OFF" for e in events)
    assert ("aeroexec.engine.behaviors.motion" in modules) == took_off
    unused = ("recording", "targets", "target_tracking", "speech", "communication", "perception", "manipulation")
    assert sorted(modules & {f"aeroexec.engine.behaviors.{name}" for name in unused}) == []
    planners = {m for m in modules if m.startswith("aeroexec.engine.planning.")}
    assert sorted(planners) == ["aeroexec.engine.planning.worker"]  # the engine's planning thread, idle


def test_the_library_serves_every_behavior_and_process_of_the_aerial_modules_when_asked(tmp_path):
    """What the library and the process registry serve is what importing every module gives, a class or a process
    of a module not imported yet included; a plugin's behavior of the same name wins."""
    imported_after("from aeroexec.engine.library import default_library\ndefault_library()", cache=tmp_path)  # kept
    imported_after("""
        import sys
        from aeroexec.engine.library import default_library, default_processes
        from aeroexec.engine.execution.process import BehaviorProcess
        library, processes = default_library(), default_processes()
        assert "aeroexec.engine.behaviors.targets" not in sys.modules
        assert "aeroexec.engine.behaviors.recording" not in sys.modules
        tracker = library.get("TRACK_OBJECT_IMAGE")
        assert tracker is not None and tracker.behavior == "TRACK_OBJECT_IMAGE"
        assert tracker.__module__ in sys.modules
        recorder = processes.create("video_recorder")
        assert type(recorder).__name__ == "VideoRecorder" and recorder.name == "video_recorder"
        assert "UNKNOWN" not in library and library.get("UNKNOWN") is None

        class Mine(BehaviorProcess):
            behavior = "GO_TO_POINT"

        library.register(Mine)
        assert library.get("GO_TO_POINT") is Mine

        from aeroexec.engine.behaviors.aerial import aerial_behaviors, aerial_processes
        everything = aerial_behaviors()
        assert default_library().names() == everything.names()
        assert {n: everything.get(n) for n in everything.names()} == {
            n: default_library().get(n) for n in everything.names()}
        assert default_processes().names() == aerial_processes().names()
    """, cache=tmp_path)


def test_a_run_s_set_up_is_frozen_in_the_command_s_own_process_only(tmp_path):
    """What a run's start makes lives as long as the run: the ``aeroexec`` command pauses the cyclic collector while
    it sets the flight up and freezes what was made (as it does for its imports); a caller running ``main(args)``
    in its own process keeps its collector as it was."""
    code = f"""
        import contextlib, gc, io, sys
        from aeroexec.cli.main import main
        arguments = ["run", {str(MISSIONS / "figure10.py")!r}, "--plain", "--max-time", "0", "--output"]
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            main(arguments + [{str(tmp_path / "embedded")!r}])
        embedded = gc.get_freeze_count()
        sys.argv = ["aeroexec", *arguments, {str(tmp_path / "command")!r}]
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            main()
        print(embedded, gc.get_freeze_count() > 0, gc.isenabled(), file=sys.stderr)
    """
    done = subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True, cwd="/")
    assert done.stderr.split()[-3:] == ["0", "True", "True"], done.stderr
