"""A simulation case, drawn from its seed alone: a mission, the operator's commands at simulated times (sent
through the supervisor as ``aeroexec ctl`` sends them), faults (a link drop, ``kill -9`` then ``--resume``,
SIGTERM or SIGHUP, a full disk at a byte, a slow disk) and rules files. The same seed gives the same case, on any
machine; :meth:`Case.without` drops one of its actions or faults (shrinking).

Some fault kinds find defects not fixed yet; they are drawn only when named in ``extra`` (``aeroexec campaign --with
KIND``): :data:`GATED` says which and why. Those that found the defects of issue 40 (:data:`FOUND`) are drawn always.
"""

from __future__ import annotations

import random
from dataclasses import dataclass, field, replace

from aeroexec.rehearsal.simulation.missions import Mission, draw_mission, tree_mission

#: Fault kinds that found defects of issue 40 while those were being fixed; fixed now, they are drawn in every
#: campaign (what each found, for the record).
FOUND = {
    "edited_resume": "resume after kill -9 with the mission's waypoint edited (the tree's shape alone is compared)",
    "foreign_journal": "resume a journal copied from another run's folder",
    "rules_negation": "a rule negating a predicate without arguments asked in flight (calm :- not(low), up.: "
                      "TypeError in the rules' anti-join)",
    "rules_blowup": "rules files that blow up in flight (a negation over a join with nothing in it, a transitive "
                    "closure over a few hundred facts: a step of 150 ms and more)",
    "odd_update": "ctl update with an odd item number (a superscript digit, 5,000 digits) or no fragment",
    "crash_after_end": "kill -9 after the mission ended, while the flight ends (landing, disarming): --resume "
                       "flies the whole mission again",
    "contingency_undone": "a geofence whose contingency is return or hold, crossed by a plan: the plan fails when "
                          "its waypoint is preempted and the end-of-flight LAND lands the drone outside the fence",
    "photo_enospc": "the disk full when a photo is written, from the Nth photo on (the plan fails and the drone "
                    "lands where it is)",
    "disk_full": "a full disk at a random byte of the event log (the last line and the exit status disagree)",
    "process_signal": "SIGTERM or SIGHUP sent to a real aeroexec run process at a random time (one after the run "
                      "ended made it exit 130 though run_ended said completed)",
}
#: Fault kinds drawn only when asked for (``--with KIND``): each finds a defect not fixed yet.
GATED: dict[str, str] = {}


def drawn_kinds(extra: frozenset[str] | tuple[str, ...] = ()) -> frozenset[str]:
    """The fault kinds a campaign draws: every one of :data:`FOUND` and the gated ones asked for."""
    return frozenset(extra) | frozenset(FOUND)


#: An edit's target that is the item running when the command is sent (``ctl items`` says which).
RUNNING = "@running"
#: The share of cases flown by real ``aeroexec run`` processes (the others in the campaign's process).
SUBPROCESS_SHARE = 0.02
#: The share of cases flown by a fleet of 2 to 5 drones.
FLEET_SHARE = 0.015
#: Operator commands drawn, with their weights.
COMMANDS = {"pause": 5, "resume": 3, "abort": 1, "suspend": 1, "status": 2, "items": 1, "query": 1, "add": 1,
            "remove": 1, "skip": 1, "edit": 3, "load": 1}


@dataclass(frozen=True)
class Action:
    """An operator command sent at ``time`` (simulated seconds from the start of the run)."""

    time: float
    command: str
    argument: str = ""

    def __str__(self) -> str:
        argument = self.argument if len(self.argument) <= 80 else f"{self.argument[:60]}... ({len(self.argument)} " \
                                                                  f"characters)"
        return f"t={self.time:g} ctl {self.command}{' ' + argument if argument else ''}"


@dataclass(frozen=True)
class Fault:
    """A fault at ``time``: ``kind`` is link_drop (``length`` s), crash (kill -9 then --resume), sigterm, sighup,
    disk_full (``size``: bytes of the event log written before the disk is full), slow_disk, photo_enospc (``size``:
    photos written before the disk is full); the gated kinds of :data:`GATED`."""

    kind: str
    time: float = 0.0
    length: float = 0.0
    size: int = 0

    def __str__(self) -> str:
        extra = f" for {self.length:g} s" if self.length else f" after {self.size} bytes" if self.size else ""
        return f"t={self.time:g} {self.kind}{extra}"


@dataclass(frozen=True)
class Case:
    """One flight of the campaign, as its seed draws it."""

    seed: int
    mission: Mission
    actions: tuple[Action, ...] = ()
    faults: tuple[Fault, ...] = ()
    rules: str | None = None  # a --rules file's text
    safety_rules: str | None = None  # a --safety-rules file's text
    subprocess: bool = False  # flown by a real ``aeroexec run`` process
    fleet: tuple[Mission, ...] = ()  # flown by a fleet of these drones' missions (``aeroexec fleet``)
    dropped: tuple[str, ...] = field(default_factory=tuple)  # what shrinking took out, in words

    def without(self, what: Action | Fault | str) -> Case:
        """The case less one action, fault, or its rules (``"rules"``, ``"safety_rules"``)."""
        if isinstance(what, Action):
            return replace(self, actions=tuple(a for a in self.actions if a != what),
                           dropped=(*self.dropped, str(what)))
        if isinstance(what, Fault):
            return replace(self, faults=tuple(f for f in self.faults if f != what), dropped=(*self.dropped, str(what)))
        return replace(self, **{what: None}, dropped=(*self.dropped, what))

    def parts(self) -> list[Action | Fault | str]:
        """What shrinking may take out, one at a time."""
        return [*self.actions, *self.faults, *(name for name in ("rules", "safety_rules") if getattr(self, name))]

    def fault(self, kind: str) -> Fault | None:
        return next((f for f in self.faults if f.kind == kind), None)

    def describe(self) -> str:
        lines = [f"seed {self.seed}: a {self.mission.kind} mission of {self.mission.leaves} items"
                 + (" (a real aeroexec run process)" if self.subprocess else "")
                 + (f" (a fleet of {len(self.fleet)} drones: aeroexec fleet)" if self.fleet else "")]
        lines += [f"  {part}" for part in (*self.actions, *self.faults)]
        if self.rules:
            lines.append(f"  rules: {self.rules.strip().splitlines()[0]} ...")
        if self.safety_rules:
            lines.append("  safety rules: " + " ".join(r.split(":", 1)[1].strip() for r in
                                                        self.safety_rules.splitlines() if r.startswith("- rule:")))
        if self.dropped:
            lines.append(f"  (shrunk: without {'; '.join(self.dropped)})")
        return "\n".join(lines)


def _edit(rng: random.Random, mission: Mission, extra: frozenset[str]) -> tuple[str, str]:
    """A change of the running mission: insert, replace or delete at a future item or the end (at the running
    item too with ``edit_running``); for a Python mission, a skip."""
    if mission.kind == "python":
        return "skip", ""
    last = max(2, min(mission.leaves - 1, 5))  # items are numbered from 1 (TAKE_OFF); the last few are at the end
    target = RUNNING if rng.random() < 0.35 else str(rng.randint(2, last))
    point = f'GO_TO_POINT COORDINATES="{rng.randint(-5, 5)}, {rng.randint(-5, 5)}, {rng.randint(1, 4)}"'
    roll = rng.random()
    if "odd_update" in extra and roll < 0.15:
        return "update", rng.choice(["INSERT \u00b2 LAND", "INSERT " + "9" * 5000 + " LAND", "INSERT"])
    if roll < 0.1:
        return "insert", f"before {RUNNING} 'LAND'"
    if roll < 0.4:
        return "insert", f"{rng.choice(['before', 'after'])} {target} '{point}'"
    if roll < 0.6:
        return "insert", f"after {last} 'WAIT DURATION=1'"
    if roll < 0.8:
        return "replace", f"{target} '{point}'"
    return "delete", target


def _rules(rng: random.Random, extra: frozenset[str]) -> tuple[str, tuple[str, ...]]:
    """A --rules file over what the drone believes, and the questions over what it derives the mission asks; with
    ``rules_blowup``, sometimes one that blows up (a negation over a join with nothing in it, a transitive closure
    over a few hundred facts)."""
    if "rules_blowup" in extra and rng.random() < 0.4:
        if rng.random() < 0.5:
            return "d1 :- object(?C, zzz).\nd4 :- not(d1).\n", ("d4",)
        facts = "".join(f"object(n{i}, n{i + 1}).\n" for i in range(rng.choice([150, 250, 400])))
        return (facts + "reach(?A, ?B) :- object(?A, ?B).\nreach(?A, ?C) :- reach(?A, ?B), object(?B, ?C).\n",
                ("reach(n1, ?X)", "reach(?X, n3)"))
    pieces = [("high :- charge(battery, ?C), ?C > 50.", "high"),
              ("low :- charge(battery, ?C), ?C < 20.", "not(low)"),
              ("up :- flight_state(self, ?S), belong(?S, [hovering, moving]).", "up"),
              ("calm :- not(low), up.", "calm" if "rules_negation" in extra else "up"),
              ("far(?D) :- position(self, ?P), distance(?P, (0, 0, 0), ?D), ?D > 3.", "far(?D)")]
    chosen = sorted(rng.sample(range(len(pieces)), rng.randint(1, len(pieces))))
    if 3 in chosen:  # calm reads low and up
        chosen = sorted({*chosen, 1, 2})
    return "\n".join(pieces[i][0] for i in chosen) + "\n", tuple(pieces[i][1] for i in chosen)


def _safety_rules(rng: random.Random, extra: frozenset[str]) -> str:
    """A --safety-rules file: a geofence (a plan's waypoints may cross it) or a battery rule, with a land, hold or
    return contingency."""
    rules = []
    if rng.random() < 0.5:
        radius = rng.choice([12, 30])
        contingency = rng.choice(['land', 'return', 'hold'])
        if contingency != "land" and "contingency_undone" not in extra:
            contingency = "land"
        rules.append(f"- rule: fence\n  never: position(self, ?p), distance(?p, (0, 0, 0), ?d), ?d > {radius}\n"
                     f"  contingency: {contingency}\n")
    if rng.random() < 0.5 or not rules:
        rules.append(f"- rule: battery\n  never: charge(battery, ?c), ?c < {rng.choice([20, 99.9, 99.8])}\n"
                     f"  contingency: {rng.choice(['land', 'return', 'hold'])}\n")
    return "".join(rules)


def draw(seed: int, extra: frozenset[str] | tuple[str, ...] = frozenset(),
         kinds: tuple[str, ...] = ("tree", "python", "plan"), subprocess_share: float = SUBPROCESS_SHARE) -> Case:
    """The case of ``seed``: what it flies, what the operator does and when, what goes wrong."""
    extra = drawn_kinds(extra)
    rng = random.Random(seed)
    rules, questions = _rules(rng, extra) if rng.random() < 0.25 else (None, ())
    mission = draw_mission(rng, kinds, questions=questions)
    horizon = 3.0 + 2.5 * mission.leaves  # s: about how long the mission flies
    actions: list[Action] = []
    commands, weights = zip(*COMMANDS.items(), strict=True)
    for _ in range(rng.choice([0, 0, 1, 1, 2, 3, 4])):
        at = round(rng.uniform(0.0, horizon), 2)
        command = rng.choices(commands, weights)[0]
        argument = ""
        if command == "pause" and rng.random() < 0.8:  # mostly resumed later
            actions.append(Action(round(at + rng.uniform(0.2, 4.0), 2), "resume"))
        elif command == "query":
            argument = rng.choice(["position(self, ?P)", "charge(battery, ?C)", "flight_state(self, ?S)"])
        elif command == "add":
            argument = f"visited(p{rng.randint(1, 3)})"
        elif command == "remove":
            argument = "visited(?X)"
        elif command == "edit":
            if mission.kind == "plan" and rng.random() < 0.5:
                continue
            command, argument = _edit(rng, mission, extra)
        elif command == "load":
            argument = "@mission"  # a new mission drawn for it: written beside the first
        actions.append(Action(at, command, argument))
    faults: list[Fault] = []
    if rng.random() < 0.15:
        faults.append(Fault("link_drop", round(rng.choice([0.0, rng.uniform(0.0, horizon)]), 2),
                            round(rng.uniform(0.5, 8.0), 1)))
    roll = rng.random()
    killed = round(rng.uniform(1.0, max(2.0, 0.7 * horizon)), 2)  # while the mission flies, mostly
    if roll < 0.12:
        faults.append(Fault("crash", killed))
    elif roll < 0.16:
        faults.append(Fault("sigterm", round(rng.uniform(0.0, horizon), 2)))
    elif roll < 0.18:
        faults.append(Fault("sighup", round(rng.uniform(0.0, horizon), 2)))
    elif roll < 0.2 and "edited_resume" in extra and mission.kind == "tree" and mission.points:
        faults.append(Fault("edited_resume", killed))
    elif roll < 0.22 and "foreign_journal" in extra:
        faults.append(Fault("foreign_journal", killed))
    elif roll < 0.26 and "disk_full" in extra:
        faults.append(Fault("disk_full", size=rng.randint(200, 40_000)))
    elif roll < 0.28:
        faults.append(Fault("slow_disk"))
    elif roll < 0.34 and "photo_enospc" in extra and ("TAKE_PHOTO" in mission.text or "\t2000\t" in mission.text
                                                      or "\t206\t" in mission.text):
        faults.append(Fault("photo_enospc", size=rng.randint(0, 2)))
    safety = _safety_rules(rng, extra) if rng.random() < 0.15 else None
    process = rng.random() < subprocess_share
    if process:  # a real process: its faults are signals and a full disk; no commands at simulated times
        actions = []
        faults = [f for f in faults if f.kind in ("crash", "sigterm", "sighup", "disk_full")]
        if not faults and rng.random() < 0.7:
            faults = [Fault(rng.choice(["crash", "sigterm", "sighup"]), killed)]
        if "process_signal" not in extra:  # a signal to a process lands anywhere: see FOUND
            faults = [f if f.kind not in ("sigterm", "sighup") else replace(f, kind="crash") for f in faults]
        if "disk_full" in extra and rng.random() < 0.4:
            faults = [Fault("disk_full", size=rng.randint(2_000, 40_000))]
    fleet: tuple[Mission, ...] = ()
    if not process and rng.random() < FLEET_SHARE:  # drones flying tree missions together, each its own
        fleet = tuple(tree_mission(rng) for _ in range(rng.randint(2, 5)))
        mission, actions, faults, rules, safety = fleet[0], [], [], None, None
    return Case(seed, mission, tuple(sorted(actions, key=lambda a: a.time)), tuple(faults), rules, safety,
                subprocess=process, fleet=fleet)


__all__ = ["COMMANDS", "FOUND", "GATED", "RUNNING", "Action", "Case", "Fault", "draw", "drawn_kinds"]
