"""The missions a simulation case flies, drawn from its random generator alone: behavior trees built from the
node registry's controls and decorators and the catalog's behaviors, Python missions written against the mission
API, and MAVLink plans (QGC WPL 110) mixing the items real missions hold (take-off, waypoints, loiters, delays,
speed changes, jumps, a landing or a return). Every mission is short (a few simulated seconds to a minute), so a
campaign flies hundreds a minute.

A drawn mission is a :class:`Mission`: its file's text and extension, the goals that each of its leaves may reach
at most once (leaves under no loop nor reactive control), and the points it flies to (a resumed run must fly no
other).
"""

from __future__ import annotations

import random
from dataclasses import dataclass, field

#: Items of real missions (tests/plans/data/real_missions) by MAV_CMD number, with their weight in the draws.
PLAN_ITEMS = {16: 10, 19: 2, 93: 1, 112: 1, 178: 2, 177: 1, 115: 1, 201: 1, 2000: 1, 206: 1}
HOME = (47.3977, 8.5456, 488.0)  # lat, lon, alt (m AMSL) of a plan's home: an open field is made around it


@dataclass(frozen=True)
class Mission:
    """A drawn mission: ``kind`` (tree, python or plan), its file's ``text`` and ``suffix``, the points it flies to
    (``points``, ENU metres; a plan's are geographic) and whether a leaf of it may reach its goal again
    (``repeats``)."""

    kind: str
    text: str
    suffix: str
    points: tuple[tuple[float, float, float], ...] = ()
    repeats: bool = False
    leaves: int = 0
    notes: tuple[str, ...] = field(default_factory=tuple)


def _point(rng: random.Random) -> tuple[float, float, float]:
    """A point near home in the built-in field, clear of its tower and walls (a few metres out, 1-4 m up)."""
    return (round(rng.uniform(-6.0, 6.0), 1), round(rng.uniform(-6.0, 2.5), 1), round(rng.uniform(1.0, 4.0), 1))


class _TreeDraw:
    """One tree's draws: leaves counted, points and loops noted."""

    def __init__(self, rng: random.Random, questions: tuple[str, ...] = ()) -> None:
        self.rng, self.questions = rng, questions
        self.points: list[tuple[float, float, float]] = []
        self.repeats = False
        self.leaves = 0

    def flight_leaf(self) -> str:
        rng = self.rng
        self.leaves += 1
        roll = rng.random()
        if self.questions and rng.random() < 0.25:  # what the rules file derives
            return f'<ForceSuccess><CheckBelief belief="{rng.choice(self.questions)}"/></ForceSuccess>'
        if roll < 0.45:
            point = _point(rng)
            self.points.append(point)
            speed = f' SPEED="{rng.choice([1, 2, 3, 5])}"' if rng.random() < 0.4 else ""
            return f'<GO_TO_POINT COORDINATES="{point[0]}, {point[1]}, {point[2]}"{speed}/>'
        if roll < 0.6:
            return f'<ROTATE ANGLE="{rng.choice([0, 45, 90, -90, 180])}"/>'
        if roll < 0.72:
            return f'<WAIT DURATION="{rng.choice([0.5, 1, 2])}"/>'
        if roll < 0.8:
            return ('<CheckBelief belief="charge(battery, ?C), ?C > '
                    f'{rng.choice([10, 50, 99.9])}"/>')
        if roll < 0.86:
            return '<QueryBelief belief="position(self, ?here)"/>'
        if roll < 0.9:
            return f'<AddBelief belief="visited(p{rng.randint(1, 3)})"/>'
        if roll < 0.94:
            return f'<Sleep msec="{rng.choice([100, 500, 1500])}"/>'
        if roll < 0.96:
            return "<AlwaysFailure/>"
        if roll < 0.98:
            return "<TAKE_PHOTO/>"
        return "<AlwaysSuccess/>"

    def body(self, depth: int) -> str:
        """A subtree flown in the air (after TAKE_OFF, before LAND)."""
        rng = self.rng
        if depth <= 0 or rng.random() < 0.35:
            return self.flight_leaf()
        roll = rng.random()
        children = "".join(self.body(depth - 1) for _ in range(rng.randint(1, 3)))
        if roll < 0.35:
            return f"<Sequence>{children}</Sequence>"
        if roll < 0.5:
            return f"<Fallback>{children}<AlwaysSuccess/></Fallback>"
        if roll < 0.6:
            return f"<ForceSuccess>{self.body(depth - 1)}</ForceSuccess>"
        if roll < 0.68:
            self.repeats = True
            return f'<Repeat num_cycles="{rng.choice([1, 2])}"><Sequence>{children}</Sequence></Repeat>'
        if roll < 0.75:
            self.repeats = True
            return (f'<RetryUntilSuccessful num_attempts="{rng.choice([1, 2])}"><Sequence>{children}</Sequence>'
                    f"</RetryUntilSuccessful>")
        if roll < 0.82:
            return f'<Timeout msec="{rng.choice([2000, 8000, 20000])}"><Sequence>{children}</Sequence></Timeout>'
        if roll < 0.88:
            return f"<Inverter><Inverter>{self.body(depth - 1)}</Inverter></Inverter>"
        if roll < 0.94:
            self.repeats = True
            return ('<ReactiveSequence><CheckBelief belief="charge(battery, ?C), ?C > 5"/>'
                    f"<Sequence>{children}</Sequence></ReactiveSequence>")
        return (f'<IfThenElse><CheckBelief belief="charge(battery, ?C), ?C > {rng.choice([5, 99.99])}"/>'
                f"<Sequence>{children}</Sequence>{self.flight_leaf()}</IfThenElse>")


def tree_mission(rng: random.Random, airborne: bool = False, questions: tuple[str, ...] = ()) -> Mission:
    """A behavior tree: TAKE_OFF (none when ``airborne``: a mission loaded in flight), a random body of controls,
    decorators and leaves, and (mostly) LAND."""
    draw = _TreeDraw(rng, questions)
    altitude = rng.choice([1.5, 2, 3, 4])
    body = "".join(draw.body(rng.randint(1, 3)) for _ in range(rng.randint(1, 3)))
    if questions:  # the rules are asked in the air at least once
        body = f'<ForceSuccess><CheckBelief belief="{rng.choice(questions)}"/></ForceSuccess>{body}'
        draw.leaves += 1
    land = "<LAND/>" if rng.random() < 0.85 else ""  # else the end of the flight lands it
    take_off = "" if airborne else f'<TAKE_OFF ALTITUDE="{altitude}"/>'
    text = (f'<root BTCPP_format="4" main_tree_to_execute="Main">\n  <BehaviorTree ID="Main">\n'
            f'    <Sequence name="campaign">\n      {take_off}\n      {body}\n      {land}\n'
            f"    </Sequence>\n  </BehaviorTree>\n</root>\n")
    return Mission("tree", text, ".xml", tuple(draw.points), draw.repeats, draw.leaves + 2)


def python_mission(rng: random.Random, airborne: bool = False, questions: tuple[str, ...] = ()) -> Mission:
    """A Python mission through ``aeroexec.engine.api``: take off, go to points (some that fail), wait, ask
    beliefs, land; some raise, some catch what failed."""
    points = [_point(rng) for _ in range(rng.randint(1, 4))]
    lines = ["import aeroexec.engine.api as api", "", "", "def mission():",
             f"    api.execute_behavior('TAKE_OFF', altitude={rng.choice([1.5, 2, 3])})" if not airborne else
             "    api.wait(0.1)"]
    for point in points:
        lines.append(f"    api.execute_behavior('GO_TO_POINT', coordinates={list(point)})")
        roll = rng.random()
        if roll < 0.2:
            lines.append(f"    api.wait({rng.choice([0.5, 1.0, 2.0])})")
        elif roll < 0.3:
            lines.append("    found, _ = api.consult_belief('charge(battery, ?C), ?C > 50')")
            lines.append("    if not found:")
            lines.append("        raise RuntimeError('battery below 50 %')")
        elif roll < 0.4:
            lines.append(f"    api.add_belief('visited(p{rng.randint(1, 3)})')")
        elif roll < 0.45:
            lines.append("    api.execute_behavior('ROTATE', angle=90)")
        elif roll < 0.6 and questions:
            lines.append(f"    api.consult_belief({rng.choice(questions)!r})")
    if rng.random() < 0.1:
        lines.append("    raise RuntimeError('the mission gives up')")
    if rng.random() < 0.85:
        lines.append("    api.execute_behavior('LAND')")
    return Mission("python", "\n".join(lines) + "\n", ".py", tuple(points), False, len(points) + 2)


def plan_mission(rng: random.Random) -> Mission:
    """A MAVLink plan (QGC WPL 110) around :data:`HOME`: take-off, a mix of the items real missions hold, then a
    landing or a return to launch."""
    lat, lon, alt = HOME
    rows = [(0, 1, 0, 16, 0, 0, 0, 0, lat, lon, alt, 1)]  # home

    def add(frame: int, command: int, p1: float = 0, p2: float = 0, p3: float = 0, p4: float = 0,
            x: float = 0.0, y: float = 0.0, z: float = 0.0) -> None:
        rows.append((len(rows), 0, frame, command, p1, p2, p3, p4, x, y, z, 1))

    add(3, 22, z=rng.choice([3, 5, 8]))
    kinds, weights = zip(*PLAN_ITEMS.items(), strict=True)
    points = []
    for _ in range(rng.randint(1, 6)):
        command = rng.choices(kinds, weights)[0]
        north, east = rng.uniform(-20, 20), rng.uniform(-20, 20)
        where = (round(lat + north / 111_320.0, 7), round(lon + east / 75_000.0, 7), round(rng.uniform(3, 10), 1))
        if command in (16, 19):
            points.append(where)
            add(3, command, rng.choice([0, 1]) if command == 16 else rng.choice([1, 2]), *(0, 0, 0), *where)
        elif command in (93, 112):
            add(2, command, rng.choice([1, 2]))
        elif command == 178:
            add(2, command, 1, rng.choice([2, 4, 6]), -1)
        elif command == 177 and len(rows) > 3:
            add(2, command, rng.randint(2, len(rows) - 1), 1)
        elif command == 115:
            add(2, command, rng.choice([0, 90, 180]), 20, 0, 0)
        elif command == 201:
            add(3, command, *(0, 0, 0, 0), *where)
        elif command == 2000:
            add(2, command, 0, 0, 1)
        elif command == 206:
            add(2, command, 5, 0, 1)
    if rng.random() < 0.5:
        add(3, 21, x=rows[-1][8] or lat, y=rows[-1][9] or lon)
    else:
        add(2, 20)
    text = "QGC WPL 110\n" + "".join("\t".join(str(v) for v in row) + "\n" for row in rows)
    return Mission("plan", text, ".waypoints", tuple(points), True, len(rows))


def draw_mission(rng: random.Random, kinds: tuple[str, ...] = ("tree", "python", "plan"),
                 airborne: bool = False, questions: tuple[str, ...] = ()) -> Mission:
    """A mission of one of ``kinds``: trees the most, then Python missions, then plans (``airborne``: one loaded
    in flight, without a take-off; ``questions``: what a rules file derives, for the mission to ask)."""
    weights = {"tree": 6, "python": 3, "plan": 2}
    kind = rng.choices(kinds, [weights[k] for k in kinds])[0]
    if kind == "plan":
        return plan_mission(rng)
    return {"tree": tree_mission, "python": python_mission}[kind](rng, airborne, questions)


__all__ = ["HOME", "PLAN_ITEMS", "Mission", "draw_mission", "plan_mission", "python_mission", "tree_mission"]
