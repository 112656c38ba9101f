"""Mutating the real examples of every input format and judging what the readers make of them.

A mutation is a list of edits (:class:`Edit`) applied to a seed file's bytes: byte flips, control characters,
truncation, repeated slices (huge files), deep nesting, numbers that break floats (huge, nan, inf, 1e308),
wrong YAML types and unicode. :func:`judge` runs one input through the format's public entry point (the
functions ``aeroexec verify``, ``catalog --check``, ``run --world`` and the control socket call) and says what
happened: ``ok`` (accepted, or refused with every error naming its place), ``unplaced`` (an error without
file:line), ``uncaught`` (an exception that is not the project's error) or ``hang`` (more than the time limit).
The fuzz tests draw edits with hypothesis; ``bench/fuzz.py`` draws them at random for minutes.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import re
import signal
import tempfile
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

from aeroexec.beliefs import BeliefError, BeliefMemory, RuleError, parse_expression, read_rules
from aeroexec.drones.sim import WorldError, load_world
from aeroexec.engine.catalog.behavior_catalog import default_catalog, load_catalog
from aeroexec.engine.errors import CatalogError
from aeroexec.flight.missions import MissionFileError, check_mission
from aeroexec.trees import formats as mission_formats
from aeroexec.trees.mission_world import mission_world

ROOT = Path(__file__).parents[2]
DATA = Path(__file__).with_name("data")  # failing examples found by the fuzz tests, replayed by test_fuzz.py
HANG_SECONDS = 10.0

#: Text an edit may insert: control characters, nesting openers, numbers that break floats, unicode, YAML types.
PAYLOADS = [b"\x00", b"\x07", b"\x0b", b"\x1b", b"\x7f", b"\xff\xfe", b"\xc3", "é€𝄞".encode(), "\u202e".encode(),
            b"[" * 500, b"{a: " * 300, b"<Inverter>" * 300, b"<task name='t'>" * 300, b"not(" * 200, b"f(" * 400,
            b"9" * 400, b"1e308", b"-1e309", b".nan", b".inf", b"nan", b"-.inf", b"NaN", b"0x" + b"f" * 80,
            b"null", b"~", b"[]", b"{}", b"[1, [2, [3]]]", b"{x: 1}", b"!!binary AAAA", b"&a [*a]", b"*x",
            b"?", b"?_0", b"'", b'"', b"<", b"&lt;", b"]]>", b"\n", b"\t", b"  ", b"- ", b": ", b",", b"\r\n",
            b"%", b"@", b"`", b"#", b"{", b"}", b")", b"(", b"--- ", b"...\n"]
KINDS = ("flip", "insert", "delete", "repeat", "truncate", "replace_number")


@dataclass(frozen=True)
class Edit:
    """One change to a seed: ``kind`` at ``position`` (a fraction of the length, in 1/65536) with ``size``."""

    kind: str
    position: int
    size: int
    payload: int


def apply(seed: bytes, edits: list[Edit]) -> bytes:
    """The seed with each edit applied in turn."""
    data = bytearray(seed)
    for edit in edits:
        at = len(data) * edit.position // 65536
        payload = PAYLOADS[edit.payload % len(PAYLOADS)]
        if edit.kind == "flip" and data:
            data[min(at, len(data) - 1)] ^= 1 << (edit.size % 8)
        elif edit.kind == "insert":
            data[at:at] = payload
        elif edit.kind == "delete":
            del data[at:at + edit.size % 200]
        elif edit.kind == "repeat":  # a slice repeated up to a few thousand times: long lists, huge files
            piece = bytes(data[at:at + 1 + edit.size % 120])
            data[at:at] = piece * (1 + (edit.size * 37) % 4000)
        elif edit.kind == "truncate":
            del data[at:]
        elif edit.kind == "replace_number":
            found = list(re.finditer(rb"-?\d+(\.\d+)?", bytes(data)))
            if found:
                match = found[edit.size % len(found)]
                data[match.start():match.end()] = payload if edit.payload % 3 else b"9" * (300 + edit.size % 5000)
    return bytes(data)


@dataclass(frozen=True)
class Format:
    """An input format: the seeds it is fuzzed from, the file suffix, and how the project reads it."""

    name: str
    suffix: str
    seeds: tuple[Path, ...]
    read: Callable[[Path], list[str]]  # the error messages; raises only the project's errors (caught here)


@dataclass(frozen=True)
class Verdict:
    outcome: str  # ok, unplaced, uncaught, hang
    detail: str = ""


class _Hang(BaseException):
    """The time limit of one input ran out (raised by SIGALRM in the main thread)."""


_catalog = None


def _mission(path: Path) -> list[str]:
    global _catalog
    _catalog = _catalog or default_catalog()
    try:  # a mission planned on a map is checked in the world generated around it, as verify does
        fmt = mission_formats.format_of(path)
        checked = check_mission(path, _catalog, mission_world(path) if fmt is not None and fmt.items else None)
    except MissionFileError as error:
        return [str(error)]
    return [str(p) for p in checked.errors]


def _catalog_file(path: Path) -> list[str]:
    try:
        load_catalog(path)
    except CatalogError as error:
        return [str(p) for p in error.errors]
    return []


def _world(path: Path) -> list[str]:
    try:
        load_world(path)
    except WorldError as error:
        return [str(error)]
    return []


def _safety_rules(path: Path) -> list[str]:
    global _catalog
    _catalog = _catalog or default_catalog()
    from aeroexec.engine.safety.declared import rules_file

    return [str(p) for p in rules_file(path, _catalog).errors]


_memory: BeliefMemory | None = None


def _belief(path: Path) -> list[str]:
    """A belief expression as a condition (parse, then query) and, when ground, as a belief added and removed."""
    global _memory
    if _memory is None:
        _memory = BeliefMemory()
        _memory.add_all(["position(self, (1.0, 2.0, 3.0))", "flight_state(self, flying)", "object(o1, box)",
                         "color(o1, red)", "battery_charge_percentage(self, 80)", "p(a, b)"])
    text = path.read_bytes().decode("utf-8", "replace")
    try:
        expression = parse_expression(text)
        _memory.query_all(expression)
        if len(expression.literals) == 1 and not expression.variables:
            with contextlib.suppress(BeliefError):
                _memory.add(text)
                _memory.remove(text)
    except BeliefError as error:
        return [str(error)]
    return []


def _rules(path: Path) -> list[str]:
    """A rules file (``--rules``): read, taken by a memory, and every predicate it derives asked."""
    memory = BeliefMemory()
    try:
        rules = read_rules(path)
        memory.add_rules(rules)
        for name, arity in {r.head.signature for r in rules if r.body.literals}:
            memory.query_all(f"{name}({', '.join(f'?A{i}' for i in range(arity))})" if arity else name)
    except RuleError as error:
        return [str(p) for p in error.problems]
    except BeliefError as error:
        return [str(error)]
    return []


_server = None


def _control(path: Path) -> list[str]:
    """One line on the control socket, answered as the server would (a wrong token is refused, never a crash)."""
    global _server
    if _server is None:
        from aeroexec.drones.sim import SimulatedDrone, default_world
        from aeroexec.engine.engine import Engine
        from aeroexec.flight.control import ControlServer

        world = default_world()
        _server = ControlServer(Engine(SimulatedDrone(world), obstacles=world))
    answer, _ = _server._answer(path.read_bytes())
    if not isinstance(answer, dict) or ("error" not in answer and not answer.get("ok")):
        raise AssertionError(f"the control socket answered {answer!r}")
    return []


def _journal(path: Path) -> list[str]:
    """A run's flight journal read as ``aeroexec journal`` and ``run --resume`` read it: answered, or refused
    naming the file (a damaged one too)."""
    from aeroexec.flight.journal import Journal, JournalError
    from aeroexec.flight.journal.resume_point import resume_point

    try:
        with Journal(path) as journal:
            journal.records()
            journal.done()
        resume_point(path)
    except JournalError as error:
        return [str(error)]
    return []


def _fleet_file(path: Path) -> list[str]:
    from aeroexec.fleet.fleet_file import FleetFileError, load_fleet

    try:
        load_fleet(path)
    except FleetFileError as error:
        return [str(p) for p in error.problems]
    return []


class _Sample:
    def __init__(self, key_expr: str, payload: bytes) -> None:
        self.key_expr, self.payload = key_expr, payload


class _Session:
    """Enough of a Zenoh session for a fleet node that is handed its samples (:attr:`samples`)."""

    class _Entity:
        def __init__(self, samples: list) -> None:
            self.samples = samples

        def put(self, payload: bytes) -> None:
            pass

        def try_recv(self) -> _Sample | None:
            return self.samples.pop(0) if self.samples else None

        def undeclare(self) -> None:
            pass

    def __init__(self) -> None:
        self.samples: list[_Sample] = []

    def declare_subscriber(self, *args, **kwargs) -> _Entity:  # noqa: ANN002, ANN003
        return self._Entity(self.samples)

    declare_queryable = declare_publisher = declare_subscriber


_fleet = None


def _fleet_message(path: Path) -> list[str]:
    """A message of a fleet member (its first line the topic, then the payload) as drone d1's node and link take it
    (at the end of d1's period, and on its next): refused or believed, never an exception (refusals are logged by
    sender and reason, not errors of a file)."""
    global _fleet
    if _fleet is None:
        from aeroexec.drones.sim import SimulatedDrone
        from aeroexec.engine.engine import Engine
        from aeroexec.fleet.link import FleetLink
        from aeroexec.fleet.node import FleetNode

        engine = Engine(SimulatedDrone())
        session = _Session()
        node = FleetNode(session, "f", "token")
        _fleet = (FleetLink(node, "d1", engine, share=("object", "code", "position")).join(), session)
    link, session = _fleet
    topic, _, payload = path.read_bytes().partition(b"\n")
    session.samples.append(_Sample(f"aeroexec/f/d2/{topic.decode('utf-8', 'replace')}", payload))
    link.update(link.engine.memory, link.engine.now())
    link.update(link.engine.memory, link.engine.now())
    return []


def _fleet_certificate(path: Path) -> list[str]:
    """A member's certificate file, checked as before a session opens (against a CA and a key made here)."""
    from aeroexec.fleet.credentials import Authority, CredentialsError, Identity

    folder = Path(tempfile.gettempdir()) / f"aeroexec-fuzz-ca-{os.getpid()}"
    made = Authority(folder, "f").issue("d1")
    try:
        Identity(path, made.key, made.ca).read("f")
    except CredentialsError as error:
        return [str(error)]
    return []


def _fragment(path: Path) -> list[str]:
    """A fragment of a change in flight (XML or BEHAVIOR PORT=VALUE), read and its nodes checked as a change's are."""
    global _catalog
    from aeroexec.trees.loaders.fragment import read_fragment
    from aeroexec.trees.model import TreeDocument, TreeFormatError, TreeNode
    from aeroexec.trees.verify import TreeVerifier

    _catalog = _catalog or default_catalog()
    try:
        nodes = read_fragment(path.read_bytes().decode("utf-8", "replace"), str(path))
    except TreeFormatError as error:
        return [f"{file}:{line}: {message}" for file, line, message in error.problems]
    verifier = TreeVerifier(TreeDocument({"m": TreeNode("Sequence", "m", {}, nodes, str(path), 1)}, "m", str(path)),
                            _catalog)
    for node in nodes:
        for inner in node.walk():
            verifier.check_node(inner)
    return [str(p) for p in verifier.problems if p.severity == "error"]


REAL = "tests/plans/data/real_missions"  # real mission files, SOURCES.md says from where


def _files(*patterns: str) -> tuple[Path, ...]:
    return tuple(sorted(p for pattern in patterns for p in ROOT.glob(pattern)))


#: The seed files of each mission format of the table (aeroexec.trees.formats), by the format's name: every
#: format of the table is fuzzed (a format without seeds here fails ``test_every_mission_format_is_fuzzed``).
MISSION_SEEDS = {
    "BehaviorTree.CPP XML": _files("missions/figure10.xml", "missions/iarc7.xml", "tests/trees/data/inspection.xml",
                         # and Aerostack2's, mapped at load
                         "tests/aerostack/data/aerostack2_trees/as2_RTL_test_2.xml",
                         "tests/aerostack/data/aerostack2_trees/gazebo_square.xml"),
    "TML": _files("missions/*.tml.xml"),
    "QGroundControl plans": _files("missions/*.plan", f"{REAL}/sky_mission/*.plan",
                                   f"{REAL}/qgroundcontrol/SectionTest.plan"),
    "QGroundControl legacy missions": _files(f"{REAL}/qgroundcontrol/OldFileFormat.mission"),
    "QGC WPL 110 waypoint files": _files(f"{REAL}/ardupilot/copter_mission.txt",
                                         f"{REAL}/qgroundcontrol/MissionPlanner.waypoints"),
    "Python missions": _files("missions/inspection.py", "missions/square_patrol.py", "missions/marker_search.py",
                              # and Aerostack2's scripts
                              "tests/aerostack/data/aerostack2_scripts/as2_example1.py",
                              "tests/aerostack/data/aerostack2_scripts/gazebo_mission_swarm.py"),
    "YAML trees": _files("missions/square_patrol.yaml", "missions/iarc7.yaml", "tests/trees/data/inspection.yaml"),
    "Aerostack2 interpreter plans": _files("tests/aerostack/data/aerostack2_plans/*.yaml",
                                           "tests/aerostack/data/aerostack2_plans/*.json"),
    "Aerostack nodes: YAML": _files("tests/trees/data/inspection_aerostack.yaml",
                                    "tests/trees/data/aerostack_tower_inspection.yaml"),
}

FORMATS = {f.name: f for f in [
    *(Format(m.name, m.suffixes[0], MISSION_SEEDS.get(m.name, ()), _mission) for m in mission_formats.formats()),
    Format("catalogs", ".yaml", _files("catalogs/aerial.yaml"), _catalog_file),
    Format("world files", ".yaml", _files("drones/sim/default_world.yaml"), _world),
    Format("belief expressions", ".txt", _files("tests/fuzz/seeds/*.belief"), _belief),
    Format("control messages", ".json", _files("tests/fuzz/seeds/*.json"), _control),
    Format("safety rules", ".rules.yaml", _files("tests/fuzz/seeds/*.rules.yaml"), _safety_rules),
    Format("fleet files", ".yaml", _files("missions/fleet_search.yaml", "missions/relay.yaml"), _fleet_file),
    Format("fleet messages", ".msg", _files("tests/fuzz/seeds/*.msg"), _fleet_message),
    Format("fleet certificates", ".pem", _files("tests/fuzz/seeds/*.pem"), _fleet_certificate),
    Format("rules files", ".rules", _files("tests/fuzz/seeds/*.rules"), _rules),
    Format("flight journals", ".sqlite", _files("tests/fuzz/seeds/*.sqlite"), _journal),
    Format("change fragments", ".fragment", _files("tests/fuzz/seeds/*.fragment"), _fragment),
]}

#: Errors about a whole file, which rightly name the file without a line.
WHOLE_FILE = re.compile(r"(not a regular file|the file is [\d,]+ bytes|the file is more than|cannot read (the|an)"
                        r"|has no mission\(\) or runMission\(\)|is empty|not XML: the file has no element"
                        r"|not a certificate \(PEM\)|not made by the fleet's CA|not the key of|valid from .* not now"
                        r"|is not of fleet|a CA's certificate is no member's"
                        r"|not a flight journal|the journal is damaged|the journal cannot be read"
                        r"|a journal of another format|nothing to resume|no state of the tree|nothing is left to do"
                        r"|by itself)")


def placed(message: str, path: Path, fmt: Format) -> bool:
    """True when an error names its place: the file and line (or the whole file), or the expression."""
    if fmt.read is _belief:
        return message.startswith("The ") and "belief expression" in message or "predicate" in message
    name = re.escape(str(path))
    if re.match(rf"{name}:[1-9]\d*(:\d+)?: ", message):
        return True
    if re.match(r"[^\s:]+:[1-9]\d*(:\d+)?: ", message):  # an included file, named with its line
        return True
    return bool(re.match(rf"{name}: ", message) and WHOLE_FILE.search(message))


@contextlib.contextmanager
def time_limit(seconds: float) -> Iterator[None]:
    """A hang is ``seconds`` of this process's CPU time, not of the wall clock: a loaded machine (other processes
    on the cores) makes a reader slower, never a hang; a reader stuck in a loop spends CPU and is stopped."""
    def expired(signum, frame):  # noqa: ANN001, ARG001
        raise _Hang()

    previous = signal.signal(signal.SIGPROF, expired)
    signal.setitimer(signal.ITIMER_PROF, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_PROF, 0)
        signal.signal(signal.SIGPROF, previous)


def judge(fmt: Format, data: bytes, folder: Path, seconds: float = HANG_SECONDS) -> Verdict:
    """What the project does with ``data`` as a file of format ``fmt``."""
    path = folder / f"input{fmt.suffix}"
    path.write_bytes(data)
    try:
        with time_limit(seconds):
            messages = fmt.read(path)
    except _Hang:
        return Verdict("hang", f"more than {seconds:g} s of CPU")
    except Exception as error:
        return Verdict("uncaught", f"{type(error).__name__}: {str(error)[:300]}")
    unplaced = [m for m in messages if not placed(m, path, fmt)]
    if unplaced:
        return Verdict("unplaced", unplaced[0][:300])
    return Verdict("ok")


def keep(fmt: Format, data: bytes, verdict: Verdict) -> Path:
    """Save a failing input as a regression file in ``data/<format>/`` (replayed by the tests)."""
    folder = DATA / re.sub(r"\W+", "_", fmt.name).strip("_").lower()
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{verdict.outcome}_{hashlib.sha1(data).hexdigest()[:12]}{fmt.suffix}"
    path.write_bytes(data)
    return path


def format_of(path: Path) -> Format:
    """The format of a kept regression file, from its folder's name."""
    for fmt in FORMATS.values():
        if re.sub(r"\W+", "_", fmt.name).strip("_").lower() == path.parent.name:
            return fmt
    raise KeyError(path.parent.name)


def scratch() -> tempfile.TemporaryDirectory:
    return tempfile.TemporaryDirectory(prefix="aeroexec-fuzz-")


__all__ = ["FORMATS", "KINDS", "MISSION_SEEDS", "PAYLOADS", "Edit", "Format", "Verdict", "apply", "format_of", "judge",
           "keep", "placed", "scratch"]
