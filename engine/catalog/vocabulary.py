"""Reading a catalog's belief vocabulary: its predicates and its rules, each problem with the file's line.

Rules (``rules:``, a block of text or a list of rules, in the belief language's rule syntax) derive
predicates of their own; they are checked against the catalog's predicates (a rule may not derive a stored
or computed one) and become declarations (``derived``) that missions' expressions are checked against.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping

from aeroexec.beliefs import BeliefError, Conjunction, Rule, RuleError, RuleProblem, parse_rules
from aeroexec.engine.catalog.descriptors import PredicateDeclaration
from aeroexec.engine.yaml_nodes import NodeReader

from aeroexec.lazy import lazy_module
from aeroexec.limits import RULES_WORK_PER_STEP, RULES_WORK_WHY

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

    import yaml
    from aeroexec.beliefs import BeliefMemory
else:  # PyYAML is imported when a text is read, not with this module (a catalog or world kept parsed reads none)
    yaml = lazy_module("yaml")


def check_rules(predicates: Mapping[str, PredicateDeclaration], rules: Iterable[Rule]) -> list[RuleProblem]:
    """Every problem of ``rules`` against the declared ``predicates`` (derived declarations left out), and the
    evaluations that would pass the bound of rules in flight (:data:`~aeroexec.limits.RULES_WORK_PER_STEP`) over
    the facts given with them."""
    from aeroexec.beliefs import BeliefMemory  # here: checking rules needs it, not a catalog kept parsed

    rules = list(rules)
    stored = {p.name: p.arity for p in predicates.values() if not p.computed and not p.derived}
    memory = BeliefMemory(predicates=stored)
    for p in predicates.values():
        if p.computed:
            memory.register(p.name, p.arity, _never, inputs=max(0, p.arity - 1))
    try:  # the facts too: a fact declares its predicate (zone(z1). makes zone/1 known to the rules)
        memory.add_rules(rules)
    except RuleError as error:
        return error.problems
    memory.limit_rules(RULES_WORK_PER_STEP, RULES_WORK_WHY)  # what flies is tried as it will fly, with the facts
    return memory.try_rules()


def derived_declarations(rules: Iterable[Rule], predicates: Mapping[str, PredicateDeclaration]
                         ) -> dict[str, PredicateDeclaration]:
    """Declarations of what ``rules`` derive, and of the predicates of their facts not declared yet (sets)."""
    found: dict[str, PredicateDeclaration] = {}
    for rule in rules:
        name, arity = rule.head.signature
        if rule.body.literals:
            found.setdefault(name, PredicateDeclaration(name, arity, multivalued=True, derived=True,
                                                        description=f"derived by the rule at {rule.where}",
                                                        line=rule.line))
        elif name not in predicates:
            found.setdefault(name, PredicateDeclaration(name, arity, multivalued=True, line=rule.line))
    return found


def _never(*args: object) -> None:
    return None


class VocabularySections:
    """The catalog reader's ``predicates:`` and ``rules:`` sections, and the belief expressions checked against them
    (mixed into :class:`~aeroexec.engine.catalog.loader.CatalogReader`)."""

    r: NodeReader
    content: Any
    _vocabulary: BeliefMemory | None

    def _predicates(self, node: yaml.Node) -> None:
        keys = ("predicate", "arity", "multivalued", "persistence", "computed", "values", "aliases", "description")
        for item in self.r.sequence(node, "predicates") or ():
            e = self.r.mapping(item, "a predicate", keys)
            if e is None or not self._required(e, item, "predicate", "a predicate"):
                continue
            name = self.r.text(e["predicate"][1], "predicate")
            arity = self.r.integer(e["arity"][1], f"the arity of {name}") if "arity" in e else None
            if "arity" not in e:
                self.r.error(item, f"predicate {name}: arity is missing")
            if name is None or arity is None:
                continue
            if name in self.content.predicates:
                self.r.error(item, f"predicate {name} is declared twice (first at line "
                                   f"{self.content.predicates[name].line})")
                continue
            persistence = None
            if "persistence" in e and self.r.text(e["persistence"][1], "persistence") != "permanent":
                persistence = self.r.number(e["persistence"][1], f"the persistence of {name} (seconds or permanent)",
                                            positive=True)
            self.content.predicates[name] = PredicateDeclaration(
                name, arity,
                multivalued=bool("multivalued" in e and self.r.flag(e["multivalued"][1], "multivalued")),
                persistence=persistence,
                computed=bool("computed" in e and self.r.flag(e["computed"][1], "computed")),
                values=tuple(v for v, _ in self.r.names(e["values"][1], f"the values of {name}")) if "values" in e
                else (), aliases=self._aliases(e["aliases"][1], name) if "aliases" in e else {},
                description=self._description(e), line=item.start_mark.line + 1)

    def _aliases(self, node: yaml.Node, predicate: str) -> dict[str, tuple[str, ...]]:
        """``aliases: {flying: [hovering, moving]}``: names for several values of a predicate."""
        entries = self.r.mapping(node, f"the aliases of {predicate}") or {}
        return {alias: tuple(v for v, _ in self.r.names(value, f"the alias {alias} of {predicate}"))
                for alias, (_, value) in entries.items()}

    def _rules(self, node: yaml.Node) -> None:
        """``rules:`` as one block of text (``|``) or a list of rules, read with the lines they are at."""
        items = node.value if isinstance(node, yaml.SequenceNode) else [node]
        rules: list[Rule] = []
        for item in items:
            text = self.r.text(item, "a rule")
            if not text:
                continue
            first = item.start_mark.line + (2 if getattr(item, "style", None) in ("|", ">") else 1)
            try:
                rules += parse_rules(text, self.r.file, first)
            except RuleError as error:
                for problem in error.problems:
                    self.r.error_at(problem.line or first, problem.message)
        problems = check_rules(self.content.predicates, rules)
        for problem in problems:
            self.r.error_at(problem.line, problem.message)
        if not problems:
            self.content.rules.extend(rules)
            self.content.predicates.update(derived_declarations(rules, self.content.predicates))
            self._vocabulary = None

    def _expression(self, node: yaml.Node, what: str) -> Conjunction | None:
        if node.tag == "tag:yaml.org,2002:seq":  # a list of expressions is their conjunction
            parts = [self.r.text(item, what) for item in node.value]
            text = ", ".join(p for p in parts if p)
        else:
            text = self.r.text(node, what)
        if not text:
            return None
        try:
            return self._memory().check(text)
        except BeliefError as exc:
            self.r.error(node, f"{what}: {exc.message}")
            return None

    def _memory(self) -> BeliefMemory:
        if self._vocabulary is None:
            from aeroexec.beliefs import BeliefMemory

            self._vocabulary = BeliefMemory(predicates={p.name: p.arity for p in self.content.predicates.values()})
        return self._vocabulary



__all__ = ["VocabularySections", "check_rules", "derived_declarations"]
