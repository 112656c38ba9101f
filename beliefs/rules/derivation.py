"""The beliefs rules derive, kept up to date: bottom-up semi-naive evaluation, maintained by differences.

A :class:`RuleBook` holds a memory's rules in strata (``beliefs/rules/program.py``) and one relation per derived
predicate. Nothing is derived until a derived predicate is asked; then each stratum it needs is brought up
to date from what changed since (the journals of the relations it reads): added beliefs are followed
semi-naively from the new rows alone, removed ones by delete-and-rederive (DRed), a change under a
negation or of a computed predicate by evaluating the stratum again. While nothing a rule reads has
changed, asking costs a look-up of versions.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from itertools import filterfalse
from typing import Any

from aeroexec.beliefs.errors import EvaluationRefused
from aeroexec.beliefs.expression import Conjunction, Goal, Rule
from aeroexec.beliefs.query import CompiledQuery
from aeroexec.beliefs.relation import Journal, Relation, Relations
from aeroexec.beliefs.rules.budget import Budget
from aeroexec.beliefs.rules.joins import EACH_COST, evaluate
from aeroexec.beliefs.rules.program import Signature, Stratum
from aeroexec.beliefs.terms import Struct, Var, match

#: Most beliefs one derived predicate may hold (about 200 bytes each with its indexes): past it, refused
MAX_DERIVED = 1_000_000
STORED = "#stored"  # the stored beliefs of a derived predicate, read by its rules as a rule of their own
DELTA = "#delta"  # the rows a round added (or removed), read by one goal of a rule
GONE = "#gone"  # the rows of a derived predicate DRed removed, read by a first goal to find those still derived


class Delta:
    """Rows added and removed, netted (an add then a remove cancel)."""

    __slots__ = ("added", "removed")

    def __init__(self) -> None:
        self.added: dict[tuple, None] = {}
        self.removed: dict[tuple, None] = {}

    def merge(self, added: Iterable[tuple], removed: Iterable[tuple]) -> None:
        for row in added:
            if row in self.removed:
                del self.removed[row]
            else:
                self.added[row] = None
        for row in removed:
            if row in self.added:
                del self.added[row]
            else:
                self.removed[row] = None

    def __bool__(self) -> bool:
        return bool(self.added or self.removed)


class _Layer:
    """A stratum as evaluated: its compiled rules, the changes of its inputs not yet followed."""

    def __init__(self, stratum: Stratum, rules: list[Rule]) -> None:
        self.stratum = stratum
        self.rules = rules  # the stratum's rules, and "p(?1..) :- p#stored(?1..)" for each of its predicates
        self.predicates = set(stratum.predicates)
        self.pending: dict[Signature, Delta] = {}
        self.valid = False
        self.refused: tuple[Any, EvaluationRefused] | None = None  # (the inputs' stamp, the refusal) when refused
        self.sources: list[_Layer] = []  # the strata it reads directly (those they read are found when asked)
        self.readers: list[_Layer] = []  # the strata that read it directly, lowest first


class RuleBook:
    """The rules of one belief memory and the relations of the predicates they derive."""

    def __init__(self, stored: Relations, exclusive: Callable[[str], bool], computed: dict,
                 prepare: Callable[[Conjunction], Conjunction]) -> None:
        self.stored = stored
        self.rules: list[Rule] = []
        self.derived: dict[Signature, Relation] = {}
        self.view = Relations()
        self._exclusive = exclusive
        self._computed = computed
        self._prepare = prepare
        self._layers: list[_Layer] = []
        self._layer_of: dict[Signature, _Layer] = {}
        self._readers: dict[Signature, list[tuple[_Layer, Signature]]] = {}  # stored relation -> who reads it
        self._variants: dict[tuple, CompiledQuery] = {}
        self._stamp: Any = None
        self._epoch = 0
        self._seen_epoch = -1
        self._names: set[str] = set()
        self._read: list[Relation] = []  # the stored relations the rules read (those that exist)
        self._needed: dict[tuple, list[_Layer]] = {}  # the derived predicates asked -> the strata they need
        #: what one ask may spend (renewed at each ask): none by default; an engine bounds it (rules in flight)
        self.budget = Budget()

    # -- the program ------------------------------------------------------------------------------------------------
    def load(self, rules: list[Rule], strata: list[Stratum]) -> None:
        """Take ``rules`` (already checked) in ``strata``; derived beliefs are found again when next asked."""
        old = self.derived
        self.rules = list(rules)
        self.derived = {}
        self._names = {name for s in strata for name, _ in s.predicates}
        self._layers, self._layer_of, self._readers, self._variants, self._needed = [], {}, {}, {}, {}
        for stratum in strata:
            own = []
            for name, arity in stratum.predicates:
                relation = Relation(name, arity, False, lazy=True)
                if (name, arity) in old:  # versions only grow: a cached answer is never taken for a new one
                    relation.version = old[(name, arity)].version + 1
                self.derived[(name, arity)] = relation
                args = tuple(Var(f"?{i}") for i in range(arity))
                own.append(Rule(Struct(name, args), Conjunction((Goal(Struct(name + STORED, args)),))))
            prepared = [Rule(r.head, self._prepare(r.body), r.file, r.line) for r in stratum.rules]
            layer = _Layer(stratum, prepared + own)
            for signature in stratum.predicates:
                self._layer_of[signature] = layer
            self._layers.append(layer)
        for layer in self._layers:  # direct sources only: a chain of N strata keeps N links, not N * N / 2
            sources: dict[int, _Layer] = {}
            for signature in self._inputs(layer):
                source = self._layer_of.get(signature)
                if source is not None and source is not layer:
                    sources[source.stratum.index] = source
                if signature[0].endswith(STORED):
                    self._readers.setdefault((signature[0][: -len(STORED)], signature[1]), []).append(
                        (layer, signature))
                elif signature not in self._layer_of:
                    self._readers.setdefault(signature, []).append((layer, signature))
            layer.sources = list(sources.values())
            for source in layer.sources:
                source.readers.append(layer)
        for rel in self.stored.values():
            rel.journal = None  # a relation the rules read is read whole when next asked; the others kept no journal
        self.view = Relations()
        self._seen_epoch = -1
        self._stamp = None

    def _inputs(self, layer: _Layer) -> set[Signature]:
        found: set[Signature] = set()
        for rule in layer.rules:
            found |= rule.body.predicates
        return found - layer.predicates

    def is_derived(self, signature: Signature) -> bool:
        return signature in self.derived

    def share(self, signatures: set[Signature]) -> None:
        """Rules reading ``signatures`` (shared beliefs: rows the memory answers from without storing them, so no
        journal tells their changes) are evaluated again whenever asked, as rules reading a computed predicate."""
        volatile: set[Signature] = set()
        for layer in self._layers:  # bottom-up: a stratum reading a volatile one is volatile too
            stratum = layer.stratum
            if stratum.reads & signatures or stratum.reads & volatile:
                stratum.volatile = True
                layer.valid = False
            if stratum.volatile:
                volatile.update(stratum.predicates)

    def volatile(self, signature: Signature) -> bool:
        layer = self._layer_of.get(signature)
        return layer is not None and layer.stratum.volatile

    # -- asking ------------------------------------------------------------------------------------------------------
    def ready(self, signatures: tuple[Signature, ...]) -> Relations:
        """The relations (stored and derived) with the strata of ``signatures`` up to date.

        While no relation the rules read has changed, this is a sum of their versions and a look at the needed
        strata: asking a derived predicate again costs a few microseconds.
        """
        stored = self.stored
        if self._seen_epoch != stored.epoch:
            self._mirror()
        stamp = stored.epoch + sum(map(_version, self._read))
        if stamp != self._stamp:
            self._collect()
            self._stamp = stamp
        needed = self._needed.get(signatures)
        if needed is None:
            needed = self._needed[signatures] = self._strata_of(signatures)
        if self.budget.per_ask:
            self.budget.spent = 0
        for layer in needed:
            if not layer.valid or layer.pending or layer.stratum.volatile:
                if layer.refused is not None and layer.refused[0] == stamp and not layer.stratum.volatile:
                    raise layer.refused[1]  # refused for these very inputs: asking again costs nothing
                whole = self.budget.spent == 0  # the stratum has the whole bound to itself
                try:
                    self._update(layer)
                except BaseException as error:  # a rule past the limits: evaluated again from scratch when next asked
                    self._invalidate(layer)
                    # refused with the whole bound: so it is again while the beliefs it reads are the same
                    layer.refused = (stamp, error) if whole and isinstance(error, EvaluationRefused) else None
                    raise
                layer.refused = None
        self.view.epoch = stored.epoch * 4096 + self._epoch
        return self.view

    def _strata_of(self, signatures: tuple[Signature, ...]) -> list[_Layer]:
        """The strata an ask of ``signatures`` brings up to date, lowest first."""
        below: set[int] = set()
        todo = [layer for signature in signatures if (layer := self._layer_of.get(signature)) is not None]
        while todo:
            layer = todo.pop()
            if layer.stratum.index not in below:
                below.add(layer.stratum.index)
                todo.extend(layer.sources)
        return [self._layers[i] for i in sorted(below)]

    def trial(self) -> None:
        """Derive every derived predicate (before flight), each stratum with the whole bound of :attr:`budget`, and
        raise :class:`EvaluationRefused` for the first that would pass it when asked first, from scratch: alone, or
        with the strata it reads (each predicate is asked on its own in flight, not all of them in one step)."""
        budget = self.budget
        cost: dict[int, int] = {}
        for layer in self._layers:  # lowest first: those it reads are done, its own work is measured alone
            budget.spent = 0
            self.ready(layer.stratum.predicates[:1])
            cost[layer.stratum.index] = budget.spent
            budget.spent = 0
            if budget.work is None:
                continue
            total = sum(cost[below.stratum.index] for below in self._strata_of(layer.stratum.predicates[:1]))
            if total > budget.work:
                rule = _named(layer, layer.rules[0])
                raise EvaluationRefused(f"asking {rule.head.name} evaluates its rules and those it reads in {total:,} "
                                        f"units of work, more than {budget.work:,} in one ask{budget.why}: refused",
                                        rule.file, rule.line)

    def _invalidate(self, layer: _Layer) -> None:
        """``layer`` and every stratum reading it, evaluated again from scratch when next asked (a stratum that
        stopped half-way never hands half its changes on)."""
        todo = [layer]
        while todo:
            current = todo.pop()
            if current.valid or current is layer:
                current.valid = False
                current.pending = {}
                todo.extend(current.readers)

    def rows(self, signature: Signature) -> Relation:
        """The derived relation of ``signature``, up to date."""
        self.ready((signature,))
        return self.derived[signature]

    def _mirror(self) -> None:
        self._read = [rel for signature in self._readers if (rel := self.stored.get(signature)) is not None]
        view = self.view
        for signature, rel in self.stored.items():
            if signature in self.derived:
                view[(signature[0] + STORED, signature[1])] = rel
            else:
                view[signature] = rel
        view.update(self.derived)
        self._seen_epoch = self.stored.epoch

    def _collect(self) -> None:
        """Hand the changes of the stored relations the rules read to the strata that read them."""
        for signature, readers in self._readers.items():
            rel = self.stored.get(signature)
            if rel is None:
                continue
            if rel.journal is None:  # not read yet: all of it is new
                rel.journal = Journal()
                added, removed = dict(rel.rows), {}
            else:
                added, removed = rel.journal.take()
            if added or removed:
                for layer, name in readers:
                    if layer.valid:
                        layer.pending.setdefault(name, Delta()).merge(added, removed)

    # -- evaluating ----------------------------------------------------------------------------------------------------
    def _update(self, layer: _Layer) -> None:
        pending, layer.pending = layer.pending, {}
        stratum = layer.stratum
        if not layer.valid or stratum.volatile or any(s in stratum.negated for s in pending):
            if layer.valid:  # what it held, to tell the strata above what changed (a copy: counted as work)
                self.budget.charge(sum(len(self.derived[p].rows) for p in stratum.predicates), _named(
                    layer, layer.rules[0]))
            before = {p: dict(self.derived[p].rows) for p in stratum.predicates} if layer.valid else None
            self._compute(layer)
            layer.valid = True
            if before is None:
                changes = {p: (dict(self.derived[p].rows), {}) for p in stratum.predicates}
            else:
                changes = {p: ({r: None for r in self.derived[p].rows if r not in before[p]},
                               {r: None for r in before[p] if r not in self.derived[p].rows})
                           for p in stratum.predicates}
        elif any(delta.removed for delta in pending.values()):
            changes = self._dred(layer, pending)
        else:
            changes = {p: ({}, {}) for p in stratum.predicates}
            seeds = self._seeds(layer, {s: d.added for s, d in pending.items()})
            self._saturate(layer, seeds, changes)
        for signature, (added, removed) in changes.items():
            if added or removed:
                self._resized(signature)
                for other in layer.readers:
                    if other.valid and signature in other.stratum.reads:
                        other.pending.setdefault(signature, Delta()).merge(added, removed)

    def _compute(self, layer: _Layer) -> None:
        for signature in layer.stratum.predicates:
            old = self.derived[signature]
            fresh = Relation(old.name, old.arity, False, lazy=True)
            fresh.version = old.version + 1
            self.derived[signature] = self.view[signature] = fresh
        found: dict[Signature, dict[tuple, None]] = {p: {} for p in layer.predicates}
        for i, rule in enumerate(layer.rules):
            found[rule.head.signature].update(dict.fromkeys(
                evaluate(self._variant(layer, i, None), self.view, rule, self.budget, _named(layer, rule))))
        self._saturate(layer, found, None)

    def _seeds(self, layer: _Layer, inputs: dict[Signature, dict]) -> dict[Signature, dict[tuple, None]]:
        """New rows of the stratum derived with one goal reading only the rows of ``inputs`` (rows added to a
        relation, or a round's new rows), the other goals everything."""
        found: dict[Signature, dict[tuple, None]] = {p: {} for p in layer.predicates}
        inputs = {s: rows for s, rows in inputs.items() if rows}
        if not inputs:
            return found
        with self._deltas(inputs):
            for i, rule in enumerate(layer.rules):
                rows = self.derived[rule.head.signature].rows
                new = found[rule.head.signature]
                for j, signature in _positive_goals(rule):
                    if signature in inputs:
                        found_now = dict.fromkeys(filterfalse(
                            rows.__contains__, evaluate(self._variant(layer, i, j), self.view, rule, self.budget,
                                                        _named(layer, rule), (signature[0] + DELTA, signature[1]))))
                        if new:
                            new.update(found_now)
                        else:
                            new = found[rule.head.signature] = found_now
        return found

    def _saturate(self, layer: _Layer, delta: dict[Signature, dict[tuple, None]],
                  changes: dict[Signature, tuple[dict, dict]] | None) -> None:
        """Add ``delta`` (rows not stored yet: every caller's and each round's are found so) and follow it
        semi-naively until nothing new is derived (``changes``: what was added and removed, kept up to date; None
        when the caller does not need it)."""
        recursive = layer.stratum.recursive
        while any(delta.values()):
            for signature, rows in delta.items():
                if rows:
                    rel = self.derived[signature]
                    self.budget.charge(len(rows), _rule_of(layer, signature))  # stored and indexed
                    if len(rel.rows) + len(rows) > MAX_DERIVED:
                        rule = _rule_of(layer, signature)
                        raise EvaluationRefused(f"the rules of {signature[0]} derive more than {MAX_DERIVED:,} beliefs "
                                                f"(the limit of one derived predicate, for memory): refused",
                                                rule.file, rule.line)
                    rel.insert_new(rows)
                    if changes is not None:
                        added, removed = changes[signature]
                        for row in rows:
                            if row in removed:
                                del removed[row]
                            else:
                                added[row] = None
            if not recursive:
                return
            delta = self._seeds(layer, delta)

    def _dred(self, layer: _Layer, pending: dict[Signature, Delta]) -> dict[Signature, tuple[dict, dict]]:
        """Delete and rederive: remove what the removed rows could have derived, derive again what still holds,
        then follow the added rows."""
        removed_inputs = {s: d.removed for s, d in pending.items() if d.removed}
        restored = [(self.view.get(s), rows) for s, rows in removed_inputs.items() if self.view.get(s) is not None]
        for rel, rows in restored:  # the inputs as they were, for finding what was derived from the removed rows
            journal, rel.journal = rel.journal, None
            rel.insert_new([r for r in rows if r not in rel.rows])
            rel.journal = journal
        gone: dict[Signature, dict[tuple, None]] = {p: {} for p in layer.predicates}
        try:
            frontier = self._matches(layer, removed_inputs, gone)
            while layer.stratum.recursive and any(frontier.values()):
                frontier = self._matches(layer, {s: r for s, r in frontier.items() if r}, gone)
        finally:
            for rel, rows in restored:
                journal, rel.journal = rel.journal, None
                for row in rows:
                    if row in rel.rows:
                        rel.delete(row)
                rel.journal = journal
        changes: dict[Signature, tuple[dict, dict]] = {p: ({}, dict(gone[p])) for p in layer.predicates}
        for signature, rows in gone.items():
            rel = self.derived[signature]
            for row in rows:
                rel.delete(row)
        again: dict[Signature, dict[tuple, None]] = {p: {} for p in layer.predicates}
        with _Deltas(self.view, {s: rows for s, rows in gone.items() if rows}, GONE):
            for i, rule in enumerate(layer.rules):
                signature = rule.head.signature
                if not gone[signature]:
                    continue
                if _flat_head(rule.head):  # the rows still derived, set at a time: the body joined with the gone rows
                    rows = self.derived[signature].rows
                    again[signature].update(dict.fromkeys(filterfalse(rows.__contains__, evaluate(
                        self._variant(layer, i, GONE), self.view, rule, self.budget, _named(layer, rule),
                        (signature[0] + GONE, signature[1])))))
                    continue
                query = self._variant(layer, i, None)
                self.budget.charge(len(gone[signature]) * EACH_COST, _named(layer, rule))
                for row in gone[signature]:
                    bindings: dict = {}
                    if match(rule.head.args, row, bindings) and query.first(self.view, bindings) is not None:
                        again[signature][row] = None
        seeds = self._seeds(layer, {s: d.added for s, d in pending.items() if d.added})
        for signature, rows in seeds.items():
            again[signature].update(rows)
        self._saturate(layer, again, changes)
        return changes

    def _matches(self, layer: _Layer, inputs: dict[Signature, dict], gone: dict[Signature, dict[tuple, None]]
                 ) -> dict[Signature, dict[tuple, None]]:
        """Rows of the stratum (still stored) that a rule derives with one goal on the rows of ``inputs``, the
        relations as they were (rows removed put back, so no goal is answered through an exclusive key)."""
        found: dict[Signature, dict[tuple, None]] = {p: {} for p in layer.predicates}
        with self._deltas(inputs):
            for i, rule in enumerate(layer.rules):
                signature = rule.head.signature
                rel = self.derived[signature]
                for j, goal in _positive_goals(rule):
                    if goal in inputs:
                        for row in evaluate(self._variant(layer, i, j, exclusive=False), self.view, rule,
                                            self.budget, _named(layer, rule), (goal[0] + DELTA, goal[1])):
                            if row in rel.rows and row not in gone[signature]:
                                gone[signature][row] = None
                                found[signature][row] = None
        return found

    # -- pieces --------------------------------------------------------------------------------------------------------
    def _variant(self, layer: _Layer, i: int, j: int | str | None, exclusive: bool = True) -> CompiledQuery:
        """Rule ``i`` of a stratum compiled with its ``j``-th literal reading the delta relation (``j`` GONE: with a
        first goal reading the rows of its head that DRed removed, ``head#gone``)."""
        key = (layer.stratum.index, i, j, exclusive)
        query = self._variants.get(key)
        if query is None:
            body = layer.rules[i].body
            if j == GONE:
                head = layer.rules[i].head
                body = Conjunction((Goal(Struct(head.name + GONE, head.args)), *body.literals), body.text)
            elif j is not None:
                literals = list(body.literals)
                goal = literals[j].term
                literals[j] = Goal(Struct(goal.name + DELTA, goal.args))
                body = Conjunction(tuple(literals), body.text)
            query = CompiledQuery(body, self._exclusive_of if exclusive else _never, self._computed)
            self._variants[key] = query
        return query

    def _exclusive_of(self, name: str) -> bool:
        if "#" in name:
            return False if name.endswith((DELTA, GONE)) else self._exclusive(name[: -len(STORED)])
        return name not in self._names and self._exclusive(name)

    def _deltas(self, inputs: dict[Signature, dict]) -> _Deltas:
        return _Deltas(self.view, inputs)

    def _resized(self, signature: Signature) -> None:
        size = len(self.derived[signature].rows)
        if not size & (size - 1):
            self._epoch += 1


def _named(layer: _Layer, rule: Rule) -> Rule:
    """The rule a refusal names: ``rule`` itself, or for the internal ``p :- p#stored`` one a rule written for p."""
    return rule if rule.file or rule.line else _rule_of(layer, rule.head.signature)


def _rule_of(layer: _Layer, signature: Signature) -> Rule:
    """The first rule of ``layer`` deriving ``signature`` (named when storing its beliefs is refused)."""
    return next((r for r in layer.rules if r.head.signature == signature and r.file), layer.rules[0])


def _version(rel: Relation) -> int:
    return rel.version


class _Deltas:
    """Puts ``name#delta`` relations (or another ``suffix``) in the view for the rules' delta goals, and takes them
    out after."""

    def __init__(self, view: Relations, inputs: dict[Signature, dict], suffix: str = DELTA) -> None:
        self.view, self.inputs, self.suffix = view, inputs, suffix

    def __enter__(self) -> None:
        for (name, arity), rows in self.inputs.items():
            rel = Relation(name + self.suffix, arity, False, lazy=True)
            rel.rows = rows if type(rows) is dict else dict.fromkeys(rows)  # read, never changed, while it is here
            self.view[(name + self.suffix, arity)] = rel

    def __exit__(self, *exc: object) -> None:
        for name, arity in self.inputs:
            self.view.pop((name + self.suffix, arity), None)


def _flat_head(head: Struct) -> bool:
    """Whether every argument of ``head`` is a variable, none twice (its rows can be read as a goal's)."""
    args = head.args
    return all(type(a) is Var and not a.anonymous for a in args) and len(set(args)) == len(args)


def _positive_goals(rule: Rule) -> list[tuple[int, Signature]]:
    return [(j, lit.term.signature) for j, lit in enumerate(rule.body.literals) if type(lit) is Goal]


def _never(name: str) -> bool:
    return False


__all__ = ["STORED", "RuleBook"]
