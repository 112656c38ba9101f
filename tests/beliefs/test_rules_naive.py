"""Rules against a naive bottom-up evaluator, predicates without arguments included (``d4 :- not(d1).``).

Random stratified programs (``random_programs.generate(..., nullary=True)``: stored and derived predicates of
zero to three arguments) are answered by the memory (from scratch, then maintained after facts are added and
removed) and by ``naive_evaluator.derive`` (every rule applied to every fact until nothing new, level by level);
both must give the same beliefs. The seed is printed; ``AEROEXEC_RULES_SEED=N`` replays it.
"""

from __future__ import annotations

import os
import random
import sys
from pathlib import Path

from aeroexec.beliefs import BeliefMemory, EvaluationRefused, Struct, parse_rules

sys.path.insert(0, str(Path(__file__).parent))
from naive_evaluator import derive  # noqa: E402
from random_programs import Program, generate  # noqa: E402

PROGRAMS = 400


def _query(name: str, arity: int) -> str:
    return f"{name}({', '.join(f'?A{i}' for i in range(arity))})" if arity else name


def ours(program: Program, work: int | None = None) -> list[set[tuple]]:
    memory = BeliefMemory(multivalued=program.stored)
    memory.limit_rules(work)
    for name, row in program.facts:
        memory.add(Struct(name, row))
    memory.add_rules("\n".join(text for text, _ in program.rules), f"program {program.number}")
    answers = []
    for phase in (0, 1):
        answers.append({(name, tuple(s.values())) for name, types in program.derived.items()
                        for s in memory.query_all(_query(name, len(types)))})
        if phase == 0:
            for added, name, row in program.changes:
                (memory.add if added else memory.remove)(Struct(name, row))
    return answers


def naive(program: Program) -> list[set[tuple]]:
    rules = parse_rules("\n".join(text for text, _ in program.rules))
    facts = dict.fromkeys(Struct(name, row) for name, row in program.facts)
    answers = []
    for _ in (0, 1):
        known = derive(rules, list(facts), program.levels)
        answers.append({(f.name, f.args) for f in known if f.name in program.derived})
        for added, name, row in program.changes:
            if added:
                facts[Struct(name, row)] = None
            else:
                facts.pop(Struct(name, row), None)
    return answers


def test_rules_with_predicates_without_arguments_give_the_naive_answers():
    seed = int(os.environ.get("AEROEXEC_RULES_SEED", random.SystemRandom().randrange(1 << 32)))
    print(f"rules naive seed: {seed} (replay: AEROEXEC_RULES_SEED={seed})")
    rng = random.Random(seed)
    nullary = 0
    for number in range(PROGRAMS):
        program = generate(number, rng, nullary=True)
        nullary += any(not types for types in program.derived.values())
        try:
            found = ours(program)
        except Exception as error:  # noqa: BLE001 - the program is shown with the error
            raise AssertionError(f"seed {seed}, program {number}:\n" + "\n".join(t for t, _ in program.rules)
                                 + f"\nfacts: {program.facts}\nraised {type(error).__name__}: {error}") from error
        wanted = naive(program)
        pairs = list(zip(found, wanted, strict=True))
        assert found == wanted, (f"seed {seed}, program {number}:\n" + "\n".join(t for t, _ in program.rules)
                                 + f"\nfacts: {program.facts}\nchanges: {program.changes}\n"
                                 f"aeroexec only: {[sorted(f - w, key=str) for f, w in pairs]}\n"
                                 f"naive only: {[sorted(w - f, key=str) for f, w in pairs]}")
    assert nullary > PROGRAMS // 10  # programs with a derived predicate of no argument were drawn


def test_a_negation_of_a_predicate_without_arguments_is_asked_in_and_out_of_joins():
    memory = BeliefMemory(multivalued={"object": 2})
    memory.add("object(a, b)")
    memory.add_rules("d1 :- object(?C, zzz).\nd4 :- not(d1).\nd5(?C) :- object(?C, ?), not(d1), d4.\n"
                     "d6 :- d4, not(object(?, zzz)).", "zones.rules")
    assert [memory.query_all(q) for q in ("d1", "d4", "d5(?C)", "d6")] == [[], [{}], [{"?C": "a"}], [{}]]
    memory.add("object(x, zzz)")
    assert [memory.query_all(q) for q in ("d1", "d4", "d5(?C)", "d6")] == [[{}], [], [], []]
    memory.remove("object(x, zzz)")
    assert [memory.query_all(q) for q in ("d1", "d4", "d5(?C)", "d6")] == [[], [{}], [{"?C": "a"}], [{}]]


BOUND = 300


def test_rules_under_a_bound_are_refused_with_a_line_or_give_the_naive_answers():
    """The bound of rules in flight, small: every program either gives the naive answers or is refused with the
    line of one of its rules, having spent at most about the bound; never another error."""
    seed = int(os.environ.get("AEROEXEC_RULES_SEED", random.SystemRandom().randrange(1 << 32)))
    print(f"rules bound seed: {seed} (replay: AEROEXEC_RULES_SEED={seed})")
    rng = random.Random(seed)
    outcomes = {"answered": 0, "refused": 0}
    for number in range(PROGRAMS // 2):
        program = generate(number, rng, nullary=True)
        if rng.random() < 0.3:  # one that blows up: goals sharing no variable, over every stored predicate
            goals = [f"{name}({', '.join(f'?B{name}{i}' for i in range(len(types)))})" if types else name
                     for name, types in program.stored.items()]
            program.rules.append((f"p9 :- {', '.join(goals)}.", ""))
            program.derived["p9"] = ()
            program.levels["p9"] = max(program.levels.values(), default=0) + 1
        try:
            found = ours(program, BOUND)
        except EvaluationRefused as refused:
            lines = {f"program {number}:{line}" for line in range(1, len(program.rules) + 1)}
            assert str(refused).split(": ", 1)[0] in lines, str(refused)
            outcomes["refused"] += 1
            continue
        assert found == naive(program), f"seed {seed}, program {number}:\n" + "\n".join(t for t, _ in program.rules)
        outcomes["answered"] += 1
    print(outcomes)
    assert min(outcomes.values()) > PROGRAMS // 40, outcomes  # both outcomes were drawn
