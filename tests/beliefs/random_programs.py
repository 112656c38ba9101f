"""Random stratified rule programs over random facts, written both in aeroexec's rule language and in Prolog.

A program has stored predicates ``eN`` and derived ones ``pN`` (each on a level: a rule reads derived
predicates of its own level or below, and negates only lower ones, so every program can be stratified),
typed arguments (atoms or integers: ``<`` compares integers only, as Prolog's would raise on atoms),
recursion, negation, comparisons, ``=``, constants in goals and heads, anonymous variables under negation;
and a list of changes (facts added and removed) applied after the first answers, so maintenance by
differences is checked as well as evaluation from scratch.
"""

from __future__ import annotations

import random
from dataclasses import dataclass, field

ATOMS = ("a", "b", "c", "d")
_PROLOG_EQUALITY = {"!=": "\\==", "=": "=="}
INTS = (0, 1, 2, 3)


@dataclass
class Program:
    number: int
    stored: dict[str, tuple[str, ...]]  # name -> argument types ("a" or "i")
    derived: dict[str, tuple[str, ...]]
    rules: list[tuple[str, str]] = field(default_factory=list)  # (aeroexec text, prolog text)
    facts: list[tuple[str, tuple]] = field(default_factory=list)
    changes: list[tuple[bool, str, tuple]] = field(default_factory=list)  # (added?, predicate, row)
    levels: dict[str, int] = field(default_factory=dict)  # derived predicate -> its level (negates only lower ones)

    def prefix(self, name: str) -> str:
        return f"g{self.number}_{name}"


def _value(kind: str, rng: random.Random):
    return rng.choice(ATOMS if kind == "a" else INTS)


def _fmt(value) -> str:
    return str(value)


def _call(name: str, args: list[str]) -> str:
    """``name(a, b)``, or ``name`` alone for a predicate without arguments (Prolog's ``p()`` is not ``p``)."""
    return f"{name}({', '.join(args)})" if args else name


def generate(number: int, rng: random.Random, nullary: bool = False) -> Program:
    """Program ``number``; ``nullary``: predicates without arguments too (``d1 :- e0(?X, zzz).``, ``d4 :- not(d1).``),
    drawn from ``rng`` only then, so the programs of a seed stay the same without it."""
    low = 0 if nullary else 1
    stored = {f"e{i}": tuple(rng.choice("ai") for _ in range(rng.randint(low, 3))) for i in range(rng.randint(2, 4))}
    levels = rng.randint(1, 3)
    derived: dict[str, tuple[str, ...]] = {}
    level_of: dict[str, int] = {}
    for i in range(rng.randint(2, 5)):
        name = f"p{i}"
        derived[name] = tuple(rng.choice("ai") for _ in range(rng.randint(0, 3) or (0 if nullary else 1)))
        level_of[name] = min(levels - 1, i * levels // 5)
    program = Program(number, stored, derived, levels=level_of)
    for name in derived:
        for _ in range(rng.randint(1, 3)):
            rule = _rule(program, name, level_of, rng)
            if rule is not None:
                program.rules.append(rule)
    for name, types in stored.items():
        for _ in range(rng.randint(2, 14)):
            program.facts.append((name, tuple(_value(t, rng) for t in types)))
    program.facts = list(dict.fromkeys(program.facts))
    present = set(program.facts)
    for _ in range(rng.randint(1, 6)):
        if present and rng.random() < 0.5:
            fact = rng.choice(sorted(present, key=str))
            present.discard(fact)
            program.changes.append((False, *fact))
        else:
            name = rng.choice(sorted(stored))
            fact = (name, tuple(_value(t, rng) for t in stored[name]))
            if fact not in present:
                present.add(fact)
                program.changes.append((True, *fact))
    return program


def _rule(program: Program, head: str, level_of: dict[str, int], rng: random.Random) -> tuple[str, str] | None:
    level = level_of[head]
    positive = [n for n in program.stored] + [n for n, lv in level_of.items() if lv <= level]
    negative = [n for n in program.stored] + [n for n, lv in level_of.items() if lv < level]
    types = {**program.stored, **program.derived}
    variables: dict[str, str] = {}  # name -> type
    ours: list[str] = []
    theirs: list[str] = []
    counter = [0]

    def fresh(kind: str) -> str:
        counter[0] += 1
        name = f"V{counter[0]}"
        variables[name] = kind
        return name

    def argument(kind: str, allow_new: bool) -> tuple[str, str]:
        known = [v for v, t in variables.items() if t == kind]
        roll = rng.random()
        if known and roll < 0.5:
            v = rng.choice(known)
            return f"?{v}", v
        if (roll < 0.6 if known else roll < 0.15) or not allow_new:
            value = _fmt(_value(kind, rng))
            return value, value
        v = fresh(kind)
        return f"?{v}", v

    for _ in range(rng.randint(1, 3)):
        name = rng.choice(positive)
        args = [argument(t, True) for t in types[name]]
        ours.append(_call(name, [a for a, _ in args]))
        theirs.append(_call(program.prefix(name), [b for _, b in args]))
    if rng.random() < 0.4:  # a comparison
        ints = [v for v, t in variables.items() if t == "i"]
        anything = list(variables)
        op = rng.choice(["<", "<=", ">", ">=", "!=", "=", "!="])
        if op in ("<", "<=", ">", ">=") and ints:
            a = rng.choice(ints)
            b_ours, b_theirs = (f"?{rng.choice(ints)}",) * 2 if rng.random() < 0.5 else (str(rng.choice(INTS)),) * 2
            b_theirs = b_theirs.lstrip("?")
            ours.append(f"?{a} {op} {b_ours}")
            theirs.append(f"{a} {op.replace('<=', '=<')} {b_theirs}")
        elif op in ("!=", "=") and anything:
            a = rng.choice(anything)
            same = [v for v in anything if variables[v] == variables[a]]
            if rng.random() < 0.5:
                b = rng.choice(same)
                other = b
                ours.append(f"?{a} {op} ?{b}")
            else:
                other = _fmt(_value(variables[a], rng))
                ours.append(f"?{a} {op} {other}")
            theirs.append(f"{a} {_PROLOG_EQUALITY[op]} {other}")
    # a negation of a stored or lower derived predicate
    if rng.random() < 0.45 and (variables or any(not types[n] for n in negative)):
        name = rng.choice(negative)
        args = []
        for t in types[name]:
            known = [v for v, k in variables.items() if k == t]
            roll = rng.random()
            if known and roll < 0.7:
                v = rng.choice(known)
                args.append((f"?{v}", v))
            elif roll < 0.85:
                value = _fmt(_value(t, rng))
                args.append((value, value))
            else:
                args.append(("?", "_"))
        ours.append(f"not({_call(name, [a for a, _ in args])})")
        call = _call(program.prefix(name), [b for _, b in args])
        tabled = name in program.derived and all(b != "_" for _, b in args)
        theirs.append(f"tnot({call})" if tabled else f"\\+ {call}")
    head_args = []
    for t in program.derived[head]:
        known = [v for v, k in variables.items() if k == t]
        if known and rng.random() < 0.85:
            v = rng.choice(known)
            head_args.append((f"?{v}", v))
        else:
            value = _fmt(_value(t, rng))
            head_args.append((value, value))
    ours_text = f"{_call(head, [a for a, _ in head_args])} :- {', '.join(ours)}."
    theirs_text = f"{_call(program.prefix(head), [b for _, b in head_args])} :- {', '.join(theirs)}."
    return ours_text, theirs_text


def prolog(programs: list[Program]) -> str:
    """One Prolog file answering every program, before and after its changes: lines ``N phase pred args``."""
    out = [":- set_prolog_flag(verbose, silent).", ":- style_check(-singleton).", ":- style_check(-discontiguous)."]
    for program in programs:
        for name, types in program.stored.items():
            out.append(f":- dynamic {program.prefix(name)}/{len(types)}.")
        for name, types in program.derived.items():
            out.append(f":- table {program.prefix(name)}/{len(types)}.")
        for name, row in program.facts:
            out.append(f"{_call(program.prefix(name), list(map(_fmt, row)))}.")
        for _, theirs in program.rules:
            out.append(theirs)
        for name, types in program.derived.items():  # a derived predicate without a rule that applies is empty
            out.append(f"{_call(program.prefix(name), ['_' for _ in types])} :- fail.")
    out.append("show(N, Phase, Name, Arity, Pred) :- length(Args, Arity), Goal =.. [Pred|Args],")
    out.append("    findall(Args, Goal, All), sort(All, Sorted),")
    out.append("    forall(member(A, Sorted), (atomic_list_concat(A, ',', Text), format('~w ~w ~w ~w~n', "
               "[N, Phase, Name, Text]))).")
    out.append("main :-")
    for program in programs:
        for phase in (0, 1):
            for name, types in program.derived.items():
                out.append(f"    show({program.number}, {phase}, {name}, {len(types)}, {program.prefix(name)}),")
            if phase == 0:
                for added, name, row in program.changes:
                    fact = _call(program.prefix(name), list(map(_fmt, row)))
                    out.append(f"    {'assertz' if added else 'retract'}({fact}),")
                out.append("    abolish_all_tables,")
    out.append("    true.")
    return "\n".join(out) + "\n"
